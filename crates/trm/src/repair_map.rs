//! `trm repair-map MAP --world W.ron [--out FILE] [--compare-rebuild]`: a map repaired
//! for a world that changed (`trm_roadmap::repair`).

use std::path::PathBuf;
use std::time::Instant;

use anyhow::{Context, Result};
use trm_roadmap::{BuildOptions, Builder, RepairOptions, Roadmap};

/// Arguments of `repair-map`.
#[derive(clap::Args)]
pub struct Args {
    /// The map (built by build-map, or repaired before).
    map: PathBuf,
    /// The world the map must be valid in (RON, or a MoveIt planning scene .yaml).
    #[arg(long, value_name = "WORLD.ron")]
    world: PathBuf,
    /// Output map (default: the map's name with .repaired.map.json).
    #[arg(long)]
    out: Option<PathBuf>,
    /// Also build the map from scratch in the new world (same size, seed and settings) and
    /// compare coverage and time.
    #[arg(long)]
    compare_rebuild: bool,
    /// Worker threads (the map does not depend on it).
    #[arg(long, value_parser = crate::parse::count(1, 4096))]
    threads: Option<usize>,
}

impl Args {
    /// Where the repaired map goes.
    pub fn out_path(&self) -> PathBuf {
        self.out.clone().unwrap_or_else(|| {
            let name = self.map.file_name().map_or("map".into(), |n| {
                n.to_string_lossy()
                    .trim_end_matches(".json")
                    .trim_end_matches(".map")
                    .to_string()
            });
            self.map.with_file_name(format!("{name}.repaired.map.json"))
        })
    }
}

/// Repairs the map, prints the report, writes the repaired map.
pub fn run(args: &Args) -> Result<()> {
    let map = Roadmap::load(&args.map)?;
    let problem = map
        .problem_with(&trm_taskmap::loaders())
        .with_context(|| format!("{}: the spec stored in the map", args.map.display()))?;
    let world = trm_moveit::load_world(&args.world)?;
    for name in covering_the_start(&problem, &world) {
        println!(
            "note: {}: `{name}` collides with the robot at the map's start posture (the spec's \
             start): the map is repaired around it, but plans from that start will be refused",
            args.world.display()
        );
    }
    let out = args.out_path();
    let pool = crate::thread_pool(args.threads)?;
    let started = Instant::now();
    let (repaired, report) =
        pool.install(|| trm_roadmap::repair(&map, &problem, &world, &RepairOptions::default()))?;
    let seconds = started.elapsed().as_secs_f64();
    println!("{report}");
    println!(
        "repaired in {seconds:.2} s (finding what is blocked {:.3} s, growing {:.2} s, connecting {:.2} s); {} points, {} edges, {} occupied cells (before: {})",
        report.seconds[0],
        report.seconds[1],
        report.seconds[2],
        repaired.points.len(),
        repaired.edges.len(),
        repaired.occupied_cells(),
        map.occupied_cells()
    );
    if let Some(parked) = &repaired.parked {
        println!(
            "kept aside (parked, back without a search when the world frees them): {} nodes, {} edges",
            parked.points.len(),
            parked.edges.len()
        );
    }
    if args.compare_rebuild {
        let mut fresh = map.problem_with(&trm_taskmap::loaders())?;
        fresh.objective.set_world(world.clone());
        let started = Instant::now();
        let rebuilt =
            pool.install(|| Builder::new(&fresh, &BuildOptions::like(&map)).run(|_| {}))?;
        let rebuild_seconds = started.elapsed().as_secs_f64();
        println!(
            "rebuild in the new world: {} points, {} occupied cells in {rebuild_seconds:.2} s (edges not built); repair: {:.0} % of its coverage in {:.0} % of its time",
            rebuilt.points.len(),
            rebuilt.occupied_cells(),
            100.0 * repaired.occupied_cells() as f64 / rebuilt.occupied_cells().max(1) as f64,
            100.0 * seconds / rebuild_seconds
        );
    }
    crate::write_atomic(&out, repaired.to_json(&out)?.as_bytes())?;
    println!("wrote {}", out.display());
    Ok(())
}

/// The objects of `world` that, each alone, collide with the robot at `problem`'s start.
fn covering_the_start(problem: &trm_tasks::Problem, world: &trm_collision::World) -> Vec<String> {
    let objective = &problem.objective;
    let mut scratch = objective.scratch();
    world
        .objects()
        .iter()
        .filter(|o| {
            let mut alone = trm_collision::World::new();
            alone.add(o.name(), o.shape().clone(), *o.pose()).is_ok()
                && !objective.is_collision_free_in(&problem.start, &alone, &mut scratch)
        })
        .map(|o| o.name().to_string())
        .collect()
}
