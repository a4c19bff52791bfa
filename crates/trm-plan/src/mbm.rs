//! MotionBenchMaker problem sets (Chamzas et al., 2022): a folder per problem family, each
//! holding `sceneNNNN.yaml` (a MoveIt planning scene) and `requestNNNN.yaml` (a motion plan
//! request with a joint goal). [`solve`] answers one problem with RRT-Connect on any robot
//! model: the active motors are the joints the goal constrains, every other motor stays where
//! the start state puts it (clamped into its limits).

use std::path::{Path, PathBuf};

use trm_collision::CollisionModel;
use trm_kinematics::RobotModel;
use trm_tasks::Objective;

use crate::PlanError;
use crate::moveit::{MotionPlanRequest, PlanningScene, motors_from_state};
use crate::rrt::{EdgeCheck, RrtOptions, path_length, rrt_connect, shortcut};

/// One problem of a set.
#[derive(Debug, Clone, PartialEq, Eq, PartialOrd, Ord)]
pub struct Problem {
    /// Family (the folder's name).
    pub family: String,
    /// Number (from the file names).
    pub index: u32,
    /// The scene file.
    pub scene: PathBuf,
    /// The request file.
    pub request: PathBuf,
}

/// A problem set opened from a folder or a `.tar.bz2`/`.tar` of one (unpacked into a fresh
/// temporary folder, at most [`trm_io::MAX_INPUT_BYTES`] in all, removed when the set
/// is dropped; `tar` refuses entries that would land outside it).
pub struct ProblemSet {
    /// The problems, sorted by family and number.
    pub problems: Vec<Problem>,
    unpacked: Option<PathBuf>,
    root: PathBuf,
}

impl Drop for ProblemSet {
    fn drop(&mut self) {
        if let Some(dir) = &self.unpacked {
            let _ = std::fs::remove_dir_all(dir);
        }
    }
}

impl ProblemSet {
    /// Opens `path`: a folder of family folders (or holding one folder of them, as VAMP's
    /// archives do), or an archive of one.
    pub fn open(path: &Path) -> Result<Self, PlanError> {
        let unpacked = if path.is_file() {
            Some(unpack(path)?)
        } else {
            None
        };
        let mut set = ProblemSet {
            problems: Vec::new(),
            root: PathBuf::new(),
            unpacked,
        };
        set.root = set_root(set.unpacked.as_deref().unwrap_or(path));
        set.problems = find_problems(&set.root)?;
        Ok(set)
    }

    /// The folder holding the family folders (inside the unpacked archive, for an archive).
    pub fn root(&self) -> &Path {
        &self.root
    }
}

fn unpack(archive: &Path) -> Result<PathBuf, PlanError> {
    let bad = |problem: String| PlanError::InvalidMoveIt {
        path: archive.to_path_buf(),
        line: 0,
        problem,
        fix: "give a MotionBenchMaker set: a folder, or a .tar.bz2 of one as VAMP ships them"
            .into(),
    };
    let dir = std::env::temp_dir().join(format!(
        "trm-mbm-{}-{}",
        std::process::id(),
        UNPACKED.fetch_add(1, std::sync::atomic::Ordering::Relaxed)
    ));
    let io = |path: &Path, source| PlanError::Io {
        path: path.to_path_buf(),
        source,
    };
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).map_err(|e| io(&dir, e))?;
    let result = (|| {
        let file = std::fs::File::open(archive).map_err(|e| io(archive, e))?;
        let name = archive.to_string_lossy();
        let reader: Box<dyn std::io::Read> = if name.ends_with(".bz2") || name.ends_with(".tbz2") {
            Box::new(bzip2::read::BzDecoder::new(file))
        } else {
            Box::new(file)
        };
        let mut tar = tar::Archive::new(reader);
        let mut total = 0u64;
        for entry in tar
            .entries()
            .map_err(|e| bad(format!("not a tar archive ({e})")))?
        {
            let mut entry = entry.map_err(|e| bad(format!("a damaged archive entry ({e})")))?;
            total += entry.size();
            if total > trm_io::MAX_INPUT_BYTES {
                return Err(bad(format!(
                    "unpacks to more than {} bytes",
                    trm_io::MAX_INPUT_BYTES
                )));
            }
            entry
                .unpack_in(&dir)
                .map_err(|e| bad(format!("an entry could not be unpacked ({e})")))?;
        }
        Ok(())
    })();
    match result {
        Ok(()) => Ok(dir),
        Err(e) => {
            let _ = std::fs::remove_dir_all(&dir);
            Err(e)
        }
    }
}

