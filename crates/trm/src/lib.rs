//! `trm <command>`: the commands people run with trm (`trm --help` lists them; `cargo xtask
//! <command>` forwards here). Each command parses its flags, calls the libraries and prints.
//!
//! The library side serves front ends built on the same conventions (the repository's xtask):
//! [`run_staged`] puts output files in place only when a command succeeds, [`parse`] holds the
//! flag parsers, [`plot`] the SVG charts and [`progress`] the progress bars.

mod benchmark_mbm;
mod build_map;
mod collide;
mod compare;
mod distributed;
mod explore_task_map;
mod fit_proxies;
mod fk;
mod gen_acm;
mod gen_mbm;
mod model_info;
mod optimise;
mod plan;
pub mod plot;
pub mod progress;
mod reach_grasp;
mod repair_map;
mod scenario;
mod solve;
mod stand_up;
mod support;
mod view;

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use clap::{Parser, Subcommand};
use trm_kinematics::RobotModel;

#[derive(Parser)]
#[command(
    name = "trm",
    about = "trm: task-relevant roadmaps for high-DOF robots",
    version
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Print a model's joints, motors with limits, couplings, links, frames, groups and postures.
    ModelInfo(model_info::Args),
    /// Forward kinematics of joint configurations read from JSON (world poses of every link).
    Fk(fk::Args),
    /// Build a task-relevant roadmap from a spec (parallel E-TRM) and save it.
    BuildMap(build_map::Args),
    /// Summarise a map file: points, edges, components, extent, spacing, cost, build statistics.
    MapInfo(build_map::InfoArgs),
    /// Explore the task map of feasible grasps of an object (RRT with restarts).
    ExploreTaskMap(explore_task_map::Args),
    /// Table III: xNES against SIR, SIRD, MH, Nelder-Mead (and CMA-ES, (1+1)-CMA-ES) on two postures.
    CompareOptimisers(compare::Args),
    /// Colliding pairs and minimum self-distance of joint configurations read from JSON.
    Collide(collide::Args),
    /// Generate a model's allowed-collision matrix (the description's `disabled_collisions`).
    GenAcm(gen_acm::Args),
    /// A MotionBenchMaker-like set for a spec's robot: seeded table, shelf and cage scenes with
    /// reaching goals (NGIK), written as MoveIt scenes and requests.
    GenMbm(gen_mbm::Args),
    /// Run an optimiser on a test function several times: evaluations to target and a summary.
    Optimise(optimise::Args),
    /// Repair a map for a world that changed: remove what it blocks, re-grow, reconnect.
    RepairMap(repair_map::Args),
    /// A map in a moving world: objects move, appear and vanish, goals change; each step
    /// invalidates, repairs within a budget and replans (specs/scenarios/).
    Scenario(scenario::Args),
    /// Fit a sphere, capsule or box around each link's collision meshes; optionally write the URDF with them.
    FitProxies(fit_proxies::Args),
    /// Plan a motion through one or several maps in the current world (lazy A*).
    Plan(plan::Args),
    /// A MotionBenchMaker set (MoveIt scenes and joint-goal requests) solved by RRT-Connect:
    /// solved %, median and p95 time per family.
    BenchmarkMbm(benchmark_mbm::Args),
    /// A reaching motion to grasp an object, optimised with its task map (or an exact target).
    ReachGrasp(reach_grasp::Args),
    /// Solve a posture (NGIK) from a task spec: cost, breakdown, collision check, posture file.
    Solve(solve::Args),
    /// Safe trajectory optimisation of a whole-body motion spec; by default the iCub stands up
    /// from a chair (Table II, Fig. 3, Fig. 4).
    #[command(alias = "whole-body")]
    StandUp(stand_up::Args),
    /// A 3-D view (JSON scene + self-contained three.js page) of a robot, world, map and motion.
    View(view::Args),
}

