//! `cargo xtask speedup SPEC --points 200,400 --threads 1,2 [--searches 1,2,4,…,32]`: Fig. 2 of
//! the parallel E-TRM paper on this machine, two ways — P fixed by the spec on 1, 2, … threads,
//! and the paper's experiment, P concurrent searches on P workers — then how P changes the work
//! (evaluations, generations, sequential time per generation) and a model of the curve for 32,
//! 128 and 1 024 workers built from those measurements.

use std::fmt::Write as _;
use std::path::PathBuf;

use anyhow::Result;
use plotters::prelude::{BLACK, Color};
use trm_roadmap::{BuildOptions, Builder, Progress};
use trm_tasks::Problem;

/// Arguments of `speedup`.
#[derive(clap::Args)]
pub struct Args {
    /// The task spec.
    spec: PathBuf,
    /// Point counts to time, comma-separated.
    #[arg(long, default_value = "200,400", value_delimiter = ',', value_parser = trm::parse::count(1, trm_roadmap::MAX_POINTS))]
    points: Vec<usize>,
    /// Thread counts, comma-separated.
    #[arg(long, default_value = "1,2", value_delimiter = ',', value_parser = trm::parse::count(1, 1024))]
    threads: Vec<usize>,
    /// Values of P for the work table and the model (built with the largest thread count).
    #[arg(long, default_value = "1,2,4,8,16,32", value_delimiter = ',', value_parser = trm::parse::count(1, trm_roadmap::MAX_SEARCHES))]
    searches: Vec<usize>,
    /// Seed.
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Output directory for speedup.md and speedup.svg.
    #[arg(long, default_value = "target/speedup")]
    pub out_dir: PathBuf,
}

/// Seconds at which each point count was first reached, and the build's last progress report.
fn timed(
    problem: &Problem,
    threads: usize,
    searches: Option<usize>,
    seed: u64,
    marks: &[usize],
) -> Result<(Vec<f64>, Progress)> {
    let target = marks.iter().copied().max().unwrap_or(0);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()?;
    let mut times = vec![f64::NAN; marks.len()];
    let mut last = None;
    pool.install(|| {
        Builder::new(
            problem,
            &BuildOptions {
                points: Some(target),
                searches,
                seed: Some(seed),
                ..Default::default()
            },
        )
        .run(|p| {
            for (k, &m) in marks.iter().enumerate() {
                if p.points >= m && times[k].is_nan() {
                    times[k] = p.seconds;
                }
            }
            last = Some(*p);
        })
    })?;
    let last = last.ok_or_else(|| anyhow::anyhow!("the build reported no progress"))?;
    Ok((times, last))
}

/// Speedup rows: the time of the first row over each row's, per point count.
fn speedup_rows(md: &mut String, label: &str, rows: &[(usize, Vec<f64>)], marks: &[usize]) {
    let _ = write!(md, "| {label} |");
    for p in marks {
        let _ = write!(md, " {p} points (s) | speedup | efficiency |");
    }
    md.push_str("\n|---|");
    for _ in marks {
        md.push_str("---|---|---|");
    }
    md.push('\n');
    let base = rows.first().map(|r| r.1.clone()).unwrap_or_default();
    for (n, times) in rows {
        let _ = write!(md, "| {n} |");
        for (k, s) in times.iter().enumerate() {
            let speedup = base[k] / s;
            let _ = write!(
                md,
                " {s:.2} | {speedup:.2}× | {:.0} % |",
                100.0 * speedup * rows[0].0 as f64 / *n as f64
            );
        }
        md.push('\n');
    }
}

/// Least-squares line y = a + b x.
fn fit_line(points: &[(f64, f64)]) -> (f64, f64) {
    let n = points.len() as f64;
    let (sx, sy) = points
        .iter()
        .fold((0.0, 0.0), |(a, b), (x, y)| (a + x, b + y));
    let (mx, my) = (sx / n, sy / n);
    let sxx: f64 = points.iter().map(|(x, _)| (x - mx).powi(2)).sum();
    let sxy: f64 = points.iter().map(|(x, y)| (x - mx) * (y - my)).sum();
    let b = if sxx > 0.0 { sxy / sxx } else { 0.0 };
    (my - b * mx, b)
}

/// Assumed cluster interconnect for the model: latency per message (s) and bandwidth (bytes/s).
const LATENCY: f64 = 5e-6;
const BANDWIDTH: f64 = 1e9;

/// One row of the work table: P, and the build's last report.
struct Work {
    p: usize,
    end: Progress,
    seconds: f64,
}

