//! Planning through task-relevant roadmaps (Stollenga et al., IROS 2013, end of Section IV):
//! A* over one or several maps joined through their common configuration space, with edges and
//! nodes checked lazily against the *current* world (as OMPL's LazyPRM does), then shortcutting
//! and time-optimal timing within velocity and acceleration limits ([`timing`]: blends that
//! stay collision-free, TOPP-RA).
//!
//! ```no_run
//! use trm_plan::{Goal, Planner, PlanOptions};
//! let map = trm_roadmap::Roadmap::load("target/maps/reach.map.json")?;
//! let problem = map.problem()?;
//! let mut planner = Planner::new(&problem.objective, &[&map])?;
//! let plan = planner.plan(&problem.start, &Goal::TaskPoint { t: vec![-0.3, 0.1, 0.1], tolerance: 0.03 }, &PlanOptions::default())?;
//! println!("{} waypoints, {:.2} s", plan.trajectory.positions.len(), plan.trajectory.times.last().unwrap());
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

mod error;
mod planner;
pub mod pose_goal;
mod query;
pub mod rrt;
mod samples;
pub mod scenario;
mod simplify;
pub mod timing;
mod trajectory;

pub use error::PlanError;
pub use planner::{
    Connection, EXPERIENCE_FORMAT, EXPERIENCE_VERSION, GOAL_ATTEMPTS, GRAPH_MEMORY,
    GRAPH_SEARCH_WORK, GRAPH_TURNS, HEAD_START_SAMPLES, MAX_GRAPH_SEARCHES, Planner,
    RETRIEVE_STEPS, ROUND_GROWTH, Source,
};
pub use query::{EXACT_WEIGHT, ExactGoal, Goal, PlanOptions, PlanStats, Planned};
pub use scenario::{
    Action, Scenario, ScenarioError, ScenarioOptions, ScenarioRun, StepReport, run_scenario,
};
pub use timing::Timing;
pub use trajectory::{Trajectory, time_parametrise};
