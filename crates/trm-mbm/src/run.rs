//! A set run problem by problem: plain, with a task-space form of each goal, with experience
//! kept, every path re-checked when asked; and its report.

use std::fmt::Write as _;

use trm_collision::CollisionModel;
use trm_kinematics::RobotModel;
use trm_plan::rrt::RrtOptions;
use trm_roadmap::Roadmap;

use crate::error::MbmError;
use crate::experience::{Scope, solve_leave_one_out, solve_with_experience};
use crate::loaded::LoadedProblem;
use crate::problems::Problem;
use crate::report::{markdown_table, side_by_side};
use crate::solve::{Outcome, Solver, Verdict, certify_path_loaded};

/// One problem of a benchmark run and how it went.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Run {
    /// Its family.
    pub family: String,
    /// Its number in the family.
    pub index: u32,
    /// The planner's outcome.
    pub outcome: Outcome,
    /// With verification: what certification proved about the path ([`crate::certify_path`]).
    pub verified: Option<Verdict>,
}

/// A set's joint goals posed as task-space goals
/// ([`trm_moveit::MotionPlanRequest::to_task_space`]).
#[derive(Debug, Clone, PartialEq)]
pub struct TaskSpaceGoals {
    /// The link whose pose is the goal (e.g. the hand).
    pub link: String,
    /// Side of the cube the link's origin must reach, m.
    pub position_tolerance: f64,
    /// Tolerance about each axis, rad.
    pub orientation_tolerance: f64,
}

/// How a set is run.
#[derive(Debug, Clone, Default)]
pub struct BenchmarkOptions {
    /// RRT-Connect's settings (a request's `allowed_planning_time` is its time limit unless
    /// `max_seconds` is given).
    pub rrt: RrtOptions,
    /// Prove every returned path free in continuous motion ([`crate::certify_path`]).
    pub verify: bool,
    /// Pose each joint goal as the task-space goal it implies (the plain run only).
    pub task_space: Option<TaskSpaceGoals>,
    /// Runs of the set with experience kept after the plain one
    /// ([`solve_with_experience`]; 0: none).
    pub experience_passes: usize,
    /// Maps for a second run of the set beside the plain one, attached to each problem's
    /// planner ([`crate::solve_with_maps`]; none: no such run).
    pub maps: Vec<Roadmap>,
    /// The obstacles trm plans among, and its paths are verified in.
    pub obstacles: crate::Obstacles,
    /// Check the link pairs the robot's own allowed-collision matrix checks, ignoring each
    /// scene's (as VAMP does: its checks know no scene matrix), so that both planners face
    /// the same pairs.
    pub ignore_scene_matrices: bool,
}

/// What a set run came to: the plain run, and each pass with experience kept.
#[derive(Debug, Clone)]
pub struct Benchmark {
    /// The problems as read and prepared (for checking other planners' paths in them:
    /// [`crate::certify_path_loaded`]).
    pub problems: Vec<LoadedProblem>,
    /// The plain run, one per problem.
    pub runs: Vec<Run>,
    /// Each pass with experience, one run per problem.
    pub experience: Vec<Vec<Run>>,
    /// With experience: each problem planned through the plain run's paths of the other
    /// problems of its family, then of the set ([`solve_leave_one_out`]), one run per problem,
    /// and beside it each problem solved afresh right before or after, in turn.
    pub leave_one_out: Vec<(Scope, Vec<Run>, Vec<Run>)>,
    /// The run with [`BenchmarkOptions::maps`] attached, one per problem (empty without maps).
    pub with_maps: Vec<Run>,
    /// Whether solved paths were re-checked ([`BenchmarkOptions::verify`]).
    pub verified: bool,
}

