//! One problem solved by RRT-Connect on any robot model, and a path proved free in continuous
//! motion.

use trm_collision::CollisionModel;
use trm_kinematics::RobotModel;
use trm_moveit::{MotionPlanRequest, PlanningScene, motors_from_state};
use trm_plan::Planner;
use trm_plan::rrt::{RrtOptions, path_length};
use trm_roadmap::Roadmap;
use trm_tasks::Objective;

use crate::error::MbmError;
use crate::loaded::LoadedProblem;

pub use trm_moveit::LIMIT_SLACK;
pub use trm_plan::GOAL_ATTEMPTS;

/// How one problem went.
#[derive(Debug, Clone, Default, PartialEq, serde::Serialize)]
pub struct Outcome {
    /// Start and goal are collision-free and within limits (a problem that is not valid is
    /// left out of the solved rate, as VAMP's and OMPL's reports do).
    pub valid: bool,
    /// A path was found.
    pub solved: bool,
    /// Planning time (checks, search, shortcutting; not reading the files), s.
    pub seconds: f64,
    /// Of [`Outcome::seconds`], the time spent simplifying the path (shortcutting and checking
    /// it again), s: the rest is planning alone.
    pub simplify_seconds: f64,
    /// Building the obstacles' structures for this problem (a point cloud's: for trm the
    /// world object and the screen's grid, for VAMP its CAPT), s; not in [`Outcome::seconds`].
    pub build_seconds: f64,
    /// Path length, rad.
    pub length: f64,
    /// Waypoints of the path.
    pub waypoints: usize,
    /// Configurations checked for collision.
    pub checks: u64,
    /// Why it is invalid or unsolved.
    pub note: String,
    /// The path (start to goal, active motors).
    pub path: Vec<Vec<f64>>,
}

/// Solves one problem for `robot` with `collision` (built once per set), by RRT-Connect;
/// `options.max_seconds` falls back to the request's `allowed_planning_time` when absent.
/// For a problem solved or checked more than once, prepare it once ([`LoadedProblem`]) and
/// call [`solve_loaded`].
pub fn solve(
    robot: &RobotModel,
    collision: &CollisionModel,
    scene: &PlanningScene,
    request: &MotionPlanRequest,
    options: &RrtOptions,
) -> Result<Outcome, MbmError> {
    let problem = LoadedProblem::new(collision, scene.clone(), request.clone())?;
    solve_loaded(robot, &problem, options)
}

/// [`solve`] of a prepared problem.
pub fn solve_loaded(
    robot: &RobotModel,
    problem: &LoadedProblem,
    options: &RrtOptions,
) -> Result<Outcome, MbmError> {
    solve_with_maps(robot, problem, options, &[])
}

/// [`solve_loaded`] with `maps` (built for the request's group) attached to the planner
/// ([`Planner::add_map`]: their nodes and edges checked in the problem's scene when the search
/// first wants them).
pub fn solve_with_maps(
    robot: &RobotModel,
    problem: &LoadedProblem,
    options: &RrtOptions,
    maps: &[Roadmap],
) -> Result<Outcome, MbmError> {
    Solver::new(robot, maps).solve(problem, options)
}

/// Solves problems one after the other through kept planners, as a user keeps one planner
/// per robot ([`Planner`]): one per planning group, `maps` attached once; each problem's
/// matrix and scene are set on it ([`Planner::set_collision`], [`Planner::set_world`]: what
/// changed compiled again) before its query is timed, as VAMP builds a problem's environment
/// before its timing starts. The outcome of a problem does not depend on the ones before.
#[derive(Debug)]
pub struct Solver<'a> {
    robot: &'a RobotModel,
    maps: &'a [Roadmap],
    /// The planners made so far, by the active motors they move.
    planners: Vec<(Vec<usize>, Planner)>,
}

impl<'a> Solver<'a> {
    /// A solver of `robot`'s problems with `maps` attached to its planners.
    pub fn new(robot: &'a RobotModel, maps: &'a [Roadmap]) -> Self {
        Solver {
            robot,
            maps,
            planners: Vec::new(),
        }
    }

