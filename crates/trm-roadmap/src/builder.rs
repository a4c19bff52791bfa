//! One map builder: a spec's problem built with its options, connected or not, resumed from a
//! checkpoint or not, on the current thread pool or shared among a team.

use std::path::PathBuf;

use trm_tasks::Problem;
use trm_tasks::spec::MapSpec;

use crate::build::{Progress, Setup, State, active_names, run};
use crate::checkpoint::Checkpoint;
use crate::error::{Result, RoadmapError};
use crate::map::Roadmap;
use crate::team::{Solo, Team, on_threads};

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
    /// The joint step (rad) at which a connected build ([`Builder::connected`]) checks edges.
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

impl BuildOptions {
    /// The options that build `map` again (in another world, say): its size, P, seed and edge
    /// step.
    pub fn like(map: &Roadmap) -> Self {
        BuildOptions {
            points: Some(map.points.len()),
            searches: Some(map.searches),
            seed: Some(map.seed),
            edge_resolution: if map.edge_resolution > 0.0 {
                map.edge_resolution
            } else {
                DEFAULT_EDGE_RESOLUTION
            },
            ..Default::default()
        }
    }
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

/// P of a build of `problem` with `options` (before it is checked).
fn searches_of(problem: &Problem, options: &BuildOptions) -> usize {
    options.searches.unwrap_or_else(|| {
        problem
            .spec
            .map
            .as_ref()
            .map_or_else(|| MapSpec::default().searches, |m| m.searches)
    })
}

/// `job` on the current rayon pool's threads: a team of T threads when P is a multiple of
/// T > 1 (so every thread always runs as many searches as the others), else alone on the pool.
fn on_pool(
    searches: usize,
    mut progress: impl FnMut(&Progress),
    job: impl Fn(&mut dyn Team, &mut dyn FnMut(&Progress)) -> Result<Roadmap> + Sync,
) -> Result<Roadmap> {
    let threads = rayon::current_num_threads();
    if threads <= 1 || !searches.is_multiple_of(threads) {
        return job(&mut Solo, &mut progress);
    }
    let mut map = on_threads(threads, 1, job, progress)?;
    map.stats.threads = threads;
    Ok(map)
}

/// A map build: the spec's problem built with [`BuildOptions`], optionally connected
/// (edges to each point's `edge_neighbours` nearest, checked every
/// [`BuildOptions::edge_resolution`]) and optionally finishing a killed build from its
/// [`Checkpoint`]; run on the current rayon pool's threads ([`Builder::run`]) or shared
/// among the processes of a [`Team`] ([`Builder::run_with`]). Save the map with
/// [`Roadmap::save`].
///
/// ```no_run
/// use trm_roadmap::{BuildOptions, Builder};
/// let problem = trm_tasks::Problem::load("specs/reach.ron")?;
/// let map = Builder::new(&problem, &BuildOptions::default())
///     .connected()
///     .run(|p| eprintln!("{} points", p.points))?;
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Debug, Clone)]
pub struct Builder<'p> {
    problem: &'p Problem,
    options: &'p BuildOptions,
    resumed: Option<Checkpoint>,
    connect: bool,
}

impl<'p> Builder<'p> {
    /// A build of `problem`'s map (it needs a task function and `map` settings, or their
    /// defaults) with `options`. Zero or absurd point and search counts are errors.
    pub fn new(problem: &'p Problem, options: &'p BuildOptions) -> Self {
        Builder {
            problem,
            options,
            resumed: None,
            connect: false,
        }
    }

    /// Connects the map once built: each point to the spec's `edge_neighbours` nearest, edges
    /// checked every `options.edge_resolution` (checked before any building).
    pub fn connected(mut self) -> Self {
        self.connect = true;
        self
    }

    /// Finishes a build from its [`Checkpoint`] with exactly the map the uninterrupted build
    /// gives (timing statistics aside). The problem must be [`Checkpoint::problem`]'s. The
    /// seed, P and the search settings are the checkpoint's: a `seed` or `searches` option
    /// that differs is an error; `points` may set another target (the build goes on as if it
    /// had been started with it), and `checkpoint` keeps writing checkpoints.
    pub fn resume(self, checkpoint: Checkpoint) -> Self {
        self.resuming(Some(checkpoint))
    }

    /// [`Builder::resume`] when `checkpoint` is given.
    pub fn resuming(mut self, checkpoint: Option<Checkpoint>) -> Self {
        self.resumed = checkpoint;
        self
    }

    /// Runs the build on the current rayon pool's threads. When P is a multiple of T > 1
    /// threads it runs as a team of T threads ([`on_threads`]), each owning P / T searches
    /// (asks, evaluations, h_map, tells) and exchanging once per generation, rather than
    /// forking and joining every step of every generation: the same map, faster (reach map on
    /// 2 threads: see the book's Roadmaps page).
    pub fn run(self, progress: impl FnMut(&Progress)) -> Result<Roadmap> {
        let searches = self
            .resumed
            .as_ref()
            .map_or_else(|| searches_of(self.problem, self.options), |c| c.searches);
        on_pool(searches, progress, |team, progress| {
            self.clone().run_with(team, progress)
        })
    }

    /// Runs the build shared among the processes of `team` (e.g. the ranks of an MPI job:
    /// every one runs it with the same problem, options and checkpoint, and every one returns
    /// the map): the same map as [`Builder::run`], the edges shared too.
    pub fn run_with(self, team: &mut dyn Team, progress: impl FnMut(&Progress)) -> Result<Roadmap> {
        let (problem, options) = (self.problem, self.options);
        if self.connect {
            crate::edges::check_edge_resolution(options.edge_resolution)?;
        }
        let (setup, state) = match self.resumed {
            Some(checkpoint) => resumed_setup(problem, checkpoint, options, team)?,
            None => {
                let mut setup =
                    Setup::new(problem, options.points, options.searches, options.seed)?;
                setup.max_generations = options.max_generations;
                setup.repel_weight = options.repel_weight;
                let state = State::fresh(&setup);
                (setup, state)
            }
        };
        let mut map = run(&setup, state, options.checkpoint.as_ref(), team, progress)?;
        if self.connect {
            let neighbours = map.settings.edge_neighbours;
            crate::edges::connect_with(
                &mut map,
                &problem.objective,
                neighbours,
                options.edge_resolution,
                team,
            )?;
        }
        Ok(map)
    }
}

/// The setup and state of a build resumed from `checkpoint`, refused when the options or the
/// problem are not the checkpoint's.
fn resumed_setup<'p>(
    problem: &'p Problem,
    checkpoint: Checkpoint,
    options: &BuildOptions,
    team: &mut dyn Team,
) -> Result<(Setup<'p>, State)> {
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
    let state = State::restore(&setup, checkpoint, team)?;
    Ok((setup, state))
}
