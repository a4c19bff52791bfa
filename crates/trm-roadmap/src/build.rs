//! Parallel E-TRM (Stollenga, Schmidhuber and Gomez; Algorithm 2, which with P = 1 is
//! Algorithm 1, E-TRM): P concurrent xNES searches grow the map, each minimising
//! h* = h + α_map h_map + α_repel h_repel, one generation at a time for all of them.
//!
//! Determinism: P (an algorithm setting) is separate from the thread count (an execution
//! setting). The searches' candidates are evaluated in parallel, but every random draw comes from
//! a per-search ChaCha stream or from the master stream in the sequential part, and the map only
//! changes between generations, in search order: a seed and P give the same map on any number of
//! threads.

use std::collections::BTreeSet;
use std::path::PathBuf;
use std::time::Instant;

use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;
use trm_kinematics::LANES;
use trm_optim::{Bounds, Optimizer, Population, Start, StopOptions, Xnes, XnesOptions};

use crate::checkpoint::{Checkpoint, SearchState, StreamPosition};
use trm_tasks::spec::{FailureCount, MapSpec};
use trm_tasks::{Objective, Problem, ScratchPool};

use crate::edges::distance;
use crate::error::{Result, RoadmapError};
use crate::index::TaskIndex;
use crate::map::{BuildStats, FORMAT, MapPoint, Roadmap, VERSION};

/// Execution settings of a build (the algorithm settings are the spec's `map`).
#[derive(Debug, Clone)]
pub struct BuildOptions {
    /// Stop at this many points (overrides the spec's `max_points` when set).
    pub points: Option<usize>,
    /// Concurrent searches P (overrides the spec's `searches` when set).
    pub searches: Option<usize>,
    /// Seed (overrides the spec's solver seed when set).
    pub seed: Option<u64>,
    /// Longest search, in generations (a cap beside the 20/40 convergence rule).
    pub max_generations: u64,
    /// Weight of the repulsion between concurrent searches.
    pub repel_weight: f64,
    /// Write a [`Checkpoint`] while building (and once at the end), to resume a killed build.
    pub checkpoint: Option<CheckpointOptions>,
    /// The joint step (rad) at which [`build_connected`] checks edges.
    pub edge_resolution: f64,
}

/// The joint step (rad) at which edges are checked unless told otherwise.
pub const DEFAULT_EDGE_RESOLUTION: f64 = 0.05;

/// Where and how often a build writes its [`Checkpoint`].
#[derive(Debug, Clone, PartialEq)]
pub struct CheckpointOptions {
    /// The checkpoint file (replaced atomically each time).
    pub path: PathBuf,
    /// Write one each time the map has grown by this many points.
    pub every: usize,
}

impl Default for BuildOptions {
    fn default() -> Self {
        BuildOptions {
            points: None,
            searches: None,
            seed: None,
            max_generations: 400,
            repel_weight: 1.0,
            checkpoint: None,
            edge_resolution: DEFAULT_EDGE_RESOLUTION,
        }
    }
}

/// Progress, reported after each generation that changed the map and at the end.
#[derive(Debug, Clone, Copy)]
pub struct Progress {
    /// Points in the map.
    pub points: usize,
    /// Target number of points.
    pub target: usize,
    /// Consecutive failed searches.
    pub failures: usize,
    /// All failed searches.
    pub total_failures: u64,
    /// Evaluations so far.
    pub evaluations: u64,
    /// Generations run so far (in this run, when resumed).
    pub generations: u64,
    /// Wall seconds spent so far in the parallel part of the generations (asks, candidate and
    /// centre evaluations, tells; in this run); the rest of `seconds` is the sequential part
    /// (selecting, starting and checking searches, growing the map).
    pub parallel_seconds: f64,
    /// Seconds since the start.
    pub seconds: f64,
}

struct Search {
    xnes: Xnes,
    rng: ChaCha8Rng,
    from: Option<usize>,
    centre_t: Vec<f64>,
    centre_f: f64,
    /// The last ask's candidates, copied into a buffer kept from generation to generation.
    candidates: Population,
}