impl Command {
    /// The files and directories the command writes to, checked before it starts work.
    fn outputs(&self) -> (Vec<PathBuf>, Vec<PathBuf>) {
        let file = |p: &Option<PathBuf>| p.iter().cloned().collect::<Vec<_>>();
        // an output file and the files written beside it (same stem, these extensions)
        let beside = |p: &Option<PathBuf>, extensions: &[&str]| {
            p.iter()
                .flat_map(|p| {
                    std::iter::once(p.clone()).chain(extensions.iter().map(|e| p.with_extension(e)))
                })
                .collect::<Vec<_>>()
        };
        match self {
            Command::BuildMap(a) => (
                std::iter::once(a.out_path())
                    .chain(a.checkpoint_path())
                    .collect(),
                vec![],
            ),
            Command::ExploreTaskMap(a) => (vec![a.out_path()], vec![]),
            Command::Collide(a) => (file(&a.out), vec![]),
            Command::Fk(a) => (file(&a.out), vec![]),
            Command::GenAcm(a) => (
                file(&a.out)
                    .into_iter()
                    .chain(file(&a.write_description))
                    .collect(),
                vec![],
            ),
            Command::Plan(a) => (beside(&a.out, &["json", "ros.yaml", "svg"]), vec![]),
            Command::ReachGrasp(a) => (beside(&a.out, &["json", "ros.yaml"]), vec![]),
            Command::Solve(a) => (file(&a.out), vec![]),
            Command::View(a) => (vec![a.out.clone()], vec![]),
            Command::CompareOptimisers(a) => (vec![], vec![a.out_dir.clone()]),
            Command::RepairMap(a) => (vec![a.out_path()], vec![]),
            Command::Scenario(a) => (vec![], vec![a.out_dir.clone()]),
            Command::BenchmarkMbm(a) => (vec![], vec![a.out_dir.clone()]),
            Command::GenMbm(a) => (vec![], vec![a.out.clone()]),
            Command::FitProxies(a) => (file(&a.out), vec![]),
            Command::StandUp(a) => (
                beside(&Some(a.out.join("trajectory.csv")), &["ros.yaml"]),
                vec![a.out.clone()],
            ),
            Command::ModelInfo(a) => (
                file(&a.ros_postures)
                    .into_iter()
                    .chain(file(&a.write_srdf))
                    .chain(file(&a.write_description))
                    .collect(),
                vec![],
            ),
            Command::MapInfo(_) | Command::Optimise(_) => (vec![], vec![]),
        }
    }
}

/// Checks the output locations a command will write (`files`, and `dirs` it fills), runs
/// `work` with every file it writes through [`write_atomic`] staged, and puts them in place
/// only when it succeeds: a failed run writes nothing.
pub fn run_staged(
    files: &[PathBuf],
    dirs: &[PathBuf],
    work: impl FnOnce() -> Result<()>,
) -> Result<()> {
    for f in files {
        trm_io::check_output(f).with_context(|| format!("output {}", f.display()))?;
    }
    for d in dirs {
        if d.exists() && !d.is_dir() {
            anyhow::bail!(
                "output directory {} is not a directory\n  fix: remove it or choose another directory",
                d.display()
            );
        }
        if !d.exists() {
            trm_io::check_output(d).with_context(|| format!("output directory {}", d.display()))?;
        }
    }
    *staged() = Some(Vec::new());
    let result = work();
    let files = staged().take().unwrap_or_default();
    result?;
    for f in files {
        let path = f.path().to_path_buf();
        f.commit()
            .with_context(|| format!("putting {} in place", path.display()))?;
    }
    Ok(())
}

/// Output files written by this run but not yet in place (`None`: write directly, as tests
/// calling a command's `run` do).
fn staged() -> std::sync::MutexGuard<'static, Option<Vec<trm_io::StagedFile>>> {
    static STAGED: std::sync::Mutex<Option<Vec<trm_io::StagedFile>>> = std::sync::Mutex::new(None);
    STAGED.lock().unwrap_or_else(|e| e.into_inner())
}

