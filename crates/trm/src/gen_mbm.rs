//! `trm gen-mbm SPEC --out DIR`: a MotionBenchMaker-like problem set for the spec's
//! robot (`trm_mbm::generate`): seeded table, shelf and cage scenes in front of it, reaching
//! goals inside them found by NGIK, written as MoveIt scenes and requests.

use std::path::PathBuf;

use anyhow::Result;
use trm_mbm::generate::{FAMILIES, SetOptions, generate, write_set};

/// Arguments of `gen-mbm`.
#[derive(clap::Args)]
pub struct Args {
    /// The task spec: robot, active motors (the goals' joints), start posture, costs, the part
    /// that reaches (`task: Some(Position(part: …))`) and solver. Its world is replaced.
    spec: PathBuf,
    /// Problems per family.
    #[arg(long, default_value_t = 20, value_parser = crate::parse::count(1, 10_000))]
    per_family: usize,
    /// Families (comma-separated): table, shelf, cage.
    #[arg(long, value_delimiter = ',', default_values_t = FAMILIES.map(String::from))]
    families: Vec<String>,
    /// Seed of every scene, target and NGIK run.
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Centre of the scenes, root frame, m (x,y,z); default: 8 cm beyond the reaching part at
    /// the start posture along --facing.
    #[arg(long, value_delimiter = ',', value_parser = crate::parse::finite, allow_hyphen_values = true)]
    center: Vec<f64>,
    /// The horizontal direction the robot faces, root frame (x,y).
    #[arg(long, value_delimiter = ',', default_values_t = [1.0, 0.0], value_parser = crate::parse::finite, allow_hyphen_values = true)]
    facing: Vec<f64>,
    /// Largest distance of the reaching part from its target at a goal, m.
    #[arg(long, default_value_t = 0.02, value_parser = crate::parse::positive)]
    tolerance: f64,
    /// Scenes and targets tried per problem.
    #[arg(long, default_value_t = 30, value_parser = crate::parse::count(1, 10_000))]
    tries: usize,
    /// The folder the set is written to (one folder per family).
    #[arg(long)]
    pub out: PathBuf,
}

/// Generates and writes the set.
pub fn run(args: &Args) -> Result<()> {
    anyhow::ensure!(
        args.center.is_empty() || args.center.len() == 3,
        "--center: {} values given\n  fix: give x,y,z",
        args.center.len()
    );
    anyhow::ensure!(
        args.facing.len() == 2 && args.facing.iter().any(|v| *v != 0.0),
        "--facing: {} given\n  fix: give a horizontal direction x,y, not zero",
        args.facing
            .iter()
            .map(|v| v.to_string())
            .collect::<Vec<_>>()
            .join(",")
    );
    let spec = trm_tasks::spec::Problem::load_with(&args.spec, &trm_taskmap::loaders())?;
    let options = SetOptions {
        families: args.families.clone(),
        per_family: args.per_family,
        seed: args.seed,
        center: (args.center.len() == 3).then(|| [args.center[0], args.center[1], args.center[2]]),
        facing: [args.facing[0], args.facing[1]],
        tolerance: args.tolerance,
        tries: args.tries,
    };
    let total = (args.families.len() * args.per_family) as u64;
    let mut progress = crate::progress::Progress::new("problems", total);
    let set = generate(&spec, &options, |done, _| {
        progress.set(done as u64, total, "")
    })?;
    progress.finish();
    write_set(&args.out, &set)?;
    println!(
        "wrote {} problems ({} families of {}) to {}",
        set.len(),
        args.families.len(),
        args.per_family,
        args.out.display()
    );
    Ok(())
}
