//! Bringing a robot: proxies fitted to its meshes (`trm.fit_proxies`), its allowed-collision
//! matrix (`CollisionModel.generate_acm`) and a MotionBenchMaker-like set for it
//! (`trm.generate_mbm`), as the `trm` tool's `fit-proxies`, `gen-acm` and `gen-mbm` do.

use crate::*;

/// Fits a sphere, capsule or box around each link's collision meshes of a URDF (meshes found
/// through `package_paths` and ROS_PACKAGE_PATH), as `trm fit-proxies`: the smallest of the
/// three, every vertex enclosed. With `out`, writes the URDF with the meshes replaced by the
/// proxies. Returns one dict per fitted link: link, primitive, volume and hull volume (m³),
/// pose `(4, 4)` in the link frame, worst_outside (m; ≤ 0: every vertex enclosed).
#[pyfunction]
#[pyo3(signature = (urdf, package_paths = Vec::new(), out = None))]
pub(crate) fn fit_proxies<'py>(
    py: Python<'py>,
    urdf: &str,
    package_paths: Vec<std::path::PathBuf>,
    out: Option<String>,
) -> PyResult<Bound<'py, PyList>> {
    let model = RobotModel::load(urdf).map_err(err)?;
    let collision = CollisionModel::with_package_paths(&model, package_paths).map_err(err)?;
    let fits = py
        .detach(|| trm_collision::fit::fit_model(&collision))
        .map_err(err)?;
    if let Some(out) = out {
        let text = trm_io::read_input(std::path::Path::new(urdf))
            .map_err(|e| err(format!("{urdf}: {e}")))?;
        let written = trm_collision::fit::urdf_with_proxies(&text, urdf, &fits).map_err(err)?;
        trm_io::write_atomic(std::path::Path::new(&out), written.as_bytes())
            .map_err(|e| err(format!("writing {out}: {e}")))?;
    }
    let list = PyList::empty(py);
    for f in &fits {
        let d = PyDict::new(py);
        d.set_item("link", &f.link)?;
        d.set_item("primitive", f.fitted.shape.kind())?;
        d.set_item("volume", f.fitted.volume)?;
        d.set_item("hull_volume", f.hull)?;
        let mut pose = Vec::with_capacity(16);
        matrix(&f.fitted.pose, &mut pose);
        d.set_item("pose", shaped(py, None, &[4, 4], pose)?)?;
        d.set_item("worst_outside", f.worst)?;
        list.append(d)?;
    }
    Ok(list)
}

/// A MotionBenchMaker-like problem set for a task spec's robot, as `trm gen-mbm`: seeded
/// table, shelf and cage scenes in front of it with reaching goals solved by NGIK, written to
/// `out` as MoveIt scenes and requests (`family/sceneNNNN.yaml`, `requestNNNN.yaml`), which
/// `trm.benchmark_mbm` reads. `center` places the scenes (default: in front of the task's
/// reach), `facing` is the horizontal direction the robot faces. Returns the number of
/// problems written.
#[pyfunction]
#[pyo3(signature = (spec, out, families = None, per_family = 20, seed = 0, center = None, facing = (1.0, 0.0), tolerance = 0.02, tries = 30))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn generate_mbm(
    py: Python<'_>,
    spec: &str,
    out: &str,
    families: Option<Vec<String>>,
    per_family: usize,
    seed: u64,
    center: Option<[f64; 3]>,
    facing: (f64, f64),
    tolerance: f64,
    tries: usize,
) -> PyResult<usize> {
    let problem = trm_tasks::Problem::load_with(spec, &trm_taskmap::loaders()).map_err(err)?;
    let defaults = trm_mbm::generate::SetOptions::default();
    let options = trm_mbm::generate::SetOptions {
        families: families.unwrap_or(defaults.families),
        per_family,
        seed,
        center,
        facing: [facing.0, facing.1],
        tolerance,
        tries,
    };
    let set = py
        .detach(|| trm_mbm::generate::generate(&problem, &options, |_, _| {}))
        .map_err(err)?;
    trm_mbm::generate::write_set(std::path::Path::new(out), &set).map_err(err)?;
    Ok(set.len())
}
