//! Table III of Stollenga et al. (IROS 2013) as a library: NGIK's xNES against SIR, SIRD,
//! Metropolis–Hastings and Nelder–Mead (plus CMA-ES and (1+1)-CMA-ES) on any task specs, many
//! seeded runs each, with the paper's settings.
//!
//! ```
//! # let spec = r#"(model: "planar_arm",
//! #     costs: [(weight: 1.0, cost: Position(part: "tool", target: Point((0.5, 0.5, 0.0))))])"#;
//! # let problem = trm_tasks::Problem::from_ron(spec, "<example>", std::path::Path::new("."))?;
//! use trm_tasks::Comparison;
//! let comparison = Comparison {
//!     algorithms: vec!["xnes".into(), "simplex".into()],
//!     runs: 3,
//!     max_evaluations: 2_000,
//!     no_improvement: 1_000,
//!     ..Default::default()
//! };
//! let result = comparison.run(&[("arm", &problem)])?;
//! let xnes = result.summary(0, "xnes").unwrap();
//! assert_eq!(xnes.runs, 3);
//! println!("{}", result.to_markdown());
//! # Ok::<(), trm_tasks::TaskError>(())
//! ```
//!
//! Runs are independent and run in parallel on rayon's pool; run k of an algorithm uses seed
//! `seed + k`, so results do not depend on the thread count.

use std::fmt::Write as _;
use std::time::Instant;

use rayon::prelude::*;

use crate::error::{Result, TaskError};
use crate::spec::{Problem, SolverSpec};

/// The settings of a comparison. [`Default`] is the paper's: all seven algorithms, 30 runs,
/// 400 000 evaluations, stop after 30 000 without improvement.
#[derive(Debug, Clone, PartialEq)]
pub struct Comparison {
    /// Algorithm names (`trm_optim::ALGORITHMS`).
    pub algorithms: Vec<String>,
    /// Runs per algorithm and problem (≥ 1).
    pub runs: u64,
    /// Seed of run 0; run k uses `seed + k`.
    pub seed: u64,
    /// Evaluation budget per run.
    pub max_evaluations: u64,
    /// Stop a run when its best has not improved for this many evaluations.
    pub no_improvement: u64,
}

impl Default for Comparison {
    fn default() -> Self {
        Comparison {
            algorithms: [
                "xnes",
                "sir",
                "sird",
                "mh",
                "simplex",
                "cmaes",
                "oneplusone",
            ]
            .map(String::from)
            .to_vec(),
            runs: 30,
            seed: 0,
            max_evaluations: 400_000,
            no_improvement: 30_000,
        }
    }
}

/// One run of a comparison.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct ComparisonRun {
    /// Index of the problem.
    pub problem: usize,
    /// Algorithm name.
    pub algorithm: String,
    /// Seed of the run.
    pub seed: u64,
    /// Final cost.
    pub cost: f64,
    /// Evaluation at which the best was found (the paper's "Nr. evaluations").
    pub best_at: u64,
    /// Evaluations in total.
    pub evaluations: u64,
    /// Whether the final posture is collision-free.
    pub collision_free: bool,
    /// Wall time, seconds.
    pub seconds: f64,
    /// Best-so-far trace `(evaluations, cost)`.
    pub trace: Vec<(u64, f64)>,
    /// The final posture, one value per motor of the robot.
    pub motors: Vec<f64>,
}

/// Mean ± standard error of one algorithm on one problem.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ComparisonSummary {
    /// Runs.
    pub runs: usize,
    /// Mean final cost and its standard error.
    pub cost: (f64, f64),
    /// Mean evaluations at the best and its standard error.
    pub best_at: (f64, f64),
    /// Runs whose posture is collision-free.
    pub collision_free: usize,
}

/// Every run of a comparison, with the settings and labels it ran with.
#[derive(Debug, Clone, PartialEq)]
pub struct ComparisonResult {
    /// The settings.
    pub settings: Comparison,
    /// One label per problem (e.g. its spec file).
    pub labels: Vec<String>,
    /// The runs, problem by problem, algorithm by algorithm, seed by seed.
    pub runs: Vec<ComparisonRun>,
    /// Wall time of the whole comparison, seconds.
    pub wall_seconds: f64,
    /// Threads of the pool it ran on.
    pub threads: usize,
}

