//! Whole-body motions from Python: `trm.stand_up`.

use crate::*;

/// Safe trajectory optimisation of a whole-body motion spec (e.g.
/// `specs/wholebody/standup.ron`: the iCub stands up from a chair), as `trm stand-up`:
/// bootstrap, then the constrained (1+1)-CMA-ES; `rollouts` and `bootstrap_rollouts` replace
/// the spec's budgets. Returns the result as a dict (rollouts, feasible, the hand-tuned and
/// optimised solutions with their metrics, parameters and rollouts).
#[pyfunction]
#[pyo3(signature = (spec, seed = 0, rollouts = None, bootstrap_rollouts = None))]
pub(crate) fn stand_up(
    py: Python<'_>,
    spec: &str,
    seed: u64,
    rollouts: Option<u64>,
    bootstrap_rollouts: Option<u64>,
) -> PyResult<Py<PyAny>> {
    let problem = trm_wholebody::WholeBody::load_with_budgets(spec, rollouts, bootstrap_rollouts)
        .map_err(err)?;
    let result = py
        .detach(|| trm_wholebody::optimize(&problem, seed, |_, _| {}))
        .map_err(err)?;
    to_python(py, &result)
}