/// The map under construction: points, their index and the SELECTPROPORTIONAL bookkeeping.
struct Growing {
    points: Vec<MapPoint>,
    index: TaskIndex,
    neighbours: Vec<usize>,
    fails: Vec<usize>,
    /// (neighbours + failures, index) of every point searches may start from, for
    /// SELECTPROPORTIONAL.
    scores: BTreeSet<(usize, usize)>,
    /// Whether searches may start from a point (all in a build; near the lost region in a
    /// repair).
    selectable: Vec<bool>,
}

impl Growing {
    fn new(dim: usize) -> Self {
        Growing {
            points: Vec::new(),
            index: TaskIndex::new(dim),
            neighbours: Vec::new(),
            fails: Vec::new(),
            scores: BTreeSet::new(),
            selectable: Vec::new(),
        }
    }

    /// Adds a point and counts it as a neighbour of the points within `radius` (and they of it);
    /// searches may start from it when `selectable`.
    fn add(&mut self, point: MapPoint, radius: f64, near: &mut Vec<usize>, selectable: bool) {
        let i = self.points.len();
        self.index.within(&point.t, radius, near);
        for &j in near.iter() {
            self.set_neighbours(j, self.neighbours[j] + 1);
        }
        self.index.add(&point.t);
        self.points.push(point);
        self.neighbours.push(near.len());
        self.fails.push(0);
        self.selectable.push(selectable);
        if selectable {
            self.scores.insert((near.len(), i));
        }
    }

    fn score(&self, i: usize) -> usize {
        self.neighbours[i] + self.fails[i]
    }

    fn set_neighbours(&mut self, i: usize, n: usize) {
        self.rescore(i, |g| g.neighbours[i] = n);
    }

    fn set_fails(&mut self, i: usize, n: usize) {
        self.rescore(i, |g| g.fails[i] = n);
    }

    /// Changes point `i`'s bookkeeping with `change`, keeping its score in the set.
    fn rescore(&mut self, i: usize, change: impl FnOnce(&mut Self)) {
        let was = (self.score(i), i);
        change(self);
        if self.selectable[i] {
            self.scores.remove(&was);
            self.scores.insert((self.score(i), i));
        }
    }

    /// SELECTPROPORTIONAL: a point with the fewest neighbours + failures, uniformly among ties
    /// (in index order, so a draw picks the same point whatever the bookkeeping).
    fn select(&self, rng: &mut ChaCha8Rng) -> Option<usize> {
        let &(best, _) = self.scores.first()?;
        let ties = self.scores.range((best, 0)..(best + 1, 0));
        let k = rng.random_range(0..ties.clone().count());
        ties.map(|&(_, i)| i).nth(k)
    }
}

/// The most points a map may ask for (a bound that names itself rather than an allocation
/// failure).
pub const MAX_POINTS: usize = 10_000_000;
/// The most concurrent searches P.
pub const MAX_SEARCHES: usize = 4096;

/// Where a build's candidates are evaluated: h(q) and g(q) for a batch, on this process's
/// threads ([`Threads`]) or spread over processes (the `mpi` feature's `trm_roadmap::mpi`).
/// Every evaluation of an [`Objective`] gives the same bits however candidates are split, so a
/// seed and P give the same map whatever evaluates them.
pub trait Evaluator {
    /// h(qs\[k\]) into `fitness[k]` and g(qs\[k\]) into `tasks[k·dim..(k + 1)·dim]`.
    fn evaluate(
        &mut self,
        objective: &Objective,
        qs: &[&[f64]],
        fitness: &mut [f64],
        tasks: &mut [f64],
    ) -> Result<()>;
}

/// Evaluates on the threads of the current rayon pool, [`LANES`] candidates at a time, with
/// scratch buffers kept from call to call (no allocation per evaluation).
#[derive(Debug, Default)]
pub struct Threads {
    scratch: ScratchPool,
}

