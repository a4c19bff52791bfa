//! Python bindings of trm (the `trm` package; this is its extension module `trm._trm`).
//!
//! NumPy arrays in and out, batch-first: a configuration is an `(n,)` array, a batch an
//! `(N, n)` one, and results gain the leading `N` axis. Long calls release the GIL; errors
//! become `trm.TrmError` (a `ValueError`) carrying trm's located messages.

mod benchmark;
mod collision;
mod cost;
mod models;
mod optim;
mod plan;
mod problem;
mod roadmap;
mod robot;
mod taskmap;
mod viewer;
mod wholebody;

pub(crate) use collision::{Collision, PyWorld};
pub(crate) use optim::{Optimizer, minimize_constrained};
pub(crate) use plan::{MotionPlanRequest, Planner, run_scenario};
pub(crate) use problem::Problem;
pub(crate) use roadmap::Roadmap;
pub(crate) use robot::Robot;
pub(crate) use taskmap::TaskMap;
pub(crate) use viewer::view;

use numpy::ndarray::{ArrayD, IxDyn};
use numpy::{IntoPyArray, PyArrayDyn, PyArrayMethods, PyReadonlyArrayDyn, PyUntypedArrayMethods};
use pyo3::create_exception;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use trm_collision::{CollisionModel, Shape, World};
use trm_kinematics::nalgebra::{Isometry3, Matrix3xX, Matrix6xX, Translation3, UnitQuaternion};
use trm_kinematics::{ActiveSet, RobotModel};

create_exception!(
    _trm,
    TrmError,
    PyValueError,
    "An error from trm: the message names the file, the place and the fix."
);

/// A serialisable value as Python data (dicts, lists, numbers, strings), through JSON.
fn to_python<T: serde::Serialize>(py: Python<'_>, value: &T) -> PyResult<Py<PyAny>> {
    let text = serde_json::to_string(value).map_err(err)?;
    Ok(py.import("json")?.call_method1("loads", (text,))?.unbind())
}

/// Any trm error as a `TrmError` with its full message.
fn err(e: impl std::fmt::Display) -> PyErr {
    TrmError::new_err(e.to_string())
}

/// `obj` as a C-contiguous float64 array (lists and other sequences are converted; complex
/// values are refused).
fn float_array<'py>(obj: &Bound<'py, PyAny>) -> PyResult<PyReadonlyArrayDyn<'py, f64>> {
    // the common case without a call into Python: already a contiguous float64 array
    if let Ok(a) = obj.extract::<PyReadonlyArrayDyn<'py, f64>>()
        && a.is_c_contiguous()
    {
        return Ok(a);
    }
    let np = obj.py().import("numpy")?;
    // numpy would drop an imaginary part with only a warning
    if np.call_method1("iscomplexobj", (obj,))?.is_truthy()? {
        return Err(err(
            "complex values: give real numbers (take .real if the imaginary parts are 0)",
        ));
    }
    let a = np
        .call_method1("ascontiguousarray", (obj, "float64"))
        .map_err(|e| err(format!("expected numbers: {e}")))?;
    a.extract::<PyReadonlyArrayDyn<'py, f64>>()
        .map_err(|e| err(format!("expected a float array: {e}")))
}

/// A configuration `(n,)` or a batch `(N, n)`: the values, row by row, and `Some(N)` for a batch.
fn configurations(
    obj: &Bound<'_, PyAny>,
    n: usize,
    what: &str,
) -> PyResult<(Vec<f64>, Option<usize>)> {
    let a = float_array(obj)?;
    let shape = a.shape().to_vec();
    let batch = match shape.as_slice() {
        [m] if *m == n => None,
        [rows, m] if *m == n => Some(*rows),
        _ => {
            return Err(err(format!(
                "{what}: shape {shape:?}; expected ({n},) or (N, {n}) ({n} values per configuration)"
            )));
        }
    };
    let values = a.as_slice().map_err(err)?.to_vec();
    if let Some(i) = values.iter().position(|v| !v.is_finite()) {
        return Err(err(format!(
            "{what}: value #{i} is {}; give finite numbers",
            values[i]
        )));
    }
    Ok((values, batch))
}

/// A float64 NumPy array of any shape.
type Array<'py> = Bound<'py, PyArrayDyn<f64>>;