static UNPACKED: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);

/// `dir`, or its one subfolder when it holds nothing else and no scene.
fn set_root(dir: &Path) -> PathBuf {
    let entries: Vec<PathBuf> = std::fs::read_dir(dir)
        .map(|r| r.filter_map(|e| e.ok().map(|e| e.path())).collect())
        .unwrap_or_default();
    match entries.as_slice() {
        [only] if only.is_dir() && !only.join("scene0001.yaml").exists() => only.clone(),
        _ => dir.to_path_buf(),
    }
}

/// What a family (or a whole set) came to, as the field reports planners.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Summary {
    /// Problems.
    pub problems: usize,
    /// Valid problems (start and goal free and within limits).
    pub valid: usize,
    /// Valid problems solved.
    pub solved: usize,
    /// Median and 95th percentile of the solved problems' times, s (`None` when none solved).
    pub time: Option<(f64, f64)>,
    /// Median path length of the solved problems, rad.
    pub length: Option<f64>,
    /// Median collision checks of the solved problems.
    pub checks: Option<f64>,
}

/// The `q`-quantile (0..=1, nearest rank) of `values`; `None` for none.
pub fn quantile(values: &[f64], q: f64) -> Option<f64> {
    let mut sorted = values.to_vec();
    sorted.sort_by(f64::total_cmp);
    let k = ((q * sorted.len() as f64).ceil() as usize).clamp(1, sorted.len().max(1));
    sorted.get(k - 1).copied()
}

impl Summary {
    /// The summary of `outcomes`.
    pub fn of<'a>(outcomes: impl IntoIterator<Item = &'a Outcome>) -> Self {
        let outcomes: Vec<&Outcome> = outcomes.into_iter().collect();
        let solved: Vec<&&Outcome> = outcomes.iter().filter(|o| o.valid && o.solved).collect();
        let of = |f: &dyn Fn(&Outcome) -> f64| solved.iter().map(|o| f(o)).collect::<Vec<f64>>();
        let times = of(&|o| o.seconds);
        Summary {
            problems: outcomes.len(),
            valid: outcomes.iter().filter(|o| o.valid).count(),
            solved: solved.len(),
            time: quantile(&times, 0.5).zip(quantile(&times, 0.95)),
            length: quantile(&of(&|o| o.length), 0.5),
            checks: quantile(&of(&|o| o.checks as f64), 0.5),
        }
    }
}

/// The problems under `dir` (its folders' `sceneNNNN.yaml` with their `requestNNNN.yaml`),
/// sorted by family and number. A scene without its request is an error naming it.
pub fn find_problems(dir: &Path) -> Result<Vec<Problem>, PlanError> {
    let io = |path: &Path, source| PlanError::Io {
        path: path.to_path_buf(),
        source,
    };
    let mut problems = Vec::new();
    let mut folders: Vec<PathBuf> = std::fs::read_dir(dir)
        .map_err(|e| io(dir, e))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.is_dir())
        .collect();
    folders.sort();
    for folder in folders {
        let family = folder
            .file_name()
            .map(|n| n.to_string_lossy().to_string())
            .unwrap_or_default();
        for entry in std::fs::read_dir(&folder).map_err(|e| io(&folder, e))? {
            let path = entry.map_err(|e| io(&folder, e))?.path();
            let name = path
                .file_name()
                .map(|n| n.to_string_lossy().to_string())
                .unwrap_or_default();
            let Some(number) = name
                .strip_prefix("scene")
                .and_then(|n| n.strip_suffix(".yaml"))
            else {
                continue;
            };
            let Ok(index) = number.parse::<u32>() else {
                continue;
            };
            let request = folder.join(format!("request{number}.yaml"));
            if !request.is_file() {
                return Err(PlanError::InvalidMoveIt {
                    path: path.clone(),
                    line: 0,
                    problem: format!("no {} beside it", request.display()),
                    fix: "give every scene its request (MotionBenchMaker writes them in pairs)"
                        .into(),
                });
            }
            problems.push(Problem {
                family: family.clone(),
                index,
                scene: path,
                request,
            });
        }
    }
    problems.sort();
    if problems.is_empty() {
        return Err(PlanError::InvalidMoveIt {
            path: dir.to_path_buf(),
            line: 0,
            problem: "no sceneNNNN.yaml in any folder".into(),
            fix: "give the folder that holds one folder per problem family (MotionBenchMaker's layout)".into(),
        });
    }
    Ok(problems)
}

