//! The cost and task catalogue of task-relevant roadmaps, RON task specs, and NGIK.
//!
//! A posture is whatever minimises a weighted sum of cost functions h = Σ aᵢ hᵢ(p, q, w) over the
//! robot's poses p, its active motors q and the world w (Table I of Stollenga et al., IROS
//! 2013); a task function g(p, q, w) (Table II) maps it to the task space roadmaps cover.
//! [`Problem::load`] reads a spec (format: [`formats::task_spec`]); [`solve`] runs NGIK:
//!
//! ```
//! let spec = r#"(
//!     model: "icub_upper_body",
//!     active: ["torso", "right_arm"],
//!     costs: [
//!         (weight: 1.0, cost: HomePosture()),
//!         (weight: 10.0, cost: Collision()),
//!         (weight: 20.0, cost: Position(part: "r_palm_center", target: Point((-0.25, 0.15, 0.1)))),
//!     ],
//!     solver: (max_evaluations: 3000, seed: 1),
//! )"#;
//! let problem = trm_tasks::Problem::from_ron(spec, "<example>", std::path::Path::new("."))?;
//! let solution = trm_tasks::solve(&problem.objective, &problem.start, &problem.spec.solver)?;
//! assert!(solution.cost < 2.0 && solution.collision_free);
//! # Ok::<(), trm_tasks::TaskError>(())
//! ```
//!
//! The catalogue is closed in the file format and open in code: implement [`Cost`] or
//! [`TaskFunction`] and add it to an [`Objective`]. Populations are evaluated in batches of
//! [`trm_kinematics::LANES`] ([`Objective::eval_batch`]); a term written against [`Frames`] (as
//! every catalogue term is) reads each lane of a batch in place and gives the one-candidate
//! value bit for bit.

mod comparison;
mod context;
pub mod costs;
mod error;
mod ngik;
mod objective;
mod pool;
pub mod spec;
pub mod tasks;

pub use comparison::{Comparison, ComparisonResult, ComparisonRun, ComparisonSummary};
pub use context::{Anchor, BatchContext, Context, Frames, LaneView};
pub use costs::{Cost, PoseMap, PoseMapLoader, SpecLoaders, TaskTarget};
pub use error::{Result, TaskError};
pub use ngik::{Solution, solve, solve_with, solver_start};
pub use objective::{Clearance, Objective, Scratch, TermValue};
pub use pool::{Lease, ScratchPool};
pub use spec::{Problem, Spec};
pub use tasks::TaskFunction;

/// The file formats this crate reads and writes.
pub mod formats {
    #[doc = include_str!("../docs/task-spec.md")]
    pub mod task_spec {}
}