/// Runs `problems` as `options` say, each problem read and prepared once for every run and
/// check; `progress(stage, done, total, problem)` after each problem (stage: `problems`, then
/// `problems with experience`).
pub fn benchmark(
    robot: &RobotModel,
    collision: &CollisionModel,
    problems: &[Problem],
    options: &BenchmarkOptions,
    mut progress: impl FnMut(&str, usize, usize, &Problem),
) -> Result<Benchmark, MbmError> {
    let mut loaded = LoadedProblem::load_all(collision, problems)?;
    if options.ignore_scene_matrices {
        for p in &mut loaded {
            p.collision = p.own.clone();
            p.notes.clear();
        }
    }
    match options.obstacles {
        crate::Obstacles::AsGiven => {}
        crate::Obstacles::AsVamp => {
            for p in &mut loaded {
                p.world = crate::vamp_world(&p.world, &p.problem.family);
            }
        }
        crate::Obstacles::Cloud { per_object } => {
            let screen = trm_collision::WorldChecker::screen_model(collision);
            for p in &mut loaded {
                let (world, build) = crate::cloud_world(
                    &p.world,
                    per_object,
                    p.problem.index.into(),
                    screen.as_deref(),
                )?;
                (p.world, p.cloud) = (world, Some(build));
            }
        }
    }
    let (runs, with_maps) = run_set(robot, &loaded, options, |k, p| {
        progress("problems", k, problems.len(), p)
    })?;
    let mut experience = Vec::new();
    if options.experience_passes > 0 {
        let total = options.experience_passes * problems.len();
        let mut count = 0;
        let passes = solve_with_experience(
            robot,
            &loaded,
            &options.rrt,
            options.experience_passes,
            |_, k| {
                count += 1;
                progress("problems with experience", count, total, &problems[k]);
            },
        )?;
        for outcomes in passes {
            experience.push(runs_of(robot, &loaded, outcomes, options)?);
        }
    }
    let mut leave_one_out = Vec::new();
    if options.experience_passes > 0 {
        // the plain run's paths, each problem planned through the others'
        let paths: Vec<Vec<Vec<f64>>> = runs
            .iter()
            .map(|r| match r.outcome.solved {
                true => r.outcome.path.clone(),
                false => Vec::new(),
            })
            .collect();
        for (scope, stage) in [
            (Scope::Family, "leave-one-out, family"),
            (Scope::Set, "leave-one-out, set"),
        ] {
            let mut finished = 0;
            let outcomes = solve_leave_one_out(robot, &loaded, &paths, scope, &options.rrt, |k| {
                finished += 1;
                progress(stage, finished, problems.len(), &problems[k])
            })?;
            leave_one_out.push((
                scope,
                runs_of(robot, &loaded, outcomes.outcomes, options)?,
                runs_of(robot, &loaded, outcomes.fresh, options)?,
            ));
        }
    }
    Ok(Benchmark {
        problems: loaded,
        runs,
        experience,
        leave_one_out,
        with_maps,
        verified: options.verify,
    })
}

/// Outcomes in the order of `problems` as runs, their paths verified when `options` say.
fn runs_of(
    robot: &RobotModel,
    problems: &[LoadedProblem],
    outcomes: Vec<Outcome>,
    options: &BenchmarkOptions,
) -> Result<Vec<Run>, MbmError> {
    outcomes
        .into_iter()
        .zip(problems)
        .map(|(outcome, p)| {
            Ok(Run {
                family: p.problem.family.clone(),
                index: p.problem.index,
                verified: verify_outcome(robot, p, &outcome, options)?,
                outcome,
            })
        })
        .collect()
}

/// Solves each problem by RRT-Connect + shortcutting through kept planners ([`Solver`]: the
/// outcomes [`crate::solve_loaded`] gives), re-checking solved paths when `options.verify`;
/// with `options.task_space`, each joint goal is first turned into the task-space goal it
/// implies. With `options.maps`, each problem is also solved with the maps attached
/// ([`crate::solve_with_maps`]) right before or after, in turn, so that a machine's changing
/// load weighs on both runs alike, and so does the head start the second query of a problem
/// gets from the first (its scene in the caches). Returns the plain runs and those with the maps
/// (empty without maps); `progress(done, problem)` after each problem.
pub fn run_set(
    robot: &RobotModel,
    problems: &[LoadedProblem],
    options: &BenchmarkOptions,
    mut progress: impl FnMut(usize, &Problem),
) -> Result<(Vec<Run>, Vec<Run>), MbmError> {
    let mut runs = Vec::with_capacity(problems.len());
    let mut with_maps = Vec::new();
    let (mut plain, mut mapped) = (Solver::new(robot, &[]), Solver::new(robot, &options.maps));
    for (k, p) in problems.iter().enumerate() {
        let posed;
        let p = match &options.task_space {
            Some(t) => {
                posed = p.with_task_space(robot, t)?;
                &posed
            }
            None => p,
        };
        let run = |solver: &mut Solver| -> Result<Run, MbmError> {
            let outcome = solver.solve(p, &options.rrt)?;
            Ok(Run {
                family: p.problem.family.clone(),
                index: p.problem.index,
                verified: verify_outcome(robot, p, &outcome, options)?,
                outcome,
            })
        };
        if options.maps.is_empty() {
            runs.push(run(&mut plain)?);
        } else if k % 2 == 0 {
            runs.push(run(&mut plain)?);
            with_maps.push(run(&mut mapped)?);
        } else {
            // in turn first and second: the query second finds the problem's scene in the
            // caches
            with_maps.push(run(&mut mapped)?);
            runs.push(run(&mut plain)?);
        }
        progress(k + 1, &p.problem);
    }
    Ok((runs, with_maps))
}