/// How far outside its joint limits a start or goal value may lie and still be taken, clamped
/// onto the limit. URDFs round ±π to ±3.14159, so MotionBenchMaker's Fetch states at ±π lie
/// 2.7·10⁻⁶ rad outside; MoveIt moves such starts inside (its FixStartStateBounds adapter, up
/// to 0.05 rad) and samples joint goals within the bounds.
pub const LIMIT_SLACK: f64 = 1e-4;

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
pub fn solve(
    robot: &RobotModel,
    collision: &CollisionModel,
    scene: &PlanningScene,
    request: &MotionPlanRequest,
    options: &RrtOptions,
) -> Result<Outcome, PlanError> {
    options.check()?;
    let world = scene.to_world()?;
    let (collision, notes) = scene_collision(collision, scene)?;
    let (objective, active, mut start) = problem_objective(robot, &collision, &world, request)?;
    let mut goal = request.goal.positions.clone();
    let mut checker = objective.world_checker(&world)?;
    let mut outcome = Outcome {
        note: notes.join("; "),
        ..Default::default()
    };
    // time spent finding a goal configuration for a task-space goal (part of the answer)
    let mut goal_seconds = 0.0;
    if !request.pose_goal.is_empty() {
        let root = &robot.tree().links[0].name;
        if let Some(frame) = request.pose_goal.foreign_frame(root) {
            return Err(PlanError::InvalidMoveIt {
                path: request.origin.clone(),
                line: 0,
                problem: format!("a goal constraint is given in frame `{frame}`"),
                fix: format!("give it in the robot's root frame `{root}`"),
            });
        }
        let started = std::time::Instant::now();
        let found = request.pose_goal.solve(
            objective.active(),
            &start,
            options.seed,
            GOAL_ATTEMPTS,
            |q| checker.free(q),
        )?;
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
    if let Some(why) = invalid(robot, &active, &mut start, &mut goal, |q| checker.free(q)) {
        outcome.note = why.into();
        return Ok(outcome);
    }
    outcome.valid = true;
    let options = RrtOptions {
        max_seconds: options.max_seconds.or(request.planning_time),
        ..options.clone()
    };
    match rrt_connect(&objective, &world, &start, &goal, &options) {
        Ok(found) => {
            outcome.solved = true;
            outcome.seconds = goal_seconds + found.seconds;
            outcome.length = path_length(&found.path);
            outcome.waypoints = found.path.len();
            outcome.checks = found.checks;
            outcome.path = found.path;
        }
        Err(e) => outcome.note = e.to_string(),
    }
    Ok(outcome)
}

/// `collision` with the scene's allowed-collision matrix applied
/// ([`crate::moveit::AllowedCollisions::apply`]), and notes on the entries it skipped.
fn scene_collision<'a>(
    collision: &'a CollisionModel,
    scene: &PlanningScene,
) -> Result<(std::borrow::Cow<'a, CollisionModel>, Vec<String>), PlanError> {
    let Some(acm) = &scene.allowed_collisions else {
        return Ok((std::borrow::Cow::Borrowed(collision), Vec::new()));
    };
    let (applied, notes) = acm.apply(collision)?;
    Ok((
        applied.map_or(
            std::borrow::Cow::Borrowed(collision),
            std::borrow::Cow::Owned,
        ),
        notes,
    ))
}

/// Refuses a task-space goal where only joint goals are handled (`what`).
fn joint_goal_only(request: &MotionPlanRequest, what: &str) -> Result<(), PlanError> {
    if request.pose_goal.is_empty() {
        return Ok(());
    }
    Err(PlanError::InvalidMoveIt {
        path: request.origin.clone(),
        line: 0,
        problem: format!("a task-space goal: {what} take joint goals"),
        fix: "give joint constraints, or solve task-space goals with mbm::solve (benchmark-mbm without --experience/--vamp)".into(),
    })
}

/// IK starts tried for a task-space goal (the start, then seeded random configurations).
pub const GOAL_ATTEMPTS: usize = 500;

/// Why a problem is invalid (`None`: start and goal within the limits of the `active` motors
/// and `free`). Values within [`LIMIT_SLACK`] outside a limit are clamped onto it.
fn invalid(
    robot: &RobotModel,
    active: &[usize],
    start: &mut [f64],
    goal: &mut [f64],
    mut free: impl FnMut(&[f64]) -> bool,
) -> Option<&'static str> {
    let within = |q: &mut [f64]| {
        active.iter().zip(q).all(|(&i, v)| {
            let limits = &robot.motors()[i].limits;
            let inside = (limits.lower - LIMIT_SLACK..=limits.upper + LIMIT_SLACK).contains(v);
            *v = v.clamp(limits.lower, limits.upper);
            inside
        })
    };
    if !within(start) {
        Some("the start is outside the joint limits")
    } else if !free(start) {
        Some("the start collides")
    } else if !within(goal) {
        Some("the goal is outside the joint limits")
    } else if !free(goal) {
        Some("the goal collides")
    } else {
        None
    }
}

