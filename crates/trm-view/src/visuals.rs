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
    /// The parts, each `link` a tree index (the scene gives the links their slots).
    pub parts: Vec<SceneVisual>,
    /// One line per visual that could not be loaded: the link, the file, why.
    pub missing: Vec<String>,
}

/// Loads every `<visual>` of `collision`'s robot, meshes found as its collision meshes are
/// ([`CollisionModel::options`]). A mesh that cannot be found or read is listed in
/// [`Visuals::missing`], never an error: the scene still shows the collision shapes.
pub(crate) fn load(collision: &CollisionModel) -> Visuals {
    let robot = collision.robot();
    let mut out = Visuals::default();
    // each file read once per scale (a robot's two fingers share one mesh)
    let mut files: HashMap<(PathBuf, [u64; 3]), Result<Vec<MeshPart>, String>> = HashMap::new();
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
                .and_then(|c| rgba(c.rgba.0.map(|x| x as f32)));
            let color = urdf_color.unwrap_or(DEFAULT_COLOR);
            if let Some(shape) = Shape::from_urdf(&v.geometry) {
                match shape.check() {
                    Ok(()) => out.parts.push(SceneVisual {
                        link,
                        shape,
                        local,
                        color,
                    }),
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
            let parts = files
                .entry((path.clone(), scale.map(f64::to_bits)))
                .or_insert_with(|| parts_of_mesh(&path, scale));
            match parts {
                Ok(parts) => {
                    for (shape, part_color) in by_color(parts) {
                        out.parts.push(SceneVisual {
                            link,
                            shape,
                            local,
                            color: part_color.or(urdf_color).unwrap_or(DEFAULT_COLOR),
                        });
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
        let color = part.color.and_then(rgba);
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

/// A colour as drawn: finite components clamped into 0..=1 (files written for 0..=255 show
/// saturated rather than failing, as RViz draws them); `None` when one is not a number.
fn rgba(c: [f32; 4]) -> Option<[f32; 4]> {
    c.iter()
        .all(|x| x.is_finite())
        .then(|| c.map(|x| x.clamp(0.0, 1.0)))
}
