//! `trm.Planner`: planning through maps in a world.

use crate::*;

/// A planner over one or several maps of the same robot and active motors, checked against a
/// world.
#[pyclass(module = "trm")]
pub(crate) struct Planner {
    pub(crate) maps: Vec<trm_roadmap::Roadmap>,
    pub(crate) problem: trm_tasks::Problem,
    pub(crate) world: Option<World>,
}

/// Runs a scenario (RON: objects that move, appear and vanish, goals that change; see
/// specs/scenarios/) on `roadmap`, as `trm scenario`: each step invalidates what the world
/// blocks, repairs within a budget (`repair_evaluations` cost evaluations, reproducible; else
/// `repair_ms` milliseconds) and replans. Returns a dict: `steps` (a dict per step: t,
/// blocked, restored, added, seconds, action, goal, goal_error, hit, nodes, edges, parked
/// nodes and edges), `times` `(T,)` and `positions` `(T, motors)`, the robot's motion.
#[pyfunction]
#[pyo3(signature = (scenario, roadmap, repair_evaluations = None, repair_ms = 40.0))]
pub(crate) fn run_scenario<'py>(
    py: Python<'py>,
    scenario: &str,
    roadmap: &Roadmap,
    repair_evaluations: Option<u64>,
    repair_ms: f64,
) -> PyResult<Bound<'py, PyDict>> {
    if !(repair_ms.is_finite() && repair_ms > 0.0) {
        return Err(err(format!(
            "repair_ms {repair_ms}: give a finite number of milliseconds above 0"
        )));
    }
    let spec = trm_plan::Scenario::load(scenario).map_err(err)?;
    let problem = roadmap
        .map
        .problem_with(&trm_taskmap::loaders())
        .map_err(err)?;
    let options = trm_plan::ScenarioOptions {
        repair_seconds: repair_evaluations.is_none().then_some(repair_ms / 1e3),
        repair_evaluations,
        ..Default::default()
    };
    let run = py
        .detach(|| trm_plan::run_scenario(&roadmap.map, &problem, &spec, &options))
        .map_err(err)?;
    let d = PyDict::new(py);
    d.set_item("steps", to_python(py, &run.steps)?)?;
    let times = run.motion.times.clone();
    let motors = run.motion.positions.first().map_or(0, Vec::len);
    let positions: Vec<f64> = run.motion.positions.concat();
    d.set_item("times", shaped(py, None, &[times.len()], times)?)?;
    d.set_item(
        "positions",
        shaped(py, None, &[run.motion.positions.len(), motors], positions)?,
    )?;
    Ok(d)
}

#[pymethods]
impl Planner {
    /// A planner over `maps` (a Roadmap or a list of them), in `world` (none: the maps' own).
    #[new]
    #[pyo3(signature = (maps, world = None))]
    fn new(maps: &Bound<'_, PyAny>, world: Option<&PyWorld>) -> PyResult<Self> {
        let maps: Vec<trm_roadmap::Roadmap> = match maps.extract::<PyRef<'_, Roadmap>>() {
            Ok(m) => vec![m.map.clone()],
            Err(_) => maps
                .extract::<Vec<PyRef<'_, Roadmap>>>()?
                .iter()
                .map(|m| m.map.clone())
                .collect(),
        };
        let first = maps.first().ok_or_else(|| err("give at least one map"))?;
        let problem = first.problem_with(&trm_taskmap::loaders()).map_err(err)?;
        Ok(Planner {
            problem,
            maps,
            world: world.map(|w| w.world.clone()),
        })
    }

    /// Plans from `start` (active values; the spec's start when absent) to a task point `to`
    /// (a map node within `tolerance`, then, with `exact`, NGIK to the point itself) or, with
    /// `posture=True`, to a posture (active values). Returns a dict: `times (T,)`,
    /// `positions (T, motors)`, `motor_names`, `task_path`, `length` (rad), `seconds`.
    #[pyo3(signature = (to, start = None, tolerance = 0.03, posture = false, exact = true, seed = 0))]
    #[allow(clippy::too_many_arguments)]
    fn plan<'py>(
        &self,
        py: Python<'py>,
        to: &Bound<'py, PyAny>,
        start: Option<&Bound<'py, PyAny>>,
        tolerance: f64,
        posture: bool,
        exact: bool,
        seed: u64,
    ) -> PyResult<Bound<'py, PyDict>> {
        let o = &self.problem.objective;
        let from = match start {
            Some(s) => configurations(s, o.dim(), "start")?.0,
            None => self.problem.start.clone(),
        };
        let target = float_array(to)?.as_slice().map_err(err)?.to_vec();
        let goal = if posture {
            trm_plan::Goal::Configuration(target)
        } else {
            trm_plan::Goal::TaskPoint {
                t: target,
                tolerance,
            }
        };
        let options = trm_plan::PlanOptions {
            seed,
            exact_goal: exact,
            ..Default::default()
        };
        let planned = py
            .detach(|| -> Result<trm_plan::Planned, String> {
                let refs: Vec<&trm_roadmap::Roadmap> = self.maps.iter().collect();
                let mut planner = trm_plan::Planner::new(o, &refs).map_err(|e| e.to_string())?;
                if let Some(w) = &self.world {
                    planner.set_world(w.clone());
                }
                planner
                    .plan(&from, &goal, &options)
                    .map_err(|e| e.to_string())
            })
            .map_err(err)?;
        let t = &planned.trajectory;
        let d = PyDict::new(py);
        d.set_item(
            "times",
            shaped(py, None, &[t.times.len()], t.times.clone())?,
        )?;
        let motors = t.names.len();
        let flat: Vec<f64> = t.positions.iter().flatten().copied().collect();
        d.set_item(
            "positions",
            shaped(py, None, &[t.positions.len(), motors], flat)?,
        )?;
        d.set_item("motor_names", t.names.clone())?;
        let dim = t.task_path.first().map_or(0, Vec::len);
        let tasks: Vec<f64> = t.task_path.iter().flatten().copied().collect();
        d.set_item(
            "task_path",
            shaped(py, None, &[t.task_path.len(), dim], tasks)?,
        )?;
        d.set_item("length", planned.stats.length)?;
        d.set_item("seconds", planned.stats.seconds)?;
        Ok(d)
    }
}