impl Evaluator for Threads {
    fn evaluate(
        &mut self,
        objective: &Objective,
        qs: &[&[f64]],
        fitness: &mut [f64],
        tasks: &mut [f64],
    ) -> Result<()> {
        evaluate_on_threads(objective, qs, fitness, tasks, &self.scratch);
        Ok(())
    }
}

thread_local! {
    /// Each worker's kNN result buffer for h_map (kept: no allocation per candidate).
    static NEAREST: std::cell::RefCell<Vec<(f64, usize)>> = const { std::cell::RefCell::new(Vec::new()) };
}

/// h and g of `qs` on the current rayon pool's threads, [`LANES`] at a time ([`Threads`]),
/// with scratch buffers from `pool`.
pub fn evaluate_on_threads(
    objective: &Objective,
    qs: &[&[f64]],
    fitness: &mut [f64],
    tasks: &mut [f64],
    pool: &ScratchPool,
) {
    let dim = objective.task().map_or(0, |t| t.dim());
    fitness
        .par_chunks_mut(LANES)
        .zip(tasks.par_chunks_mut((LANES * dim).max(1)))
        .zip(qs.par_chunks(LANES))
        .for_each_init(
            || pool.lease(objective),
            |scratch, ((fitness, tasks), qs)| {
                objective.eval_with_task_batch(qs, scratch, fitness, tasks);
            },
        );
}

/// Where new points may go: within `radius` of one of the `lost` task points (a repair).
pub(crate) struct Region {
    pub(crate) lost: TaskIndex,
    pub(crate) radius: f64,
}

impl Region {
    fn contains(&self, t: &[f64], nn: &mut Vec<(f64, usize)>) -> bool {
        self.lost.nearest(t, 1, nn);
        nn.first().is_some_and(|&(dt, _)| dt <= self.radius)
    }
}

/// The fixed settings of one build.
pub(crate) struct Setup<'a> {
    problem: &'a Problem,
    /// The objective the build minimises (the problem's, or the same in another world).
    pub(crate) objective: &'a Objective,
    /// A repair grows only here; selection starts searches only from points near it.
    pub(crate) region: Option<Region>,
    pub(crate) settings: MapSpec,
    pub(crate) target: usize,
    searches: usize,
    seed: u64,
    pub(crate) max_generations: u64,
    pub(crate) repel_weight: f64,
    /// A repair's budget: stop at this instant, or after this many evaluations.
    pub(crate) deadline: Option<Instant>,
    pub(crate) max_evaluations: Option<u64>,
    bounds: Bounds,
    dim: usize,
}

impl<'a> Setup<'a> {
    /// Checks the spec and the counts; the task's dimension comes from its task function.
    pub(crate) fn new(
        problem: &'a Problem,
        target: Option<usize>,
        searches: Option<usize>,
        seed: Option<u64>,
    ) -> Result<Self> {
        let objective = &problem.objective;
        let task = objective.task().ok_or_else(|| {
            RoadmapError::Unsuitable(format!(
                "{}: the spec has no task function; add `task: Some(Position(part: \"...\"))`",
                problem.origin
            ))
        })?;
        let settings: MapSpec = problem.spec.map.clone().unwrap_or_default();
        let target = target.unwrap_or(settings.max_points);
        if target == 0 || target > MAX_POINTS {
            return Err(RoadmapError::Unsuitable(format!(
                "{target} points: give 1 to {MAX_POINTS} (spec `map.max_points` or the points option)"
            )));
        }
        let searches = searches.unwrap_or(settings.searches);
        if searches == 0 || searches > MAX_SEARCHES {
            return Err(RoadmapError::Unsuitable(format!(
                "{searches} concurrent searches: give 1 to {MAX_SEARCHES} (spec `map.searches` or the searches option)"
            )));
        }
        let (lower, upper) = objective.active().bounds();
        Ok(Setup {
            problem,
            objective,
            region: None,
            target,
            searches,
            seed: seed.unwrap_or(problem.spec.solver.seed),
            max_generations: 0,
            repel_weight: 0.0,
            deadline: None,
            max_evaluations: None,
            bounds: Bounds::new(lower, upper)?,
            dim: task.dim(),
            settings,
        })
    }
}

