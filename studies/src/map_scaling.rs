//! `cargo xtask map-scaling SPEC --points 10000`: how map building and map files scale with the
//! map's size. One build to the largest size, and at each mark (100, 200, 500, 1 000, …):
//! build time so far and per point, resident memory, kd-tree query time, and the size, save
//! and load times of the map file holding the first n points.

use std::fmt::Write as _;
use std::path::PathBuf;
use std::time::Instant;

use anyhow::{Context, Result};
use rand::{RngExt, SeedableRng};
use trm_roadmap::{BuildOptions, Builder, Roadmap, TaskIndex, connect};
use trm_tasks::Problem;

/// Arguments of `map-scaling`.
#[derive(clap::Args)]
pub struct Args {
    /// The task spec (e.g. specs/reach_1cm.ron).
    spec: PathBuf,
    /// The largest map (points).
    #[arg(long, default_value_t = 10_000, value_parser = trm::parse::count(1, trm_roadmap::MAX_POINTS))]
    points: usize,
    /// Worker threads (default: all cores).
    #[arg(long, value_parser = trm::parse::count(1, 4096))]
    threads: Option<usize>,
    /// Output directory: scaling.md and the final map.
    #[arg(long, default_value = "target/map-scaling")]
    pub out_dir: PathBuf,
}

/// Resident memory of this process, MiB (Linux; `None` elsewhere).
fn resident_mib(field: &str) -> Option<f64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with(field))?;
    let kib: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib / 1024.0)
}

/// The marks 100, 200, 500, 1 000, 2 000, 5 000, … up to `points` (and `points` itself).
fn marks(points: usize) -> Vec<usize> {
    let mut marks: Vec<usize> = (2..12)
        .flat_map(|e| [1, 2, 5].map(|m| m * 10usize.pow(e)))
        .take_while(|&m| m < points)
        .collect();
    marks.push(points);
    marks
}

/// Runs the build and the measurements, prints and writes the table.
pub fn run(args: &Args) -> Result<()> {
    let problem = Problem::load_with(&args.spec, &trm_taskmap::loaders())?;
    let pool = trm::thread_pool(args.threads)?;
    let marks = marks(args.points);
    let mut reached: Vec<Option<(f64, Option<f64>)>> = vec![None; marks.len()];
    let mut progress = trm::progress::Progress::new("points", args.points as u64);
    let options = BuildOptions {
        points: Some(args.points),
        ..Default::default()
    };
    let (map, edge_seconds) = pool.install(|| -> Result<(Roadmap, f64)> {
        let mut map = Builder::new(&problem, &options).run(|p| {
            progress.set(p.points as u64, p.target as u64, "");
            for (k, &m) in marks.iter().enumerate() {
                if p.points >= m && reached[k].is_none() {
                    reached[k] = Some((p.seconds, resident_mib("VmRSS:")));
                }
            }
        })?;
        progress.finish();
        let started = Instant::now();
        let neighbours = map.settings.edge_neighbours;
        connect(&mut map, &problem.objective, neighbours, 0.05)?;
        Ok((map, started.elapsed().as_secs_f64()))
    })?;
    let n_max = map.points.len();
    let dim = map.points.first().map_or(0, |p| p.t.len());
    let d = map.settings.spacing;
    let mut md = format!(
        "Map scaling: {} ({} task dimensions, d = {d}), seed {}, P = {}, {} threads; edges of the {n_max}-point map: {:.1} s.\n\n\
         | points | build s | ms/point (this step) | ms/point (all) | RSS MiB | kNN µs | JSON MB | save ms | load ms | load + verify ms |\n\
         |---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n",
        args.spec.display(),
        dim,
        map.seed,
        map.searches,
        pool.current_num_threads(),
        edge_seconds
    );
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(0);
    // the probe files go to the temporary directory: a failed run leaves nothing in out_dir
    let scratch_file =
        std::env::temp_dir().join(format!("trm-scaling-{}.map.json", std::process::id()));
    let mut previous = (0usize, 0.0f64);
    for (k, &n) in marks.iter().enumerate() {
        let Some((seconds, rss)) = reached[k] else {
            let _ = writeln!(
                md,
                "| {n} | not reached: {} | | | | | | | | |",
                map.stats.stopped_because
            );
            continue;
        };
        let n = n.min(n_max);
        // kd-tree of the first n task points: m = dim nearest neighbours of points near them
        let mut index = TaskIndex::new(dim);
        for p in &map.points[..n] {
            index.add(&p.t);
        }
        let queries: Vec<Vec<f64>> = (0..20_000)
            .map(|_| {
                let p = &map.points[rng.random_range(0..n)];
                p.t.iter()
                    .map(|v| v + d * rng.random_range(-1.0..1.0))
                    .collect()
            })
            .collect();
        let mut nn = Vec::new();
        let started = Instant::now();
        for q in &queries {
            index.nearest(q, dim.max(1), &mut nn);
        }
        let knn_us = started.elapsed().as_secs_f64() * 1e6 / queries.len() as f64;
        // the file of the first n points and the edges among them
        let mut part = map.clone();
        part.points.truncate(n);
        part.edges.retain(|&(a, b, _)| a < n && b < n);
        let started = Instant::now();
        part.save(&scratch_file)?;
        let save_ms = started.elapsed().as_secs_f64() * 1e3;
        let bytes = std::fs::metadata(&scratch_file)?.len();
        let started = Instant::now();
        let loaded = Roadmap::load(&scratch_file)?;
        let load_ms = started.elapsed().as_secs_f64() * 1e3;
        loaded
            .problem_with(&trm_taskmap::loaders())
            .context("verifying the map against its spec")?;
        let verify_ms = started.elapsed().as_secs_f64() * 1e3;
        let step = (seconds - previous.1) * 1e3 / (n - previous.0).max(1) as f64;
        let _ = writeln!(
            md,
            "| {n} | {seconds:.2} | {step:.2} | {:.2} | {} | {knn_us:.2} | {:.2} | {save_ms:.0} | {load_ms:.0} | {verify_ms:.0} |",
            seconds * 1e3 / n as f64,
            rss.map_or("n/a".into(), |r| format!("{r:.0}")),
            bytes as f64 / 1e6,
        );
        previous = (n, seconds);
    }
    let _ = std::fs::remove_file(&scratch_file);
    if let Some(peak) = resident_mib("VmHWM:") {
        let _ = writeln!(md, "\nPeak resident memory: {peak:.0} MiB.");
    }
    let stem = args
        .spec
        .file_stem()
        .map_or("map".into(), |s| s.to_string_lossy().to_string());
    let map_path = args.out_dir.join(format!("{stem}.map.json"));
    trm::write_atomic(&map_path, map.to_json(&map_path)?.as_bytes())?;
    trm::write_atomic(&args.out_dir.join("scaling.md"), md.as_bytes())?;
    println!("{md}");
    println!(
        "wrote {}/{{scaling.md, {stem}.map.json}}",
        args.out_dir.display()
    );
    Ok(())
}
