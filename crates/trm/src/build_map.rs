//! `trm build-map SPEC [--out FILE] [--points N] [--threads T] [--searches P] [--seed S]
//! [--checkpoint-every N [--checkpoint FILE]]`, `trm build-map --resume FILE` and
//! `trm map-info FILE`.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use trm_roadmap::{BuildOptions, Builder, Checkpoint, CheckpointOptions, Roadmap, Team};
use trm_tasks::Problem;

/// Arguments of `build-map`.
#[derive(clap::Args)]
pub struct Args {
    /// The task spec (with a task function and map settings); not with --resume, whose
    /// checkpoint carries its spec.
    #[arg(required_unless_present = "resume", conflicts_with = "resume")]
    spec: Option<PathBuf>,
    /// Output map file (default: target/maps/<spec name>.map.json; with --resume, the
    /// checkpoint's name with .json).
    #[arg(long)]
    out: Option<PathBuf>,
    /// Number of points (default: the spec's map.max_points).
    #[arg(long, value_parser = crate::parse::count(1, trm_roadmap::MAX_POINTS))]
    points: Option<usize>,
    /// Worker threads (an execution setting: the map does not depend on it).
    #[arg(long, value_parser = crate::parse::count(1, 4096))]
    threads: Option<usize>,
    /// Concurrent searches P (an algorithm setting; default: the spec's map.searches).
    #[arg(long, value_parser = crate::parse::count(1, trm_roadmap::MAX_SEARCHES), conflicts_with = "resume")]
    searches: Option<usize>,
    /// Seed (default: the spec's solver.seed).
    #[arg(long, conflicts_with = "resume")]
    seed: Option<u64>,
    /// Write a checkpoint each time the map has grown by N points (and at the end), to resume
    /// a killed build with --resume.
    #[arg(long, value_name = "N", value_parser = crate::parse::count(1, trm_roadmap::MAX_POINTS))]
    checkpoint_every: Option<usize>,
    /// The checkpoint file (default: the map's name with .checkpoint).
    #[arg(long, value_name = "FILE")]
    checkpoint: Option<PathBuf>,
    /// Finish a killed build from its checkpoint, with exactly the map the uninterrupted build
    /// gives; it goes on checkpointing into the same file at the same interval.
    #[arg(long, value_name = "FILE")]
    resume: Option<PathBuf>,
    /// Interpolation step (rad) for checking edges.
    #[arg(long, default_value_t = trm_roadmap::DEFAULT_EDGE_RESOLUTION)]
    edge_resolution: f64,
    /// Also write a 3-D view of the map (`<out stem>.scene.html` and `.scene.json`).
    #[arg(long)]
    view: bool,
    /// Spread the evaluations over the processes of an MPI job (run under `mpirun`; needs an
    /// xtask built with `--features mpi`). Rank 0 builds and writes the map; every rank uses
    /// --threads threads. The map is the same on any number of ranks.
    #[arg(long)]
    mpi: bool,
}

impl Args {
    /// Where the map goes: `--out`, or target/maps/<spec name>.map.json (with `--resume`, the
    /// checkpoint's path with .json).
    pub fn out_path(&self) -> PathBuf {
        match (&self.out, &self.spec, &self.resume) {
            (None, None, Some(checkpoint)) => checkpoint.with_extension("json"),
            (_, spec, _) => crate::default_out(
                &self.out,
                spec.as_deref().unwrap_or(Path::new("map")),
                "target/maps",
                "map.json",
            ),
        }
    }

    /// Where checkpoints go, when the build writes them.
    pub fn checkpoint_path(&self) -> Option<PathBuf> {
        let path = self
            .checkpoint
            .clone()
            .or_else(|| self.resume.clone())
            .unwrap_or_else(|| self.out_path().with_extension("checkpoint"));
        (self.checkpoint_every.is_some() || self.resume.is_some() || self.checkpoint.is_some())
            .then_some(path)
    }
}