/// A flat array shaped `shape`, with the batch axis in front when there is one.
fn shaped<'py>(
    py: Python<'py>,
    batch: Option<usize>,
    shape: &[usize],
    data: Vec<f64>,
) -> PyResult<Array<'py>> {
    let full: Vec<usize> = batch.into_iter().chain(shape.iter().copied()).collect();
    Ok(ArrayD::from_shape_vec(IxDyn(&full), data)
        .map_err(err)?
        .into_pyarray(py))
}

/// The result of the one configuration (a model without motors has none).
fn first<T: Copy>(values: &[T]) -> PyResult<T> {
    values
        .first()
        .copied()
        .ok_or_else(|| err("no configuration: the model has no motors"))
}

/// One number per configuration: the number itself for one configuration, an `(N,)` array for
/// a batch.
fn numbers(py: Python<'_>, batch: Option<usize>, values: Vec<f64>) -> PyResult<Py<PyAny>> {
    Ok(match batch {
        None => first(&values)?.into_pyobject(py)?.into_any().unbind(),
        Some(_) => shaped(py, batch, &[], values)?.into_any().unbind(),
    })
}

/// One flag per configuration: a bool for one configuration, a list of bools for a batch.
fn flags(py: Python<'_>, batch: Option<usize>, values: Vec<bool>) -> PyResult<Py<PyAny>> {
    Ok(match batch {
        None => first(&values)?
            .into_pyobject(py)?
            .to_owned()
            .into_any()
            .unbind(),
        Some(_) => PyList::new(py, values)?.into_any().unbind(),
    })
}

/// 4 × 4 homogeneous matrix, row-major, into `out` (16 values).
fn write_matrix(pose: &Isometry3<f64>, out: &mut [f64]) {
    let r = pose.rotation.to_rotation_matrix();
    let t = &pose.translation.vector;
    for i in 0..3 {
        out[4 * i..4 * i + 3].copy_from_slice(&[r[(i, 0)], r[(i, 1)], r[(i, 2)]]);
        out[4 * i + 3] = t[i];
    }
    out[12..].copy_from_slice(&[0.0, 0.0, 0.0, 1.0]);
}

/// 4 × 4 homogeneous matrix, row-major, appended to `out`.
fn matrix(pose: &Isometry3<f64>, out: &mut Vec<f64>) {
    let start = out.len();
    out.resize(start + 16, 0.0);
    write_matrix(pose, &mut out[start..]);
}

/// A pose from a position and URDF roll-pitch-yaw.
fn pose(xyz: [f64; 3], rpy: [f64; 3]) -> Isometry3<f64> {
    Isometry3::from_parts(
        Translation3::new(xyz[0], xyz[1], xyz[2]),
        UnitQuaternion::from_euler_angles(rpy[0], rpy[1], rpy[2]),
    )
}

/// The extension module.
#[pymodule]
fn _trm(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("TrmError", m.py().get_type::<TrmError>())?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add("ALGORITHMS", trm_optim::ALGORITHMS.to_vec())?;
    m.add_class::<Robot>()?;
    m.add_class::<PyWorld>()?;
    m.add_class::<Collision>()?;
    m.add_class::<Problem>()?;
    m.add_class::<Optimizer>()?;
    m.add_class::<Roadmap>()?;
    m.add_class::<Planner>()?;
    m.add_class::<MotionPlanRequest>()?;
    m.add_function(wrap_pyfunction!(view, m)?)?;
    m.add_function(wrap_pyfunction!(minimize_constrained, m)?)?;
    m.add_class::<TaskMap>()?;
    m.add_function(wrap_pyfunction!(run_scenario, m)?)?;
    m.add_function(wrap_pyfunction!(benchmark::compare_optimisers, m)?)?;
    m.add_function(wrap_pyfunction!(benchmark::benchmark_mbm, m)?)?;
    m.add_function(wrap_pyfunction!(wholebody::stand_up, m)?)?;
    m.add_function(wrap_pyfunction!(taskmap::reach_grasp, m)?)?;
    m.add_function(wrap_pyfunction!(models::fit_proxies, m)?)?;
    m.add_function(wrap_pyfunction!(models::generate_mbm, m)?)?;
    Ok(())
}
