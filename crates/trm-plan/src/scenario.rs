//! Scenarios: a map's world with objects that move, appear and vanish, and a sequence of task
//! goals; [`run_scenario`] steps one at a fixed rate — the world changes, the map is kept valid
//! ([`LiveMap`]: invalidation, parking and restoring), repaired within a budget, and the robot
//! replans whenever its goal changes or the rest of its motion is blocked, then moves on.
//!
//! Spec (RON; times in seconds, positions in metres, angles as URDF roll-pitch-yaw):
//!
//! ```ron
//! (
//!     description: "a box slides across the table",
//!     duration: 4.0,
//!     rate: 10.0,                       // steps per second (default 10)
//!     objects: [
//!         (name: "box", shape: Box(size: (0.08, 0.06, 0.16)),
//!          path: [(t: 0.0, xyz: (-0.3, -0.3, -0.04)), (t: 4.0, xyz: (-0.3, 0.5, -0.04))]),
//!         (name: "can", shape: Cylinder(radius: 0.03, length: 0.12),
//!          path: [(t: 0.0, xyz: (-0.25, 0.1, 0.0))], appear: 2.0),
//!     ],
//!     goals: [(t: 0.0, to: [-0.3, 0.1, 0.0]), (t: 2.0, to: [-0.25, 0.2, 0.05])],
//! )
//! ```
//!
//! An object follows its keyframes piecewise linearly (held before the first and after the
//! last), is present from `appear` (default 0) until `vanish` (default never), and joins the
//! map's own world; the goal at time t is the last one whose `t` has come.

use std::path::Path;
use std::time::Instant;

use serde::Deserialize;
use trm_collision::edge::distance;
use trm_collision::{Shape, World};
use trm_io::SpecError;
use trm_kinematics::nalgebra::{Isometry3, Translation3, UnitQuaternion};
use trm_roadmap::{LiveMap, RepairOptions, Roadmap, RoadmapError};
use trm_tasks::Problem;

use crate::PlanError;
use crate::planner::Planner;
use crate::query::{Goal, PlanOptions};
use crate::trajectory::Trajectory;

/// What can go wrong with a scenario.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ScenarioError {
    /// The spec is malformed or does not fit the map.
    #[error(transparent)]
    Spec(Box<SpecError>),
    /// The spec file could not be read.
    #[error("{}: {source}", path.display())]
    Io {
        /// The file.
        path: std::path::PathBuf,
        /// The operating-system error.
        source: std::io::Error,
    },
    /// From keeping the map valid.
    #[error(transparent)]
    Roadmap(#[from] RoadmapError),
    /// From planning (not an unreachable goal: that is a step's outcome).
    #[error(transparent)]
    Plan(#[from] PlanError),
}

/// A keyframe of a moving object.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Keyframe {
    /// Time, s.
    pub t: f64,
    /// Position, m.
    pub xyz: [f64; 3],
    /// Orientation, roll-pitch-yaw, rad.
    #[serde(default)]
    pub rpy: [f64; 3],
}

/// An object of a scenario.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MovingObject {
    /// Unique name (not one of the map's world).
    pub name: String,
    /// Shape, as in world files.
    pub shape: Shape,
    /// Keyframes, times ascending (one keyframe: it stands still).
    pub path: Vec<Keyframe>,
    /// When it appears, s.
    #[serde(default)]
    pub appear: f64,
    /// When it vanishes, s (never when absent).
    #[serde(default)]
    pub vanish: Option<f64>,
}

/// A task goal from time `t` on.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TimedGoal {
    /// From when, s.
    pub t: f64,
    /// The task point.
    pub to: Vec<f64>,
}

fn ten() -> f64 {
    10.0
}

