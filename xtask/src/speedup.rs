//! `cargo xtask speedup SPEC --points 200,400 --threads 1,2 [--searches 1,2,4,8]`: Fig. 2 of
//! the parallel E-TRM paper on this machine — time to reach each point count per thread count,
//! speedup against the ideal — and how the number of concurrent searches P changes the
//! evaluations needed per point.

use std::fmt::Write as _;
use std::path::PathBuf;

use anyhow::Result;
use plotters::prelude::{BLACK, Color};
use trm_roadmap::{BuildOptions, build};
use trm_tasks::Problem;

/// Arguments of `speedup`.
#[derive(clap::Args)]
pub struct Args {
    /// The task spec.
    spec: PathBuf,
    /// Point counts to time, comma-separated.
    #[arg(long, default_value = "200,400", value_delimiter = ',', value_parser = crate::parse::count(1, trm_roadmap::MAX_POINTS))]
    points: Vec<usize>,
    /// Thread counts, comma-separated.
    #[arg(long, default_value = "1,2", value_delimiter = ',', value_parser = crate::parse::count(1, 1024))]
    threads: Vec<usize>,
    /// Values of P for the evaluations-per-point table (built with the largest thread count).
    #[arg(long, default_value = "1,2,4,8", value_delimiter = ',', value_parser = crate::parse::count(1, trm_roadmap::MAX_SEARCHES))]
    searches: Vec<usize>,
    /// Seed.
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Output directory for speedup.md and speedup.svg.
    #[arg(long, default_value = "target/speedup")]
    pub out_dir: PathBuf,
}

/// Seconds at which each point count was first reached, evaluations and points in the end.
fn timed(
    problem: &Problem,
    threads: usize,
    searches: Option<usize>,
    seed: u64,
    marks: &[usize],
) -> Result<(Vec<f64>, u64, usize)> {
    let target = marks.iter().copied().max().unwrap_or(0);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()?;
    let mut times = vec![f64::NAN; marks.len()];
    let map = pool.install(|| {
        build(
            problem,
            &BuildOptions {
                points: Some(target),
                searches,
                seed: Some(seed),
                ..Default::default()
            },
            |p| {
                for (k, &m) in marks.iter().enumerate() {
                    if p.points >= m && times[k].is_nan() {
                        times[k] = p.seconds;
                    }
                }
            },
        )
    })?;
    Ok((times, map.stats.evaluations, map.points.len()))
}

/// Runs the measurements and writes the table and plot.
pub fn run(args: &Args) -> Result<()> {
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    if let Some(t) = args.threads.iter().find(|&&t| t > cores) {
        anyhow::bail!(
            "--threads {t}: this machine has {cores} cores; more threads than cores only time oversubscription\n  fix: give thread counts from 1 to {cores}"
        );
    }
    let problem = Problem::load(&args.spec)?;
    let mut md = format!(
        "Time to reach each map size ({} , seed {}, P from the spec), on {} available cores.\n\n| threads |",
        args.spec.display(),
        args.seed,
        std::thread::available_parallelism().map_or(1, |n| n.get())
    );
    for p in &args.points {
        let _ = write!(md, " {p} points (s) | speedup |");
    }
    md.push_str("\n|---|");
    for _ in &args.points {
        md.push_str("---|---|");
    }
    md.push('\n');
    let mut rows = Vec::new();
    for &t in &args.threads {
        let (times, _, _) = timed(&problem, t, None, args.seed, &args.points)?;
        eprintln!("{t} threads: {times:?}");
        rows.push((t, times));
    }
    let base = rows.first().map(|r| r.1.clone()).unwrap_or_default();
    for (t, times) in &rows {
        let _ = write!(md, "| {t} |");
        for (k, s) in times.iter().enumerate() {
            let _ = write!(md, " {s:.2} | {:.2}× |", base[k] / s);
        }
        md.push('\n');
    }
    let threads = args.threads.iter().copied().max().unwrap_or(1);
    let _ = write!(
        md,
        "\nConcurrent searches P ({threads} threads, {} points):\n\n| P | evaluations | evaluations/point | seconds |\n|---|---|---|---|\n",
        args.points.iter().copied().min().unwrap_or(0)
    );
    let small = [args.points.iter().copied().min().unwrap_or(0)];
    for &p in &args.searches {
        let (times, evals, points) = timed(&problem, threads, Some(p), args.seed, &small)?;
        let _ = writeln!(
            md,
            "| {p} | {evals} | {:.0} | {:.2} |",
            evals as f64 / points.max(1) as f64,
            times[0]
        );
    }
    std::fs::create_dir_all(&args.out_dir)?;
    crate::write_atomic(&args.out_dir.join("speedup.md"), md.as_bytes())?;
    let max_t = threads as f64;
    let mut series = vec![crate::plot::Series {
        label: "ideal".into(),
        points: vec![(1.0, 1.0), (max_t, max_t)],
        color: Some(BLACK.mix(0.5)),
    }];
    for (k, p) in args.points.iter().enumerate() {
        series.push(crate::plot::Series {
            label: format!("{p} points"),
            points: rows
                .iter()
                .map(|(t, times)| (*t as f64, base[k] / times[k]))
                .collect(),
            color: None,
        });
    }
    let svg = crate::plot::lines(
        "Parallel E-TRM speedup",
        ("threads", "speedup"),
        0.5..max_t + 0.5,
        0.0..max_t + 0.5,
        series,
    )?;
    crate::write_atomic(&args.out_dir.join("speedup.svg"), svg.as_bytes())?;
    println!("{md}");
    println!(
        "wrote {}/{{speedup.md, speedup.svg}}",
        args.out_dir.display()
    );
    Ok(())
}