/// `trm map-info M | head` ends quietly when `head` closes the pipe, as command-line tools do,
/// instead of panicking in `println!`: SIGPIPE back to its default disposition (Rust programs
/// start with it ignored). Call it first in `main`, before any other thread exists.
#[allow(unsafe_code)]
pub fn quiet_on_closed_pipes() {
    #[cfg(unix)]
    // SAFETY: `signal` with a valid signal number and the default handler, called before any
    // other thread exists; nothing else in the program handles SIGPIPE.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
}

/// Parses a command line (the first argument is the program's name) into `C`, exiting with
/// clap's message on bad flags. Negative numbers are values: `--seed -1` is refused by the
/// flag's own check, naming the flag, not taken for an unknown option.
pub fn parse_args<C, I, T>(args: I) -> C
where
    C: clap::Parser,
    I: IntoIterator<Item = T>,
    T: Into<std::ffi::OsString> + Clone,
{
    parse_with(C::command(), args)
}

/// [`parse_args`] with the command built by the caller (an extra help text, say).
pub fn parse_with<C, I, T>(command: clap::Command, args: I) -> C
where
    C: clap::FromArgMatches,
    I: IntoIterator<Item = T>,
    T: Into<std::ffi::OsString> + Clone,
{
    let command = command.mut_subcommands(|sub| {
        sub.mut_args(|arg| {
            if arg.get_action().takes_values() {
                arg.allow_negative_numbers(true)
            } else {
                arg
            }
        })
    });
    command
        .try_get_matches_from(args)
        .and_then(|m| C::from_arg_matches(&m))
        .unwrap_or_else(|e| e.exit())
}

/// The tool's commands, one line each (`  name  what it does`), as `trm --help` lists them.
pub fn command_list() -> String {
    use clap::CommandFactory;
    let command = Cli::command();
    let width = command
        .get_subcommands()
        .map(|c| c.get_name().len())
        .max()
        .unwrap_or(0);
    command
        .get_subcommands()
        .map(|c| {
            let about = c.get_about().map(|a| a.to_string()).unwrap_or_default();
            let first = about.lines().next().unwrap_or_default().to_string();
            format!("  {:width$}  {first}\n", c.get_name())
        })
        .collect()
}

/// Ends the process: status 0 when `result` is `Ok`, else 1 after printing the error and its
/// causes on stderr.
pub fn exit_with(result: Result<()>) -> ! {
    if let Err(e) = result {
        eprintln!("error: {}", message(&e));
        std::process::exit(1);
    }
    std::process::exit(0)
}

/// Runs `trm` on a command line (the first argument is the program's name) and ends the
/// process with its status.
pub fn main_from<I, T>(args: I) -> !
where
    I: IntoIterator<Item = T>,
    T: Into<std::ffi::OsString> + Clone,
{
    let cli: Cli = parse_args(args);
    let (files, dirs) = cli.command.outputs();
    exit_with(run_staged(&files, &dirs, || dispatch(cli.command)))
}

/// The error and its causes, each cause once (a message that already quotes its cause is not
/// followed by it again).
fn message(e: &anyhow::Error) -> String {
    let mut text = e.to_string();
    for cause in e.chain().skip(1) {
        let cause = cause.to_string();
        if !text.contains(&cause) {
            text = format!("{text}: {cause}");
        }
    }
    text
}

/// Runs the command.
fn dispatch(command: Command) -> Result<()> {
    match command {
        Command::ModelInfo(args) => model_info::run(&args),
        Command::Fk(args) => fk::run(&args),
        Command::BuildMap(args) => build_map::run(&args),
        Command::MapInfo(args) => build_map::info(&args),
        Command::Collide(args) => collide::run(&args),
        Command::CompareOptimisers(args) => compare::run(&args),
        Command::ExploreTaskMap(args) => explore_task_map::run(&args),
        Command::GenAcm(args) => gen_acm::run(&args),
        Command::GenMbm(args) => gen_mbm::run(&args),
        Command::Optimise(args) => optimise::run(&args),
        Command::Plan(args) => plan::run(&args),
        Command::ReachGrasp(args) => reach_grasp::run(&args),
        Command::Solve(args) => solve::run(&args),
        Command::RepairMap(args) => repair_map::run(&args),
        Command::Scenario(args) => scenario::run(&args),
        Command::BenchmarkMbm(args) => benchmark_mbm::run(&args),
        Command::FitProxies(args) => fit_proxies::run(&args),
        Command::StandUp(args) => stand_up::run(&args),
        Command::View(args) => view::run(&args),
    }
}