    /// Solves `problem` as [`solve_with_maps`] does, through the planner kept for its group.
    pub fn solve(
        &mut self,
        problem: &LoadedProblem,
        options: &RrtOptions,
    ) -> Result<Outcome, MbmError> {
        options.check()?;
        let (request, world) = (&problem.request, &problem.world);
        let (objective, active, start) =
            problem_objective(self.robot, &problem.own, world, request)?;
        let k = match self.planners.iter().position(|(a, _)| *a == active) {
            Some(k) => k,
            None => {
                // compiled once per group, for the IK of a task-space goal, the validity
                // checks and the search
                let mut planner = Planner::new(&objective, &[])?;
                for map in self.maps {
                    planner.add_map(map)?;
                }
                self.planners.push((active.clone(), planner));
                self.planners.len() - 1
            }
        };
        let planner = &mut self.planners[k].1;
        planner.set_collision(&problem.collision)?;
        planner.set_world(world.clone());
        let maps = !self.maps.is_empty();
        solve_on(self.robot, planner, maps, problem, &active, start, options)
    }
}

/// [`Solver::solve`] on `planner`, set for `problem`'s group, matrix and scene, with `maps`
/// attached or not (`start`: the request's start, active motors).
fn solve_on(
    robot: &RobotModel,
    planner: &mut Planner,
    maps: bool,
    problem: &LoadedProblem,
    active: &[usize],
    mut start: Vec<f64>,
    options: &RrtOptions,
) -> Result<Outcome, MbmError> {
    let request = &problem.request;
    let mut goal = request.goal.positions.clone();
    let mut outcome = Outcome {
        note: problem.notes.join("; "),
        build_seconds: problem.cloud.map_or(0.0, |c| c.build_seconds),
        ..Default::default()
    };
    // time spent finding a goal configuration for a task-space goal (part of the answer)
    let mut goal_seconds = 0.0;
    if !request.pose_goal.is_empty() {
        let root = &robot.tree().links[0].name;
        if let Some(frame) = request.pose_goal.foreign_frame(root) {
            return Err(MbmError::Invalid {
                path: request.origin.clone(),
                line: 0,
                problem: format!("a goal constraint is given in frame `{frame}`"),
                fix: format!("give it in the robot's root frame `{root}`"),
            });
        }
        let started = std::time::Instant::now();
        let found = planner.solve_pose(&start, &request.pose_goal, options.seed)?;
        goal_seconds = started.elapsed().as_secs_f64();
        match found {
            Some(q) => goal = q,
            None => {
                outcome.valid = true;
                outcome.note = format!(
                    "no collision-free configuration meets the task-space goal ({GOAL_ATTEMPTS} IK starts)"
                );
                return Ok(outcome);
            }
        }
    }
    if let Some(why) = invalid(robot, active, &mut start, &mut goal, planner) {
        outcome.note = why;
        return Ok(outcome);
    }
    outcome.valid = true;
    let options = RrtOptions {
        max_seconds: options.max_seconds.or(request.planning_time),
        ..options.clone()
    };
    match planner.connect(&start, &goal, &options) {
        Ok(found) => {
            outcome.solved = true;
            outcome.seconds = goal_seconds + found.seconds;
            outcome.simplify_seconds = found.simplify_seconds;
            outcome.length = path_length(&found.path);
            outcome.waypoints = found.path.len();
            outcome.checks = found.checks;
            outcome.path = found.path;
            if maps {
                // how the maps served, after the problem's own notes
                let source = found.source.name();
                outcome.note = match outcome.note.is_empty() {
                    true => source.into(),
                    false => format!("{}; {source}", outcome.note),
                };
            }
        }
        Err(e) => outcome.note = e.to_string(),
    }
    Ok(outcome)
}

/// Refuses a task-space goal where only joint goals are handled (`what`).
pub(crate) fn joint_goal_only(request: &MotionPlanRequest, what: &str) -> Result<(), MbmError> {
    if request.pose_goal.is_empty() {
        return Ok(());
    }
    Err(MbmError::Invalid {
        path: request.origin.clone(),
        line: 0,
        problem: format!("a task-space goal: {what} take joint goals"),
        fix: "give joint constraints, or solve task-space goals with mbm::solve (benchmark-mbm without --experience/--vamp)".into(),
    })
}

