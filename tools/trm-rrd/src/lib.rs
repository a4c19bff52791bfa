//! trm scenes as Rerun recordings (`.rrd`), for people who already use the Rerun viewer: one
//! entity per link under `robot/` whose transform changes on the `time` timeline, its collision
//! bodies below it, the world under `world/`, the map under `map/`, the path under `path`.
//!
//! ```sh
//! cargo xtask view --traj motion.csv --out target/view/scene.html    # writes scene.json too
//! cargo run --release --manifest-path tools/trm-rrd/Cargo.toml -- target/view/scene.json scene.rrd
//! rerun scene.rrd
//! ```

use rerun::{
    Boxes3D, Capsules3D, Color, Cylinders3D, Ellipsoids3D, LineStrips3D, Points3D, Quaternion,
    RecordingStream, Transform3D,
};
use trm_collision::Shape;
use trm_view::{Pose, Scene};

/// Why a recording could not be written.
#[derive(Debug, thiserror::Error)]
#[error("rerun recording: {0}")]
pub struct RrdError(String);

/// Result alias of this crate.
pub type Result<T, E = RrdError> = std::result::Result<T, E>;

fn transform(p: &Pose) -> Transform3D {
    let f = |v: f64| v as f32;
    Transform3D::from_translation_rotation(
        [f(p[0]), f(p[1]), f(p[2])],
        Quaternion::from_xyzw([f(p[3]), f(p[4]), f(p[5]), f(p[6])]),
    )
}

fn rerun_error(e: impl std::fmt::Display) -> RrdError {
    RrdError(e.to_string())
}

/// Logs `shape` at `entity`, placed by `local` (its pose in the parent entity's frame).
fn log_shape(
    rec: &RecordingStream,
    entity: &str,
    shape: &Shape,
    local: &Pose,
    color: Color,
) -> Result<()> {
    rec.log_static(entity, &transform(local))
        .map_err(rerun_error)?;
    let r = |v: f64| v as f32;
    let logged = match shape {
        Shape::Sphere { radius } => rec.log_static(
            entity,
            &Ellipsoids3D::from_radii([r(*radius)]).with_colors([color]),
        ),
        Shape::Box { size } => rec.log_static(
            entity,
            &Boxes3D::from_sizes([[r(size[0]), r(size[1]), r(size[2])]]).with_colors([color]),
        ),
        Shape::Cylinder { radius, length } => rec.log_static(
            entity,
            &Cylinders3D::from_lengths_and_radii([r(*length)], [r(*radius)]).with_colors([color]),
        ),
        // Rerun's capsules run from the origin along +z; ours are centred
        Shape::Capsule { radius, length } => rec.log_static(
            entity,
            &Capsules3D::from_lengths_and_radii([r(*length)], [r(*radius)])
                .with_translations([[0.0, 0.0, -r(*length) / 2.0]])
                .with_colors([color]),
        ),
        Shape::Convex { points } => rec.log_static(
            entity,
            &Points3D::new(points.iter().map(|p| [r(p[0]), r(p[1]), r(p[2])])).with_colors([color]),
        ),
    };
    logged.map_err(rerun_error)
}

fn cost_color(c: f64, lo: f64, hi: f64) -> Color {
    let u = if hi > lo {
        ((c - lo) / (hi - lo)).clamp(0.0, 1.0)
    } else {
        0.5
    };
    Color::from_rgb((255.0 * u) as u8, 60, (255.0 * (1.0 - u)) as u8)
}

/// Writes `scene` as a Rerun recording (`.rrd`, Rerun 0.36): open it with `rerun FILE`.
pub fn write_rrd(scene: &Scene, path: &std::path::Path) -> Result<()> {
    let rec = rerun::RecordingStreamBuilder::new("trm")
        .save(path)
        .map_err(rerun_error)?;
    let link_entity = |slot: usize| format!("robot/{}", scene.links[slot]);
    for b in &scene.bodies {
        let hue = (b.link * 37 % 255) as u8;
        let entity = format!("{}/{}", link_entity(b.link), b.name.replace('#', "_"));
        let color = Color::from_unmultiplied_rgba(hue, 160, 255 - hue, 200);
        log_shape(&rec, &entity, &b.shape, &b.local, color)?;
    }
    for o in &scene.world {
        let color = Color::from_unmultiplied_rgba(140, 140, 140, 120);
        log_shape(&rec, &format!("world/{}", o.name), &o.shape, &o.pose, color)?;
    }
    let f32s = |p: &[f64; 3]| [p[0] as f32, p[1] as f32, p[2] as f32];
    if let Some(map) = &scene.map {
        let (lo, hi) = map
            .cost
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &c| {
                (a.min(c), b.max(c))
            });
        let colors: Vec<Color> = map.cost.iter().map(|&c| cost_color(c, lo, hi)).collect();
        let points = Points3D::new(map.points.iter().map(f32s)).with_colors(colors);
        rec.log_static("map/points", &points).map_err(rerun_error)?;
        let edges = map
            .edges
            .iter()
            .map(|e| vec![f32s(&map.points[e[0]]), f32s(&map.points[e[1]])]);
        rec.log_static("map/edges", &LineStrips3D::new(edges))
            .map_err(rerun_error)?;
    }
    if scene.path.len() > 1 {
        let strip: Vec<[f32; 3]> = scene.path.iter().map(f32s).collect();
        rec.log_static("path", &LineStrips3D::new([strip]))
            .map_err(rerun_error)?;
    }
    for f in &scene.frames {
        rec.set_duration_secs("time", f.t);
        for (slot, pose) in f.poses.iter().enumerate() {
            rec.log(link_entity(slot), &transform(pose))
                .map_err(rerun_error)?;
        }
    }
    rec.flush_blocking().map_err(rerun_error)?;
    Ok(())
}

#[cfg(test)]
mod tests {
    #[test]
    fn a_scene_becomes_a_rerun_recording() {
        let model = trm_models::icub_upper_body();
        let collision = trm_collision::CollisionModel::new(&model).unwrap();
        let mut scene = trm_view::Scene::new("rrd", &collision);
        let home = model.posture("home").unwrap().to_vec();
        scene.add_frame(0.0, &home).unwrap();
        scene.add_frame(0.5, &home).unwrap();
        let path = std::env::temp_dir().join(format!("trm-{}.rrd", std::process::id()));
        super::write_rrd(&scene, &path).unwrap();
        let bytes = std::fs::read(&path).unwrap();
        assert!(
            bytes.len() > 1000 && bytes.starts_with(b"RRF2"),
            "{} bytes",
            bytes.len()
        );
        let _ = std::fs::remove_file(&path);
    }
}