/// Builds, connects and saves a map.
pub fn run(args: &Args) -> Result<()> {
    // checked before minutes of map building
    trm_roadmap::check_edge_resolution(args.edge_resolution).context("--edge-resolution")?;
    let out = args.out_path();
    // the build runs on this thread, made a worker of the global pool (an MPI communicator
    // stays on the thread that initialised MPI); under --mpi one thread per rank unless
    // --threads says otherwise
    let threads = match (args.mpi, args.threads) {
        (true, None) => 1,
        (_, threads) => crate::thread_count(threads)?,
    };
    // (only fails when the global pool already exists: a second run in one test process)
    let _ = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .use_current_thread()
        .build_global();
    let mut options = BuildOptions {
        points: args.points,
        searches: args.searches,
        seed: args.seed,
        edge_resolution: args.edge_resolution,
        ..Default::default()
    };
    let (problem, resumed) = match (&args.spec, &args.resume) {
        (Some(spec), _) => (Problem::load_with(spec, &trm_taskmap::loaders())?, None),
        (None, Some(file)) => {
            let checkpoint = Checkpoint::load(file)?;
            let problem = checkpoint
                .problem_with(&trm_taskmap::loaders())
                .with_context(|| format!("the spec stored in checkpoint {}", file.display()))?;
            let target = checkpoint
                .resume_target(options.points)
                .with_context(|| format!("--points with checkpoint {}", file.display()))?;
            println!(
                "resuming {} from {} points (of {target}), P = {}, seed {}",
                checkpoint.spec_path(),
                checkpoint.points(),
                checkpoint.seed_and_searches().1,
                checkpoint.seed_and_searches().0
            );
            (problem, Some(checkpoint))
        }
        (None, None) => anyhow::bail!("give a spec, or --resume with a checkpoint"),
    };
    if let Some(path) = args.checkpoint_path() {
        let every = match (args.checkpoint_every, &resumed) {
            (Some(every), _) => every,
            (None, Some(checkpoint)) => checkpoint.every(),
            (None, None) => anyhow::bail!(
                "--checkpoint {} without an interval\n  fix: add --checkpoint-every N (points)",
                path.display()
            ),
        };
        options.checkpoint = Some(CheckpointOptions { path, every });
    }
    let job = Job {
        args,
        problem: &problem,
        options: &options,
        out: &out,
    };
    if args.mpi {
        return crate::distributed::build_map(job, resumed);
    }
    job.run(resumed, None)
}

/// A build-map run, ready to go: on this process's threads, or shared among the ranks of an MPI
/// job.
pub struct Job<'a> {
    /// The arguments.
    pub args: &'a Args,
    /// The task.
    pub problem: &'a Problem,
    /// The build options.
    pub options: &'a BuildOptions,
    /// Where the map goes.
    pub out: &'a Path,
}

impl Job<'_> {
    /// Builds (or resumes), connects and writes the map, on this process's threads or shared
    /// among `team` (every process builds; rank 0 shows progress and writes).
    pub fn run(self, resumed: Option<Checkpoint>, team: Option<&mut dyn Team>) -> Result<()> {
        let Job {
            args,
            problem,
            options,
            out,
        } = self;
        let writes = team.as_ref().is_none_or(|t| t.rank() == 0);
        let mut progress = crate::progress::Progress::new("points", 0);
        let map = (|| -> Result<Roadmap> {
            let report = |p: &trm_roadmap::Progress| {
                if !writes {
                    return;
                }
                let rate = p.evaluations as f64 / p.seconds.max(1e-9);
                progress.set(
                    p.points as u64,
                    p.target as u64,
                    &format!(
                        "{} failed searches ({} in a row), {} evaluations ({rate:.0}/s)",
                        p.total_failures, p.failures, p.evaluations
                    ),
                );
            };
            let map = match team {
                Some(team) => Builder::new(problem, options)
                    .connected()
                    .resuming(resumed)
                    .run_with(team, report)?,
                None => Builder::new(problem, options)
                    .connected()
                    .resuming(resumed)
                    .run(report)?,
            };
            if writes {
                progress.finish();
            }
            Ok(map)
        })()?;
        if !writes {
            return Ok(());
        }
        crate::write_atomic(out, map.to_json(out)?.as_bytes())?;
        print_summary(&map);
        let svg = out.with_extension("svg");
        crate::write_atomic(&svg, crate::plot::map_scatter(&map, None)?.as_bytes())?;
        println!("wrote {} and {}", out.display(), svg.display());
        if args.view {
            let mut scene =
                trm_view::Scene::of_problem(problem, &format!("map of {}", problem.origin))?;
            scene.add_roadmap(&map, problem.objective.active())?;
            crate::support::scene::write_scene(&scene, &crate::support::scene::scene_path(out))?;
        }
        Ok(())
    }
}

/// Prints what `world` blocks in `map`: through the index (built once, then timed over
/// repeated queries) and by checking every node and edge, with both times.
fn blocking_report(map: &Roadmap, problem: &Problem, world: &Path) -> Result<()> {
    let world = trm_moveit::load_world(world)?;
    let objective = &problem.objective;
    let started = std::time::Instant::now();
    let index = trm_roadmap::BlockIndex::new(map, objective)?;
    let index_ms = started.elapsed().as_secs_f64() * 1e3;
    let mut times = Vec::new();
    let mut blocked = Default::default();
    for _ in 0..21 {
        let started = std::time::Instant::now();
        blocked = index.blocked(map, objective, &world)?;
        times.push(started.elapsed().as_secs_f64() * 1e3);
    }
    times.sort_by(f64::total_cmp);
    let started = std::time::Instant::now();
    let exhaustive = trm_roadmap::blocked_exhaustive(map, objective, &world)?;
    let exhaustive_ms = started.elapsed().as_secs_f64() * 1e3;
    anyhow::ensure!(
        blocked == exhaustive,
        "the index and the exhaustive check disagree: please report this"
    );
    let blocked: trm_roadmap::Blocked = blocked;
    println!(
        "in this world: {} objects differ from the map's ({}); {} of {} nodes and {} of {} edges blocked",
        blocked.changed.len(),
        blocked.changed.join(", "),
        blocked.nodes.len(),
        map.points.len(),
        blocked.edges.len(),
        map.edges.len()
    );
    println!(
        "found in {:.3} ms (median of 21; index built once in {index_ms:.1} ms); checking every node and edge: {exhaustive_ms:.1} ms ({} threads)",
        times[times.len() / 2],
        rayon::current_num_threads()
    );
    Ok(())
}

