//! A set run problem by problem, in parallel, with an optional task-space form of each goal.

use trm_collision::CollisionModel;
use trm_kinematics::RobotModel;
use trm_moveit::{MotionPlanRequest, PlanningScene};
use trm_plan::rrt::RrtOptions;

use crate::error::MbmError;
use crate::problems::Problem;
use crate::solve::{Outcome, path_is_free, solve};

/// One problem of a benchmark run and how it went.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Run {
    /// Its family.
    pub family: String,
    /// Its number in the family.
    pub index: u32,
    /// The planner's outcome.
    pub outcome: Outcome,
    /// With verification: whether the path is free when re-checked one configuration at a time
    /// at half the resolution ([`path_is_free`]).
    pub verified: Option<bool>,
}

/// A set's joint goals posed as task-space goals ([`MotionPlanRequest::to_task_space`]).
#[derive(Debug, Clone, PartialEq)]
pub struct TaskSpaceGoals {
    /// The link whose pose is the goal (e.g. the hand).
    pub link: String,
    /// Side of the cube the link's origin must reach, m.
    pub position_tolerance: f64,
    /// Tolerance about each axis, rad.
    pub orientation_tolerance: f64,
}

/// Solves each problem by RRT-Connect + shortcutting ([`solve`]), re-checking solved paths
/// when `verify`; with `task_space`, each joint goal is first turned into the task-space goal
/// it implies. `progress(done, problem)` after each.
pub fn run_set(
    robot: &RobotModel,
    collision: &CollisionModel,
    problems: &[Problem],
    options: &RrtOptions,
    verify: bool,
    task_space: Option<&TaskSpaceGoals>,
    mut progress: impl FnMut(usize, &Problem),
) -> Result<Vec<Run>, MbmError> {
    let mut runs = Vec::with_capacity(problems.len());
    for (k, p) in problems.iter().enumerate() {
        let scene = PlanningScene::load(&p.scene)?;
        let mut request = MotionPlanRequest::load(&p.request)?;
        if let Some(t) = task_space {
            request = request.to_task_space(
                robot,
                &t.link,
                t.position_tolerance,
                t.orientation_tolerance,
            )?;
        }
        let outcome = solve(robot, collision, &scene, &request, options)?;
        let verified = (verify && outcome.solved)
            .then(|| {
                path_is_free(
                    robot,
                    collision,
                    &scene,
                    &request,
                    &outcome.path,
                    options.resolution / 2.0,
                )
            })
            .transpose()?;
        runs.push(Run {
            family: p.family.clone(),
            index: p.index,
            outcome,
            verified,
        });
        progress(k + 1, p);
    }
    Ok(runs)
}
