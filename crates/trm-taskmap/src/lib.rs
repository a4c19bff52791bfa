//! Task maps (Gienger, Toussaint and Goerick, "Task maps in humanoid robot manipulation",
//! IROS 2008, Section II and eq. 18–19): a set of feasible points g in a 6-D goal space (the
//! position and rotation vector of a hand relative to an object) for which an evaluation C(g)
//! exceeds a threshold θ, explored with the paper's RRT scheme — plus restarts, so that disjoint
//! clusters are found too — and the task-map cost c_map = (x − x_map)ᵀ W (x − x_map) to the
//! nearest map element, with its gradient.
//!
//! ```
//! use trm_taskmap::{ExploreOptions, Metric, explore};
//! // feasible: anywhere along a 20 cm stick (x), within 1 cm of its axis, any roll about it
//! let feasible = |g: &[f64; 6]| 0.01 - g[1].abs().max(g[2].abs()).max(g[4].abs() / 20.0).max(g[5].abs() / 20.0)
//!     .max(g[0].abs() - 0.1);
//! let settings = ExploreOptions { iterations: 3000, ..ExploreOptions::around([0.0; 6], [0.15, 0.02, 0.02, 3.2, 0.3, 0.3]) };
//! let map = explore(&[[0.0; 6]], &settings, &Metric::default(), feasible)?;
//! assert!(map.points.len() > 50);
//! # Ok::<(), trm_taskmap::TaskMapError>(())
//! ```

mod explore;
mod grasp;
mod map;
mod motion;
mod spec;

pub use explore::{ExploreOptions, explore};
pub use grasp::{Finger, GraspResult, Hand, find_grasp};
pub use map::{Metric, TaskMap, TaskMapError, TaskPoint, to_params, to_pose};
pub use motion::{CostWeights, Motion, MotionGoal, MotionOptions, ReachProblem, grasp_axis};
pub use spec::{
    ExploreSpec, Explored, LoadedTaskMapSpec, Reach, SearchSpec, TaskMapSpec, placement,
};

/// The readers a task spec needs to name task maps (`TaskMap(file: …)` costs of trm-tasks, read
/// as [`TaskMap`] files): pass them where the spec is resolved
/// ([`trm_tasks::Problem::load_with`], `Roadmap::problem_with`).
pub fn loaders() -> trm_tasks::SpecLoaders {
    trm_tasks::SpecLoaders {
        pose_maps: Some(|path| {
            TaskMap::load(path)
                .map(|m| std::sync::Arc::new(m) as std::sync::Arc<dyn trm_tasks::PoseMap>)
                .map_err(|e| e.to_string())
        }),
    }
}

/// The file formats this crate reads and writes.
pub mod formats {
    #[doc = include_str!("../docs/task-map-spec.md")]
    pub mod task_map_spec {}
}