/// Why a problem is invalid (`None`: start and goal within the limits of the `active` motors
/// and free for `planner`); a colliding start or goal names its pairs
/// ([`Planner::collisions`]). Values within [`LIMIT_SLACK`] outside a limit are clamped onto it.
pub(crate) fn invalid(
    robot: &RobotModel,
    active: &[usize],
    start: &mut [f64],
    goal: &mut [f64],
    planner: &mut Planner,
) -> Option<String> {
    let within = |q: &mut [f64]| {
        active.iter().zip(q).all(|(&i, v)| {
            let limits = &robot.motors()[i].limits;
            let inside = (limits.lower - LIMIT_SLACK..=limits.upper + LIMIT_SLACK).contains(v);
            *v = v.clamp(limits.lower, limits.upper);
            inside
        })
    };
    let mut collides = |what: &str, q: &[f64]| {
        (!planner.is_free(q))
            .then(|| format!("the {what} collides: {}", planner.collisions(q).join("; ")))
    };
    if !within(start) {
        Some("the start is outside the joint limits".into())
    } else if let Some(why) = collides("start", start) {
        Some(why)
    } else if !within(goal) {
        Some("the goal is outside the joint limits".into())
    } else {
        collides("goal", goal)
    }
}

/// The floor of the independent check ([`certify_path`]), m: 1 nm, finer than the planner's
/// own proofs' ([`trm_collision::certify::DEFAULT_FLOOR`], 1 µm), so that a motion the
/// planner proved (bisected at other points) is proved again unless it passes within a
/// nanometre of contact: a shortcut path pulled tight along a box can pass within a
/// micrometre of it.
pub const VERIFY_FLOOR: f64 = 1e-9;

/// What certification proved about a path ([`certify_path`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Verdict {
    /// Free in continuous motion.
    Proved,
    /// A configuration along it collides.
    Collides,
    /// Not proved: it comes within the check's floor of contact ([`VERIFY_FLOOR`]).
    Unproved,
}

impl std::fmt::Display for Verdict {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Verdict::Proved => "proved",
            Verdict::Collides => "collides",
            Verdict::Unproved => "unproved",
        })
    }
}

/// Whether `path` (the request's active motors, as a planner for it returns them) is free in
/// continuous motion in the problem's world, proved by [`trm_collision::Certifier`]: `f64`,
/// exact distances and lever-arm bounds, independent of the points and the precision of the
/// planner that made the path (and so usable on any planner's paths).
pub fn certify_path(
    robot: &RobotModel,
    collision: &CollisionModel,
    scene: &PlanningScene,
    request: &MotionPlanRequest,
    path: &[Vec<f64>],
) -> Result<Verdict, MbmError> {
    let problem = LoadedProblem::new(collision, scene.clone(), request.clone())?;
    certify_path_loaded(robot, &problem, path)
}

/// [`certify_path`] in a prepared problem.
pub fn certify_path_loaded(
    robot: &RobotModel,
    problem: &LoadedProblem,
    path: &[Vec<f64>],
) -> Result<Verdict, MbmError> {
    let active = problem.request.active_set(robot, &neutral(robot))?;
    let mut certifier =
        trm_collision::Certifier::new(&problem.collision, &active)?.with_floor(VERIFY_FLOOR)?;
    let certificate = certifier.path(&problem.world, path)?;
    Ok(match certificate.failure {
        None => Verdict::Proved,
        Some((_, trm_collision::Certificate::Collides { .. })) => Verdict::Collides,
        Some(_) => Verdict::Unproved,
    })
}

/// Every motor at 0 clamped into its limits: where a request's start state is silent.
fn neutral(robot: &RobotModel) -> Vec<f64> {
    robot
        .motors()
        .iter()
        .map(|m| 0.0f64.clamp(m.limits.lower, m.limits.upper))
        .collect()
}

/// The objective of a request in `world`: the goal's joints active, every other motor where
/// the start state puts it (clamped into its limits); with the active motors' indices and the
/// start's active values.
pub(crate) fn problem_objective(
    robot: &RobotModel,
    collision: &CollisionModel,
    world: &trm_collision::World,
    request: &MotionPlanRequest,
) -> Result<(Objective, Vec<usize>, Vec<f64>), MbmError> {
    let base = neutral(robot);
    let active_set = request.active_set(robot, &base)?;
    let active = active_set.motor_indices().to_vec();
    let (start_motors, _) = motors_from_state(robot, &request.start, &base);
    let start: Vec<f64> = active.iter().map(|&i| start_motors[i]).collect();
    Ok((
        Objective::new(active_set, collision.clone(), world.clone()),
        active,
        start,
    ))
}
