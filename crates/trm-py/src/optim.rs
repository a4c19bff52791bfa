//! `trm.Optimizer` and `trm.minimize_constrained`: the ask/tell optimisers.

use crate::*;

/// An ask/tell optimiser of trm-optim (xnes, cmaes, one-plus-one-cmaes, sir, sird, mh,
/// nelder-mead, …), seeded: `X = opt.ask()` gives `(λ, d)` candidates, `opt.tell(f)` their
/// values in order.
#[pyclass(module = "trm")]
pub(crate) struct Optimizer {
    /// The optimiser and its random stream (a mutex: Python objects may move between threads).
    pub(crate) inner: std::sync::Mutex<(Box<dyn trm_optim::Optimizer + Send>, ChaCha8Rng)>,
}

impl Optimizer {
    fn with<T>(&self, f: impl FnOnce(&mut dyn trm_optim::Optimizer, &mut ChaCha8Rng) -> T) -> T {
        let mut guard = self
            .inner
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner);
        let (o, rng) = &mut *guard;
        f(o.as_mut(), rng)
    }
}

#[pymethods]
impl Optimizer {
    /// `algo` at `x0` with step `sigma`; `popsize` overrides the default population, `bounds`
    /// a `(lower, upper)` box.
    #[new]
    #[pyo3(signature = (algo, x0, sigma, seed = 0, popsize = None, max_evals = None))]
    fn new(
        algo: &str,
        x0: &Bound<'_, PyAny>,
        sigma: f64,
        seed: u64,
        popsize: Option<usize>,
        max_evals: Option<u64>,
    ) -> PyResult<Self> {
        let x = float_array(x0)?;
        let mean = x.as_slice().map_err(err)?.to_vec();
        let mut start = trm_optim::Start::new(mean, sigma);
        start.stop.max_evaluations = max_evals.or(start.stop.max_evaluations);
        let inner = trm_optim::by_name(algo, &start, popsize).map_err(err)?;
        Ok(Optimizer {
            inner: std::sync::Mutex::new((inner, ChaCha8Rng::seed_from_u64(seed))),
        })
    }

    /// The next candidates, `(λ, d)`.
    fn ask<'py>(&self, py: Python<'py>) -> PyResult<Array<'py>> {
        let (rows, d, flat) = self.with(|o, rng| {
            let d = o.dim();
            let xs = o.ask(rng);
            (xs.len(), d, xs.as_slice().to_vec())
        });
        shaped(py, None, &[rows, d], flat)
    }

    /// The values of the last `ask`'s candidates, in order: numbers, or `inf` for a candidate
    /// that could not be evaluated (it ranks last); NaN and `-inf` are refused.
    fn tell(&self, values: &Bound<'_, PyAny>) -> PyResult<()> {
        let f = float_array(values)?;
        let f = f.as_slice().map_err(err)?;
        if let Some(i) = f.iter().position(|v| v.is_nan() || *v == f64::NEG_INFINITY) {
            return Err(err(format!(
                "values[{i}] is {}: give every candidate a number (inf for one that cannot be evaluated)",
                f[i]
            )));
        }
        self.with(|o, _| o.tell(f)).map_err(err)
    }

    /// Whether a stopping rule holds.
    #[getter]
    fn done(&self) -> bool {
        self.with(|o, _| !o.stop().is_empty())
    }

    /// The stopping rules that hold, as text.
    #[getter]
    fn stop_reasons(&self) -> Vec<String> {
        self.with(|o, _| o.stop().iter().map(|r| format!("{r:?}")).collect())
    }

    /// The best point so far.
    #[getter]
    fn best_x<'py>(&self, py: Python<'py>) -> PyResult<Array<'py>> {
        let b = self.with(|o, _| o.state().best_x().to_vec());
        shaped(py, None, &[b.len()], b)
    }

    /// The best value so far.
    #[getter]
    fn best_f(&self) -> f64 {
        self.with(|o, _| o.state().best_f())
    }

    /// Evaluations told so far.
    #[getter]
    fn evaluations(&self) -> u64 {
        self.with(|o, _| o.state().evaluations())
    }

    /// The distribution's centre.
    #[getter]
    fn mean<'py>(&self, py: Python<'py>) -> PyResult<Array<'py>> {
        let m = self.with(|o, _| o.mean().to_vec());
        shaped(py, None, &[m.len()], m)
    }
}

/// Minimises `fun(x) -> float` subject to `constraints(x) -> (m,)` values (feasible where
/// every value ≤ 0) with the (1+1)-CMA-ES with constrained covariance adaptation (Arnold and
/// Hansen 2012), bootstrapped from an infeasible start by minimising the total violation first
/// (`bootstrap_budget` evaluations at most; `None`: `max_evals` covers both). `fun` is only
/// called at feasible points. Returns a dict: `x`, `f`, `evaluations`, `feasible`,
/// `bootstrap_evaluations`.
#[pyfunction]
#[pyo3(signature = (fun, constraints, x0, sigma, seed = 0, max_evals = 10_000, bootstrap_budget = None))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn minimize_constrained<'py>(
    py: Python<'py>,
    fun: &Bound<'py, PyAny>,
    constraints: &Bound<'py, PyAny>,
    x0: &Bound<'py, PyAny>,
    sigma: f64,
    seed: u64,
    max_evals: u64,
    bootstrap_budget: Option<u64>,
) -> PyResult<Bound<'py, PyDict>> {
    let mean = float_array(x0)?.as_slice().map_err(err)?.to_vec();
    let to_array = |x: &[f64]| shaped(py, None, &[x.len()], x.to_vec());
    // the number of constraints, from one call at the start
    let m = float_array(&constraints.call1((to_array(&mean)?,))?)?.len();
    let mut start = trm_optim::Start::new(mean, sigma);
    start.stop.max_evaluations = Some(max_evals);
    let mut failure: Option<PyErr> = None;
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let report = {
        let failure = std::cell::RefCell::new(&mut failure);
        let record = |e: PyErr| {
            let mut f = failure.borrow_mut();
            if f.is_none() {
                **f = Some(e);
            }
        };
        trm_optim::minimize_constrained(
            &start,
            bootstrap_budget,
            m,
            &mut rng,
            |x| {
                let value = to_array(x)
                    .and_then(|a| fun.call1((a,)))
                    .and_then(|v| v.extract::<f64>());
                value.unwrap_or_else(|e| {
                    record(e);
                    f64::NAN
                })
            },
            |x, g| {
                let values = to_array(x)
                    .and_then(|a| constraints.call1((a,)))
                    .and_then(|v| {
                        float_array(&v).and_then(|a| Ok(a.as_slice().map_err(err)?.to_vec()))
                    });
                match values {
                    Ok(v) if v.len() == g.len() => g.copy_from_slice(&v),
                    Ok(v) => {
                        record(err(format!(
                            "constraints returned {} values, {} at the start",
                            v.len(),
                            g.len()
                        )));
                        g.fill(f64::NAN);
                    }
                    Err(e) => {
                        record(e);
                        g.fill(f64::NAN);
                    }
                }
            },
        )
        .map_err(err)?
    };
    if let Some(e) = failure {
        return Err(e);
    }
    let d = PyDict::new(py);
    d.set_item("x", to_array(&report.report.best_x)?)?;
    d.set_item("f", report.report.best_f)?;
    d.set_item("evaluations", report.report.evaluations)?;
    d.set_item("feasible", report.feasible)?;
    d.set_item("bootstrap_evaluations", report.bootstrap_evaluations)?;
    Ok(d)
}