/// The repository's models/ directory (the commands' defaults name files in the repository).
fn models_dir() -> PathBuf {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../models");
    dir.canonicalize().unwrap_or(dir)
}

/// Loads `path` (a .urdf or .ron model description, or an embedded model's name), or the
/// embedded iCub upper body when absent.
fn load_model(path: Option<&Path>) -> Result<RobotModel> {
    match path {
        None => Ok(trm_models::icub_upper_body()),
        Some(p) => Ok(trm_models::load(&p.to_string_lossy(), Path::new(""))?),
    }
}

/// A trajectory `--out` must not end in `.json`: the CSV goes there and the JSON beside it, at
/// the same name with `.json`.
fn check_csv_out(out: Option<&Path>) -> Result<()> {
    if let Some(out) = out {
        trm_moveit::check_trajectory_out("--out", out)?;
    }
    Ok(())
}

/// `out`, or `<dir>/<spec's stem>.<extension>`.
fn default_out(out: &Option<PathBuf>, spec: &Path, dir: &str, extension: &str) -> PathBuf {
    out.clone().unwrap_or_else(|| {
        let stem = spec
            .file_stem()
            .map_or("out".into(), |s| s.to_string_lossy().to_string());
        Path::new(dir).join(format!("{stem}.{extension}"))
    })
}

/// Where mesh files are looked for.
#[derive(clap::Args, Default)]
pub struct MeshArgs {
    /// A directory searched for `package://NAME/...` meshes (repeatable); the directories of
    /// ROS_PACKAGE_PATH are searched after these.
    #[arg(long = "package-path", value_name = "DIR", value_parser = parse::directory)]
    package_paths: Vec<PathBuf>,
}

impl MeshArgs {
    /// The model's collision model, meshes found through the package paths.
    fn collision_model(&self, model: &RobotModel) -> Result<trm_collision::CollisionModel> {
        let paths = self.package_paths.clone();
        Ok(trm_collision::CollisionModel::with_package_paths(
            model, paths,
        )?)
    }
}

/// Value parsers for flags: out-of-range values are refused by clap with the flag's name.
pub mod parse {
    /// A count in `min..=max`.
    pub fn count(min: u64, max: usize) -> clap::builder::RangedU64ValueParser<usize> {
        clap::builder::RangedU64ValueParser::new().range(min..=max as u64)
    }

    fn number(text: &str) -> Result<f64, String> {
        text.trim()
            .parse::<f64>()
            .map_err(|_| format!("`{text}` is not a number"))
    }

    /// A finite number.
    pub fn finite(text: &str) -> Result<f64, String> {
        number(text).and_then(|v| {
            if v.is_finite() {
                Ok(v)
            } else {
                Err(format!("{v} is not finite"))
            }
        })
    }

    /// A finite number above 0.
    pub fn positive(text: &str) -> Result<f64, String> {
        finite(text).and_then(|v| {
            if v > 0.0 {
                Ok(v)
            } else {
                Err(format!("{v} is not above 0"))
            }
        })
    }

    /// An existing directory.
    pub fn directory(text: &str) -> Result<std::path::PathBuf, String> {
        let path = std::path::PathBuf::from(text);
        match std::fs::metadata(&path) {
            Ok(m) if m.is_dir() => Ok(path),
            Ok(_) => Err(format!("`{text}` is a file, not a directory")),
            Err(e) => Err(format!("`{text}`: {e} (give a directory that exists)")),
        }
    }