impl Comparison {
    /// The paper's solver settings for `algorithm` with this comparison's budgets: population
    /// 300 for xNES, SIR, SIRD (and CMA-ES here), σ = 0.4 for xNES and the CMA-ES variants,
    /// 0.005 for the MH/SIR/SIRD proposals, 0.1 as the simplex's initial edge.
    pub fn solver(&self, algorithm: &str, seed: u64) -> SolverSpec {
        let (sigma, population) = match algorithm {
            "xnes" | "cmaes" => (0.4, Some(300)),
            "snes" | "oneplusone" => (0.4, None),
            "sir" | "sird" => (0.005, Some(300)),
            "mh" => (0.005, None),
            _ => (0.1, None),
        };
        SolverSpec {
            algo: algorithm.to_string(),
            sigma,
            population,
            max_evaluations: self.max_evaluations,
            no_improvement: Some(self.no_improvement),
            target: None,
            seed,
        }
    }

    /// Checks the settings (known algorithms named once, 1 to 100 000 runs whose seeds do not
    /// wrap around, budgets of at least one evaluation); [`Comparison::run`] checks them too.
    pub fn check(&self) -> Result<()> {
        let invalid = |problem: String| {
            Err(TaskError::Invalid {
                what: "comparison".into(),
                problem,
            })
        };
        if self.algorithms.is_empty() {
            return invalid("no algorithms: name at least one".into());
        }
        for (i, a) in self.algorithms.iter().enumerate() {
            if !trm_optim::ALGORITHMS.contains(&a.as_str()) {
                return invalid(format!(
                    "unknown algorithm `{a}`; known: {}",
                    trm_optim::ALGORITHMS.join(", ")
                ));
            }
            if self.algorithms[..i].contains(a) {
                return invalid(format!("algorithm `{a}` is named twice"));
            }
        }
        if self.runs == 0 || self.runs > 100_000 {
            return invalid(format!("{} runs: give 1 to 100000", self.runs));
        }
        if self.seed.checked_add(self.runs - 1).is_none() {
            return invalid(format!(
                "seeds {} + {} runs wrap around: give a smaller seed",
                self.seed, self.runs
            ));
        }
        if self.max_evaluations == 0 || self.no_improvement == 0 {
            return invalid("budgets must be at least 1 evaluation".into());
        }
        Ok(())
    }

    /// Runs every algorithm `runs` times on every `(label, problem)`, from the problem's start
    /// posture, in parallel.
    pub fn run(&self, problems: &[(&str, &Problem)]) -> Result<ComparisonResult> {
        self.run_with_progress(problems, |_, _| {})
    }