/// Runs the measurements and writes the table and plot.
pub fn run(args: &Args) -> Result<()> {
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    if let Some(t) = args.threads.iter().find(|&&t| t > cores) {
        anyhow::bail!(
            "--threads {t}: this machine has {cores} cores; more threads than cores only time oversubscription\n  fix: give thread counts from 1 to {cores}"
        );
    }
    let problem = Problem::load_with(&args.spec, &trm_taskmap::loaders())?;
    let mut md = format!(
        "Time to reach each map size ({}, seed {}) on {cores} available cores.\n\nP from the spec, on 1, 2, … threads:\n\n",
        args.spec.display(),
        args.seed,
    );
    let mut rows = Vec::new();
    for &t in &args.threads {
        let (times, _) = timed(&problem, t, None, args.seed, &args.points)?;
        eprintln!("{t} threads: {times:?}");
        rows.push((t, times));
    }
    speedup_rows(&mut md, "threads", &rows, &args.points);
    // the paper's experiment: P searches on P workers
    let mut paper = Vec::new();
    let mut paper_ends = Vec::new();
    for &t in &args.threads {
        let (times, end) = timed(&problem, t, Some(t), args.seed, &args.points)?;
        eprintln!("P = {t} on {t} threads: {times:?}");
        paper.push((t, times));
        paper_ends.push((t, end));
    }
    md.push_str("\nThe paper's experiment, P concurrent searches on P workers (threads):\n\n");
    speedup_rows(&mut md, "P = workers", &paper, &args.points);

    // the work as P grows (on all the threads given), and the model built from it
    let threads = args.threads.iter().copied().max().unwrap_or(1);
    let mark = args.points.iter().copied().max().unwrap_or(0);
    let _ = write!(
        md,
        "\nWork as P grows ({threads} threads, {mark} points):\n\n| P | evaluations | evaluations/point | generations | points/generation | seconds | sequential ms/generation | core-µs/evaluation |\n|---|---|---|---|---|---|---|---|\n"
    );
    let mut work = Vec::new();
    for &p in &args.searches {
        let (times, end) = timed(&problem, threads, Some(p), args.seed, &[mark])?;
        let w = Work {
            p,
            seconds: times[0],
            end,
        };
        let _ = writeln!(
            md,
            "| {p} | {} | {:.0} | {} | {:.3} | {:.2} | {:.3} | {:.2} |",
            w.end.evaluations,
            w.end.evaluations as f64 / w.end.points.max(1) as f64,
            w.end.generations,
            w.end.points as f64 / w.end.generations.max(1) as f64,
            w.seconds,
            1e3 * (w.end.seconds - w.end.parallel_seconds) / w.end.generations.max(1) as f64,
            1e6 * w.end.parallel_seconds * threads as f64 / w.end.evaluations.max(1) as f64,
        );
        work.push(w);
    }
    // the model needs a one-thread run (the cost of one evaluation) and a two-thread one
    // (synchronisation)
    let has = |t: usize| paper_ends.iter().any(|(n, _)| *n == t);
    let model = (has(1) && has(2)).then(|| Model::fit(&problem, &work, &paper_ends));
    let modelled: Vec<(f64, f64)> = model.as_ref().map_or_else(Vec::new, |model| {
        [1usize, 2, 4, 8, 16, 32, 128, 1024]
            .iter()
            .map(|&p| (p as f64, model.speedup(p as f64)))
            .collect()
    });
    match &model {
        Some(model) => {
            let _ = write!(
                md,
                "\n{}\n\n| workers P | modelled speedup | efficiency |\n|---|---|---|\n",
                model.describe()
            );
            for &(p, s) in &modelled {
                let _ = writeln!(md, "| {p} | {s:.1}× | {:.0} % |", 100.0 * s / p);
            }
        }
        None => md.push_str("\nNo model: it needs runs on 1 and 2 threads (`--threads 1,2`).\n"),
    }
    md.push_str("\nThe paper (Fig. 2, 400 points, 64-core Dell PowerEdge C6145): 2 267 s on 1 core, 186 s on 32 (12.2×, 38 % efficiency).\n");
    std::fs::create_dir_all(&args.out_dir)?;
    trm::write_atomic(&args.out_dir.join("speedup.md"), md.as_bytes())?;
    let curve = |rows: &[(usize, Vec<f64>)], k: usize| {
        rows.iter()
            .map(|(t, times)| (*t as f64, rows[0].1[k] / times[k]))
            .collect::<Vec<_>>()
    };
    let mut series = vec![trm::plot::Series {
        label: "ideal".into(),
        points: vec![(1.0, 1.0), (32.0, 32.0)],
        color: Some(BLACK.mix(0.5)),
    }];
    for (k, p) in args.points.iter().enumerate() {
        series.push(trm::plot::Series {
            label: format!("{p} points, P = threads (measured)"),
            points: curve(&paper, k),
            color: None,
        });
    }
    series.push(trm::plot::Series {
        label: format!("{mark} points, model"),
        points: modelled
            .iter()
            .copied()
            .filter(|&(p, _)| p <= 32.0)
            .collect(),
        color: None,
    });
    series.push(trm::plot::Series {
        label: "paper, 400 points".into(),
        points: vec![(1.0, 1.0), (32.0, 2267.0 / 186.0)],
        color: None,
    });
    let svg = trm::plot::lines(
        "Parallel E-TRM speedup (P searches on P workers)",
        ("workers", "speedup"),
        0.5..33.0,
        0.0..33.0,
        series,
    )?;
    trm::write_atomic(&args.out_dir.join("speedup.svg"), svg.as_bytes())?;
    println!("{md}");
    println!(
        "wrote {}/{{speedup.md, speedup.svg}}",
        args.out_dir.display()
    );
    Ok(())
}

