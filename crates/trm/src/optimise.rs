//! `trm optimise --algo A --function F --dim D --target T --runs R --seed S`: evaluations
//! to target per run and a summary, as a table or JSON.

use anyhow::{Context, Result};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use serde_json::json;
use trm_optim::functions::TestFunction;
use trm_optim::{ALGORITHMS, Start, StopOptions, by_name, minimize_fn};

/// Arguments of `optimise`.
#[derive(clap::Args)]
pub struct Args {
    /// Algorithm: xnes, snes, cmaes, oneplusone, sir, sird, mh or simplex.
    #[arg(long, default_value = "xnes")]
    algo: String,
    /// Test function: sphere, ellipsoid, cigar, discus, rosenbrock, rastrigin, or rotated-<name>.
    #[arg(long, default_value = "sphere")]
    function: String,
    /// Dimension.
    #[arg(long, default_value_t = 10, value_parser = crate::parse::count(1, 10_000))]
    dim: usize,
    /// Target value: a run succeeds when its best value is ≤ this.
    #[arg(long, default_value_t = 1e-8, value_parser = crate::parse::finite)]
    target: f64,
    /// Independent runs (run k uses seed S + k; the rotation of rotated functions uses S).
    #[arg(long, default_value_t = 11, value_parser = clap::value_parser!(u64).range(1..=100_000))]
    runs: u64,
    /// Base seed.
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Evaluation budget per run.
    #[arg(long, default_value_t = 100_000, value_parser = clap::value_parser!(u64).range(1..=1_000_000_000))]
    max_evals: u64,
    /// Initial step size (start: the origin for Rosenbrock, (1, …, 1) otherwise).
    #[arg(long, default_value_t = 0.5, value_parser = crate::parse::positive)]
    sigma: f64,
    /// Population size (particles for SIR/SIRD); the algorithm's default when absent.
    #[arg(long, value_parser = crate::parse::count(2, 1_000_000))]
    population: Option<usize>,
    /// Print JSON instead of a table.
    #[arg(long)]
    json: bool,
}

/// One run's outcome.
struct Run {
    seed: u64,
    evaluations_to_target: Option<u64>,
    best_f: f64,
    evaluations: u64,
    reasons: String,
}

/// Runs and prints.
pub fn run(args: &Args) -> Result<()> {
    if !ALGORITHMS.contains(&args.algo.as_str()) {
        anyhow::bail!(
            "unknown --algo `{}`; known: {}",
            args.algo,
            ALGORITHMS.join(", ")
        );
    }
    if args.seed.checked_add(args.runs - 1).is_none() {
        anyhow::bail!(
            "--seed {} --runs {}: run k uses seed S + k, which wraps around\n  fix: give a smaller seed",
            args.seed,
            args.runs
        );
    }
    let f = TestFunction::by_name(&args.function, args.dim, args.seed)
        .with_context(|| format!("--function {}", args.function))?;
    let mut runs = Vec::new();
    for k in 0..args.runs {
        let start = Start::new(f.start(), args.sigma).with_stop(StopOptions {
            target: Some(args.target),
            max_evaluations: Some(args.max_evals),
            ..Default::default()
        });
        let mut optimizer = by_name(&args.algo, &start, args.population)?;
        let mut rng = ChaCha8Rng::seed_from_u64(args.seed + k);
        let report = minimize_fn(optimizer.as_mut(), &mut rng, |x| f.eval(x));
        runs.push(Run {
            seed: args.seed + k,
            evaluations_to_target: (report.best_f <= args.target).then_some(report.evaluations),
            best_f: report.best_f,
            evaluations: report.evaluations,
            reasons: format!("{:?}", report.reasons),
        });
    }
    let mut ok: Vec<u64> = runs
        .iter()
        .filter_map(|r| r.evaluations_to_target)
        .collect();
    ok.sort_unstable();
    let median = match ok.len() {
        0 => None,
        n if n % 2 == 1 => Some(ok[n / 2] as f64),
        n => Some((ok[n / 2 - 1] + ok[n / 2]) as f64 / 2.0),
    };
    if args.json {
        let out = json!({
            "algo": args.algo, "function": f.name(), "dim": args.dim, "target": args.target,
            "sigma": args.sigma, "population": args.population, "max_evals": args.max_evals,
            "seed": args.seed,
            "runs": runs.iter().map(|r| json!({
                "seed": r.seed, "evaluations_to_target": r.evaluations_to_target,
                "best_f": r.best_f, "evaluations": r.evaluations, "reasons": r.reasons,
            })).collect::<Vec<_>>(),
            "successes": ok.len(), "median_evaluations_to_target": median,
        });
        println!("{}", serde_json::to_string_pretty(&out)?);
        return Ok(());
    }
    println!(
        "{} on {} (d = {}), target {:e}, σ0 = {}, budget {} evaluations, seed {}",
        args.algo,
        f.name(),
        args.dim,
        args.target,
        args.sigma,
        args.max_evals,
        args.seed
    );
    println!(
        "{:>6} {:>12} {:>14} {:>12}  stop",
        "seed", "to target", "best f", "evaluations"
    );
    for r in &runs {
        let to = r
            .evaluations_to_target
            .map_or("failed".to_string(), |e| e.to_string());
        println!(
            "{:>6} {:>12} {:>14.4e} {:>12}  {}",
            r.seed, to, r.best_f, r.evaluations, r.reasons
        );
    }
    println!(
        "success {}/{} ({:.0} %), median evaluations to target: {}",
        ok.len(),
        args.runs,
        100.0 * ok.len() as f64 / args.runs.max(1) as f64,
        median.map_or("-".to_string(), |m| m.to_string())
    );
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn args(algo: &str, function: &str) -> Args {
        Args {
            algo: algo.into(),
            function: function.into(),
            dim: 4,
            target: 1e-6,
            runs: 2,
            seed: 1,
            max_evals: 5_000,
            sigma: 0.5,
            population: None,
            json: true,
        }
    }

    #[test]
    fn optimise_runs_every_algorithm_and_rejects_unknown_names() {
        for algo in ALGORITHMS {
            run(&args(algo, "sphere")).unwrap();
        }
        assert!(run(&args("xnse", "sphere")).is_err());
        let e = format!("{:#}", run(&args("xnes", "spere")).unwrap_err());
        assert!(e.contains("rotated-sphere"), "{e}");
    }
}
