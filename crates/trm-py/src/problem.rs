//! `trm.Problem`: task specs, their objective and NGIK.

use crate::*;

/// A task spec loaded with its robot: the objective (costs, task function, collision), the
/// active motors and the start.
#[pyclass(module = "trm")]
pub(crate) struct Problem {
    pub(crate) problem: trm_tasks::Problem,
    /// The error slots of the costs added from Python.
    pub(crate) python_costs: Vec<std::sync::Arc<std::sync::Mutex<Option<String>>>>,
}

impl Problem {
    /// The first error a Python cost raised since the last call, as a `TrmError` (the slots
    /// are cleared for the next call).
    fn python_cost_error(&self) -> PyResult<()> {
        for slot in &self.python_costs {
            if let Some(e) = slot.lock().ok().and_then(|mut s| s.take()) {
                return Err(err(e));
            }
        }
        Ok(())
    }
}

#[pymethods]
impl Problem {
    /// Loads a RON spec (e.g. `specs/reach.ron`).
    #[staticmethod]
    fn load(path: &str) -> PyResult<Self> {
        Ok(Problem {
            problem: trm_tasks::Problem::load_with(path, &trm_taskmap::loaders()).map_err(err)?,
            python_costs: Vec::new(),
        })
    }

    /// Adds a cost written in Python: `weight · function(q, frames)`, where `q` is a batch of
    /// candidates' active values `(N, d)` and `frames` a dict of the named frames' world poses
    /// `(N, 4, 4)`; it returns `(N,)` finite costs ≥ 0. NGIK calls it once per batch of
    /// candidates, taking the GIL for that call only. An exception, a wrong shape or a bad value
    /// is raised as a `TrmError` naming the cost when `solve` or `cost` returns.
    #[pyo3(signature = (function, weight = 1.0, label = None, frames = Vec::new()))]
    fn add_cost(
        &mut self,
        function: Py<PyAny>,
        weight: f64,
        label: Option<String>,
        frames: Vec<String>,
    ) -> PyResult<()> {
        let label = label.unwrap_or_else(|| format!("python cost {}", self.python_costs.len()));
        let frames = frames
            .into_iter()
            .map(|name| {
                let id = self
                    .problem
                    .robot
                    .frame_id(&name)
                    .map_err(|e| err(format!("add_cost `{label}`: frames: {e}")))?;
                Ok((name, id))
            })
            .collect::<PyResult<Vec<_>>>()?;
        let error = std::sync::Arc::new(std::sync::Mutex::new(None));
        let term = cost::PythonCost {
            function,
            label,
            frames,
            error: error.clone(),
        };
        self.problem
            .objective
            .add(weight, Box::new(term))
            .map_err(err)?;
        self.python_costs.push(error);
        Ok(())
    }

    /// Names of the active motors (the columns of `q`).
    #[getter]
    fn active_names(&self) -> Vec<String> {
        self.problem
            .objective
            .active()
            .names()
            .map(str::to_string)
            .collect()
    }