/// Arguments of `map-info`.
#[derive(clap::Args)]
pub struct InfoArgs {
    /// A map file written by build-map.
    map: PathBuf,
    /// Also report what this world (RON, or a MoveIt scene .yaml) blocks in the map — nodes and edges, found through
    /// the map's bounding-box index — with the time that takes against checking everything.
    #[arg(long, value_name = "WORLD.ron")]
    world: Option<PathBuf>,
}

/// Prints a map's summary.
pub fn info(args: &InfoArgs) -> Result<()> {
    let map = Roadmap::load(&args.map)?;
    println!(
        "{} ({}, {})",
        args.map.display(),
        map.software,
        map.spec_path
    );
    // the spec travels inside the map: rebuild its objective (checking every point against
    // it) for the cost breakdown
    let problem = map
        .problem_with(&trm_taskmap::loaders())
        .with_context(|| format!("{}: the spec stored in the map", args.map.display()))?;
    print_summary(&map);
    let mut scratch = problem.objective.scratch();
    let mut sums: Vec<(String, f64)> = Vec::new();
    for p in &map.points {
        let (_, terms) = problem.objective.breakdown(&p.q, &mut scratch);
        if sums.is_empty() {
            sums = terms.iter().map(|t| (t.label.clone(), 0.0)).collect();
        }
        for (s, t) in sums.iter_mut().zip(&terms) {
            s.1 += t.weight * t.value;
        }
    }
    println!("mean cost breakdown (weighted):");
    for (label, total) in sums {
        println!(
            "  {label:<36} {:.5}",
            total / map.points.len().max(1) as f64
        );
    }
    if let Some(path) = &args.world {
        blocking_report(&map, &problem, path)?;
    }
    Ok(())
}

fn print_summary(map: &Roadmap) {
    let s = &map.stats;
    let summary = map.summary();
    let n = summary.points;
    println!(
        "{} points, {} edges, {} connected components; task `{}`; {} active motors; seed {}, {} searches",
        n,
        summary.edges,
        summary.components,
        map.task,
        map.active.len(),
        map.seed,
        map.searches
    );
    let extent: Vec<String> = summary
        .extent
        .iter()
        .map(|(lo, hi)| format!("[{lo:.3}, {hi:.3}]"))
        .collect();
    println!("task-space extent: {}", extent.join(" × "));
    if let Some((mean, min)) = summary.spacing {
        println!(
            "nearest-neighbour spacing: mean {mean:.4}, min {min:.4} (setting d = {})",
            map.settings.spacing
        );
    }
    if let Some((occupied, total)) = summary.coverage {
        println!(
            "coverage: {occupied} of {total} cells of side d in the extent box ({:.0} %)",
            100.0 * occupied as f64 / total
        );
    }
    println!("mean task cost {:.4}", summary.mean_cost);
    println!(
        "built in {:.1} s (+ {:.1} s edges) on {} threads: {} evaluations ({:.0}/point, {:.0}/s), {} searches, {} failed; stopped: {}",
        s.build_seconds,
        s.edge_seconds,
        s.threads,
        s.evaluations,
        s.evaluations as f64 / n.max(1) as f64,
        s.evaluations as f64 / s.build_seconds.max(1e-9),
        s.searches_started,
        s.failures,
        s.stopped_because
    );
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_zero_or_nan_edge_resolution_is_refused_before_building() {
        for resolution in [0.0, f64::NAN, -0.05, 1e-9] {
            let e = run(&Args {
                spec: Some(crate::models_dir().join("../specs/reach.ron")),
                out: Some(crate::test_dir("bm").join("never.map.json")),
                points: Some(5),
                threads: Some(1),
                searches: None,
                seed: None,
                edge_resolution: resolution,
                view: false,
                checkpoint_every: None,
                checkpoint: None,
                resume: None,
                mpi: false,
            })
            .unwrap_err();
            assert!(format!("{e:#}").contains("--edge-resolution"), "{e:#}");
        }
    }
}