/// With `options.verify`, what certification proves about a solved problem's path.
fn verify_outcome(
    robot: &RobotModel,
    problem: &LoadedProblem,
    outcome: &Outcome,
    options: &BenchmarkOptions,
) -> Result<Option<Verdict>, MbmError> {
    (options.verify && outcome.solved)
        .then(|| certify_path_loaded(robot, problem, &outcome.path))
        .transpose()
}

impl Benchmark {
    /// The report in markdown: the plain run's per-family table and, for each pass with
    /// experience, how many problems the experience answered and its table; with verification,
    /// how many paths collide when re-checked.
    pub fn markdown(&self) -> String {
        let mut md = markdown_table(self.runs.iter().map(|r| (r.family.as_str(), &r.outcome)));
        if self.verified {
            md.push_str(&verified_line(&self.runs, "Every returned path"));
        }
        for (pass, runs) in self.experience.iter().enumerate() {
            let solved = |note: Option<&str>| {
                runs.iter()
                    .filter(|r| r.outcome.solved && note.is_none_or(|n| r.outcome.note == n))
                    .count()
            };
            let retrieved = solved(Some("retrieved"));
            let _ = write!(
                md,
                "\nWith experience kept, pass {} ({}; {} of {} solved problems answered by the experience alone, {retrieved} of them by retrieving the kept path whose ends they repeat):\n\n{}",
                pass + 1,
                if pass == 0 {
                    "one planner per family: each problem planned through the paths of the family's earlier problems, checked lazily in its scene, RRT-Connect where they do not reach"
                } else {
                    "the same queries again: the set once more with every path of pass 1 kept, the problem's own included — a replay, not experience of a new query"
                },
                solved(Some("experience")) + retrieved,
                solved(None),
                markdown_table(runs.iter().map(|r| (r.family.as_str(), &r.outcome)))
            );
            if self.verified {
                md.push_str(&verified_line(runs, "Every path"));
            }
        }
        for (scope, runs, fresh) in &self.leave_one_out {
            let through = runs
                .iter()
                .filter(|r| r.outcome.solved && r.outcome.note == "experience")
                .count();
            let _ = write!(
                md,
                "\nLeave-one-out experience, {}: each problem planned through the plain run's paths of every other problem of {} (never its own), RRT-Connect where they do not reach; {through} answered through them. Beside each problem solved afresh right before or after it, in turn (ratio = leave-one-out / fresh):\n\n{}",
                match scope {
                    Scope::Family => "within the family",
                    Scope::Set => "across the set",
                },
                match scope {
                    Scope::Family => "its family",
                    Scope::Set => "the set that moves the same motors",
                },
                side_by_side(
                    (&family_outcomes(runs), "leave-one-out"),
                    (&family_outcomes(fresh), "fresh")
                )
            );
            if self.verified {
                md.push_str(&verified_line(runs, "Every leave-one-out path"));
            }
        }
        if !self.with_maps.is_empty() {
            let by_graph = self
                .with_maps
                .iter()
                .filter(|r| r.outcome.solved && r.outcome.note.ends_with("graph"))
                .count();
            let solved = self.with_maps.iter().filter(|r| r.outcome.solved).count();
            let _ = write!(
                md,
                "\nWith the maps attached ({by_graph} of {solved} solved problems answered through them), beside the plain run (ratio = with maps / without):\n\n{}",
                side_by_side(
                    (&family_outcomes(&self.with_maps), "with maps"),
                    (&family_outcomes(&self.runs), "without")
                )
            );
            if self.verified {
                md.push_str(&verified_line(&self.with_maps, "Every path with maps"));
            }
        }
        md
    }
}

/// Each run's family and outcome.
fn family_outcomes(runs: &[Run]) -> Vec<(&str, &Outcome)> {
    runs.iter()
        .map(|r| (r.family.as_str(), &r.outcome))
        .collect()
}

/// "`what` certified …: P of N proved free, C collide, U …" of verified runs.
fn verified_line(runs: &[Run], what: &str) -> String {
    verdicts_line(runs.iter().filter_map(|r| r.verified), what)
}

/// "`what` certified in continuous motion …: P of N proved free, C collide, U not proved."
pub fn verdicts_line(verdicts: impl Iterator<Item = Verdict>, what: &str) -> String {
    let mut counts = [0; 3];
    for v in verdicts {
        counts[v as usize] += 1;
    }
    let [proved, collides, unproved] = counts;
    format!(
        "\n{what} certified in continuous motion (f64, exact distances, lever-arm bounds; its own code path): {proved} of {} proved free, {collides} collide, {unproved} come within {} nm of contact (not proved).\n",
        proved + collides + unproved,
        crate::solve::VERIFY_FLOOR * 1e9
    )
}
