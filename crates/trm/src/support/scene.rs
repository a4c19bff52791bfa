//! Viewer pages the commands write, and the postures they show.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use trm_kinematics::{ActiveSet, RobotModel};
use trm_plan::ScenarioRun;
use trm_tasks::Problem;
use trm_view::Scene;

/// Motor values from a posture file: "motors": {name: value} over `start`, or "q": [active
/// values] when `active` is known.
pub fn posture_motors(
    path: &Path,
    robot: &RobotModel,
    active: Option<&ActiveSet>,
    start: &[f64],
) -> Result<Vec<f64>> {
    Ok(trm_kinematics::PostureFile::load(path)?.to_motors(robot, active, start, path)?)
}

/// Where a command's `--view` page goes: beside `out`, named `<stem>.scene.html`.
pub fn scene_path(out: &Path) -> PathBuf {
    let stem = out
        .file_stem()
        .map_or("scene".into(), |s| s.to_string_lossy().to_string());
    out.with_file_name(format!("{stem}.scene.html"))
}

/// Writes `out` (.html) and the scene beside it (.json); the page inlines the viewer bundle when
/// `viewer/dist/viewer.js` exists, else it loads three.js from a CDN.
pub fn write_scene(scene: &Scene, out: &Path) -> Result<()> {
    if let Some(dir) = out.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    }
    let repo = crate::models_dir().join("..");
    let bundle = trm_view::find_bundle(&repo)?;
    for (path, text) in scene.page_files(out, bundle.as_deref())? {
        crate::write_atomic(&path, text.as_bytes())?;
    }
    let how = if bundle.is_some() {
        "three.js inlined, works offline".to_string()
    } else {
        format!(
            "loads three.js {} from a CDN; `npm ci && npm run build` in viewer/ makes it offline",
            trm_view::THREE_VERSION
        )
    };
    if let Some(first) = scene.missing_visuals.first() {
        eprintln!(
            "note: {} of the robot's visuals not loaded, so the page shows its collision shapes; first: {first}\n  fix: give the directory holding the visuals' package with --package-path (or ROS_PACKAGE_PATH)",
            scene.missing_visuals.len()
        );
    }
    eprintln!(
        "wrote {} ({how}) and {}: {} bodies, {} visuals, {} frames{}",
        out.display(),
        out.with_extension("json").display(),
        scene.bodies.len(),
        scene.visuals.len(),
        scene.frames.len(),
        scene
            .map
            .as_ref()
            .map(|m| format!(", {} map points, {} edges", m.points.len(), m.edges.len()))
            .unwrap_or_default()
    );
    Ok(())
}

/// A scenario run (`trm_plan::run_scenario` on `problem`'s map): the robot's motion, every
/// object that ever appears posed per frame (absent while it is not there), the map with the
/// nodes and edges parked at each step, and the task-space path.
pub fn scenario_scene(problem: &Problem, run: &ScenarioRun) -> trm_view::Result<Scene> {
    let mut scene = Scene::of_problem(problem, "scenario")?;
    scene.frames.clear();
    for (t, q) in run.motion.times.iter().zip(&run.motion.positions) {
        scene.add_frame(*t, q)?;
    }
    let mut all = run
        .worlds
        .last()
        .cloned()
        .unwrap_or_else(|| problem.objective.world().clone());
    for w in &run.worlds {
        for o in w.objects() {
            if all.object(o.name()).is_err() {
                all.add(o.name(), o.shape().clone(), *o.pose())
                    .map_err(|e| trm_view::ViewError::Invalid {
                        what: format!("scenario object `{}`", o.name()),
                        problem: e.to_string(),
                    })?;
            }
        }
    }
    scene.set_world(&all);
    scene.add_roadmap(&run.map, problem.objective.active())?;
    for (frame, (step, world)) in scene
        .frames
        .iter_mut()
        .zip(run.steps.iter().zip(&run.worlds))
    {
        frame.world = Some(
            all.objects()
                .iter()
                .map(|o| {
                    world
                        .object(o.name())
                        .ok()
                        .map(|p| trm_view::pose(p.pose()))
                })
                .collect(),
        );
        frame.map = Some(trm_view::FrameMap {
            nodes: step.nodes,
            edges: step.edges,
            blocked: step.parked_nodes.clone(),
            blocked_edges: step.parked_edges.clone(),
        });
    }
    scene.set_path(
        run.motion
            .task_path
            .iter()
            .map(|p| trm_view::point3(p))
            .collect(),
    );
    Ok(scene)
}