/// A scenario; see the module documentation.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Scenario {
    /// What happens, in words.
    #[serde(default)]
    pub description: String,
    /// Length, s.
    pub duration: f64,
    /// Steps per second.
    #[serde(default = "ten")]
    pub rate: f64,
    /// Objects added to the map's world.
    #[serde(default)]
    pub objects: Vec<MovingObject>,
    /// Task goals, times ascending.
    pub goals: Vec<TimedGoal>,
    /// Where the spec came from, and its text (for located errors found later).
    #[serde(skip)]
    source: (String, String),
}

/// The most steps a scenario may have.
pub const MAX_STEPS: usize = 100_000;

impl Scenario {
    /// Parses and checks a scenario; `origin` names it in errors.
    pub fn from_ron(text: &str, origin: &str) -> Result<Self, ScenarioError> {
        let mut scenario: Scenario = ron::from_str(text)
            .map_err(|e| ScenarioError::Spec(Box::new(SpecError::from_ron(&e, origin))))?;
        scenario.source = (origin.to_string(), text.to_string());
        let bad = |field: String, problem: String, fix: &str| {
            Err(ScenarioError::Spec(Box::new(SpecError::at(
                text, origin, &field, problem, fix,
            ))))
        };
        let d = scenario.duration;
        if !(d.is_finite() && d > 0.0) {
            return bad(
                "duration".into(),
                format!("{d} s"),
                "give a finite positive length in seconds",
            );
        }
        let r = scenario.rate;
        if !(r.is_finite() && r > 0.0 && (d * r).floor() < MAX_STEPS as f64) {
            return bad(
                "rate".into(),
                format!("{r} steps per second over {d} s"),
                &format!("give a finite positive rate with at most {MAX_STEPS} steps in all"),
            );
        }
        let ascending = |times: &mut dyn Iterator<Item = f64>| {
            let mut last = f64::NEG_INFINITY;
            for (k, t) in times.enumerate() {
                if !(t.is_finite() && t >= last) {
                    return Some(k);
                }
                last = t;
            }
            None
        };
        for (i, o) in scenario.objects.iter().enumerate() {
            if o.path.is_empty() {
                return bad(
                    format!("objects[{i}].path"),
                    "no keyframe".into(),
                    "give at least one (t: 0.0, xyz: (x, y, z))",
                );
            }
            if let Some(k) = ascending(&mut o.path.iter().map(|f| f.t)) {
                return bad(
                    format!("objects[{i}].path[{k}].t"),
                    format!("{} s", o.path[k].t),
                    "give finite keyframe times in ascending order",
                );
            }
            for (k, f) in o.path.iter().enumerate() {
                if !f.xyz.iter().chain(&f.rpy).all(|v| v.is_finite()) {
                    return bad(
                        format!("objects[{i}].path[{k}]"),
                        "a non-finite position or angle".into(),
                        "give finite numbers",
                    );
                }
            }
            let vanish = o.vanish.unwrap_or(f64::INFINITY);
            if !(o.appear.is_finite() && vanish > o.appear) {
                return bad(
                    format!("objects[{i}].appear"),
                    format!("appears at {} s, vanishes at {vanish} s", o.appear),
                    "give a finite appear time before vanish",
                );
            }
            if let Some(j) = scenario.objects[..i].iter().position(|p| p.name == o.name) {
                return bad(
                    format!("objects[{i}].name"),
                    format!("`{}` is also objects[{j}]", o.name),
                    "give every object its own name",
                );
            }
        }
        if scenario.goals.is_empty() {
            return bad(
                "goals".into(),
                "no goal".into(),
                "give at least one (t: 0.0, to: (x, y, z))",
            );
        }
        if let Some(k) = ascending(&mut scenario.goals.iter().map(|g| g.t)) {
            return bad(
                format!("goals[{k}].t"),
                format!("{} s", scenario.goals[k].t),
                "give finite goal times in ascending order",
            );
        }
        if let Some(k) = scenario
            .goals
            .iter()
            .position(|g| g.to.is_empty() || !g.to.iter().all(|v| v.is_finite()))
        {
            return bad(
                format!("goals[{k}].to"),
                "an empty or non-finite task point".into(),
                "give the task point's finite coordinates",
            );
        }
        // every object must be a valid world object
        for (i, o) in scenario.objects.iter().enumerate() {
            if let Err(e) = World::new().add(&o.name, o.shape.clone(), pose_at(&o.path, 0.0)) {
                return bad(format!("objects[{i}].shape"), e.to_string(), "");
            }
        }
        Ok(scenario)
    }

