//! `trm benchmark-mbm DIR --model MODEL [--package-path DIR] [--per-family N]`: a
//! MotionBenchMaker set (a folder per family of `sceneNNNN.yaml` + `requestNNNN.yaml`, e.g.
//! VAMP's `resources/panda/problems.tar.bz2` unpacked) solved problem by problem
//! (`trm_mbm::solve`, RRT-Connect); per family: valid, solved, median and p95 time, path
//! length, collision checks; `results.csv`, `results.md` and `times.svg` in `--out-dir`.

use std::fmt::Write as _;
use std::path::PathBuf;

use anyhow::{Context, Result};
use trm_mbm::{Outcome, ProblemSet, Verdict, certify_path_loaded};
use trm_plan::rrt::RrtOptions;
use trm_roadmap::Roadmap;

/// Arguments of `benchmark-mbm`.
#[derive(clap::Args)]
pub struct Args {
    /// The problem set: a folder holding one folder per family, or a .tar.bz2 of one (as VAMP
    /// ships them).
    dir: PathBuf,
    /// The robot (.urdf or .ron model description).
    #[arg(long)]
    model: PathBuf,
    #[command(flatten)]
    meshes: crate::MeshArgs,
    /// Problems per family (the first N by number; all when absent).
    #[arg(long, value_parser = crate::parse::count(1, 1_000_000))]
    per_family: Option<usize>,
    /// Only these families (comma-separated).
    #[arg(long, value_delimiter = ',')]
    families: Vec<String>,
    /// Seed of every problem's sampler.
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Time budget per problem, s (default: each request's allowed_planning_time).
    #[arg(long, value_parser = crate::parse::positive)]
    max_seconds: Option<f64>,
    /// Sample budget per problem (VAMP's evaluate_mbm.py gives its RRT-Connect 10⁶).
    #[arg(long, default_value_t = 1_000_000, value_parser = crate::parse::count(1, 100_000_000))]
    max_iterations: usize,
    /// Largest gap between checked points of an edge, rad (default: sized by the robot's lever
    /// arms, `trm_plan::rrt::RrtOptions::for_robot`; 1/32 rad on the Panda).
    #[arg(long, value_parser = crate::parse::positive)]
    resolution: Option<f64>,
    /// RRT-Connect's longest step, rad (default: sized by the robot's lever arms; 1 rad on
    /// the Panda).
    #[arg(long, value_parser = crate::parse::positive)]
    range: Option<f64>,
    /// Where RRT-Connect's samples come from: `uniform` (independent seeded draws) or `halton`
    /// (low discrepancy, shifted by the seed; VAMP's sampler).
    #[arg(long, value_enum, default_value_t = SamplerArg::Uniform)]
    sampler: SamplerArg,
    /// Random shortcut attempts per path (after the greedy pass).
    #[arg(long, default_value_t = 0, value_parser = crate::parse::count(0, 1_000_000))]
    shortcuts: usize,
    /// Rounds of corner cutting after shortcutting, each followed by the greedy pass again
    /// (VAMP's simplifier: B-spline step and shortcut; 0: the greedy pass only).
    #[arg(long, default_value_t = trm_plan::rrt::SMOOTHING_ROUNDS, value_parser = crate::parse::count(0, 1_000))]
    smoothing: usize,
    /// Prove every returned path (trm's and, with --vamp, VAMP's) free in continuous motion:
    /// f64, exact distances and lever-arm bounds, independent of the planner's own checks.
    #[arg(long)]
    verify: bool,
    /// Plan and verify among the obstacles VAMP plans among (VAMP's checks have no cylinders):
    /// each cylinder a capsule, in the box family a box, so that both planners face the same
    /// obstacles (trm_mbm::vamp_world)
    #[arg(long)]
    vamp_obstacles: bool,
    /// Check the link pairs the model's own allowed-collision matrix checks, ignoring each
    /// scene's, as VAMP does (a scene's matrix written for a robot's meshes may check pairs
    /// that its sphere model's spheres overlap at the problems' starts and goals)
    #[arg(long)]
    ignore_scene_matrices: bool,
    /// Plan among the scenes as a depth camera would see them, as VAMP's evaluate_mbm.py
    /// --pointcloud does: SAMPLES points on every object's surface (VAMP's: 10000), thinned to
    /// 2 cm, points of 2.5 mm (trm_mbm::cloud_world); with --vamp, VAMP plans among the same
    /// points (its CAPT). The clouds' build times are reported beside the planning times.
    #[arg(long, value_name = "SAMPLES", conflicts_with = "vamp_obstacles", value_parser = crate::parse::count(1, 1_000_000))]
    cloud: Option<usize>,
    /// Plan with certified edges: every edge the planner accepts is also proved free in
    /// continuous motion, so every returned path is (see --verify).
    #[arg(long)]
    certified: bool,
    /// Pose every joint goal as the task-space goal it implies for this link (its pose at the
    /// goal: a cube of side --position-tolerance, --orientation-tolerance about each axis) and
    /// solve that: IK for a collision-free goal of the request's group, then RRT-Connect.
    #[arg(long, value_name = "LINK", conflicts_with_all = ["experience", "vamp", "ompl"])]
    task_space: Option<String>,
    /// With --task-space: side of the cube the link's origin must reach, m.
    #[arg(long, default_value_t = 0.01, value_parser = crate::parse::positive, requires = "task_space")]
    position_tolerance: f64,
    /// With --task-space: tolerance about each axis, rad.
    #[arg(long, default_value_t = 0.05, value_parser = crate::parse::positive, requires = "task_space")]
    orientation_tolerance: f64,
    /// Also run OMPL's RRTConnect on the same problems (benches/python/mbm_ompl.py: the same
    /// robot files, coal through Pinocchio, the same edge step, `--per-family` and seed; needs
    /// `python3 -m pip install ompl pin pyyaml numpy`) and print its table after trm's; the
    /// value is OMPL's time limit per problem, s.
    #[arg(long, value_parser = crate::parse::positive, conflicts_with = "families")]
    ompl: Option<f64>,
    /// Also solve the set with experience kept, twice (`trm_mbm::solve_with_experience`:
    /// one planner per family keeps every path RRT-Connect finds; pass 1 plans each problem
    /// through the family's earlier paths, pass 2 runs the set again), a table per pass.
    #[arg(long)]
    experience: bool,
    /// Also run VAMP's RRT-Connect + simplifier on the same problems and print its table and a
    /// side-by-side one after trm's: the program benches/peers/vamp/build.sh builds
    /// (target/peers/vamp-mbm). The robot is VAMP's of the URDF's name (panda, fetch, ur5,
    /// baxter), or --vamp-robot's.
    #[arg(long, conflicts_with = "families")]
    vamp: Option<PathBuf>,
    /// With --vamp: VAMP's robot to run (panda, fetch, ur5, baxter), where the URDF names it
    /// otherwise (default: the URDF's robot name).
    #[arg(long, value_name = "NAME", requires = "vamp")]
    vamp_robot: Option<String>,
    /// Also solve the set with this map attached to each problem's planner (repeatable; built
    /// for the requests' group, in any world: its nodes and edges are checked in each scene when
    /// the search first wants them) and print that run beside the plain one.
    #[arg(long = "map", value_name = "FILE", conflicts_with = "task_space")]
    maps: Vec<PathBuf>,
    /// Where results.csv, results.md and times.svg go (and results-maps.csv with --map,
    /// results-leave-one-out-{family,set}[-fresh].csv with --experience).
    #[arg(long, default_value = "target/benchmark-mbm")]
    pub out_dir: PathBuf,
}

/// `--sampler`: [`trm_plan::rrt::Sampler`] on the command line.
#[derive(Debug, Clone, Copy, clap::ValueEnum)]
pub enum SamplerArg {
    /// Independent uniform draws.
    Uniform,
    /// The Halton sequence, shifted by the seed.
    Halton,
}

/// Runs the set, prints the per-family table, writes the files.
pub fn run(args: &Args) -> Result<()> {
    if let Some(binary) = &args.vamp {
        anyhow::ensure!(
            binary.is_file(),
            "--vamp: no program at {}\n  {VAMP_FIX}",
            binary.display()
        );
    }
    let robot = crate::load_model(Some(&args.model))?;
    let collision = args.meshes.collision_model(&robot)?;
    let mut set = ProblemSet::open(&args.dir)?;
    set.select(&args.families, args.per_family)
        .with_context(|| format!("--families/--per-family with {}", args.dir.display()))?;
    let problems = set.problems.clone();
    let sized = trm_mbm::rrt_options_for(&robot, &collision, &problems)?;
    let options = RrtOptions {
        seed: args.seed,
        max_iterations: args.max_iterations,
        max_seconds: args.max_seconds,
        resolution: args.resolution.unwrap_or(sized.resolution),
        range: args.range.unwrap_or(sized.range),
        shortcuts: args.shortcuts,
        smoothing: args.smoothing,
        certified: args.certified,
        sampler: match args.sampler {
            SamplerArg::Halton => trm_plan::rrt::Sampler::Halton,
            SamplerArg::Uniform => trm_plan::rrt::Sampler::Uniform,
        },
        ..sized
    };
    let bench = run_benchmark(args, &robot, &collision, &problems, &options)?;
    let mut md = header(args, &options);
    md.push_str(&bench.markdown());
    if args.cloud.is_some() {
        md.push_str(&cloud_lines(&bench));
    }
    print!("{md}");
    // every file is written at the end, once every part has run
    let mut files = vec![
        ("results.csv", trm_mbm::runs_csv(&bench.runs).into_bytes()),
        ("times.svg", times_plot(&bench.runs)?.into_bytes()),
    ];
    if !bench.with_maps.is_empty() {
        files.push((
            "results-maps.csv",
            trm_mbm::runs_csv(&bench.with_maps).into_bytes(),
        ));
    }
    for (scope, runs, fresh) in &bench.leave_one_out {
        let [name, beside] = match scope {
            trm_mbm::Scope::Family => [
                "results-leave-one-out-family.csv",
                "results-leave-one-out-family-fresh.csv",
            ],
            trm_mbm::Scope::Set => [
                "results-leave-one-out-set.csv",
                "results-leave-one-out-set-fresh.csv",
            ],
        };
        files.push((name, trm_mbm::runs_csv(runs).into_bytes()));
        files.push((beside, trm_mbm::runs_csv(fresh).into_bytes()));
    }
    let outcomes: Vec<(&str, &Outcome)> = bench
        .runs
        .iter()
        .map(|r| (r.family.as_str(), &r.outcome))
        .collect();
    if let Some(binary) = &args.vamp {
        let (peer, verdicts, exported) = run_vamp(args, binary, &robot, &set, &bench)?;
        files.push(("peer-problems.txt", exported.into_bytes()));
        let theirs: Vec<(&str, &Outcome)> = peer.iter().map(|(f, o)| (f.as_str(), o)).collect();
        let mut text = format!(
            "\nVAMP's RRT-Connect + simplifier on the same problems ({}, VAMP's sphere model of {}, Halton sampler, its range for the robot; time = planning + simplification as VAMP reports them):\n\n{}",
            binary.display(),
            args.vamp_robot.as_deref().unwrap_or(robot.name()),
            trm_mbm::markdown_table(theirs.iter().copied())
        );
        if args.verify {
            text.push_str(&trm_mbm::verdicts_line(
                verdicts.into_iter(),
                "VAMP's paths, in trm's model,",
            ));
        }
        if args.cloud.is_some() {
            text.push_str(&with_build_line(&outcomes, &theirs));
        }
        let _ = write!(
            text,
            "\nSide by side, on the problems both call valid (ratio = trm / VAMP):\n\n{}",
            trm_mbm::side_by_side((&outcomes, "trm"), (&theirs, "VAMP"))
        );
        if let Some(second) = bench.experience.get(1) {
            let ours: Vec<(&str, &Outcome)> = second
                .iter()
                .map(|r| (r.family.as_str(), &r.outcome))
                .collect();
            let _ = write!(
                text,
                "\ntrm with experience (pass 2) beside VAMP:\n\n{}",
                trm_mbm::side_by_side((&ours, "trm"), (&theirs, "VAMP"))
            );
        }
        print!("{text}");
        md.push_str(&text);
    }
    if let Some(limit) = args.ompl {
        md.push_str(&run_ompl(args, &set, limit)?);
    }
    files.push(("results.md", md.into_bytes()));
    std::fs::create_dir_all(&args.out_dir)?;
    for (name, bytes) in &files {
        crate::write_atomic(&args.out_dir.join(name), bytes)?;
    }
    let names: Vec<&str> = files.iter().map(|f| f.0).collect();
    println!("wrote {}/{{{}}}", args.out_dir.display(), names.join(", "));
    Ok(())
}

/// The report's first line: the set, the model and the planner's settings.
fn header(args: &Args, options: &RrtOptions) -> String {
    format!(
        "MotionBenchMaker set {} with {} (RRT-Connect + shortcutting and {} corner-cutting rounds, seed {}, range {:.3} rad, resolution 1/{:.1} rad{}, dynamic domains of {:.2} rad, {} samples at most{}{}{})\n\n",
        args.dir.display(),
        args.model.display(),
        options.smoothing,
        args.seed,
        options.range,
        1.0 / options.resolution,
        if args.range.is_none() || args.resolution.is_none() {
            " (sized by the robot's lever arms where not given)"
        } else {
            ""
        },
        options.domain_radius,
        args.max_iterations,
        args.max_seconds
            .map_or(String::new(), |s| format!(", {s} s at most")),
        match (args.vamp_obstacles, args.cloud) {
            (true, _) =>
                "; among VAMP's obstacles: cylinders as capsules, boxes in the box family".into(),
            (false, Some(n)) => format!(
                "; among point clouds: {n} points on each object's surface, thinned to {} m, points of {} m",
                trm_mbm::CLOUD_SPACING,
                trm_mbm::CLOUD_POINT_RADIUS
            ),
            (false, None) => String::new(),
        },
        if args.ignore_scene_matrices {
            "; the scenes' allowed-collision matrices ignored (the model's own only, as VAMP)"
        } else {
            ""
        }
    )
}

/// OMPL's RRTConnect on the same problems (its Python bindings, `limit` seconds each): its
/// report, printed.
fn run_ompl(args: &Args, set: &ProblemSet, limit: f64) -> Result<String> {
    let script = ompl_script();
    let python = std::env::var("TRM_PYTHON").unwrap_or_else(|_| "python3".into());
    let mut command = std::process::Command::new(python);
    command.arg(&script).arg(set.root()).args([
        "--time-limit",
        &limit.to_string(),
        "--seed",
        &args.seed.to_string(),
    ]);
    if let Some(n) = args.per_family {
        command.args(["--per-family", &n.to_string()]);
    }
    println!("\nrunning OMPL on the same problems");
    let output = command
        .stderr(std::process::Stdio::inherit())
        .output()
        .map_err(|e| anyhow::anyhow!("--ompl: starting {}: {e}", script.display()))?;
    anyhow::ensure!(
        output.status.success(),
        "--ompl: {} failed ({})\n  fix: python3 -m pip install ompl pin pyyaml numpy",
        script.display(),
        output.status
    );
    let text = format!("\n{}", String::from_utf8_lossy(&output.stdout));
    print!("{text}");
    Ok(text)
}

/// The set run as `args` say, with progress bars.
fn run_benchmark(
    args: &Args,
    robot: &trm_kinematics::RobotModel,
    collision: &trm_collision::CollisionModel,
    problems: &[trm_mbm::Problem],
    options: &RrtOptions,
) -> Result<trm_mbm::Benchmark> {
    let options = trm_mbm::BenchmarkOptions {
        rrt: options.clone(),
        verify: args.verify,
        task_space: args
            .task_space
            .as_ref()
            .map(|link| trm_mbm::TaskSpaceGoals {
                link: link.clone(),
                position_tolerance: args.position_tolerance,
                orientation_tolerance: args.orientation_tolerance,
            }),
        experience_passes: if args.experience { 2 } else { 0 },
        maps: args
            .maps
            .iter()
            .map(|p| Roadmap::load(p).with_context(|| format!("--map {}", p.display())))
            .collect::<Result<_>>()?,
        obstacles: match (args.vamp_obstacles, args.cloud) {
            (true, _) => trm_mbm::Obstacles::AsVamp,
            (false, Some(per_object)) => trm_mbm::Obstacles::Cloud { per_object },
            (false, None) => trm_mbm::Obstacles::AsGiven,
        },
        ignore_scene_matrices: args.ignore_scene_matrices,
    };
    let mut bar: Option<(String, crate::progress::Progress)> = None;
    let bench = match trm_mbm::benchmark(
        robot,
        collision,
        problems,
        &options,
        |stage, done, total, p| {
            if bar.as_ref().is_none_or(|(s, _)| s != stage) {
                if let Some((_, old)) = bar.take() {
                    old.finish();
                }
                bar = Some((
                    stage.to_string(),
                    crate::progress::Progress::new(stage, total as u64),
                ));
            }
            if let Some((_, b)) = &mut bar {
                b.set(done as u64, total as u64, &p.family);
            }
        },
    ) {
        Ok(bench) => bench,
        Err(e) => {
            // a map the requests' motors do not fit: named by its file
            if let trm_mbm::MbmError::Plan(p) = &e
                && let trm_plan::PlanError::IncompatibleMap { map, .. } = **p
            {
                anyhow::bail!("--map {}: {p}", args.maps[map].display());
            }
            return Err(e.into());
        }
    };
    if let Some((_, b)) = bar {
        b.finish();
    }
    Ok(bench)
}

/// The solved problems' planning times per family, sorted, as an SVG plot.
fn times_plot(runs: &[trm_mbm::Run]) -> Result<String> {
    let mut families: Vec<&str> = runs.iter().map(|r| r.family.as_str()).collect();
    families.dedup();
    let mut all_times = Vec::new();
    let mut series = Vec::new();
    for f in &families {
        let mut times: Vec<f64> = runs
            .iter()
            .filter(|r| r.family == *f && r.outcome.valid && r.outcome.solved)
            .map(|r| r.outcome.seconds * 1e3)
            .collect();
        times.sort_by(f64::total_cmp);
        series.push(crate::plot::Series {
            label: f.to_string(),
            points: times
                .iter()
                .enumerate()
                .map(|(i, t)| {
                    (
                        (i + 1) as f64 / times.len() as f64 * 100.0,
                        t.max(1e-3).log10(),
                    )
                })
                .collect(),
            color: None,
        });
        all_times.extend(times);
    }
    all_times.sort_by(f64::total_cmp);
    crate::plot::panels(
        (800, 420),
        &[crate::plot::Panel {
            title: "Planning time per solved problem, sorted".into(),
            axes: ("problems solved (%)".into(), "time (log10 ms)".into()),
            x: 0.0..100.0,
            y: (all_times.first().copied().unwrap_or(0.01).max(1e-3).log10() - 0.1)
                ..(all_times.last().copied().unwrap_or(1.0).max(1e-3).log10() + 0.1),
            series,
        }],
    )
}

/// How the clouds of `--cloud` were made: points drawn and kept, thinning and build times
/// (medians over the problems).
fn cloud_lines(bench: &trm_mbm::Benchmark) -> String {
    let builds: Vec<trm_mbm::CloudBuild> = bench.problems.iter().filter_map(|p| p.cloud).collect();
    let median = |f: &dyn Fn(&trm_mbm::CloudBuild) -> f64| {
        trm_mbm::quantile(&builds.iter().map(f).collect::<Vec<_>>(), 0.5).unwrap_or(0.0)
    };
    format!(
        "\nPoint clouds (medians over {} problems): {:.0} points drawn, {:.0} kept after thinning ({:.2} ms); trm's build (the world object with its exact grid, and the screen's grid): {:.3} ms\n",
        builds.len(),
        median(&|b| b.sampled as f64),
        median(&|b| b.kept as f64),
        1e3 * median(&|b| b.thin_seconds),
        1e3 * median(&|b| b.build_seconds),
    )
}

/// Medians of the build times and of planning plus build, on the problems both planners
/// solve (`--cloud` with `--vamp`).
fn with_build_line(ours: &[(&str, &Outcome)], theirs: &[(&str, &Outcome)]) -> String {
    let both: Vec<(&Outcome, &Outcome)> = ours
        .iter()
        .zip(theirs)
        .filter(|((_, a), (_, b))| a.solved && b.solved)
        .map(|((_, a), (_, b))| (*a, *b))
        .collect();
    let median = |f: &dyn Fn(&(&Outcome, &Outcome)) -> f64| {
        1e3 * trm_mbm::quantile(&both.iter().map(f).collect::<Vec<_>>(), 0.5).unwrap_or(0.0)
    };
    format!(
        "\nCloud build, median over the {} problems both solve: trm {:.3} ms, VAMP's CAPT {:.3} ms; planning + build: trm {:.3} ms, VAMP {:.3} ms\n",
        both.len(),
        median(&|(a, _)| a.build_seconds),
        median(&|(_, b)| b.build_seconds),
        median(&|(a, _)| a.seconds + a.build_seconds),
        median(&|(_, b)| b.seconds + b.build_seconds),
    )
}

/// The OMPL side of `--ompl`, in the repository the tool was built from.
fn ompl_script() -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../benches/python/mbm_ompl.py")
}

