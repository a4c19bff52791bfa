//! The robot as people see it: its URDF `<visual>` elements (primitives, and meshes — STL,
//! COLLADA, OBJ — with their materials' colours), loaded for the scene.

use std::collections::HashMap;
use std::path::PathBuf;

use serde::{Deserialize, Serialize};
use trm_collision::mesh::{MeshPart, parts_of_mesh};
use trm_collision::{CollisionModel, Shape};
use trm_kinematics::pose_from_xyz_rpy;
use trm_kinematics::urdf_rs::Geometry;

use crate::{Pose, pose};

/// The colour of a visual whose URDF and mesh give none (RViz's default grey).
pub const DEFAULT_COLOR: [f32; 4] = [0.8, 0.8, 0.8, 1.0];

/// Vertices of visual meshes are written in steps of 1 / this many metres (a micrometre: far
/// below what a screen shows, and a third of the digits of a full number).
const VERTEX_STEPS_PER_METRE: f64 = 1e6;

/// One drawn part of a link's look: a URDF `<visual>` primitive, or the part of a visual mesh
/// drawn in one colour.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneVisual {
    /// Index into [`crate::Scene::links`].
    pub link: usize,
    /// Shape, as in [`crate::SceneBody::shape`]; a mesh is a [`Shape::Mesh`].
    pub shape: Shape,
    /// Pose of the shape in the link frame.
    pub local: Pose,
    /// Colour, RGBA in 0..=1: the mesh material's, else the URDF `<material>`'s, else
    /// [`DEFAULT_COLOR`].
    pub color: [f32; 4],
}

/// A robot's visuals, and what could not be loaded.
#[derive(Debug, Default)]
pub(crate) struct Visuals {
    /// Per tree link, its parts (the scene assigns the links' slots).
    pub parts: Vec<(usize, Shape, Pose, [f32; 4])>,
    /// One line per visual that could not be loaded: the link, the file, why.
    pub missing: Vec<String>,
}

/// Loads every `<visual>` of `collision`'s robot, meshes found as its collision meshes are
/// ([`CollisionModel::options`]). A mesh that cannot be found or read is listed in
/// [`Visuals::missing`], never an error: the scene still shows the collision shapes.
pub(crate) fn load(collision: &CollisionModel) -> Visuals {
    let robot = collision.robot();
    let mut out = Visuals::default();
    let mut files: HashMap<PathBuf, Result<Vec<MeshPart>, String>> = HashMap::new();
    for (link, l) in robot.tree().links.iter().enumerate() {
        for v in &l.visuals {
            let (xyz, rpy) = (v.origin.xyz.0, v.origin.rpy.0);
            if xyz.iter().chain(&rpy).any(|c| !c.is_finite()) {
                out.missing.push(format!(
                    "link `{}`: a <visual> <origin> is not finite",
                    l.name
                ));
                continue;
            }
            let local = pose(&pose_from_xyz_rpy(xyz, rpy));
            let urdf_color = v
                .material
                .as_ref()
                .and_then(|m| m.color.as_ref())
                .map(|c| c.rgba.0.map(|x| x as f32))
                .filter(|c| c.iter().all(|x| x.is_finite()));
            let color = urdf_color.unwrap_or(DEFAULT_COLOR);
            if let Some(shape) = Shape::from_urdf(&v.geometry) {
                match shape.check() {
                    Ok(()) => out.parts.push((link, shape, local, color)),
                    Err(p) => out.missing.push(format!(
                        "link `{}`: a <visual> {}: {}",
                        l.name,
                        shape.kind(),
                        p.problem
                    )),
                }
                continue;
            }
            let Geometry::Mesh { filename, scale } = &v.geometry else {
                continue;
            };
            let path = match collision.options().find_mesh(robot, filename) {
                Ok(path) => path,
                Err(tried) => {
                    out.missing.push(format!(
                        "link `{}`: visual mesh {filename} not found (tried {})",
                        l.name,
                        tried
                            .iter()
                            .map(|p| p.display().to_string())
                            .collect::<Vec<_>>()
                            .join(", ")
                    ));
                    continue;
                }
            };
            let scale = scale.map_or([1.0; 3], |s| s.0);
            let key = path.join(format!("{scale:?}"));
            let parts = files
                .entry(key)
                .or_insert_with(|| parts_of_mesh(&path, scale));
            match parts {
                Ok(parts) => {
                    for (shape, part_color) in by_color(parts) {
                        let color = part_color.or(urdf_color).unwrap_or(DEFAULT_COLOR);
                        out.parts.push((link, shape, local, color));
                    }
                }
                Err(e) => out.missing.push(format!(
                    "link `{}`: visual mesh {}: {e}",
                    l.name,
                    path.display()
                )),
            }
        }
    }
    out
}

/// A mesh file's parts merged by colour (a CAD export holds dozens of parts in a few
/// colours: one drawn mesh each), vertices rounded to a micrometre
/// ([`VERTEX_STEPS_PER_METRE`]).
fn by_color(parts: &[MeshPart]) -> Vec<(Shape, Option<[f32; 4]>)> {
    let mut groups: Vec<MeshPart> = Vec::new();
    for part in parts.iter().filter(|p| !p.triangles.is_empty()) {
        let color = part.color.filter(|c| c.iter().all(|x| x.is_finite()));
        let k = match groups.iter().position(|g| g.color == color) {
            Some(k) => k,
            None => {
                groups.push(MeshPart {
                    vertices: Vec::new(),
                    triangles: Vec::new(),
                    color,
                });
                groups.len() - 1
            }
        };
        let group = &mut groups[k];
        let base = group.vertices.len() as u32;
        group.vertices.extend(
            part.vertices
                .iter()
                .map(|v| v.map(|x| (x * VERTEX_STEPS_PER_METRE).round() / VERTEX_STEPS_PER_METRE)),
        );
        group
            .triangles
            .extend(part.triangles.iter().map(|t| t.map(|i| base + i)));
    }
    groups
        .into_iter()
        .map(|g| {
            let shape = Shape::Mesh {
                vertices: g.vertices,
                triangles: g.triangles,
            };
            (shape, g.color)
        })
        .collect()
}