/// Everything a build holds between two generations.
pub(crate) struct State {
    master: ChaCha8Rng,
    map: Growing,
    searches: Vec<Search>,
    started: u64,
    failures: usize,
    total_failures: u64,
    evaluations: u64,
    /// Seconds spent before a resume.
    seconds_before: f64,
}

impl State {
    fn fresh(setup: &Setup) -> Self {
        State {
            master: ChaCha8Rng::seed_from_u64(setup.seed),
            map: Growing::new(setup.dim),
            searches: Vec::new(),
            started: 0,
            failures: 0,
            total_failures: 0,
            evaluations: 0,
            seconds_before: 0.0,
        }
    }

    fn checkpoint(&self, setup: &Setup, every: usize, seconds: f64) -> Result<Checkpoint> {
        let problem = setup.problem;
        let running = self
            .searches
            .iter()
            .map(|s| {
                Ok(SearchState {
                    xnes: s.xnes.snapshot()?,
                    rng: StreamPosition::of(&s.rng),
                    from: s.from,
                    centre_t: s.centre_t.clone(),
                    centre_f: s.centre_f,
                })
            })
            .collect::<Result<Vec<_>>>()?;
        Ok(Checkpoint {
            software: software(),
            spec_path: problem.origin.clone(),
            spec: problem.text.clone(),
            active: active_names(problem),
            seed: setup.seed,
            searches: setup.searches,
            target: setup.target,
            max_generations: setup.max_generations,
            repel_weight: setup.repel_weight,
            every,
            master: StreamPosition::of(&self.master),
            points: self.map.points.clone(),
            fails: self.map.fails.clone(),
            running,
            started: self.started,
            failures: self.failures,
            total_failures: self.total_failures,
            evaluations: self.evaluations,
            seconds,
        })
    }

    /// A build continuing from `points` (a repair): searches start only from the points
    /// within twice the region's radius of a lost point.
    pub(crate) fn from_points(setup: &Setup, points: Vec<MapPoint>) -> Self {
        let mut state = State::fresh(setup);
        let (mut near, mut nn) = (Vec::new(), Vec::new());
        for point in points {
            let selectable = setup.region.as_ref().is_none_or(|r| {
                r.lost.nearest(&point.t, 1, &mut nn);
                nn.first().is_some_and(|&(dt, _)| dt <= 2.0 * r.radius)
            });
            state
                .map
                .add(point, 1.5 * setup.settings.spacing, &mut near, selectable);
        }
        state
    }

    /// The state a checkpoint holds, for `setup` (which checked the checkpoint's settings).
    fn restore(setup: &Setup, checkpoint: Checkpoint) -> Result<Self> {
        let unfit = |what: String| {
            RoadmapError::Unsuitable(format!(
                "the checkpoint does not fit its own spec ({}): {what}; start the build again",
                checkpoint.spec_path
            ))
        };
        let n = setup.problem.objective.active().len();
        let mut map = Growing::new(setup.dim);
        let mut near = Vec::new();
        for (i, (point, fails)) in checkpoint
            .points
            .into_iter()
            .zip(checkpoint.fails)
            .enumerate()
        {
            if point.q.len() != n || point.t.len() != setup.dim {
                return Err(unfit(format!("points[{i}] has the wrong size")));
            }
            map.add(point, 1.5 * setup.settings.spacing, &mut near, true);
            map.set_fails(i, fails);
        }
        let searches = checkpoint
            .running
            .into_iter()
            .map(|s| {
                let xnes = Xnes::resume(s.xnes)?;
                if xnes.dim() != n || s.centre_t.len() != setup.dim {
                    return Err(unfit("a running search has the wrong dimension".into()));
                }
                Ok(Search {
                    xnes,
                    rng: s.rng.rng(setup.seed),
                    from: s.from,
                    centre_t: s.centre_t,
                    centre_f: s.centre_f,
                    candidates: Population::default(),
                })
            })
            .collect::<Result<Vec<_>>>()?;
        Ok(State {
            master: checkpoint.master.rng(setup.seed),
            map,
            searches,
            started: checkpoint.started,
            failures: checkpoint.failures,
            total_failures: checkpoint.total_failures,
            evaluations: checkpoint.evaluations,
            seconds_before: checkpoint.seconds,
        })
    }
}

