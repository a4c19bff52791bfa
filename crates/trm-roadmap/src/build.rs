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
use std::path::Path;
use std::time::Instant;

use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;
use trm_kinematics::LANES;
use trm_optim::{Bounds, Optimizer, Population, Start, StopOptions, Xnes, XnesOptions};

use crate::checkpoint::{CHECKPOINT_VERSION, Checkpoint, SearchState, StreamPosition};
use trm_tasks::spec::{FailureCount, MapSpec};
use trm_tasks::{Objective, Problem, ScratchPool};

use crate::builder::CheckpointOptions;
use crate::error::{Result, RoadmapError};
use crate::index::TaskIndex;
use crate::map::{BuildStats, FORMAT, MapPoint, Roadmap, VERSION};
use crate::team::{Team, all_gather_f64};
use trm_collision::edge::distance;

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

/// A running search, as every process of the [`Team`] knows it.
struct Search {
    /// The process that runs it.
    owner: usize,
    /// The map point it started from (none for the first search, from the start posture).
    from: Option<usize>,
    /// Candidates per generation.
    population: usize,
    /// g and h* of its last centre (h* NaN before the first generation).
    centre_t: Vec<f64>,
    centre_f: f64,
    /// Its converged (clamped) mean, once it has stopped.
    stopped: Option<Vec<f64>>,
    /// Its distribution and stream, on its owner only.
    own: Option<Owned>,
}

/// What only a search's owner holds.
struct Owned {
    xnes: Xnes,
    rng: ChaCha8Rng,
    /// The last ask's candidates, copied into a buffer kept from generation to generation.
    candidates: Population,
}

