//! `trm compare-optimisers`: Table III of Stollenga et al. (IROS 2013) — NGIK's xNES
//! against SIR, SIRD, Metropolis–Hastings and Nelder–Mead (plus CMA-ES and (1+1)-CMA-ES) on the
//! two postures of Fig. 5, 30 seeded runs each: a markdown table, a CSV of every run and a
//! convergence plot.

use std::path::PathBuf;

use anyhow::{Context, Result};
use trm_tasks::{Comparison, ComparisonResult, Problem};

/// Arguments of `compare-optimisers`.
#[derive(clap::Args)]
pub struct Args {
    /// Posture specs (default: specs/table_iii/posture1.ron and posture2.ron).
    #[arg(long = "spec")]
    specs: Vec<PathBuf>,
    /// Algorithms, comma-separated.
    #[arg(
        long,
        default_value = "xnes,sir,sird,mh,simplex,cmaes,oneplusone",
        value_delimiter = ','
    )]
    algos: Vec<String>,
    /// Runs per algorithm and posture (run k uses seed S + k).
    #[arg(long, default_value_t = 30, value_parser = clap::value_parser!(u64).range(1..=100_000))]
    runs: u64,
    /// Base seed.
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Evaluation budget per run.
    #[arg(long, default_value_t = 400_000, value_parser = clap::value_parser!(u64).range(1..=1_000_000_000))]
    max_evals: u64,
    /// Stop a run when its best has not improved for this many evaluations.
    #[arg(long, default_value_t = 30_000, value_parser = clap::value_parser!(u64).range(1..=1_000_000_000))]
    no_improvement: u64,
    /// Also write a 3-D view per posture (`posture<N>.scene.html`): one frame per algorithm,
    /// its best run's posture.
    #[arg(long)]
    pub view: bool,
    /// Output directory for table.md, runs.csv and convergence.svg.
    #[arg(long, default_value = "target/compare-optimisers")]
    pub out_dir: PathBuf,
}

/// Runs the comparison and writes its outputs.
pub fn run(args: &Args) -> Result<()> {
    let specs = if args.specs.is_empty() {
        let root = crate::models_dir()
            .parent()
            .map(PathBuf::from)
            .unwrap_or_default();
        let dir = root.join("specs/table_iii");
        let relative = |p: PathBuf| {
            std::env::current_dir()
                .ok()
                .and_then(|cwd| p.strip_prefix(cwd).ok().map(PathBuf::from))
                .unwrap_or(p)
        };
        vec![
            relative(dir.join("posture1.ron")),
            relative(dir.join("posture2.ron")),
        ]
    } else {
        args.specs.clone()
    };
    let comparison = Comparison {
        algorithms: args.algos.clone(),
        runs: args.runs,
        seed: args.seed,
        max_evaluations: args.max_evals,
        no_improvement: args.no_improvement,
    };
    comparison.check().with_context(|| {
        format!(
            "--algos {} --runs {} --seed {}",
            args.algos.join(","),
            args.runs,
            args.seed
        )
    })?;
    let problems: Vec<Problem> = specs
        .iter()
        .map(|p| {
            Problem::load_with(p, &trm_taskmap::loaders())
                .with_context(|| format!("loading {}", p.display()))
        })
        .collect::<Result<_>>()?;
    let labels: Vec<String> = specs.iter().map(|s| s.display().to_string()).collect();
    eprintln!(
        "{} runs ({} postures × {} algorithms × {}) on {} threads…",
        problems.len() as u64 * args.algos.len() as u64 * args.runs,
        problems.len(),
        args.algos.len(),
        args.runs,
        rayon::current_num_threads()
    );
    let pairs: Vec<(&str, &Problem)> = labels.iter().map(String::as_str).zip(&problems).collect();
    let progress = std::sync::Mutex::new(crate::progress::Progress::new("runs", 0));
    let result = comparison.run_with_progress(&pairs, |done, total| {
        if let Ok(mut p) = progress.lock() {
            p.set(done as u64, total as u64, "");
        }
    })?;
    if let Ok(p) = progress.lock() {
        p.finish();
    }
    let table = result.to_markdown();
    std::fs::create_dir_all(&args.out_dir)?;
    crate::write_atomic(&args.out_dir.join("runs.csv"), result.to_csv().as_bytes())?;
    crate::write_atomic(&args.out_dir.join("table.md"), table.as_bytes())?;
    let svg = plot(&result)?;
    crate::write_atomic(&args.out_dir.join("convergence.svg"), svg.as_bytes())?;
    println!("{table}");
    println!(
        "wrote {}/{{table.md, runs.csv, convergence.svg}}; wall time {:.1} s",
        args.out_dir.display(),
        result.wall_seconds
    );
    if args.view {
        for (p, problem) in problems.iter().enumerate() {
            let title = format!(
                "{}: best posture of each algorithm ({})",
                specs[p].display(),
                args.algos.join(", ")
            );
            let mut scene = trm_view::Scene::of_problem(problem, &title)?;
            scene.frames.clear();
            for (i, algo) in args.algos.iter().enumerate() {
                if let Some(best) = result.best(p, algo) {
                    scene.add_frame(i as f64, &best.motors)?;
                }
            }
            let page = args.out_dir.join(format!("posture{}.scene.html", p + 1));
            crate::support::scene::write_scene(&scene, &page)?;
        }
    }
    Ok(())
}

