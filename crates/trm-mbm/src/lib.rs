//! MotionBenchMaker problem sets (Chamzas et al., 2022): a folder per problem family, each
//! holding `sceneNNNN.yaml` (a MoveIt planning scene) and `requestNNNN.yaml` (a motion plan
//! request with a joint goal). [`solve()`] answers one problem with RRT-Connect on any robot
//! model: the active motors are the joints the goal constrains, every other motor stays where
//! the start state puts it (clamped into its limits).
//!
//! [`ProblemSet::open`] reads a set (a folder or a `.tar.bz2`), [`benchmark`] solves it
//! (plain, with a task-space form of each goal, with experience kept:
//! [`solve_with_experience`]; every problem read and prepared once: [`LoadedProblem`]), [`markdown_table`] and [`side_by_side`] report it the way the
//! field does, [`peer_problems`] and [`parse_peer_results`] exchange it with VAMP and OMPL, and
//! [`generate`](generate::generate) writes new sets for any robot from a task spec.

mod error;
mod experience;
pub mod generate;
mod loaded;
mod peers;
mod problems;
mod report;
mod run;
mod solve;

pub use error::{MbmError, Result};
pub use experience::{LeaveOneOut, Scope, solve_leave_one_out, solve_with_experience};
pub use loaded::LoadedProblem;
pub use peers::{
    CLOUD_POINT_RADIUS, CLOUD_SPACING, CloudBuild, Obstacles, cloud_world, parse_peer_results,
    peer_objects, peer_problems, vamp_world,
};
pub use problems::{Problem, ProblemSet, find_problems, rrt_options_for};
pub use report::{Summary, markdown_table, quantile, runs_csv, side_by_side};
pub use run::{
    Benchmark, BenchmarkOptions, Run, TaskSpaceGoals, benchmark, run_set, verdicts_line,
};
pub use solve::{
    GOAL_ATTEMPTS, LIMIT_SLACK, Outcome, Solver, VERIFY_FLOOR, Verdict, certify_path,
    certify_path_loaded, solve, solve_loaded, solve_with_maps,
};