    /// Reads and checks a scenario file.
    pub fn load(path: impl AsRef<Path>) -> Result<Self, ScenarioError> {
        let path = path.as_ref();
        let text = trm_io::read_input(path).map_err(|source| ScenarioError::Io {
            path: path.to_path_buf(),
            source,
        })?;
        Self::from_ron(&text, &path.display().to_string())
    }

    /// An error about `field` of this scenario's spec, located in its text.
    fn error(&self, field: &str, problem: String, fix: String) -> ScenarioError {
        let (origin, text) = &self.source;
        let origin = if origin.is_empty() {
            "scenario"
        } else {
            origin
        };
        ScenarioError::Spec(Box::new(SpecError::at(text, origin, field, problem, fix)))
    }

    /// The number of steps (times 0, 1/rate, … up to the duration).
    pub fn steps(&self) -> usize {
        (self.duration * self.rate + 1e-9).floor() as usize + 1
    }

    /// `base` with the scenario's objects present at time `t`, at their poses then.
    pub fn world_at(&self, base: &World, t: f64) -> Result<World, trm_collision::CollisionError> {
        let mut world = base.clone();
        for o in &self.objects {
            if t < o.appear || o.vanish.is_some_and(|v| t >= v) {
                continue;
            }
            world.add(&o.name, o.shape.clone(), pose_at(&o.path, t))?;
        }
        Ok(world)
    }

    /// The goal at time `t` (the last whose time has come), if any.
    pub fn goal_at(&self, t: f64) -> Option<&[f64]> {
        self.goals
            .iter()
            .rev()
            .find(|g| g.t <= t + 1e-9)
            .map(|g| g.to.as_slice())
    }
}

/// The pose along keyframes at `t`: piecewise linear position, orientation interpolated on
/// the sphere; held outside.
fn pose_at(path: &[Keyframe], t: f64) -> Isometry3<f64> {
    let pose = |f: &Keyframe| {
        Isometry3::from_parts(
            Translation3::new(f.xyz[0], f.xyz[1], f.xyz[2]),
            UnitQuaternion::from_euler_angles(f.rpy[0], f.rpy[1], f.rpy[2]),
        )
    };
    let next = path.iter().position(|f| f.t > t);
    match next {
        None => pose(&path[path.len() - 1]),
        Some(0) => pose(&path[0]),
        Some(k) => {
            let (a, b) = (&path[k - 1], &path[k]);
            let u = (t - a.t) / (b.t - a.t);
            pose(a).lerp_slerp(&pose(b), u)
        }
    }
}

/// Settings of a scenario run.
#[derive(Debug, Clone, PartialEq)]
pub struct ScenarioOptions {
    /// Repair budget per step, s (`None`: only the evaluation budget).
    pub repair_seconds: Option<f64>,
    /// Repair budget per step in evaluations (reproducible; `None`: only the time budget).
    /// With both budgets set, a repair stops at whichever is spent first.
    pub repair_evaluations: Option<u64>,
    /// Task-space tolerance of the map node a goal's path goes through.
    pub tolerance: f64,
    /// Task error at which a goal counts as reached (metres for positions).
    pub reached: f64,
    /// Planning settings (the exact finish included).
    pub plan: PlanOptions,
}

impl Default for ScenarioOptions {
    fn default() -> Self {
        ScenarioOptions {
            repair_seconds: Some(0.04),
            repair_evaluations: None,
            tolerance: 0.03,
            reached: 2e-3,
            plan: PlanOptions {
                exact_evaluations: 6_000,
                exact_tolerance: 1e-3,
                ..Default::default()
            },
        }
    }
}