    /// The start (active values), `(d,)`.
    #[getter]
    fn start<'py>(&self, py: Python<'py>) -> PyResult<Array<'py>> {
        let s = self.problem.start.clone();
        shaped(py, None, &[s.len()], s)
    }

    /// The robot.
    #[getter]
    fn robot(&self) -> Robot {
        Robot {
            model: self.problem.robot.clone(),
        }
    }

    /// The cost of active values: a float, or `(N,)` for a batch.
    fn cost<'py>(&self, py: Python<'py>, q: &Bound<'py, PyAny>) -> PyResult<Py<PyAny>> {
        let o = &self.problem.objective;
        let (values, batch) = configurations(q, o.dim(), "q")?;
        let mut scratch = o.scratch();
        let costs: Vec<f64> = values
            .chunks(o.dim().max(1))
            .map(|row| o.eval(row, &mut scratch))
            .collect();
        self.python_cost_error()?;
        numbers(py, batch, costs)
    }

    /// Active motor limits `(lower (d,), upper (d,))`.
    #[getter]
    fn bounds<'py>(&self, py: Python<'py>) -> PyResult<(Array<'py>, Array<'py>)> {
        let (l, u) = self.problem.objective.active().bounds();
        Ok((
            shaped(py, None, &[l.len()], l)?,
            shaped(py, None, &[u.len()], u)?,
        ))
    }

    /// Free of self-collisions and of collisions with `world` (the spec's when absent): a
    /// bool, or a bool list for a batch. This is the state-validity check of planners.
    #[pyo3(signature = (q, world = None))]
    fn is_collision_free<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        world: Option<&PyWorld>,
    ) -> PyResult<Py<PyAny>> {
        let o = &self.problem.objective;
        let w = world.map_or(o.world(), |w| &w.world);
        let (values, batch) = configurations(q, o.dim(), "q")?;
        let mut scratch = o.scratch();
        let free: Vec<bool> = values
            .chunks(o.dim().max(1))
            .map(|row| o.is_collision_free_in(row, w, &mut scratch))
            .collect();
        flags(py, batch, free)
    }

    /// Clearance of active values: the smallest signed distance between checked body pairs and
    /// between bodies and `world`'s objects (the spec's world when absent), as `trm solve`
    /// reports it (`Objective::clearance_in`); values above `cap` metres are given as `cap`.
    #[pyo3(signature = (q, world = None, cap = 0.5))]
    fn clearance(&self, q: &Bound<'_, PyAny>, world: Option<&PyWorld>, cap: f64) -> PyResult<f64> {
        if cap.is_nan() || cap <= 0.0 {
            return Err(err(format!(
                "cap: {cap} m; give a positive distance (inf for no cap)"
            )));
        }
        let o = &self.problem.objective;
        let w = world.map_or(o.world(), |w| &w.world);
        let (values, batch) = configurations(q, o.dim(), "q")?;
        if batch.is_some() {
            return Err(err("clearance takes one configuration (d,)"));
        }
        let clearance = o.clearance_in(&values, w, &mut o.scratch());
        Ok(clearance.distance().min(cap))
    }

    /// The task vector g(q) of active values (empty without a task function).
    fn task<'py>(&self, py: Python<'py>, q: &Bound<'py, PyAny>) -> PyResult<Array<'py>> {
        let o = &self.problem.objective;
        let (values, batch) = configurations(q, o.dim(), "q")?;
        if batch.is_some() {
            return Err(err("task takes one configuration (d,)"));
        }
        let t = o.task_value(&values, &mut o.scratch());
        shaped(py, None, &[t.len()], t)
    }

    /// NGIK from the start (or `start`): a dict with `q` (active), `motors` (all), `cost`,
    /// `breakdown` [(label, weight, value)], `task`, `collision_free`, `evaluations`,
    /// `seconds`. `algo`, `seed` and `max_evals` override the spec's solver.
    #[pyo3(signature = (start = None, algo = None, seed = None, max_evals = None))]
    fn solve<'py>(
        &self,
        py: Python<'py>,
        start: Option<&Bound<'py, PyAny>>,
        algo: Option<String>,
        seed: Option<u64>,
        max_evals: Option<u64>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let o = &self.problem.objective;
        let from = match start {
            Some(s) => configurations(s, o.dim(), "start")?.0,
            None => self.problem.start.clone(),
        };
        let solver = (self.problem.spec.solver)
            .overridden(algo.as_deref(), seed, max_evals)
            .map_err(err)?;
        let s = py.detach(|| trm_tasks::solve(o, &from, &solver));
        self.python_cost_error()?;
        let s = s.map_err(err)?;
        let d = PyDict::new(py);
        d.set_item("q", shaped(py, None, &[s.q.len()], s.q.clone())?)?;
        d.set_item(
            "motors",
            shaped(py, None, &[s.motors.len()], s.motors.clone())?,
        )?;
        d.set_item("cost", s.cost)?;
        let breakdown: Vec<(String, f64, f64)> = s
            .breakdown
            .iter()
            .map(|t| (t.label.clone(), t.weight, t.value))
            .collect();
        d.set_item("breakdown", breakdown)?;
        d.set_item("task", shaped(py, None, &[s.task.len()], s.task.clone())?)?;
        d.set_item("collision_free", s.collision_free)?;
        d.set_item("evaluations", s.evaluations)?;
        d.set_item("seconds", s.wall_time.as_secs_f64())?;
        Ok(d)
    }
}