/// The model of the paper's experiment for many workers, from the measured work table:
/// T(P) = G(P) · (t_par + t_seq(P) + t_comm(P)), with G(P) generations to the map size
/// (a power law fitted to the measured P), t_par = (λ + 1) × the seconds of one evaluation on
/// one thread (each worker evaluates its search's λ candidates and its centre), t_seq(P) =
/// a + b·P (fitted), and t_comm(P) = the synchronisation measured per generation with P = 2 on
/// 2 threads + 2·⌈log₂ P⌉ latencies + the bytes of one gather and one broadcast over an
/// assumed interconnect.
struct Model {
    /// G(P) = g1 · P^(−gamma).
    g1: f64,
    gamma: f64,
    /// Seconds per evaluation on one thread.
    eval: f64,
    /// Synchronisation seconds per generation measured on threads.
    sync: f64,
    /// λ of the later searches.
    lambda: f64,
    /// Sequential seconds per generation: a + b·P.
    seq: (f64, f64),
    /// Task dimension and active motors (message sizes).
    dim: f64,
    motors: f64,
}

impl Model {
    fn fit(problem: &Problem, work: &[Work], paper: &[(usize, Progress)]) -> Self {
        let logs: Vec<(f64, f64)> = work
            .iter()
            .map(|w| ((w.p as f64).ln(), (w.end.generations.max(1) as f64).ln()))
            .collect();
        let (log_g1, slope) = fit_line(&logs);
        let per = |e: &Progress, v: f64| v / e.generations.max(1) as f64;
        // one evaluation on one thread (P = 1 on 1 thread), and the synchronisation of a
        // generation on 2 threads beyond its evaluations shared by 2
        let eval = paper.iter().find(|(t, _)| *t == 1).map_or(0.0, |(_, e)| {
            e.parallel_seconds / e.evaluations.max(1) as f64
        });
        let sync = paper.iter().find(|(t, _)| *t == 2).map_or(0.0, |(_, e)| {
            (per(e, e.parallel_seconds) - per(e, e.evaluations as f64) * eval / 2.0).max(0.0)
        });
        let seq: Vec<(f64, f64)> = work
            .iter()
            .map(|w| {
                (
                    w.p as f64,
                    (w.end.seconds - w.end.parallel_seconds) / w.end.generations.max(1) as f64,
                )
            })
            .collect();
        let settings = problem.spec.map.clone().unwrap_or_default();
        Model {
            g1: log_g1.exp(),
            gamma: -slope,
            eval,
            sync,
            lambda: settings.later_search.0 as f64,
            seq: fit_line(&seq),
            dim: problem.objective.task().map_or(0, |t| t.dim()) as f64,
            motors: problem.objective.active().len() as f64,
        }
    }

    fn seconds(&self, p: f64) -> f64 {
        let generations = self.g1 * p.powf(-self.gamma);
        let par = (self.lambda + 1.0) * self.eval;
        let seq = (self.seq.0 + self.seq.1 * p).max(0.0);
        // gather: fitness and task vector of every candidate; broadcast: the new centres and
        // map points
        let bytes = 8.0 * p * (self.lambda * (1.0 + self.dim) + self.dim + self.motors);
        let comm = if p > 1.0 {
            self.sync + 2.0 * p.log2().ceil() * LATENCY + bytes / BANDWIDTH
        } else {
            0.0
        };
        generations * (par + seq + comm)
    }

    fn speedup(&self, p: f64) -> f64 {
        self.seconds(1.0) / self.seconds(p)
    }

    fn describe(&self) -> String {
        format!(
            "Model (README, \"Scaling beyond one machine\"): T(P) = G(P) · (t_par + t_seq(P) + t_comm(P)); fitted here: G(P) = {:.0} · P^(−{:.3}) generations, t_par = (λ + 1) · {:.2} µs = {:.1} µs, t_seq(P) = {:.1} + {:.2}·P µs, t_comm(P) = {:.1} µs (thread synchronisation, measured) + 2⌈log₂P⌉ · {:.0} µs + bytes / {:.0} GB/s (assumed interconnect).",
            self.g1,
            self.gamma,
            self.eval * 1e6,
            (self.lambda + 1.0) * self.eval * 1e6,
            self.seq.0 * 1e6,
            self.seq.1 * 1e6,
            self.sync * 1e6,
            LATENCY * 1e6,
            BANDWIDTH / 1e9
        )
    }
}