/// What the robot did in a step.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub enum Action {
    /// Went on with its motion (the goal unchanged, the rest of the motion clear).
    Kept,
    /// Planned anew: why.
    Replanned(String),
    /// Found no path: why (it stays where it is).
    Failed(String),
}

/// One step of a scenario run.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct StepReport {
    /// Time, s.
    pub t: f64,
    /// Nodes the step's world change blocked, and parked nodes it freed.
    pub blocked: usize,
    /// Parked nodes freed.
    pub restored: usize,
    /// Nodes grown by the step's repair.
    pub added: usize,
    /// Seconds: invalidation, repair, planning.
    pub seconds: [f64; 3],
    /// What the robot did.
    pub action: Action,
    /// The step's goal.
    pub goal: Option<Vec<f64>>,
    /// Task distance of the robot to the goal at the end of the step.
    pub goal_error: Option<f64>,
    /// Whether the robot's posture at the start of the step collides (an object ran into it).
    pub hit: bool,
    /// Nodes of the live map at the end of the step ([`LiveMap::all`]'s first `nodes`), and
    /// the parked ones among them.
    pub nodes: usize,
    /// Edges of the live map at the end of the step.
    pub edges: usize,
    /// Parked nodes at the end of the step.
    pub parked_nodes: Vec<usize>,
    /// Parked edges (blocked, or with a parked end) at the end of the step.
    pub parked_edges: Vec<usize>,
}

/// A scenario run.
#[derive(Debug, Clone)]
pub struct ScenarioRun {
    /// One report per step.
    pub steps: Vec<StepReport>,
    /// The robot's motion: its posture at every step.
    pub motion: Trajectory,
    /// The world at every step.
    pub worlds: Vec<World>,
    /// Every node and edge the map had during the run (indices of the steps' reports).
    pub map: Roadmap,
}

/// The options in range, the goals in the map's task space, the scenario's objects named apart
/// from the map's world's, and none present at the start on the robot's start posture.
fn check_scenario(
    map: &Roadmap,
    problem: &Problem,
    scenario: &Scenario,
    options: &ScenarioOptions,
) -> Result<(), ScenarioError> {
    options.plan.check()?;
    for (what, v) in [
        ("tolerance", options.tolerance),
        ("reached", options.reached),
    ] {
        if !(v.is_finite() && v > 0.0) {
            return Err(PlanError::InvalidOptions {
                what: format!("scenario {what}"),
                problem: format!("{v}: give a finite positive task-space distance"),
            }
            .into());
        }
    }
    let dim = map.points.first().map_or(0, |p| p.t.len());
    if let Some(k) = scenario.goals.iter().position(|g| g.to.len() != dim) {
        return Err(scenario.error(
            &format!("goals[{k}].to"),
            format!(
                "{} values for the map's {dim}-dimensional task space",
                scenario.goals[k].to.len()
            ),
            format!("give {dim} coordinates"),
        ));
    }
    let objective = &problem.objective;
    let base = objective.world();
    if let Some(i) = scenario
        .objects
        .iter()
        .position(|o| base.object(&o.name).is_ok())
    {
        return Err(scenario.error(
            &format!("objects[{i}].name"),
            format!(
                "`{}` is already an object of the map's world",
                scenario.objects[i].name
            ),
            "give the scenario's objects other names".into(),
        ));
    }
    // an object present at the start must leave the robot's start posture free (one that
    // swallows the robot later makes the steps report a failed plan and the robot stay)
    let mut scratch = objective.scratch();
    let start_free = objective.is_collision_free_in(&problem.start, base, &mut scratch);
    for (i, o) in scenario.objects.iter().enumerate() {
        if !start_free || o.appear > 0.0 || o.vanish.is_some_and(|v| v <= 0.0) {
            continue;
        }
        let mut alone = base.clone();
        let placed = alone.add(&o.name, o.shape.clone(), pose_at(&o.path, 0.0));
        if placed.is_ok() && !objective.is_collision_free_in(&problem.start, &alone, &mut scratch) {
            return Err(scenario.error(
                &format!("objects[{i}].path"),
                format!(
                    "`{}` collides with the robot's start posture at t = 0",
                    o.name
                ),
                "place it clear of the robot at t = 0, let it appear later, or start elsewhere"
                    .into(),
            ));
        }
    }
    Ok(())
}

