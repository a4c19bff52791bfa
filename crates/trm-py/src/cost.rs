//! Costs written in Python, evaluated inside NGIK: one call per batch of candidates, the GIL
//! taken for that call only.

use std::sync::{Arc, Mutex};

use numpy::ndarray::{ArrayD, IxDyn};
use numpy::{IntoPyArray, PyUntypedArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use trm_kinematics::FrameId;
use trm_tasks::{BatchContext, Context, Cost};

/// A cost term whose values come from a Python callable `f(q, frames) -> (N,)`: `q` the
/// candidates' active values `(N, d)`, `frames` a dict of the named frames' world poses
/// `(N, 4, 4)`. The first error it raises (or a wrong shape, or a value that is not a finite
/// number ≥ 0) is kept, named with the term's label, and raised when the call that evaluated it
/// returns; meanwhile its candidates cost NaN, which the optimisers count as invalid.
#[derive(Debug)]
pub struct PythonCost {
    /// The callable.
    pub function: Py<PyAny>,
    /// The term's label (breakdowns, errors).
    pub label: String,
    /// The frames handed to the callable.
    pub frames: Vec<(String, FrameId)>,
    /// The first error, shared with the `Problem` that owns the term.
    pub error: Arc<Mutex<Option<String>>>,
}

impl PythonCost {
    /// Calls the function on `rows` candidates (`q` row by row, `poses[f]` the 16 values of
    /// frame `f` per row) and writes their costs to `out`.
    fn call(&self, rows: usize, q: Vec<f64>, poses: Vec<Vec<f64>>, out: &mut [f64]) {
        out[..rows].fill(f64::NAN);
        if self.failed() {
            return;
        }
        let d = q.len() / rows.max(1);
        let outcome = Python::attach(|py| -> PyResult<Result<Vec<f64>, String>> {
            let q = ArrayD::from_shape_vec(IxDyn(&[rows, d]), q)
                .map_err(|e| crate::err(e.to_string()))?
                .into_pyarray(py);
            let frames = PyDict::new(py);
            for ((name, _), values) in self.frames.iter().zip(poses) {
                let a = ArrayD::from_shape_vec(IxDyn(&[rows, 4, 4]), values)
                    .map_err(|e| crate::err(e.to_string()))?;
                frames.set_item(name, a.into_pyarray(py))?;
            }
            let value = match self.function.bind(py).call1((q, frames)) {
                Ok(v) => v,
                Err(e) => return Ok(Err(raised(py, &e))),
            };
            let Ok(a) = crate::float_array(&value) else {
                return Ok(Err(format!(
                    "returned {}; expected ({rows},) numbers",
                    value.get_type().name()?
                )));
            };
            let shape = a.shape().to_vec();
            if shape != [rows] && !(rows == 1 && shape.is_empty()) {
                return Ok(Err(format!(
                    "returned shape {shape:?}; expected ({rows},): one cost per row of q"
                )));
            }
            Ok(Ok(a.as_slice()?.to_vec()))
        });
        match outcome {
            Ok(Ok(values)) => match values.iter().find(|v| !(v.is_finite() && **v >= 0.0)) {
                Some(bad) => self.fail(format!("returned {bad}; costs are finite numbers ≥ 0")),
                None => out[..rows].copy_from_slice(&values),
            },
            Ok(Err(problem)) => self.fail(problem),
            Err(e) => self.fail(format!("could not be called: {e}")),
        }
    }

    fn failed(&self) -> bool {
        self.error.lock().map_or(true, |e| e.is_some())
    }

    fn fail(&self, problem: String) {
        if let Ok(mut slot) = self.error.lock()
            && slot.is_none()
        {
            *slot = Some(format!("Python cost `{}` {problem}", self.label));
        }
    }

    fn row_poses(&self, poses: &trm_kinematics::PoseBuffer, out: &mut [Vec<f64>]) {
        for ((_, frame), values) in self.frames.iter().zip(out) {
            crate::matrix(poses.pose(*frame), values);
        }
    }
}

/// `raised ZeroDivisionError: division by zero (File "x.py", line 3, in f)`: the exception and
/// where in the Python code it was raised.
fn raised(py: Python<'_>, e: &PyErr) -> String {
    let kind = e
        .get_type(py)
        .name()
        .map(|n| n.to_string())
        .unwrap_or_default();
    let place = e
        .traceback(py)
        .and_then(|t| t.format().ok())
        .and_then(|t| {
            t.lines()
                .rev()
                .find(|l| l.trim_start().starts_with("File "))
                .map(|l| format!(" ({})", l.trim()))
        })
        .unwrap_or_default();
    format!("raised {kind}: {}{place}", e.value(py))
}

impl Cost for PythonCost {
    fn label(&self) -> String {
        self.label.clone()
    }

    fn eval(&self, ctx: &Context) -> f64 {
        let mut poses = vec![Vec::new(); self.frames.len()];
        self.row_poses(ctx.poses, &mut poses);
        let mut out = [0.0];
        self.call(1, ctx.q.to_vec(), poses, &mut out);
        out[0]
    }

    fn eval_batch(&self, ctx: &BatchContext, out: &mut [f64]) {
        let rows = ctx.len();
        let q: Vec<f64> = ctx.q[..rows]
            .iter()
            .flat_map(|r| r.iter().copied())
            .collect();
        let mut poses = vec![Vec::new(); self.frames.len()];
        if !self.frames.is_empty() {
            for l in 0..rows {
                self.row_poses(ctx.lane(l).poses, &mut poses);
            }
        }
        self.call(rows, q, poses, out);
    }

    fn batched(&self) -> bool {
        self.frames.is_empty()
    }
}