fn software() -> String {
    format!("trm {}", env!("CARGO_PKG_VERSION"))
}

fn active_names(problem: &Problem) -> Vec<String> {
    problem
        .objective
        .active()
        .names()
        .map(str::to_string)
        .collect()
}

/// Builds the map of a spec (it needs a task function and `map` settings, or their defaults).
/// Zero or absurd point and search counts are errors.
pub fn build(
    problem: &Problem,
    options: &BuildOptions,
    progress: impl FnMut(&Progress),
) -> Result<Roadmap> {
    build_with(problem, options, &mut Threads::default(), progress)
}

/// [`build`] with the candidates evaluated by `evaluator` (e.g. across MPI processes): the
/// same map as [`build`].
pub fn build_with(
    problem: &Problem,
    options: &BuildOptions,
    evaluator: &mut dyn Evaluator,
    progress: impl FnMut(&Progress),
) -> Result<Roadmap> {
    let mut setup = Setup::new(problem, options.points, options.searches, options.seed)?;
    setup.max_generations = options.max_generations;
    setup.repel_weight = options.repel_weight;
    let state = State::fresh(&setup);
    run(
        &setup,
        state,
        options.checkpoint.as_ref(),
        evaluator,
        progress,
    )
}

/// A map ready to plan with: built ([`build`]) and connected ([`connect`]: each point to the
/// spec's `edge_neighbours` nearest, edges checked every `options.edge_resolution`, which is
/// checked before any building). Save it with [`Roadmap::save`].
pub fn build_connected(
    problem: &Problem,
    options: &BuildOptions,
    progress: impl FnMut(&Progress),
) -> Result<Roadmap> {
    build_connected_with(problem, options, None, &mut Threads::default(), progress)
}

/// [`build_connected`] finishing a killed build from its checkpoint when `resumed` is given
/// ([`resume_with`]), the candidates evaluated by `evaluator` ([`build_with`]).
pub fn build_connected_with(
    problem: &Problem,
    options: &BuildOptions,
    resumed: Option<Checkpoint>,
    evaluator: &mut dyn Evaluator,
    progress: impl FnMut(&Progress),
) -> Result<Roadmap> {
    crate::edges::check_edge_resolution(options.edge_resolution)?;
    let mut map = match resumed {
        Some(checkpoint) => resume_with(problem, checkpoint, options, evaluator, progress)?,
        None => build_with(problem, options, evaluator, progress)?,
    };
    let neighbours = map.settings.edge_neighbours;
    crate::edges::connect(
        &mut map,
        &problem.objective,
        neighbours,
        options.edge_resolution,
    )?;
    Ok(map)
}

/// Finishes a build from its [`Checkpoint`] with exactly the map the uninterrupted build gives
/// (timing statistics aside). `problem` is [`Checkpoint::problem`]. The seed, P and the search
/// settings are the checkpoint's: a `seed` or `searches` option that differs is an error;
/// `points` may set another target (the build goes on as if it had been started with it), and
/// `checkpoint` keeps writing checkpoints.
pub fn resume(
    problem: &Problem,
    checkpoint: Checkpoint,
    options: &BuildOptions,
    progress: impl FnMut(&Progress),
) -> Result<Roadmap> {
    resume_with(
        problem,
        checkpoint,
        options,
        &mut Threads::default(),
        progress,
    )
}

