//! `trm.TaskMap`: maps of feasible grasps (Gienger et al.), explored and queried.

use crate::*;

/// A task map: the feasible grasps of an object, each a 6-D grasp `g` (the hand's position and
/// rotation vector in the object's frame) with its value, in clusters.
#[pyclass(module = "trm")]
pub(crate) struct TaskMap {
    pub(crate) map: trm_taskmap::TaskMap,
}

#[pymethods]
impl TaskMap {
    /// Explores the task map of a task-map spec (RON; RRT with restarts from a first grasp,
    /// given or found by search), as `trm explore-task-map`.
    #[staticmethod]
    fn explore(py: Python<'_>, spec: &str) -> PyResult<Self> {
        let loaded = trm_taskmap::TaskMapSpec::load(spec).map_err(err)?;
        let explored = py.detach(|| loaded.explore()).map_err(err)?;
        Ok(TaskMap { map: explored.map })
    }

    /// Loads a task-map file.
    #[staticmethod]
    fn load(path: &str) -> PyResult<Self> {
        Ok(TaskMap {
            map: trm_taskmap::TaskMap::load(path).map_err(err)?,
        })
    }

    /// Saves the map (atomically).
    fn save(&self, path: &str) -> PyResult<()> {
        self.map.save(path).map_err(err)
    }

    /// The grasps, `(N, 6)`: position (m) and rotation vector (rad) in the object's frame.
    #[getter]
    fn points<'py>(&self, py: Python<'py>) -> PyResult<Array<'py>> {
        let data: Vec<f64> = self.map.points.iter().flat_map(|p| p.g).collect();
        shaped(py, None, &[self.map.points.len(), 6], data)
    }

    /// The grasps' values, `(N,)`.
    #[getter]
    fn values<'py>(&self, py: Python<'py>) -> PyResult<Array<'py>> {
        let data: Vec<f64> = self.map.points.iter().map(|p| p.value).collect();
        shaped(py, None, &[data.len()], data)
    }

    /// Number of clusters (disjoint regions of feasible grasps).
    #[getter]
    fn clusters(&self) -> usize {
        self.map.clusters()
    }

    /// The task-map cost of a grasp `g` `(6,)`, (g − g_map)ᵀ W (g − g_map) to the map's nearest
    /// grasp, and its gradient with respect to `g` (the paper's eq. 18–19): `(cost, (6,))`.
    fn cost<'py>(&self, py: Python<'py>, g: &Bound<'py, PyAny>) -> PyResult<(f64, Array<'py>)> {
        let (values, batch) = configurations(g, 6, "g")?;
        if batch.is_some() || self.map.points.is_empty() {
            return Err(err("cost takes one grasp (6,) and a map with points"));
        }
        let g: [f64; 6] = values.try_into().map_err(|_| err("g: expected 6 values"))?;
        let (cost, gradient) = self.map.cost(&g);
        Ok((cost, shaped(py, None, &[6], gradient.to_vec())?))
    }

    fn __len__(&self) -> usize {
        self.map.points.len()
    }
}

/// The reaching motion of Gienger et al. (Section III), as `trm reach-grasp`: explores the
/// task map of `spec`, places its object at `at` (`(x, y, z)` or `(x, y, z, yaw)`) in `world`
/// (none: empty) and optimises the iCub's torso and right arm from home toward the whole map
/// (or, with `exact`, its centre grasp) for `iterations` iRprop− steps. Returns a dict: cost,
/// limits, min_distance, collisions, length, end_speed, end, final_pose `(6,)` (the hand in the
/// object's frame) and trajectory `(T, motors)`.
#[pyfunction]
#[pyo3(signature = (spec, at, world = None, exact = false, iterations = 30))]
pub(crate) fn reach_grasp<'py>(
    py: Python<'py>,
    spec: &str,
    at: Vec<f64>,
    world: Option<&PyWorld>,
    exact: bool,
    iterations: usize,
) -> PyResult<Bound<'py, PyDict>> {
    let place = trm_taskmap::placement(&at).map_err(err)?;
    let loaded = trm_taskmap::TaskMapSpec::load(spec).map_err(err)?;
    let explored = py.detach(|| loaded.explore()).map_err(err)?;
    let empty = World::new();
    let world = world.map_or(&empty, |w| &w.world);
    let reach = py
        .detach(|| explored.reach(world, place, exact, iterations))
        .map_err(err)?;
    let m = &reach.motion;
    let d = PyDict::new(py);
    for (key, value) in [
        ("cost", m.cost),
        ("limits", m.limits),
        ("min_distance", m.min_distance),
        ("length", m.length),
        ("end_speed", m.end_speed),
        ("end", m.end),
    ] {
        d.set_item(key, value)?;
    }
    d.set_item("collisions", m.collisions)?;
    d.set_item("final_pose", shaped(py, None, &[6], m.final_pose.to_vec())?)?;
    let motors = reach.motor_trajectory();
    let width = motors.first().map_or(0, Vec::len);
    d.set_item(
        "trajectory",
        shaped(py, None, &[motors.len(), width], motors.concat())?,
    )?;
    Ok(d)
}