    /// [`Comparison::run`], calling `progress(done, total)` after each run (from the worker
    /// threads, in completion order).
    pub fn run_with_progress(
        &self,
        problems: &[(&str, &Problem)],
        progress: impl Fn(usize, usize) + Sync,
    ) -> Result<ComparisonResult> {
        self.check()?;
        if problems.is_empty() {
            return Err(TaskError::Invalid {
                what: "comparison".into(),
                problem: "no problems to compare on".into(),
            });
        }
        let jobs: Vec<(usize, &str, u64)> = (0..problems.len())
            .flat_map(|p| {
                self.algorithms
                    .iter()
                    .flat_map(move |a| (0..self.runs).map(move |k| (p, a.as_str(), k)))
            })
            .collect();
        let started = Instant::now();
        let done = std::sync::atomic::AtomicUsize::new(0);
        let runs = jobs
            .par_iter()
            .map(|&(p, algorithm, k)| -> Result<ComparisonRun> {
                let problem = problems[p].1;
                let solver = self.solver(algorithm, self.seed + k);
                let s = crate::solve(&problem.objective, &problem.start, &solver)?;
                let finished = done.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1;
                progress(finished, jobs.len());
                Ok(ComparisonRun {
                    problem: p,
                    algorithm: algorithm.to_string(),
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
        Ok(ComparisonResult {
            settings: self.clone(),
            labels: problems.iter().map(|(l, _)| l.to_string()).collect(),
            runs,
            wall_seconds: started.elapsed().as_secs_f64(),
            threads: rayon::current_num_threads(),
        })
    }
}

fn mean_sem(v: impl Iterator<Item = f64>) -> (f64, f64) {
    let v: Vec<f64> = v.collect();
    let n = v.len() as f64;
    let mean = v.iter().sum::<f64>() / n;
    if v.len() < 2 {
        return (mean, 0.0);
    }
    let var = v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0);
    (mean, (var / n).sqrt())
}

impl ComparisonResult {
    /// The runs of `algorithm` on problem `problem`.
    pub fn runs_of<'a>(
        &'a self,
        problem: usize,
        algorithm: &'a str,
    ) -> impl Iterator<Item = &'a ComparisonRun> + 'a {
        self.runs
            .iter()
            .filter(move |r| r.problem == problem && r.algorithm == algorithm)
    }

    /// Mean ± standard error of `algorithm` on problem `problem` (`None`: no such runs).
    pub fn summary(&self, problem: usize, algorithm: &str) -> Option<ComparisonSummary> {
        let runs: Vec<&ComparisonRun> = self.runs_of(problem, algorithm).collect();
        (!runs.is_empty()).then(|| ComparisonSummary {
            runs: runs.len(),
            cost: mean_sem(runs.iter().map(|r| r.cost)),
            best_at: mean_sem(runs.iter().map(|r| r.best_at as f64)),
            collision_free: runs.iter().filter(|r| r.collision_free).count(),
        })
    }

    /// The lowest-cost run of `algorithm` on problem `problem`.
    pub fn best(&self, problem: usize, algorithm: &str) -> Option<&ComparisonRun> {
        self.runs
            .iter()
            .filter(|r| r.problem == problem && r.algorithm == algorithm)
            .min_by(|a, b| a.cost.total_cmp(&b.cost))
    }

    /// Mean best-so-far cost of `algorithm` on `problem` at each evaluation count of `grid`
    /// (grid points before every run has a value are left out): the convergence curve.
    pub fn convergence(&self, problem: usize, algorithm: &str, grid: &[u64]) -> Vec<(u64, f64)> {
        let runs: Vec<&ComparisonRun> = self.runs_of(problem, algorithm).collect();
        grid.iter()
            .filter_map(|&g| {
                let at: Vec<f64> = runs
                    .iter()
                    .filter_map(|r| r.trace.iter().take_while(|(e, _)| *e <= g).last())
                    .map(|t| t.1)
                    .collect();
                (at.len() == runs.len() && !at.is_empty())
                    .then(|| (g, at.iter().sum::<f64>() / at.len() as f64))
            })
            .collect()
    }

    /// One CSV row per run: `posture,algo,seed,final_cost,evaluations_at_best,evaluations,
    /// collision_free,seconds` (postures numbered from 1).
    pub fn to_csv(&self) -> String {
        let mut csv = String::from(
            "posture,algo,seed,final_cost,evaluations_at_best,evaluations,collision_free,seconds\n",
        );
        for r in &self.runs {
            let _ = writeln!(
                csv,
                "{},{},{},{},{},{},{},{:.3}",
                r.problem + 1,
                r.algorithm,
                r.seed,
                r.cost,
                r.best_at,
                r.evaluations,
                r.collision_free,
                r.seconds
            );
        }
        csv
    }

    /// Table III as markdown: final cost and evaluations at the best (mean ± standard error),
    /// collision-free runs, per problem and algorithm.
    pub fn to_markdown(&self) -> String {
        let s = &self.settings;
        let mut table = format!(
            "Final cost and evaluations at the best (mean ± standard error of the mean over {} runs; \
             seeds {}–{}; budget {} evaluations, stop after {} without improvement). Wall time {:.0} s \
             on {} threads.\n\n| Algorithm | Final cost | Nr. evaluations | collision-free |\n|---|---|---|---|\n",
            s.runs,
            s.seed,
            s.seed + s.runs - 1,
            s.max_evaluations,
            s.no_improvement,
            self.wall_seconds,
            self.threads
        );
        for (p, label) in self.labels.iter().enumerate() {
            let _ = writeln!(table, "| **Posture ({})** `{label}` | | | |", p + 1);
            for algo in &s.algorithms {
                if let Some(m) = self.summary(p, algo) {
                    let _ = writeln!(
                        table,
                        "| {} | {:.4} ± {:.4} | {:.0} ± {:.0} | {}/{} |",
                        algo.to_uppercase(),
                        m.cost.0,
                        m.cost.1,
                        m.best_at.0,
                        m.best_at.1,
                        m.collision_free,
                        m.runs
                    );
                }
            }
        }
        table
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bad_settings_are_refused_before_any_run() {
        for bad in [
            Comparison {
                runs: 0,
                ..Default::default()
            },
            Comparison {
                algorithms: vec!["xnes".into(), "xnes".into()],
                ..Default::default()
            },
            Comparison {
                algorithms: vec!["xness".into()],
                ..Default::default()
            },
            Comparison {
                seed: u64::MAX,
                runs: 2,
                ..Default::default()
            },
        ] {
            assert!(bad.run(&[]).is_err());
        }
        let e = Comparison::default().run(&[]).unwrap_err().to_string();
        assert!(e.contains("no problems"), "{e}");
    }
}
