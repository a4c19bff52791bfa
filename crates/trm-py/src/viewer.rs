//! `trm.view`: 3-D pages of robots, worlds and motions.

use crate::*;

/// Writes a self-contained 3-D page of `robot` (the same viewer as `cargo xtask view`): one
/// frame per posture in `frames` (`(n,)` or `(T, n)` motor values; the home posture, else
/// neutral, when absent) at `times` (default 0.05 s apart), `world`'s objects, and a task-space
/// `path` `(K, 3)` drawn as a line, and a `roadmap`'s points, edges and postures (as `trm view
/// --map` draws them). `out` gets the page and `out` with `.json` the scene; the
/// page loads three.js from a CDN unless `bundle` names a built viewer (viewer/dist/viewer.js)
/// to inline. The robot is drawn as it looks (its URDF visual meshes, found as its collision
/// meshes are: beside the URDF, in `package_paths`, in ROS_PACKAGE_PATH), or by its collision
/// shapes when a visual cannot be loaded. Returns the page's path.
#[pyfunction]
#[pyo3(signature = (robot, out, frames = None, times = None, world = None, path = None, title = "trm", bundle = None, roadmap = None, package_paths = Vec::new()))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn view(
    robot: &Robot,
    out: std::path::PathBuf,
    frames: Option<&Bound<'_, PyAny>>,
    times: Option<Vec<f64>>,
    world: Option<&PyWorld>,
    path: Option<&Bound<'_, PyAny>>,
    title: &str,
    bundle: Option<std::path::PathBuf>,
    roadmap: Option<&Roadmap>,
    package_paths: Vec<std::path::PathBuf>,
) -> PyResult<std::path::PathBuf> {
    let n = robot.model.motors().len();
    let postures = match frames {
        Some(f) => configurations(f, n, "frames")?.0,
        None => robot.model.home_motors(),
    };
    let count = postures.len() / n.max(1);
    let times = times.unwrap_or_else(|| (0..count).map(|k| k as f64 * 0.05).collect());
    if times.len() != count {
        return Err(err(format!(
            "times: {} values for {count} frames",
            times.len()
        )));
    }
    let collision = CollisionModel::with_package_paths(&robot.model, package_paths).map_err(err)?;
    let mut scene = trm_view::Scene::new(title, &collision);
    if let Some(w) = world {
        scene.set_world(&w.world);
    }
    for (t, q) in times.iter().zip(postures.chunks(n.max(1))) {
        scene.add_frame(*t, q).map_err(err)?;
    }
    if let Some(p) = path {
        let a = float_array(p)?;
        if a.ndim() != 2 || a.shape()[1] != 3 {
            return Err(err(format!("path: shape {:?}; expected (K, 3)", a.shape())));
        }
        let v = a.as_slice().map_err(err)?;
        scene.set_path(v.chunks(3).map(|c| [c[0], c[1], c[2]]).collect());
    }
    if let Some(r) = roadmap {
        let problem = r.map.problem_with(&trm_taskmap::loaders()).map_err(err)?;
        scene
            .add_roadmap(&r.map, problem.objective.active())
            .map_err(err)?;
    }
    let code = match &bundle {
        Some(b) => {
            Some(std::fs::read_to_string(b).map_err(|e| err(format!("{}: {e}", b.display())))?)
        }
        None => None,
    };
    trm_io::write_files(&scene.page_files(&out, code.as_deref()).map_err(err)?).map_err(err)?;
    Ok(out)
}