    /// A scaling factor: a number in (0, 1].
    pub fn factor(text: &str) -> Result<f64, String> {
        finite(text).and_then(|v| {
            if v > 0.0 && v <= 1.0 {
                Ok(v)
            } else {
                Err(format!("{v} is not in (0, 1]"))
            }
        })
    }

    /// A finite number, 0 or more.
    pub fn non_negative(text: &str) -> Result<f64, String> {
        finite(text).and_then(|v| {
            if v >= 0.0 {
                Ok(v)
            } else {
                Err(format!("{v} is below 0"))
            }
        })
    }

    /// A number in [0, 1].
    pub fn fraction(text: &str) -> Result<f64, String> {
        finite(text).and_then(|v| {
            if (0.0..=1.0).contains(&v) {
                Ok(v)
            } else {
                Err(format!("{v} is not in [0, 1]"))
            }
        })
    }
}

/// Comma-separated numbers given to a flag (`--to 0.1,0.2,0.3`); `expected` says what fits.
fn numbers(flag: &str, text: &str, expected: &str) -> Result<Vec<f64>> {
    text.split(',')
        .map(|s| s.trim().parse::<f64>().ok().filter(|v| v.is_finite()))
        .collect::<Option<_>>()
        .with_context(|| format!("{flag} `{text}`: expected {expected} (finite numbers)"))
}

/// A thread pool for `--threads`: all cores when absent; 0 is an error; more threads than
/// cores are capped to the cores (more only slow the build down) with a note.
pub fn thread_pool(threads: Option<usize>) -> Result<rayon::ThreadPool> {
    Ok(rayon::ThreadPoolBuilder::new()
        .num_threads(thread_count(threads)?)
        .build()?)
}

/// The thread count of a `--threads` flag: all cores when absent, capped to the cores.
pub fn thread_count(threads: Option<usize>) -> Result<usize> {
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    Ok(match threads {
        None => cores,
        Some(0) => {
            anyhow::bail!("--threads 0: give at least 1 (or leave it out for all {cores} cores)")
        }
        Some(t) if t > cores => {
            eprintln!(
                "note: --threads {t} capped to the {cores} cores of this machine (more only slow the work down)"
            );
            cores
        }
        Some(t) => t,
    })
}

/// A fresh scratch directory for a test, named after it and this process.
#[cfg(test)]
fn test_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("trm-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Writes `value` as pretty JSON to `path` (atomically) and says so on stderr.
pub fn write_json(path: &Path, value: &serde_json::Value) -> Result<()> {
    write_atomic(path, serde_json::to_string_pretty(value)?.as_bytes())?;
    eprintln!("wrote {}", path.display());
    Ok(())
}

/// Writes `bytes` to `path` atomically (temporary file + rename), naming the file on error.
/// Inside [`run_staged`] the file is staged and put in place when the work succeeds.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    let context = || format!("writing {}", path.display());
    match staged().as_mut() {
        Some(files) => {
            let file = trm_io::StagedFile::new(path, bytes).with_context(context)?;
            files.retain(|f| f.path() != path);
            files.push(file);
            Ok(())
        }
        None => trm_io::write_atomic(path, bytes).with_context(context),
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn flags_refuse_non_finite_numbers_and_zero_threads_and_cap_absurd_ones() {
        for bad in ["nan,0,0", "1,inf,0", "1,,2", "x"] {
            let e = super::numbers("--to", bad, "\"x,y,z\"").unwrap_err();
            assert!(e.to_string().contains("finite numbers"), "{e}");
        }
        assert_eq!(
            super::numbers("--to", "1, 2,-3e-1", "\"x,y,z\"").unwrap(),
            [1.0, 2.0, -0.3]
        );
        assert!(super::thread_pool(Some(0)).is_err());
        let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
        let pool = super::thread_pool(Some(100_000)).unwrap();
        assert_eq!(pool.current_num_threads(), cores);
    }
}