/// Solves `problems` with experience, as a robot that keeps what it learns: one planner per
/// family (`crate::Planner` over no map), each problem planned through what the family's
/// earlier problems left behind (checked lazily in the new scene) and, where that does not
/// join start and goal, by RRT-Connect, whose path is then kept ([`crate::Planner::add_path`]).
/// An outcome's note says how it was answered: `experience`, `straight` (the straight edge
/// from start to goal is free) or `RRT-Connect (path kept)`. The set is run `passes` times with the experience kept; `outcomes[pass][k]` answers
/// `problems[k]`; `done(pass, k)` is called after each. The problems of a family must share
/// the goal's joints and the start's other motors (an error names the first that does not).
pub fn solve_with_experience(
    robot: &RobotModel,
    collision: &CollisionModel,
    problems: &[Problem],
    options: &RrtOptions,
    passes: usize,
    mut done: impl FnMut(usize, usize),
) -> Result<Vec<Vec<Outcome>>, PlanError> {
    options.check()?;
    let mut outcomes = vec![vec![Outcome::default(); problems.len()]; passes];
    let mut families: Vec<&str> = problems.iter().map(|p| p.family.as_str()).collect();
    families.dedup();
    families.sort_unstable();
    families.dedup();
    for family in families {
        let members: Vec<usize> = (0..problems.len())
            .filter(|&k| problems[k].family == family)
            .collect();
        let first = MotionPlanRequest::load(&problems[members[0]].request)?;
        let (_, active, _) =
            problem_objective(robot, collision, &trm_collision::World::new(), &first)?;
        // every path kept so far: each planner of the family starts from them
        let mut kept: Vec<Vec<Vec<f64>>> = Vec::new();
        for (pass, results) in outcomes.iter_mut().enumerate() {
            let mut next = 0;
            while next < members.len() {
                // one planner per run of problems whose scenes allow the same collisions (each
                // problem is planned and checked with its own scene's matrix)
                let scene = PlanningScene::load(&problems[members[next]].scene)?;
                let (acm_collision, _) = scene_collision(collision, &scene)?;
                let acm = acm_collision.acm().clone();
                let (objective, _, _) =
                    problem_objective(robot, &acm_collision, &trm_collision::World::new(), &first)?;
                let mut planner = crate::Planner::new(&objective, &[])?;
                for path in &kept {
                    planner.add_path(path)?;
                }
                while next < members.len() {
                    let k = members[next];
                    let p = &problems[k];
                    let scene = PlanningScene::load(&p.scene)?;
                    if scene_collision(collision, &scene)?.0.acm() != &acm {
                        break;
                    }
                    next += 1;
                    let request = MotionPlanRequest::load(&p.request)?;
                    joint_goal_only(&request, "experience runs")?;
                    let (other, other_active, mut start) = problem_objective(
                        robot,
                        collision,
                        &trm_collision::World::new(),
                        &request,
                    )?;
                    if other_active != active
                        || other.active().to_motors(&start) != objective.active().to_motors(&start)
                    {
                        return Err(PlanError::InvalidMoveIt {
                            path: request.origin.clone(),
                            line: 0,
                            problem: format!(
                                "its goal's joints or its start's other motors differ from {}'s",
                                problems[members[0]].request.display()
                            ),
                            fix: "give a family whose problems share the robot's planning group and its other joints' values".into(),
                        });
                    }
                    planner.set_world(scene.to_world()?);
                    let mut goal = request.goal.positions.clone();
                    let outcome = &mut results[k];
                    if let Some(why) = invalid(robot, &active, &mut start, &mut goal, |q| {
                        planner.is_free(q)
                    }) {
                        outcome.note = why.into();
                        done(pass, k);
                        continue;
                    }
                    outcome.valid = true;
                    let began = std::time::Instant::now();
                    let rrt = RrtOptions {
                        max_seconds: options.max_seconds.or(request.planning_time),
                        ..options.clone()
                    };
                    let plan_options = crate::PlanOptions {
                        resolution: options.resolution,
                        shortcuts: 0,
                        seed: options.seed,
                        exact_goal: false,
                        sampling: Some(rrt.clone()),
                        ..Default::default()
                    };
                    let found = match planner.plan(
                        &start,
                        &crate::Goal::Configuration(goal.clone()),
                        &plan_options,
                    ) {
                        Ok(planned) if planned.stats.sampled.is_some() => Ok((
                            planned.waypoints,
                            planned.stats.sampled.map_or(0, |s| s.1),
                            None,
                        )),
                        Ok(planned) => {
                            // through experience: shortcut greedily, and checked at half the
                            // resolution as RRT-Connect's paths are; RRT-Connect where that fails
                            let world = planner.world().clone();
                            let mut checker = objective.world_checker(&world)?;
                            let mut path = planned.waypoints;
                            let mut rng =
                                <rand_chacha::ChaCha8Rng as rand::SeedableRng>::seed_from_u64(
                                    options.seed,
                                );
                            let edges = shortcut(
                                &mut path,
                                &RrtOptions {
                                    shortcuts: 0,
                                    ..options.clone()
                                },
                                &mut checker,
                                &mut rng,
                            );
                            let how = if planned.stats.retrieved {
                                "retrieved"
                            } else if planned.nodes.is_empty() {
                                "straight"
                            } else {
                                "experience"
                            };
                            // at half the resolution: the edges the shortcut found free and the
                            // planner's own (checked at the same points,
                            // `Planner::segment_free`) need only their midpoints
                            let r = options.resolution;
                            if path.windows(2).zip(&edges).all(|(w, e)| {
                                (*e != EdgeCheck::Piece || checker.edge_free(&w[0], &w[1], r))
                                    && checker.edge_midpoints_free(&w[0], &w[1], r)
                            }) {
                                Ok((path, checker.checks, Some(how)))
                            } else {
                                rrt_connect(&objective, &world, &start, &goal, &rrt)
                                    .map(|f| (f.path, checker.checks + f.checks, None))
                            }
                        }
                        Err(e) => Err(e),
                    };
                    match found {
                        Ok((path, checks, answered)) => {
                            outcome.solved = true;
                            outcome.seconds = began.elapsed().as_secs_f64();
                            outcome.length = path_length(&path);
                            outcome.waypoints = path.len();
                            outcome.checks = checks;
                            outcome.note = match answered {
                                Some(how) => how.into(),
                                None => {
                                    planner.add_path(&path)?;
                                    kept.push(path.clone());
                                    "RRT-Connect (path kept)".into()
                                }
                            };
                            outcome.path = path;
                        }
                        Err(e) => outcome.note = e.to_string(),
                    }
                    done(pass, k);
                }
            }
        }
    }
    Ok(outcomes)
}

