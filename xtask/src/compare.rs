//! `cargo xtask compare-optimisers`: Table III of Stollenga et al. (IROS 2013) — NGIK's xNES
//! against SIR, SIRD, Metropolis–Hastings and Nelder–Mead (plus CMA-ES and (1+1)-CMA-ES) on the
//! two postures of Fig. 5, 30 seeded runs each: a markdown table, a CSV of every run and a
//! convergence plot.

use std::fmt::Write as _;
use std::path::PathBuf;
use std::time::Instant;

use anyhow::{Context, Result};
use rayon::prelude::*;
use trm_tasks::spec::SolverSpec;
use trm_tasks::{Problem, solve};

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
    #[arg(long, default_value_t = 30)]
    runs: u64,
    /// Base seed.
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Evaluation budget per run.
    #[arg(long, default_value_t = 400_000)]
    max_evals: u64,
    /// Stop a run when its best has not improved for this many evaluations.
    #[arg(long, default_value_t = 30_000)]
    no_improvement: u64,
    /// Also write a 3-D view per posture (`posture<N>.scene.html`): one frame per algorithm,
    /// its best run's posture.
    #[arg(long)]
    pub view: bool,
    /// Output directory for table.md, runs.csv and convergence.svg.
    #[arg(long, default_value = "target/compare-optimisers")]
    out_dir: PathBuf,
}

/// The paper's settings per algorithm: population 300 for xNES, SIR, SIRD (and CMA-ES here),
/// σ = 0.4 for xNES (and the CMA-ES variants), σ = 0.005 for the MH/SIR/SIRD proposals.
fn solver_for(algo: &str, args: &Args, seed: u64) -> SolverSpec {
    let (sigma, population) = match algo {
        "xnes" | "cmaes" => (0.4, Some(300)),
        "snes" => (0.4, None),
        "sir" | "sird" => (0.005, Some(300)),
        "mh" => (0.005, None),
        "oneplusone" => (0.4, None),
        _ => (0.1, None), // simplex: initial edge length
    };
    SolverSpec {
        algo: algo.to_string(),
        sigma,
        population,
        max_evaluations: args.max_evals,
        no_improvement: Some(args.no_improvement),
        target: None,
        seed,
    }
}

struct RunResult {
    posture: usize,
    algo: String,
    seed: u64,
    cost: f64,
    best_at: u64,
    evaluations: u64,
    collision_free: bool,
    seconds: f64,
    trace: Vec<(u64, f64)>,
    motors: Vec<f64>,
}