/// How to get VAMP's program.
const VAMP_FIX: &str = "fix: build it with benches/peers/vamp/build.sh VAMP_DIR PDQSORT_DIR (benches/peers/vamp/README.md)";

/// A peer's outcomes (family, outcome) in the set's order, the verdicts on its solved paths
/// (with `--verify`) and the problems as given to it.
type PeerRun = (Vec<(String, Outcome)>, Vec<Verdict>, String);

/// Runs VAMP's program on `problems` (exported with `trm_mbm::peer_problems`); its
/// outcomes in the order of `problems`, with `--verify` what certification proves about its
/// paths in trm's model, and the problems as given to it.
fn run_vamp(
    args: &Args,
    binary: &std::path::Path,
    robot: &trm_kinematics::RobotModel,
    set: &ProblemSet,
    bench: &trm_mbm::Benchmark,
) -> Result<PeerRun> {
    let problems: Vec<trm_mbm::Problem> =
        bench.problems.iter().map(|p| p.problem.clone()).collect();
    let problems = &problems[..];
    let vamp_robot = args.vamp_robot.as_deref().unwrap_or(robot.name());
    // with --cloud, the very points trm planned among
    let clouds: Vec<trm_collision::World> =
        bench.problems.iter().map(|p| p.world.clone()).collect();
    let clouds = args.cloud.map(|_| &clouds[..]);
    let input = trm_mbm::peer_problems(vamp_robot, problems, clouds)?;
    let exported = input.clone();
    println!(
        "\nrunning VAMP on {} problems of {}",
        problems.len(),
        set.root().display()
    );
    // the problems through a file, not a pipe: a harness that stops reading early (a robot it
    // does not have) must not end this process by SIGPIPE before its message is read
    let staged = std::env::temp_dir().join(format!("trm-vamp-input-{}.txt", std::process::id()));
    std::fs::write(&staged, &input)
        .map_err(|e| anyhow::anyhow!("--vamp: writing {}: {e}", staged.display()))?;
    let stdin = std::fs::File::open(&staged)
        .map_err(|e| anyhow::anyhow!("--vamp: reading {}: {e}", staged.display()));
    let output = stdin.and_then(|stdin| {
        std::process::Command::new(binary)
            .stdin(stdin)
            .output()
            .map_err(|e| {
                anyhow::anyhow!("--vamp: starting {}: {e}\n  {VAMP_FIX}", binary.display())
            })
    });
    let _ = std::fs::remove_file(&staged);
    let output = output?;
    anyhow::ensure!(
        output.status.success(),
        "--vamp: {} failed ({}): {}",
        binary.display(),
        output.status,
        String::from_utf8_lossy(&output.stderr).trim()
    );
    let results = trm_mbm::parse_peer_results(&String::from_utf8_lossy(&output.stdout))
        .map_err(|e| anyhow::anyhow!("--vamp: {}'s output, {e}", binary.display()))?;
    let (mut ordered, mut verdicts) = (Vec::new(), Vec::new());
    for (p, loaded) in problems.iter().zip(&bench.problems) {
        let found = results
            .iter()
            .find(|(f, i, _)| *f == p.family && *i == p.index)
            .ok_or_else(|| anyhow::anyhow!("--vamp: no result for {} {}", p.family, p.index))?;
        let outcome = found.2.clone();
        if args.verify && outcome.solved {
            verdicts.push(certify_path_loaded(robot, loaded, &outcome.path)?);
        }
        ordered.push((p.family.clone(), outcome));
    }
    Ok((ordered, verdicts, exported))
}

#[cfg(test)]
mod tests {
    /// `--ompl` finds its script (it moved once with the command and was lost).
    #[test]
    fn the_ompl_script_is_where_the_command_looks() {
        assert!(
            super::ompl_script().is_file(),
            "{}",
            super::ompl_script().display()
        );
    }
}