/// Whether every edge of `path` is free at `resolution` in the problem's world, checked one
/// configuration at a time in `f64` from one end to the other (an independent check of a
/// planner's raked, batched, single-precision edge checks): at the points a planner checking
/// at `2 × resolution` and then at the midpoints visits ([`trm_collision::edge::edge_steps`]), no more
/// than `resolution` apart.
pub fn path_is_free(
    robot: &RobotModel,
    collision: &CollisionModel,
    scene: &PlanningScene,
    request: &MotionPlanRequest,
    path: &[Vec<f64>],
    resolution: f64,
) -> Result<bool, PlanError> {
    let world = scene.to_world()?;
    let (collision, _) = scene_collision(collision, scene)?;
    let (objective, _, _) = problem_objective(robot, &collision, &world, request)?;
    let mut scratch = objective.scratch();
    for w in path.windows(2) {
        // the points the planner's half-resolution check visits (`resolution` is that half):
        // those at the full resolution and the midpoints between them
        let steps = 2 * trm_collision::edge::edge_steps(&w[0], &w[1], 2.0 * resolution);
        for s in 0..=steps {
            let t = s as f64 / steps as f64;
            let q: Vec<f64> = w[0]
                .iter()
                .zip(&w[1])
                .map(|(a, b)| a + t * (b - a))
                .collect();
            if !objective.is_collision_free_in(&q, &world, &mut scratch) {
                return Ok(false);
            }
        }
    }
    Ok(true)
}