/// Why the robot must plan again at this step, if it must: a new goal, a goal the last
/// attempt failed to reach (tried again), the rest of the motion blocked in the current world,
/// or the motion ended short of the goal.
fn why_replan(
    motion: Option<&Motion>,
    goal: Option<&[f64]>,
    tried: Option<&[f64]>,
    q: &[f64],
    checker: &mut trm_collision::WorldChecker,
    problem: &Problem,
    options: &ScenarioOptions,
) -> Option<String> {
    let objective = &problem.objective;
    match (motion, goal) {
        (_, None) => None,
        (None, Some(goal)) if tried == Some(goal) => Some("trying again".to_string()),
        (None, Some(_)) => Some("a new goal".to_string()),
        (Some(m), Some(goal)) if m.goal != goal => Some("a new goal".to_string()),
        (Some(m), Some(_)) => {
            let next = m
                .times
                .iter()
                .position(|&s| s > m.clock)
                .unwrap_or(m.times.len());
            let mut from = q.to_vec();
            let blocked = m.waypoints[next..].iter().any(|w| {
                let free = checker.span_free(&from, w, options.plan.resolution);
                from.clone_from(w);
                !free
            });
            let ended = next == m.times.len();
            let off = |goal: &[f64]| {
                let task = objective.task_value(q, &mut objective.scratch());
                distance(&task, goal) > options.reached
            };
            if blocked {
                Some("the rest of the motion is blocked".to_string())
            } else if ended && goal.is_some_and(off) {
                Some("the motion ended short of the goal".to_string())
            } else {
                None
            }
        }
    }
}