/// Mean best-so-far cost against evaluations (log scale), one panel per posture.
fn plot(result: &ComparisonResult) -> Result<String> {
    let max_evals = result.settings.max_evaluations;
    // from 100 evaluations (or 1 for smaller budgets) to the budget
    let (first, last) = (
        (max_evals as f64).log10().min(2.0),
        (max_evals as f64).log10(),
    );
    let grid: Vec<u64> = (0..=60)
        .map(|i| 10f64.powf(first + i as f64 * (last - first) / 60.0) as u64)
        .collect();
    let mut panels = Vec::new();
    for p in 0..result.labels.len() {
        let mut series = Vec::new();
        let (mut lo, mut hi) = (f64::INFINITY, 0.0f64);
        for algo in &result.settings.algorithms {
            let points = result.convergence(p, algo, &grid);
            for (_, c) in &points {
                lo = lo.min(*c);
                hi = hi.max(*c);
            }
            series.push(crate::plot::Series {
                label: algo.to_uppercase(),
                points: points
                    .iter()
                    .map(|&(e, c)| ((e as f64).log10(), c.max(1e-3).log10()))
                    .collect(),
                color: None,
            });
        }
        panels.push(crate::plot::Panel {
            title: format!("Posture ({}): mean best cost", p + 1),
            axes: ("evaluations (log10)".into(), "cost (log10)".into()),
            x: first..last,
            y: (lo.max(1e-3) * 0.8).log10()..(hi.max(1e-2) * 1.2).log10(),
            series,
        });
    }
    crate::plot::panels((900, 420), &panels)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_comparison_writes_its_outputs_and_does_not_depend_on_the_thread_count() {
        let dir = std::env::temp_dir().join(format!("trm-compare-{}", std::process::id()));
        let args = |out: &str| Args {
            view: false,
            specs: Vec::new(),
            algos: vec!["xnes".into(), "sird".into(), "simplex".into()],
            runs: 2,
            seed: 5,
            max_evals: 1_500,
            no_improvement: 1_000,
            out_dir: dir.join(out),
        };
        let on = |threads: usize, out: &str| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap()
                .install(|| run(&args(out)))
                .unwrap();
            let csv = std::fs::read_to_string(dir.join(out).join("runs.csv")).unwrap();
            // drop the wall-time column
            csv.lines()
                .map(|l| l.rsplit_once(',').unwrap().0.to_string())
                .collect::<Vec<_>>()
        };
        let (one, two) = (on(1, "one"), on(2, "two"));
        assert_eq!(one, two);
        assert_eq!(one.len(), 1 + 2 * 3 * 2);
        let table = std::fs::read_to_string(dir.join("two/table.md")).unwrap();
        assert!(
            table.contains("| XNES |") && table.contains("Posture (2)"),
            "{table}"
        );
        let svg = std::fs::read_to_string(dir.join("two/convergence.svg")).unwrap();
        assert!(svg.starts_with("<svg") && svg.contains("SIRD"));
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