fn mean_sem(v: &[f64]) -> (f64, f64) {
    let n = v.len() as f64;
    let mean = v.iter().sum::<f64>() / n;
    if v.len() < 2 {
        return (mean, 0.0);
    }
    let var = v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0);
    (mean, (var / n).sqrt())
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
    for a in &args.algos {
        anyhow::ensure!(
            trm_optim::ALGORITHMS.contains(&a.as_str()),
            "unknown algorithm `{a}`; known: {}",
            trm_optim::ALGORITHMS.join(", ")
        );
    }
    let problems: Vec<Problem> = specs
        .iter()
        .map(|p| Problem::load(p).with_context(|| format!("loading {}", p.display())))
        .collect::<Result<_>>()?;
    let jobs: Vec<(usize, &str, u64)> = (0..problems.len())
        .flat_map(|p| {
            args.algos
                .iter()
                .flat_map(move |a| (0..args.runs).map(move |k| (p, a.as_str(), k)))
        })
        .collect();
    eprintln!(
        "{} runs ({} postures × {} algorithms × {}) on {} threads…",
        jobs.len(),
        problems.len(),
        args.algos.len(),
        args.runs,
        rayon::current_num_threads()
    );
    let started = Instant::now();
    let results: Vec<RunResult> = jobs
        .par_iter()
        .map(|&(p, algo, k)| -> Result<RunResult> {
            let problem = &problems[p];
            let solver = solver_for(algo, args, args.seed + k);
            let s = solve(&problem.objective, &problem.start, &solver)?;
            Ok(RunResult {
                posture: p,
                algo: algo.to_string(),
                seed: solver.seed,
                cost: s.cost,
                best_at: s.best_at,
                evaluations: s.evaluations,
                collision_free: s.collision_free,
                seconds: s.wall_time.as_secs_f64(),
                trace: s.trace,
                motors: s.motors,
            })
        })
        .collect::<Result<_>>()?;
    let wall = started.elapsed().as_secs_f64();

    let mut csv = String::from(
        "posture,algo,seed,final_cost,evaluations_at_best,evaluations,collision_free,seconds\n",
    );
    for r in &results {
        let _ = writeln!(
            csv,
            "{},{},{},{},{},{},{},{:.3}",
            r.posture + 1,
            r.algo,
            r.seed,
            r.cost,
            r.best_at,
            r.evaluations,
            r.collision_free,
            r.seconds
        );
    }
    let mut table = format!(
        "Final cost and evaluations at the best (mean ± standard error of the mean over {} runs; \
         seeds {}–{}; budget {} evaluations, stop after {} without improvement). Wall time {:.0} s \
         on {} threads.\n\n| Algorithm | Final cost | Nr. evaluations | collision-free |\n|---|---|---|---|\n",
        args.runs,
        args.seed,
        args.seed + args.runs - 1,
        args.max_evals,
        args.no_improvement,
        wall,
        rayon::current_num_threads()
    );
    for (p, spec) in specs.iter().enumerate() {
        let _ = writeln!(
            table,
            "| **Posture ({})** `{}` | | | |",
            p + 1,
            spec.display()
        );
        for algo in &args.algos {
            let rs: Vec<&RunResult> = results
                .iter()
                .filter(|r| r.posture == p && &r.algo == algo)
                .collect();
            let (c, cs) = mean_sem(&rs.iter().map(|r| r.cost).collect::<Vec<_>>());
            let (e, es) = mean_sem(&rs.iter().map(|r| r.best_at as f64).collect::<Vec<_>>());
            let free = rs.iter().filter(|r| r.collision_free).count();
            let _ = writeln!(
                table,
                "| {} | {c:.4} ± {cs:.4} | {e:.0} ± {es:.0} | {free}/{} |",
                algo.to_uppercase(),
                rs.len()
            );
        }
    }
    std::fs::create_dir_all(&args.out_dir)?;
    crate::write_atomic(&args.out_dir.join("runs.csv"), csv.as_bytes())?;
    crate::write_atomic(&args.out_dir.join("table.md"), table.as_bytes())?;
    let svg = plot(&results, &args.algos, specs.len(), args.max_evals)?;
    crate::write_atomic(&args.out_dir.join("convergence.svg"), svg.as_bytes())?;
    println!("{table}");
    println!(
        "wrote {}/{{table.md, runs.csv, convergence.svg}}; wall time {wall:.1} s",
        args.out_dir.display()
    );
    if args.view {
        for (p, problem) in problems.iter().enumerate() {
            let title = format!(
                "{}: best posture of each algorithm ({})",
                specs[p].display(),
                args.algos.join(", ")
            );
            let mut scene = crate::view::problem_scene(problem, &title)?;
            scene.frames.clear();
            for (i, algo) in args.algos.iter().enumerate() {
                let best = results
                    .iter()
                    .filter(|r| r.posture == p && &r.algo == algo)
                    .min_by(|a, b| a.cost.total_cmp(&b.cost));
                if let Some(best) = best {
                    scene.add_frame(i as f64, &best.motors)?;
                }
            }
            let page = args.out_dir.join(format!("posture{}.scene.html", p + 1));
            crate::view::write_scene(&scene, &page)?;
        }
    }
    Ok(())
}

/// Mean best-so-far cost against evaluations (log scale), one panel per posture.
fn plot(
    results: &[RunResult],
    algos: &[String],
    postures: usize,
    max_evals: u64,
) -> Result<String> {
    let grid: Vec<u64> = (0..=60)
        .map(|i| (10f64.powf(2.0 + i as f64 * ((max_evals as f64).log10() - 2.0) / 60.0)) as u64)
        .collect();
    let mut panels = Vec::new();
    for p in 0..postures {
        let mut series = Vec::new();
        let (mut lo, mut hi) = (f64::INFINITY, 0.0f64);
        for algo in algos {
            let runs: Vec<&RunResult> = results
                .iter()
                .filter(|r| r.posture == p && &r.algo == algo)
                .collect();
            let points: Vec<(f64, f64)> = grid
                .iter()
                .filter_map(|&g| {
                    let at: Vec<f64> = runs
                        .iter()
                        .filter_map(|r| {
                            r.trace
                                .iter()
                                .take_while(|(e, _)| *e <= g)
                                .last()
                                .map(|t| t.1)
                        })
                        .collect();
                    (at.len() == runs.len() && !at.is_empty())
                        .then(|| (g as f64, at.iter().sum::<f64>() / at.len() as f64))
                })
                .collect();
            for (_, c) in &points {
                lo = lo.min(*c);
                hi = hi.max(*c);
            }
            series.push(crate::plot::Series {
                label: algo.to_uppercase(),
                points: points
                    .iter()
                    .map(|(e, c)| (e.log10(), c.max(1e-3).log10()))
                    .collect(),
                color: None,
            });
        }
        panels.push(crate::plot::Panel {
            title: format!("Posture ({}): mean best cost", p + 1),
            axes: ("evaluations (log10)".into(), "cost (log10)".into()),
            x: 2.0..(max_evals as f64).log10(),
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