/// Runs `scenario` on `map` (built for `problem`, its `Roadmap::problem`), from the problem's
/// start posture; see the module documentation. Deterministic for a given map and options
/// unless a time budget cuts a repair short.
pub fn run_scenario(
    map: &Roadmap,
    problem: &Problem,
    scenario: &Scenario,
    options: &ScenarioOptions,
) -> Result<ScenarioRun, ScenarioError> {
    check_scenario(map, problem, scenario, options)?;
    let objective = &problem.objective;
    let active = objective.active();
    let base = objective.world().clone();
    let mut scratch = objective.scratch();
    let mut live = LiveMap::new(map, problem)?;
    let dt = 1.0 / scenario.rate;
    let repair = RepairOptions {
        seconds: options.repair_seconds,
        evaluations: options.repair_evaluations,
        refill: false,
    };
    let mut q = problem.start.clone();
    let mut motion: Option<Motion> = None;
    // the goal of the last planning attempt, successful or not
    let mut tried: Option<Vec<f64>> = None;
    let (mut steps, mut worlds, mut times, mut postures) =
        (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    for k in 0..scenario.steps() {
        let t = k as f64 * dt;
        let world = scenario.world_at(&base, t).map_err(|e| {
            ScenarioError::Roadmap(RoadmapError::Unsuitable(format!("world at {t} s: {e}")))
        })?;
        let started = Instant::now();
        let changes = live.set_world(world.clone())?;
        let invalidate = started.elapsed().as_secs_f64();
        let started = Instant::now();
        let repaired = live.repair(&repair)?;
        let repair_seconds = started.elapsed().as_secs_f64();
        let mut checker = objective
            .world_checker(&world)
            .map_err(|e| ScenarioError::Roadmap(e.into()))?;
        let hit = !checker.free(&q);
        let goal = scenario.goal_at(t).map(<[f64]>::to_vec);
        // replan when the goal changed, the rest of the motion is blocked, or it ended short
        let started = Instant::now();
        let why = why_replan(
            motion.as_ref(),
            goal.as_deref(),
            tried.as_deref(),
            &q,
            &mut checker,
            problem,
            options,
        );
        let action = match (why, &goal) {
            (Some(why), Some(goal)) => {
                tried = Some(goal.clone());
                let current = live.map();
                let mut planner = Planner::new(objective, &[&current])?;
                planner.set_world(world.clone());
                let planned = planner.plan(
                    &q,
                    &Goal::TaskPoint {
                        t: goal.clone(),
                        tolerance: options.tolerance,
                    },
                    &options.plan,
                );
                match planned {
                    Ok(p) => {
                        let waypoints = p
                            .trajectory
                            .positions
                            .iter()
                            .map(|m| active.from_motors(m))
                            .collect();
                        motion = Some(Motion {
                            waypoints,
                            times: p.trajectory.times,
                            goal: goal.clone(),
                            clock: 0.0,
                        });
                        Action::Replanned(why)
                    }
                    Err(e @ (PlanError::Unreachable { .. } | PlanError::InvalidStart(_))) => {
                        motion = None;
                        Action::Failed(e.to_string())
                    }
                    Err(e) => return Err(e.into()),
                }
            }
            _ if goal.is_none() => Action::Kept,
            _ if motion.is_none() => Action::Failed("no motion".into()),
            _ => Action::Kept,
        };
        let plan_seconds = started.elapsed().as_secs_f64();
        // record the posture at t, then move on by one step
        times.push(t);
        postures.push(active.to_motors(&q));
        if let Some(m) = &mut motion {
            m.clock += dt;
            q = sample(&m.waypoints, &m.times, m.clock);
        }
        let goal_error = goal.as_ref().map(|g| {
            let task = objective.task_value(&q, &mut scratch);
            distance(&task, g)
        });
        let all = live.all();
        steps.push(StepReport {
            t,
            blocked: changes.blocked_nodes.len(),
            restored: changes.freed_nodes.len(),
            added: repaired.added_nodes,
            seconds: [invalidate, repair_seconds, plan_seconds],
            action,
            goal,
            goal_error,
            hit,
            nodes: all.points.len(),
            edges: all.edges.len(),
            parked_nodes: (0..all.points.len())
                .filter(|&i| live.is_blocked(i))
                .collect(),
            parked_edges: (0..all.edges.len())
                .filter(|&k| !live.is_usable(k))
                .collect(),
        });
        worlds.push(world);
    }
    let motion = Trajectory {
        names: active.model().motor_names(),
        task_path: postures
            .iter()
            .map(|m| objective.task_value(&active.from_motors(m), &mut scratch))
            .collect(),
        times,
        positions: postures,
        velocities: Vec::new(),
        accelerations: Vec::new(),
    };
    Ok(ScenarioRun {
        steps,
        motion,
        worlds,
        map: live.all().clone(),
    })
}

/// The motion being executed: waypoints (active values) reached at `times`, for `goal`, and
/// how far along it the robot is.
struct Motion {
    waypoints: Vec<Vec<f64>>,
    times: Vec<f64>,
    goal: Vec<f64>,
    clock: f64,
}

/// The posture at time `clock` along waypoints reached at `times` (linear in between, held
/// after the end).
fn sample(waypoints: &[Vec<f64>], times: &[f64], clock: f64) -> Vec<f64> {
    match times.iter().position(|&s| s > clock) {
        None => waypoints[waypoints.len() - 1].clone(),
        Some(0) => waypoints[0].clone(),
        Some(k) => {
            let u = (clock - times[k - 1]) / (times[k] - times[k - 1]);
            waypoints[k - 1]
                .iter()
                .zip(&waypoints[k])
                .map(|(a, b)| a + u * (b - a))
                .collect()
        }
    }
}