/// The objective of a request in `world`: the goal's joints active, every other motor where
/// the start state puts it (clamped into its limits); with the active motors' indices and the
/// start's active values.
fn problem_objective(
    robot: &RobotModel,
    collision: &CollisionModel,
    world: &trm_collision::World,
    request: &MotionPlanRequest,
) -> Result<(Objective, Vec<usize>, Vec<f64>), PlanError> {
    let base: Vec<f64> = robot
        .motors()
        .iter()
        .map(|m| 0.0f64.clamp(m.limits.lower, m.limits.upper))
        .collect();
    let (start_motors, _) = motors_from_state(robot, &request.start, &base);
    let locked: Vec<f64> = robot
        .motors()
        .iter()
        .zip(&start_motors)
        .map(|(m, v)| v.clamp(m.limits.lower, m.limits.upper))
        .collect();
    let mut active = Vec::new();
    if request.goal.names.is_empty() {
        // a task-space goal moves the request's group
        if request.group.is_empty() {
            return Err(PlanError::InvalidMoveIt {
                path: request.origin.clone(),
                line: 0,
                problem: "a task-space goal without group_name".into(),
                fix: "give group_name: the group whose joints move".into(),
            });
        }
        active = robot
            .group(&request.group)
            .map_err(|e| PlanError::InvalidMoveIt {
                path: request.origin.clone(),
                line: 0,
                problem: format!("group_name: {e}"),
                fix: "give a group of this robot model (its description's groups)".into(),
            })?
            .to_vec();
    }
    for name in &request.goal.names {
        let i = robot
            .motor_index(name)
            .map_err(|e| PlanError::InvalidMoveIt {
                path: request.origin.clone(),
                line: 0,
                problem: format!("the goal constrains `{name}`: {e}"),
                fix: "give a request for this robot model".into(),
            })?;
        active.push(i);
    }
    let start: Vec<f64> = active.iter().map(|&i| start_motors[i]).collect();
    let active_set = trm_kinematics::ActiveSet::new(robot.clone(), active.clone(), &locked)?;
    Ok((
        Objective::new(active_set, collision.clone(), world.clone()),
        active,
        start,
    ))
}

/// Writes `problems` in the plain-text format that peer planners read for trm's side-by-side
/// benchmark (`benches/peers/vamp/mbm.cc`): a header naming `robot` and the goal's joints,
/// then per problem its family, number, start and goal (in that joint order) and its world's
/// primitives (`box x y z qw qx qy qz hx hy hz`, `cylinder x y z qw qx qy qz radius length`,
/// `sphere x y z radius`), every number in its shortest exact form.
pub fn peer_problems(robot: &str, problems: &[Problem]) -> Result<String, PlanError> {
    use std::fmt::Write as _;
    let mut joints: Option<Vec<String>> = None;
    let mut body = String::new();
    for p in problems {
        let scene = PlanningScene::load(&p.scene)?;
        let request = MotionPlanRequest::load(&p.request)?;
        joint_goal_only(&request, "peer planners")?;
        let order = joints.get_or_insert_with(|| request.goal.names.clone());
        let mismatch = |what: &str| PlanError::InvalidMoveIt {
            path: request.origin.clone(),
            line: 0,
            problem: format!("the {what} does not give the joints {}", order.join(", ")),
            fix: "give one set of problems for one robot and planning group".into(),
        };
        let mut sorted = request.goal.names.clone();
        sorted.sort();
        let mut expected = order.clone();
        expected.sort();
        if sorted != expected {
            return Err(mismatch("goal"));
        }
        let _ = writeln!(body, "problem {} {}", p.family, p.index);
        for (label, names, values) in [
            ("start", &request.start.names, &request.start.positions),
            ("goal", &request.goal.names, &request.goal.positions),
        ] {
            let _ = write!(body, "{label}");
            for joint in order.iter() {
                let i = names
                    .iter()
                    .position(|n| n == joint)
                    .ok_or_else(|| mismatch(label))?;
                let _ = write!(body, " {}", values[i]);
            }
            body.push('\n');
        }
        let primitives: Vec<_> = scene.objects.iter().flat_map(|o| &o.primitives).collect();
        let _ = writeln!(body, "objects {}", primitives.len());
        for primitive in primitives {
            let t = primitive.pose.translation.vector;
            let q = primitive.pose.rotation;
            let pose = format!("{} {} {} {} {} {} {}", t.x, t.y, t.z, q.w, q.i, q.j, q.k);
            let _ = match &primitive.shape {
                trm_collision::Shape::Sphere { radius } => {
                    writeln!(body, "sphere {} {} {} {radius}", t.x, t.y, t.z)
                }
                trm_collision::Shape::Box { size } => writeln!(
                    body,
                    "box {pose} {} {} {}",
                    size[0] / 2.0,
                    size[1] / 2.0,
                    size[2] / 2.0
                ),
                trm_collision::Shape::Cylinder { radius, length } => {
                    writeln!(body, "cylinder {pose} {radius} {length}")
                }
                other => {
                    return Err(PlanError::InvalidMoveIt {
                        path: scene.origin.clone(),
                        line: 0,
                        problem: format!("a {other:?} has no peer-file form"),
                        fix: "give boxes, spheres and cylinders (MoveIt's primitives)".into(),
                    });
                }
            };
        }
    }
    let joints = joints.unwrap_or_default();
    Ok(format!(
        "trm-mbm-problems 1\nrobot {robot}\njoints {} {}\nproblems {}\n{body}",
        joints.len(),
        joints.join(" "),
        problems.len()
    ))
}