/// The process with the fewest running searches (the lowest of ties): the owner of the next.
fn least_loaded(searches: &[Search], size: usize) -> usize {
    let mut load = vec![0usize; size];
    for s in searches {
        load[s.owner] += 1;
    }
    (0..size).min_by_key(|&r| (load[r], r)).unwrap_or(0)
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

thread_local! {
    /// Each worker's kNN result buffer for h_map (kept: no allocation per candidate).
    static NEAREST: std::cell::RefCell<Vec<(f64, usize)>> = const { std::cell::RefCell::new(Vec::new()) };
}

/// h and g of `qs` on the current rayon pool's threads, [`LANES`] at a time,
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
    pub(crate) fn fresh(setup: &Setup) -> Self {
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

    /// The checkpoint of this state, on rank 0 (`None` on the other processes, which send it
    /// their searches' distributions).
    fn checkpoint(
        &self,
        setup: &Setup,
        every: usize,
        seconds: f64,
        team: &mut dyn Team,
    ) -> Result<Option<Checkpoint>> {
        let problem = setup.problem;
        let owned = self
            .searches
            .iter()
            .enumerate()
            .filter_map(|(i, s)| s.own.as_ref().map(|own| (i, s, own)))
            .map(|(i, s, own)| {
                Ok((
                    i,
                    SearchState {
                        xnes: own.xnes.snapshot()?,
                        rng: StreamPosition::of(&own.rng),
                        from: s.from,
                        centre_t: s.centre_t.clone(),
                        centre_f: s.centre_f,
                    },
                ))
            })
            .collect::<Result<Vec<_>>>()?;
        let label = Path::new("the running searches");
        let format = "trm-searches";
        let bytes = trm_io::binary_bytes(label, &owned, format, CHECKPOINT_VERSION)?;
        let parts = team.all_gather(&bytes)?;
        if team.rank() != 0 {
            return Ok(None);
        }
        let mut running = vec![None; self.searches.len()];
        for part in parts {
            let states: Vec<(usize, SearchState)> =
                trm_io::parse_binary_versioned(label, &part, format, CHECKPOINT_VERSION)?;
            for (i, state) in states {
                if let Some(slot) = running.get_mut(i) {
                    *slot = Some(state);
                }
            }
        }
        let running = running.into_iter().collect::<Option<Vec<_>>>().ok_or_else(|| {
            RoadmapError::Unsuitable(
                "a process of the build sent no state for a search it runs; start every process with the same spec and options".into(),
            )
        })?;
        Ok(Some(Checkpoint {
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
        }))
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

    /// The state a checkpoint holds, for `setup` (which checked the checkpoint's settings), with
    /// the searches shared among `team` as the build shares them.
    pub(crate) fn restore(setup: &Setup, checkpoint: Checkpoint, team: &dyn Team) -> Result<Self> {
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
        let mut searches: Vec<Search> = Vec::with_capacity(checkpoint.running.len());
        for s in checkpoint.running {
            let xnes = Xnes::resume(s.xnes)?;
            if xnes.dim() != n || s.centre_t.len() != setup.dim {
                return Err(unfit("a running search has the wrong dimension".into()));
            }
            // owners as the build assigned them, search by search
            let owner = least_loaded(&searches, team.size());
            searches.push(Search {
                owner,
                from: s.from,
                population: xnes.population(),
                centre_t: s.centre_t,
                centre_f: s.centre_f,
                stopped: None,
                own: (owner == team.rank()).then(|| Owned {
                    xnes,
                    rng: s.rng.rng(setup.seed),
                    candidates: Population::default(),
                }),
            });
        }
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

pub(crate) fn active_names(problem: &Problem) -> Vec<String> {
    problem
        .objective
        .active()
        .names()
        .map(str::to_string)
        .collect()
}

/// Algorithm 2 from `state` on; see the module documentation.
pub(crate) fn run(
    setup: &Setup,
    mut state: State,
    checkpoint: Option<&CheckpointOptions>,
    team: &mut dyn Team,
    mut progress: impl FnMut(&Progress),
) -> Result<Roadmap> {
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
    let pool = ScratchPool::default();
    let report = |state: &State, generations, parallel_seconds, seconds| Progress {
        points: state.map.points.len(),
        target: setup.target,
        failures: state.failures,
        total_failures: state.total_failures,
        evaluations: state.evaluations,
        generations,
        parallel_seconds,
        seconds,
    };
    let stopped_because = loop {
        if let Some(c) = checkpoint
            && state.map.points.len() >= checkpointed + c.every
        {
            if let Some(file) = state.checkpoint(setup, c.every, seconds(), team)? {
                file.save(&c.path)?;
            }
            checkpointed = state.map.points.len();
        }
        if let Some(reason) = stop_reason(setup, &state, team)? {
            break reason;
        }
        start_searches(setup, &mut state, team.rank(), team.size())?;
        let parallel_start = Instant::now();
        state.evaluations += generation(setup, &mut state.searches, &state.map, team, &pool)?;
        parallel_seconds += parallel_start.elapsed().as_secs_f64();
        generations += 1;
        if check_converged(setup, &mut state, &mut near) {
            progress(&report(&state, generations, parallel_seconds, seconds()));
        }
    };
    if let Some(c) = checkpoint {
        if let Some(file) = state.checkpoint(setup, c.every, seconds(), team)? {
            file.save(&c.path)?;
        }
    }
    let build_seconds = seconds();
    progress(&report(
        &state,
        generations,
        parallel_seconds,
        build_seconds,
    ));
    Ok(finish(setup, state, stopped_because, build_seconds))
}

/// Why the build stops now, if it does: the target reached, too many failed searches, the time
/// or evaluation budget spent (rank 0's clock decides for every process).
fn stop_reason(setup: &Setup, state: &State, team: &mut dyn Team) -> Result<Option<String>> {
    let (target, settings) = (setup.target, &setup.settings);
    if state.map.points.len() >= target {
        return Ok(Some(format!("reached {target} points")));
    }
    let (counted, which) = match settings.failures {
        FailureCount::Total => (state.total_failures, "failed searches"),
        FailureCount::Consecutive => (state.failures as u64, "consecutive failed searches"),
    };
    if counted >= settings.failure_limit as u64 {
        return Ok(Some(format!(
            "{counted} {which} (k = {})",
            settings.failure_limit
        )));
    }
    if let Some(deadline) = setup.deadline {
        let now = [f64::from(u8::from(Instant::now() >= deadline))];
        let spent = if team.size() > 1 {
            all_gather_f64(team, &now)?[0]
        } else {
            now[0]
        };
        if spent != 0.0 {
            return Ok(Some("time budget spent".to_string()));
        }
    }
    if setup
        .max_evaluations
        .is_some_and(|m| state.evaluations >= m)
    {
        return Ok(Some(format!(
            "evaluation budget spent ({} evaluations)",
            state.evaluations
        )));
    }
    Ok(None)
}

/// Starts searches: one from home while the map is empty, then up to P, each from a selected
/// map point (or home) on the process that runs the fewest.
fn start_searches(setup: &Setup, state: &mut State, rank: usize, size: usize) -> Result<()> {
    let (problem, settings, bounds) = (setup.problem, &setup.settings, &setup.bounds);
    let State {
        master,
        map,
        searches,
        started: started_count,
        ..
    } = state;
    let wanted = if map.points.is_empty() {
        1
    } else {
        setup.searches.min(map.points.len())
    };
    while searches.len() < wanted {
        let from = map.select(master);
        let (q0, (lambda, sigma)) = match from {
            Some(i) => (map.points[i].q.clone(), settings.later_search),
            None => (problem.start.clone(), settings.first_search),
        };
        let owner = least_loaded(searches, size);
        let own = if owner == rank {
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
            let mut rng = ChaCha8Rng::seed_from_u64(setup.seed);
            rng.set_stream(*started_count + 1);
            Some(Owned {
                xnes,
                rng,
                candidates: Population::default(),
            })
        } else {
            None
        };
        *started_count += 1;
        searches.push(Search {
            owner,
            from,
            population: lambda,
            centre_t: vec![0.0; setup.dim],
            centre_f: f64::NAN,
            stopped: None,
            own,
        });
    }
    Ok(())
}

/// One generation of every search: each process asks its searches, evaluates their
/// candidates and their new centres in parallel and tells them; every process then learns every
/// search's centre and whether it stopped. The evaluations it took, over all processes.
fn generation(
    setup: &Setup,
    searches: &mut [Search],
    map: &Growing,
    team: &mut dyn Team,
    pool: &ScratchPool,
) -> Result<u64> {
    let (objective, settings, bounds, dim) =
        (setup.objective, &setup.settings, &setup.bounds, setup.dim);
    let d = settings.spacing;
    let m = dim; // the number of neighbours is tied to the task-space dimension
    let size = team.size();
    let centres: Vec<Vec<f64>> = searches.iter().map(|s| s.centre_t.clone()).collect();
    let have_centres = searches
        .iter()
        .map(|s| s.centre_f.is_finite())
        .collect::<Vec<_>>();
    // asks in parallel (each search draws from its own stream)
    searches
        .par_iter_mut()
        .filter_map(|s| s.own.as_mut())
        .for_each(|own| own.candidates.clone_from(own.xnes.ask(&mut own.rng)));
    let jobs: Vec<(usize, &[f64])> = searches
        .iter()
        .enumerate()
        .filter_map(|(i, s)| s.own.as_ref().map(|own| (i, own)))
        .flat_map(|(i, own)| own.candidates.iter().map(move |x| (i, x)))
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
    // h* of (search, candidate) jobs: h and g on this process's threads, then h_map and
    // h_repel in parallel batches: `fitness[k]`, and g in `tasks[k·dim..]`
    let evaluate = |jobs: &[(usize, &[f64])], fitness: &mut [f64], tasks: &mut [f64]| {
        let qs: Vec<&[f64]> = jobs.iter().map(|job| job.1).collect();
        evaluate_on_threads(objective, &qs, fitness, tasks, pool);
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
    };
    // every candidate of this process's searches
    let mut fitness = vec![0.0; jobs.len()];
    let mut tasks = vec![0.0; jobs.len() * dim];
    evaluate(&jobs, &mut fitness, &mut tasks);
    // tells in parallel, one task per search; then every search's centre
    let mut offsets = Vec::with_capacity(searches.len());
    let mut offset = 0;
    for s in searches.iter() {
        offsets.push(offset);
        offset += s.own.as_ref().map_or(0, |_| s.population);
    }
    let told: Vec<trm_optim::Result<(usize, Vec<f64>)>> = searches
        .par_iter_mut()
        .enumerate()
        .filter_map(|(i, s)| s.own.as_mut().map(|own| (i, s.population, own)))
        .map(|(i, n, own)| {
            own.xnes.tell(&fitness[offsets[i]..offsets[i] + n])?;
            let mut q = own.xnes.mean().to_vec();
            bounds.clamp(&mut q);
            Ok((i, q))
        })
        .collect();
    let centre_qs = told.into_iter().collect::<trm_optim::Result<Vec<_>>>()?;
    let centre_jobs: Vec<(usize, &[f64])> =
        centre_qs.iter().map(|(i, q)| (*i, q.as_slice())).collect();
    let mut centre_f = vec![0.0; centre_jobs.len()];
    let mut centre_t = vec![0.0; centre_jobs.len() * dim];
    evaluate(&centre_jobs, &mut centre_f, &mut centre_t);
    // each search's outcome: [index, h* and g of its centre, whether it stopped, its mean]
    let mut outcomes = Vec::new();
    for (k, (i, q)) in centre_qs.iter().enumerate() {
        let Some(own) = searches[*i].own.as_mut() else {
            continue;
        };
        own.xnes.record_center_fitness(q, centre_f[k]);
        let stopped = !own.xnes.stop().is_empty();
        outcomes.push(*i as f64);
        outcomes.push(centre_f[k]);
        outcomes.extend_from_slice(&centre_t[k * dim..(k + 1) * dim]);
        outcomes.push(f64::from(u8::from(stopped)));
        outcomes.extend_from_slice(q);
    }
    let outcomes = if size > 1 {
        all_gather_f64(team, &outcomes)?
    } else {
        outcomes
    };
    let record = 3 + dim + objective.dim();
    if outcomes.len() != searches.len() * record {
        return Err(RoadmapError::Unsuitable(format!(
            "the processes of the build reported {} values for {} searches; start every process with the same spec and options",
            outcomes.len(),
            searches.len()
        )));
    }
    let running = searches.len();
    for outcome in outcomes.chunks_exact(record) {
        let s = searches.get_mut(outcome[0] as usize).ok_or_else(|| {
            RoadmapError::Unsuitable(format!(
                "a process of the build reported search {} of {running}",
                outcome[0]
            ))
        })?;
        s.centre_f = outcome[1];
        s.centre_t.copy_from_slice(&outcome[2..2 + dim]);
        if outcome[2 + dim] != 0.0 {
            s.stopped = Some(outcome[3 + dim..].to_vec());
        }
    }
    Ok(searches
        .iter()
        .map(|s| s.population as u64 + 1)
        .sum::<u64>())
}

/// CHECK of the converged searches (in search order): each mean added to the map, or counted
/// as a failure of the search and of the point it started from. Whether the map grew.
fn check_converged(setup: &Setup, state: &mut State, near: &mut Vec<usize>) -> bool {
    let (objective, dim, d) = (setup.objective, setup.dim, setup.settings.spacing);
    let State {
        map,
        searches,
        failures,
        total_failures,
        ..
    } = state;
    let mut changed = false;
    let mut k = 0;
    while k < searches.len() {
        if searches[k].stopped.is_none() {
            k += 1;
            continue;
        }
        let s = searches.remove(k);
        let q = s.stopped.unwrap_or_default();
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
        let ok =
            cost.is_finite() && outside && inside && objective.is_collision_free(&q, &mut scratch);
        if ok {
            map.add(MapPoint { q, t, cost }, 1.5 * d, near, true);
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
    changed
}

/// The map the build made, with its settings and statistics.
fn finish(setup: &Setup, state: State, stopped_because: String, build_seconds: f64) -> Roadmap {
    let (problem, objective) = (setup.problem, setup.objective);
    Roadmap {
        format: FORMAT.into(),
        version: VERSION,
        software: software(),
        spec_path: problem.origin.clone(),
        spec: problem.text.clone(),
        seed: setup.seed,
        searches: setup.searches,
        settings: setup.settings.clone(),
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
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn new_searches_go_to_the_least_loaded_process() {
        let on = |owner| Search {
            owner,
            from: None,
            population: 2,
            centre_t: Vec::new(),
            centre_f: f64::NAN,
            stopped: None,
            own: None,
        };
        assert_eq!(least_loaded(&[], 3), 0);
        assert_eq!(least_loaded(&[on(0)], 3), 1);
        assert_eq!(least_loaded(&[on(0), on(1)], 3), 2);
        assert_eq!(least_loaded(&[on(0), on(1), on(2)], 3), 0);
        assert_eq!(least_loaded(&[on(1), on(2), on(1)], 3), 0);
        assert_eq!(least_loaded(&[on(0), on(0)], 1), 0);
    }
}