/// [`resume`] with the candidates evaluated by `evaluator`, as [`build_with`].
pub fn resume_with(
    problem: &Problem,
    checkpoint: Checkpoint,
    options: &BuildOptions,
    evaluator: &mut dyn Evaluator,
    progress: impl FnMut(&Progress),
) -> Result<Roadmap> {
    for (what, given, stored) in [
        ("seed", options.seed, checkpoint.seed),
        (
            "searches",
            options.searches.map(|p| p as u64),
            checkpoint.searches as u64,
        ),
    ] {
        if given.is_some_and(|g| g != stored) {
            return Err(RoadmapError::Unsuitable(format!(
                "the checkpoint's build has {what} {stored}; a resumed build keeps it (leave the {what} option out)"
            )));
        }
    }
    if problem.text != checkpoint.spec || active_names(problem) != checkpoint.active {
        return Err(RoadmapError::Unsuitable(format!(
            "the problem is not the checkpoint's ({}): resume with `Checkpoint::problem`",
            checkpoint.spec_path
        )));
    }
    let target = checkpoint.resume_target(options.points)?;
    let mut setup = Setup::new(
        problem,
        Some(target),
        Some(checkpoint.searches),
        Some(checkpoint.seed),
    )?;
    setup.max_generations = checkpoint.max_generations;
    setup.repel_weight = checkpoint.repel_weight;
    let state = State::restore(&setup, checkpoint)?;
    run(
        &setup,
        state,
        options.checkpoint.as_ref(),
        evaluator,
        progress,
    )
}