/// One problem as a peer planner reported it (`result` lines of `benches/peers/vamp/mbm.cc`):
/// the family, the number and the outcome (time = planning + simplification; `checks` 0: the
/// peer does not count them).
pub fn parse_peer_results(text: &str) -> Result<Vec<(String, u32, Outcome)>, String> {
    let mut results: Vec<(String, u32, Outcome)> = Vec::new();
    for (n, line) in text.lines().enumerate() {
        let at = |problem: &str| format!("line {}: {problem}: `{line}`", n + 1);
        let mut words = line.split_whitespace();
        match words.next() {
            Some("result") => {
                let fields: Vec<&str> = words.collect();
                if fields.len() != 10 {
                    return Err(at("a result has 10 fields"));
                }
                let number = |k: usize| -> Result<f64, String> {
                    fields[k]
                        .parse::<f64>()
                        .ok()
                        .filter(|v| v.is_finite())
                        .ok_or_else(|| at("not a finite number"))
                };
                let index = fields[1].parse().map_err(|_| at("not a problem number"))?;
                let valid = number(2)? != 0.0;
                let solved = number(3)? != 0.0;
                let outcome = Outcome {
                    valid,
                    solved: valid && solved,
                    seconds: (number(4)? + number(5)?) * 1e-9,
                    length: number(7)?,
                    waypoints: number(9)? as usize,
                    note: match (valid, solved) {
                        (false, _) => "start or goal in collision for the peer".into(),
                        (true, false) => "not solved by the peer".into(),
                        _ => String::new(),
                    },
                    ..Default::default()
                };
                results.push((fields[0].to_string(), index, outcome));
            }
            Some("path") => {
                let q: Result<Vec<f64>, String> = words
                    .map(|w| {
                        w.parse::<f64>()
                            .ok()
                            .filter(|v| v.is_finite())
                            .ok_or_else(|| at("not a finite number"))
                    })
                    .collect();
                let last = results
                    .last_mut()
                    .ok_or_else(|| at("a path line before any result"))?;
                last.2.path.push(q?);
            }
            None => {}
            Some(_) => return Err(at("neither `result` nor `path`")),
        }
    }
    Ok(results)
}

