//! The benchmarks from Python: Table III (`trm.compare_optimisers`) and MotionBenchMaker sets
//! (`trm.benchmark_mbm`), as the `trm` tool's commands of the same names run them.

use crate::*;

/// Table III of the TRM paper on the given task specs, as `trm compare-optimisers`: every
/// algorithm (`trm.ALGORITHMS` names; default xNES, SIR, SIRD, MH, simplex, CMA-ES,
/// (1+1)-CMA-ES) `runs` times from seeds `seed`, `seed + 1`, …, each with `max_evals`
/// evaluations and stopped after `no_improvement` without progress. Returns a dict: `table`
/// (markdown, the paper's columns), `csv` (every run), `runs` (a dict per run: problem,
/// algorithm, seed, cost, best_at, evaluations, collision_free, seconds, trace, motors) and
/// `wall_seconds`.
#[pyfunction]
#[pyo3(signature = (specs, algorithms = None, runs = 30, seed = 0, max_evals = 400_000, no_improvement = 30_000))]
pub(crate) fn compare_optimisers<'py>(
    py: Python<'py>,
    specs: Vec<String>,
    algorithms: Option<Vec<String>>,
    runs: u64,
    seed: u64,
    max_evals: u64,
    no_improvement: u64,
) -> PyResult<Bound<'py, PyDict>> {
    let defaults = trm_tasks::Comparison::default();
    let comparison = trm_tasks::Comparison {
        algorithms: algorithms.unwrap_or(defaults.algorithms),
        runs,
        seed,
        max_evaluations: max_evals,
        no_improvement,
    };
    comparison.check().map_err(err)?;
    let problems: Vec<trm_tasks::Problem> = specs
        .iter()
        .map(|s| trm_tasks::Problem::load_with(s, &trm_taskmap::loaders()).map_err(err))
        .collect::<PyResult<_>>()?;
    let pairs: Vec<(&str, &trm_tasks::Problem)> =
        specs.iter().map(String::as_str).zip(&problems).collect();
    let result = py.detach(|| comparison.run(&pairs)).map_err(err)?;
    let d = PyDict::new(py);
    d.set_item("table", result.to_markdown())?;
    d.set_item("csv", result.to_csv())?;
    d.set_item("runs", to_python(py, &result.runs)?)?;
    d.set_item("wall_seconds", result.wall_seconds)?;
    Ok(d)
}

/// A MotionBenchMaker set (a folder or `.tar.bz2` of MoveIt scenes and joint-goal requests)
/// solved by RRT-Connect + shortcutting with `model` (a `.urdf`, a `.ron` description or an
/// embedded model's name), as `trm benchmark-mbm`: `families` and `per_family` select
/// problems, `verify` proves each path free in continuous motion (its `verified`: `proved`,
/// `collides` or `unproved`), `certified` plans certified paths, `task_space` (a link)
/// poses each joint goal as the task-space goal it implies for that link (a cube of side
/// `position_tolerance`, `orientation_tolerance` about each axis), `sampler` is `uniform` or
/// `halton` (RRT-Connect's samples); with `maps` (`trm.Roadmap`s of the requests' group), each
/// problem is solved again with them attached. Returns a dict: `runs` (per problem: family,
/// index, outcome {valid, solved, seconds, length, waypoints, checks, note, path}, verified),
/// `with_maps` (the same, with the maps; empty without), `table` (markdown: solved %, median and
/// p95 time per family), `report` (`trm benchmark-mbm`'s tables) and `csv`.
#[pyfunction]
#[pyo3(signature = (path, model, families = Vec::new(), per_family = None, seed = 0, max_iterations = 1_000_000, verify = false, package_paths = Vec::new(), task_space = None, position_tolerance = 0.01, orientation_tolerance = 0.05, sampler = "uniform", maps = Vec::new(), certified = false))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn benchmark_mbm<'py>(
    py: Python<'py>,
    path: &str,
    model: &str,
    families: Vec<String>,
    per_family: Option<usize>,
    seed: u64,
    max_iterations: usize,
    verify: bool,
    package_paths: Vec<std::path::PathBuf>,
    task_space: Option<String>,
    position_tolerance: f64,
    orientation_tolerance: f64,
    sampler: &str,
    maps: Vec<PyRef<'py, Roadmap>>,
    certified: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let sampler: trm_plan::rrt::Sampler = sampler.parse().map_err(err)?;
    let task_space = task_space.map(|link| trm_mbm::TaskSpaceGoals {
        link,
        position_tolerance,
        orientation_tolerance,
    });
    let robot = trm_models::load(model, std::path::Path::new("")).map_err(err)?;
    let collision = CollisionModel::with_package_paths(&robot, package_paths).map_err(err)?;
    let mut set = trm_mbm::ProblemSet::open(std::path::Path::new(path)).map_err(err)?;
    set.select(&families, per_family).map_err(err)?;
    let sized = trm_mbm::rrt_options_for(&robot, &collision, &set.problems).map_err(err)?;
    let rrt = trm_plan::rrt::RrtOptions {
        seed,
        max_iterations,
        sampler,
        certified,
        ..sized
    };
    let options = trm_mbm::BenchmarkOptions {
        rrt,
        verify,
        task_space,
        experience_passes: 0,
        maps: maps.iter().map(|m| m.map.clone()).collect(),
        ..Default::default()
    };
    let bench = py
        .detach(|| trm_mbm::benchmark(&robot, &collision, &set.problems, &options, |_, _, _, _| {}))
        .map_err(err)?;
    let d = PyDict::new(py);
    d.set_item(
        "table",
        trm_mbm::markdown_table(bench.runs.iter().map(|r| (r.family.as_str(), &r.outcome))),
    )?;
    d.set_item("csv", trm_mbm::runs_csv(&bench.runs))?;
    d.set_item("runs", to_python(py, &bench.runs)?)?;
    d.set_item("with_maps", to_python(py, &bench.with_maps)?)?;
    d.set_item("report", bench.markdown())?;
    Ok(d)
}