/// Algorithm 2 from `state` on; see the module documentation.
pub(crate) fn run(
    setup: &Setup,
    mut state: State,
    checkpoint: Option<&CheckpointOptions>,
    evaluator: &mut dyn Evaluator,
    mut progress: impl FnMut(&Progress),
) -> Result<Roadmap> {
    let problem = setup.problem;
    let objective = setup.objective;
    let settings = &setup.settings;
    let (target, p_searches, seed, dim) = (setup.target, setup.searches, setup.seed, setup.dim);
    let bounds = &setup.bounds;
    let d = settings.spacing;
    let m = dim; // the number of neighbours is tied to the task-space dimension
    if let Some(c) = checkpoint
        && c.every == 0
    {
        return Err(RoadmapError::Unsuitable(
            "a checkpoint every 0 points: give at least 1".into(),
        ));
    }
    let started = Instant::now();
    let before = state.seconds_before;
    let seconds = || before + started.elapsed().as_secs_f64();
    let mut checkpointed = state.map.points.len();
    let (mut generations, mut parallel_seconds) = (0u64, 0.0f64);
    let mut near = Vec::new();
    let stopped_because;

    loop {
        if let Some(c) = checkpoint
            && state.map.points.len() >= checkpointed + c.every
        {
            state.checkpoint(setup, c.every, seconds())?.save(&c.path)?;
            checkpointed = state.map.points.len();
        }
        let State {
            master,
            map,
            searches,
            started: started_count,
            failures,
            total_failures,
            evaluations,
            ..
        } = &mut state;
        if map.points.len() >= target {
            stopped_because = format!("reached {target} points");
            break;
        }
        let (counted, which) = match settings.failures {
            FailureCount::Total => (*total_failures, "failed searches"),
            FailureCount::Consecutive => (*failures as u64, "consecutive failed searches"),
        };
        if counted >= settings.failure_limit as u64 {
            stopped_because = format!("{counted} {which} (k = {})", settings.failure_limit);
            break;
        }
        if setup.deadline.is_some_and(|d| Instant::now() >= d) {
            stopped_because = "time budget spent".to_string();
            break;
        }
        if setup.max_evaluations.is_some_and(|m| *evaluations >= m) {
            stopped_because = format!("evaluation budget spent ({} evaluations)", *evaluations);
            break;
        }
        // start searches: one from home while the map is empty, then up to P
        let wanted = if map.points.is_empty() {
            1
        } else {
            p_searches.min(map.points.len())
        };
        while searches.len() < wanted {
            let from = map.select(master);
            let (q0, (lambda, sigma)) = match from {
                Some(i) => (map.points[i].q.clone(), settings.later_search),
                None => (problem.start.clone(), settings.first_search),
            };
            let start = Start::new(q0, sigma)
                .with_bounds(bounds.clone())
                .with_stop(StopOptions {
                    center_stagnation: Some((20, 40)),
                    max_generations: Some(setup.max_generations),
                    tol_x: None,
                    tol_fun: None,
                    ..Default::default()
                });
            let xnes = Xnes::new(
                &start,
                &XnesOptions {
                    population: Some(lambda),
                    ..Default::default()
                },
            )?;
            let mut rng = ChaCha8Rng::seed_from_u64(seed);
            rng.set_stream(*started_count + 1);
            *started_count += 1;
            searches.push(Search {
                xnes,
                rng,
                from,
                centre_t: vec![0.0; dim],
                centre_f: f64::NAN,
                candidates: Population::default(),
            });
        }
        // one generation of every search: ask, evaluate all candidates in parallel, tell
        let parallel_start = Instant::now();
        let centres: Vec<Vec<f64>> = searches.iter().map(|s| s.centre_t.clone()).collect();
        let have_centres = searches
            .iter()
            .map(|s| s.centre_f.is_finite())
            .collect::<Vec<_>>();
        // asks in parallel (each search draws from its own stream)
        searches.par_iter_mut().for_each(|s| {
            s.candidates.clone_from(s.xnes.ask(&mut s.rng));
        });
        let jobs: Vec<(usize, &[f64])> = searches
            .iter()
            .enumerate()
            .flat_map(|(i, s)| s.candidates.iter().map(move |x| (i, x)))
            .collect();
        // h* = h + h_map + h_repel for candidate q of search i, given h(q) and g(q) = t
        let h_star = |i: usize, q: &[f64], h: f64, t: &[f64], nn: &mut Vec<(f64, usize)>| {
            // h_map: construction and smoothness over the m nearest map points
            map.index.nearest(t, m, nn);
            let mut h_map = 0.0;
            for &(dt, j) in nn.iter() {
                h_map += (d - dt).abs() + settings.smoothness * distance(q, &map.points[j].q);
            }
            let mut h = h + settings.construct_weight * h_map;
            // h_repel: keep away from the other searches' centres
            let mut h_rep = 0.0;
            for (j, c) in centres.iter().enumerate() {
                if j != i && have_centres[j] {
                    h_rep += (d - distance(t, c)).max(0.0);
                }
            }
            h += setup.repel_weight * h_rep;
            h
        };
        // h* of (search, candidate) jobs: h and g by the evaluator, then h_map and h_repel in
        // parallel batches: `fitness[k]`, and g in `tasks[k·dim..]`
        let evaluate = |evaluator: &mut dyn Evaluator,
                        jobs: &[(usize, &[f64])],
                        fitness: &mut [f64],
                        tasks: &mut [f64]|
         -> Result<()> {
            let qs: Vec<&[f64]> = jobs.iter().map(|job| job.1).collect();
            evaluator.evaluate(objective, &qs, fitness, tasks)?;
            fitness
                .par_chunks_mut(LANES)
                .zip(tasks.par_chunks(LANES * dim))
                .zip(jobs.par_chunks(LANES))
                .for_each(|((fitness, tasks), jobs)| {
                    NEAREST.with_borrow_mut(|nn| {
                        for (k, &(i, q)) in jobs.iter().enumerate() {
                            let t = &tasks[k * dim..(k + 1) * dim];
                            fitness[k] = h_star(i, q, fitness[k], t, nn);
                        }
                    })
                });
            Ok(())
        };
        // every candidate of every search
        let mut fitness = vec![0.0; jobs.len()];
        let mut tasks = vec![0.0; jobs.len() * dim];
        evaluate(evaluator, &jobs, &mut fitness, &mut tasks)?;
        *evaluations += jobs.len() as u64;
        // tells in parallel, one task per search; then every search's centre
        let mut offsets = Vec::with_capacity(searches.len());
        let mut offset = 0;
        for s in searches.iter() {
            offsets.push(offset);
            offset += s.xnes.population();
        }
        let told: Vec<trm_optim::Result<Vec<f64>>> = searches
            .par_iter_mut()
            .enumerate()
            .map(|(i, s)| {
                let n = s.xnes.population();
                s.xnes.tell(&fitness[offsets[i]..offsets[i] + n])?;
                let mut q = s.xnes.mean().to_vec();
                bounds.clamp(&mut q);
                Ok(q)
            })
            .collect();
        let centre_qs = told.into_iter().collect::<trm_optim::Result<Vec<_>>>()?;
        let centre_jobs: Vec<(usize, &[f64])> = centre_qs
            .iter()
            .enumerate()
            .map(|(i, q)| (i, q.as_slice()))
            .collect();
        let mut centre_f = vec![0.0; searches.len()];
        let mut centre_t = vec![0.0; searches.len() * dim];
        evaluate(evaluator, &centre_jobs, &mut centre_f, &mut centre_t)?;
        for (i, s) in searches.iter_mut().enumerate() {
            s.xnes.record_center_fitness(&centre_qs[i], centre_f[i]);
            s.centre_f = centre_f[i];
            s.centre_t
                .copy_from_slice(&centre_t[i * dim..(i + 1) * dim]);
        }
        *evaluations += searches.len() as u64;
        parallel_seconds += parallel_start.elapsed().as_secs_f64();
        generations += 1;

        // converged searches: CHECK their mean, add it or count a failure (in search order)
        let mut changed = false;
        let mut k = 0;
        while k < searches.len() {
            if searches[k].xnes.stop().is_empty() {
                k += 1;
                continue;
            }
            let s = searches.remove(k);
            let mut q = s.xnes.mean().to_vec();
            bounds.clamp(&mut q);
            let mut scratch = objective.scratch();
            let mut t = vec![0.0; dim];
            let cost = objective.eval_with_task(&q, &mut scratch, &mut t);
            let mut nn = Vec::new();
            map.index.nearest(&t, 1, &mut nn);
            let outside = nn.first().is_none_or(|(dt, _)| *dt >= d / 2.0);
            let inside = setup
                .region
                .as_ref()
                .is_none_or(|r| r.contains(&t, &mut nn));
            let ok = cost.is_finite()
                && outside
                && inside
                && objective.is_collision_free(&q, &mut scratch);
            if ok {
                map.add(MapPoint { q, t, cost }, 1.5 * d, &mut near, true);
                *failures = 0;
                changed = true;
            } else {
                *failures += 1;
                *total_failures += 1;
                if let Some(from) = s.from {
                    map.set_fails(from, map.fails[from] + 1);
                }
            }
        }
        if changed {
            progress(&Progress {
                points: map.points.len(),
                target,
                failures: *failures,
                total_failures: *total_failures,
                evaluations: *evaluations,
                generations,
                parallel_seconds,
                seconds: seconds(),
            });
        }
    }
    if let Some(c) = checkpoint {
        state.checkpoint(setup, c.every, seconds())?.save(&c.path)?;
    }
    let build_seconds = seconds();
    progress(&Progress {
        points: state.map.points.len(),
        target,
        failures: state.failures,
        total_failures: state.total_failures,
        evaluations: state.evaluations,
        generations,
        parallel_seconds,
        seconds: build_seconds,
    });
    Ok(Roadmap {
        format: FORMAT.into(),
        version: VERSION,
        software: software(),
        spec_path: problem.origin.clone(),
        spec: problem.text.clone(),
        seed,
        searches: p_searches,
        settings: settings.clone(),
        active: active_names(problem),
        task: objective.task().map(|t| t.label()).unwrap_or_default(),
        points: state.map.points,
        edges: Vec::new(),
        edge_resolution: 0.0,
        world: None,
        parked: None,
        stats: BuildStats {
            build_seconds,
            edge_seconds: 0.0,
            evaluations: state.evaluations,
            searches_started: state.started,
            failures: state.total_failures,
            stopped_because,
            threads: rayon::current_num_threads(),
        },
    })
}