impl ProblemSet {
    /// Keeps the problems of `families` (all when empty; a family the set lacks is an error
    /// naming those it has) and at most `per_family` of each, in order.
    pub fn select(
        &mut self,
        families: &[String],
        per_family: Option<usize>,
    ) -> Result<(), PlanError> {
        for f in families {
            if !self.problems.iter().any(|p| &p.family == f) {
                let known: std::collections::BTreeSet<&str> =
                    self.problems.iter().map(|p| p.family.as_str()).collect();
                return Err(PlanError::InvalidOptions {
                    what: format!("family `{f}`"),
                    problem: format!(
                        "is not in this set\n  fix: give some of {}",
                        known.into_iter().collect::<Vec<_>>().join(", ")
                    ),
                });
            }
        }
        if !families.is_empty() {
            self.problems.retain(|p| families.contains(&p.family));
        }
        if let Some(n) = per_family {
            let mut count = std::collections::BTreeMap::<String, usize>::new();
            self.problems.retain(|p| {
                let c = count.entry(p.family.clone()).or_default();
                *c += 1;
                *c <= n
            });
        }
        Ok(())
    }
}

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
) -> Result<Vec<Run>, PlanError> {
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

/// The runs as CSV: family, problem, valid, solved, seconds, length, waypoints, checks,
/// verified, note.
pub fn runs_csv(runs: &[Run]) -> String {
    use std::fmt::Write as _;
    let mut csv =
        String::from("family,problem,valid,solved,seconds,length,waypoints,checks,verified,note\n");
    for r in runs {
        let o = &r.outcome;
        let _ = writeln!(
            csv,
            "{},{},{},{},{},{},{},{},{},\"{}\"",
            r.family,
            r.index,
            o.valid,
            o.solved,
            o.seconds,
            o.length,
            o.waypoints,
            o.checks,
            r.verified.map_or(String::new(), |v| v.to_string()),
            o.note.replace('"', "'")
        );
    }
    csv
}

/// Formats a time in milliseconds with two decimals ("—" for none).
fn ms(seconds: Option<f64>) -> String {
    seconds.map_or("—".to_string(), |s| format!("{:.2}", s * 1e3))
}

/// The field's per-family table in markdown: valid, solved, median and p95 time, median path
/// length and collision checks, one row per family (in the order first met) and one for all.
pub fn markdown_table<'a>(outcomes: impl IntoIterator<Item = (&'a str, &'a Outcome)>) -> String {
    use std::fmt::Write as _;
    let outcomes: Vec<(&str, &Outcome)> = outcomes.into_iter().collect();
    let mut md = String::from(
        "| family | valid | solved | median ms | p95 ms | median length (rad) | median checks |\n|---|---|---|---|---|---|---|\n",
    );
    let mut row = |name: &str, s: Summary| {
        let _ = writeln!(
            md,
            "| {name} | {}/{} | {}/{} ({:.1} %) | {} | {} | {} | {} |",
            s.valid,
            s.problems,
            s.solved,
            s.valid,
            100.0 * s.solved as f64 / s.valid.max(1) as f64,
            ms(s.time.map(|t| t.0)),
            ms(s.time.map(|t| t.1)),
            s.length.map_or("—".into(), |l| format!("{l:.2}")),
            s.checks
                .filter(|&c| c > 0.0)
                .map_or("—".into(), |c| format!("{c:.0}"))
        );
    };
    for family in families(&outcomes) {
        row(
            family,
            Summary::of(outcomes.iter().filter(|o| o.0 == family).map(|o| o.1)),
        );
    }
    row("all", Summary::of(outcomes.iter().map(|o| o.1)));
    md
}

/// The families of `outcomes` in the order first met.
fn families<'a>(outcomes: &[(&'a str, &Outcome)]) -> Vec<&'a str> {
    let mut names: Vec<&str> = Vec::new();
    for (f, _) in outcomes {
        if !names.contains(f) {
            names.push(f);
        }
    }
    names
}

/// Two planners side by side per family, in markdown: each one's solved share of the problems
/// both call valid, its median and p95 time, and the ratios `ours / theirs`.
pub fn side_by_side<'a>(
    (ours, our_name): (&[(&'a str, &'a Outcome)], &str),
    (theirs, their_name): (&[(&'a str, &'a Outcome)], &str),
) -> String {
    use std::fmt::Write as _;
    let mut md = format!(
        "| family | both valid | {our_name} solved | {their_name} solved | {our_name} median ms | {their_name} median ms | median ratio | {our_name} p95 ms | {their_name} p95 ms | p95 ratio |\n|---|---|---|---|---|---|---|---|---|---|\n"
    );
    let mut row = |name: &str, pairs: Vec<(&Outcome, &Outcome)>| {
        let both: Vec<_> = pairs.iter().filter(|(a, b)| a.valid && b.valid).collect();
        let (a, b) = (
            Summary::of(both.iter().map(|p| p.0)),
            Summary::of(both.iter().map(|p| p.1)),
        );
        let ratio = |x: Option<f64>, y: Option<f64>| {
            x.zip(y)
                .filter(|(_, y)| *y > 0.0)
                .map_or("—".into(), |(x, y)| format!("{:.1}×", x / y))
        };
        let _ = writeln!(
            md,
            "| {name} | {} | {} | {} | {} | {} | {} | {} | {} | {} |",
            both.len(),
            a.solved,
            b.solved,
            ms(a.time.map(|t| t.0)),
            ms(b.time.map(|t| t.0)),
            ratio(a.time.map(|t| t.0), b.time.map(|t| t.0)),
            ms(a.time.map(|t| t.1)),
            ms(b.time.map(|t| t.1)),
            ratio(a.time.map(|t| t.1), b.time.map(|t| t.1)),
        );
    };
    let pair = |family: Option<&str>| -> Vec<(&Outcome, &Outcome)> {
        ours.iter()
            .zip(theirs)
            .filter(|((f, _), _)| family.is_none_or(|name| *f == name))
            .map(|((_, a), (_, b))| (*a, *b))
            .collect()
    };
    for family in families(ours) {
        row(family, pair(Some(family)));
    }
    row("all", pair(None));
    md
}
