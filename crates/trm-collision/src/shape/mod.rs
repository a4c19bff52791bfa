//! Collision shapes: the [`Shape`] type with its checks, its compiled hot-path form placed at a
//! pose (`compiled`), the pairwise tests between placed shapes (`pair`: bounding-sphere reject,
//! analytic round shapes, parry for the rest) and the exact segment–box distance those tests
//! use (`segment_box`).

use std::sync::Arc;

use nalgebra::{Isometry3, Point3, Vector3};
use parry3d_f64::shape::SharedShape;
use serde::{Deserialize, Serialize};

use hull::HullWalk;

mod compiled;
mod hull;
mod pair;
mod sample;
mod segment_box;
mod segment_lanes;
mod spheres;

pub(crate) use compiled::{Axial, Compiled, Geometry, LazyShape, Placed};
pub(crate) use pair::{
    Closest, bounds_apart, hull_signed_distance, intersects, proximity, signed_distance,
    sphere_apart,
};
pub(crate) use segment_lanes::{PointLanes, segment_distance_squared_lanes};
pub use spheres::{CONVEX_SPHERES, Sphere};

/// A collision shape in its own frame, with URDF conventions: boxes, cylinders and capsules
/// are centred on the origin, cylinders and capsules run along z. Lengths in metres.
///
/// A robot's bodies are convex (the first five kinds); the world may also hold what cameras and
/// CAD give: point clouds ([`Shape::Points`]) and triangle meshes ([`Shape::Mesh`]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum Shape {
    /// A ball.
    Sphere {
        /// Radius (> 0).
        radius: f64,
    },
    /// A box with full side lengths `size` (each > 0).
    Box {
        /// Full side lengths along x, y, z.
        size: [f64; 3],
    },
    /// A cylinder along z.
    Cylinder {
        /// Radius (> 0).
        radius: f64,
        /// Full length (> 0).
        length: f64,
    },
    /// A capsule along z: a segment of `length` (≥ 0) swept by a ball of `radius` (> 0).
    Capsule {
        /// Radius (> 0).
        radius: f64,
        /// Distance between the two cap centres.
        length: f64,
    },
    /// The convex hull of points (at least 4, not coplanar); meshes become this.
    Convex {
        /// The points, in the shape frame.
        points: Vec<[f64; 3]>,
    },
    /// A point cloud (world objects only): a ball of `radius` about every point — a depth
    /// camera's points with their uncertainty. The points are the truth: a body collides when
    /// it comes within `radius` of one of them.
    Points {
        /// The points, in the shape frame (at least one).
        points: Vec<[f64; 3]>,
        /// Radius of every point (> 0).
        radius: f64,
    },
    /// A triangle mesh taken as its surface, concave parts included (world objects only): a
    /// body collides when it touches a triangle, as MoveIt's meshes (a body wholly inside a
    /// closed mesh touches none).
    Mesh {
        /// The vertices, in the shape frame.
        vertices: Vec<[f64; 3]>,
        /// The triangles, as indices into `vertices` (at least one).
        triangles: Vec<[u32; 3]>,
    },
}

/// What is wrong with a shape, and how to fix it.
#[derive(Debug, Clone, PartialEq)]
pub struct ShapeProblem {
    /// What is wrong.
    pub problem: String,
    /// How to fix it.
    pub fix: String,
}

fn problem(problem: impl Into<String>, fix: impl Into<String>) -> ShapeProblem {
    ShapeProblem {
        problem: problem.into(),
        fix: fix.into(),
    }
}

impl Shape {
    /// A URDF `<geometry>` primitive (box, cylinder, capsule, sphere) as a shape; `None` for a
    /// mesh, which the caller loads ([`crate::mesh`]).
    pub fn from_urdf(geometry: &trm_kinematics::urdf_rs::Geometry) -> Option<Shape> {
        use trm_kinematics::urdf_rs::Geometry as G;
        Some(match geometry {
            G::Box { size } => Shape::Box { size: size.0 },
            G::Cylinder { radius, length } => Shape::Cylinder {
                radius: *radius,
                length: *length,
            },
            G::Capsule { radius, length } => Shape::Capsule {
                radius: *radius,
                length: *length,
            },
            G::Sphere { radius } => Shape::Sphere { radius: *radius },
            G::Mesh { .. } => return None,
        })
    }

    /// Volume, m³, of a primitive (`None` for a convex hull of points).
    pub fn volume(&self) -> Option<f64> {
        use std::f64::consts::PI;
        match self {
            Shape::Sphere { radius } => Some(4.0 / 3.0 * PI * radius.powi(3)),
            Shape::Box { size } => Some(size[0] * size[1] * size[2]),
            Shape::Cylinder { radius, length } => Some(PI * radius * radius * length),
            Shape::Capsule { radius, length } => {
                Some(PI * radius * radius * (length + 4.0 * radius / 3.0))
            }
            Shape::Convex { .. } | Shape::Points { .. } | Shape::Mesh { .. } => None,
        }
    }

    /// A shape holding every point within `margin` (m, ≥ 0) of this one: a sphere, capsule or
    /// point cloud with its radius grown (exactly that), a box or cylinder with every side
    /// moved out by `margin`, a hull of its points moved to the corners of a cube of half-side
    /// `margin` (both at most √3·`margin` beyond); `None` for a triangle mesh, which has no
    /// inside.
    pub fn grown(&self, margin: f64) -> Option<Shape> {
        let m = margin;
        Some(match self {
            Shape::Sphere { radius } => Shape::Sphere { radius: radius + m },
            Shape::Capsule { radius, length } => Shape::Capsule {
                radius: radius + m,
                length: *length,
            },
            Shape::Box { size } => Shape::Box {
                size: size.map(|s| s + 2.0 * m),
            },
            Shape::Cylinder { radius, length } => Shape::Cylinder {
                radius: radius + m,
                length: length + 2.0 * m,
            },
            Shape::Convex { points } => Shape::Convex {
                points: points
                    .iter()
                    .flat_map(|p| {
                        (0..8).map(move |k| {
                            let corner = |axis: usize| if k >> axis & 1 == 1 { m } else { -m };
                            [p[0] + corner(0), p[1] + corner(1), p[2] + corner(2)]
                        })
                    })
                    .collect(),
            },
            Shape::Points { points, radius } => Shape::Points {
                points: points.clone(),
                radius: radius + m,
            },
            Shape::Mesh { .. } => return None,
        })
    }

    /// How far beyond this shape [`Shape::grown`]`(margin)` may reach, per metre of margin: 1
    /// for round shapes, √3 for the others.
    pub fn growth(&self) -> f64 {
        match self {
            Shape::Sphere { .. } | Shape::Capsule { .. } | Shape::Points { .. } => 1.0,
            _ => 3f64.sqrt(),
        }
    }

    /// Whether a robot's link may be made of it (every kind but [`Shape::Points`] and
    /// [`Shape::Mesh`], which only the world holds).
    pub fn is_convex(&self) -> bool {
        !matches!(self, Shape::Points { .. } | Shape::Mesh { .. })
    }

    /// The shape's kind as written in files.
    pub fn kind(&self) -> &'static str {
        match self {
            Shape::Sphere { .. } => "sphere",
            Shape::Box { .. } => "box",
            Shape::Cylinder { .. } => "cylinder",
            Shape::Capsule { .. } => "capsule",
            Shape::Convex { .. } => "convex",
            Shape::Points { .. } => "points",
            Shape::Mesh { .. } => "mesh",
        }
    }

    /// Checks that every size is finite and the shape has a volume (a point cloud: points and a
    /// radius; a mesh: triangles of distinct vertices).
    pub fn check(&self) -> Result<(), ShapeProblem> {
        let positive = |what: &str, v: f64| {
            if v.is_finite() && v > 0.0 {
                Ok(())
            } else {
                Err(problem(
                    format!("{} {what} {v} is not a positive finite number", self.kind()),
                    format!("give the {what} a positive size in metres"),
                ))
            }
        };
        match self {
            Shape::Sphere { radius } => positive("radius", *radius),
            Shape::Box { size } => size.iter().try_for_each(|&s| positive("size", s)),
            Shape::Cylinder { radius, length } => {
                positive("radius", *radius)?;
                positive("length", *length)
            }
            Shape::Capsule { radius, length } => {
                positive("radius", *radius)?;
                if length.is_finite() && *length >= 0.0 {
                    Ok(())
                } else {
                    Err(problem(
                        format!("capsule length {length} is negative or not finite"),
                        "give a length ≥ 0 (0 makes a sphere)",
                    ))
                }
            }
            Shape::Convex { points } => {
                if points.iter().flatten().any(|v| !v.is_finite()) {
                    return Err(problem(
                        "convex shape has a non-finite point",
                        "remove NaN/inf vertices",
                    ));
                }
                let pts: Vec<Point3<f64>> = points.iter().map(|p| Point3::from(*p)).collect();
                if !spans_volume(&pts) || SharedShape::convex_hull(&pts).is_none() {
                    return Err(problem(
                        format!(
                            "convex shape of {} points has no volume (all points coplanar?)",
                            points.len()
                        ),
                        "give at least 4 points that span a volume",
                    ));
                }
                Ok(())
            }
            Shape::Points { points, radius } => {
                positive("radius", *radius)?;
                if points.is_empty() {
                    return Err(problem(
                        "point cloud has no point",
                        "give at least one point, or leave the object out",
                    ));
                }
                match points.iter().position(|p| p.iter().any(|v| !v.is_finite())) {
                    Some(i) => Err(problem(
                        format!("point {i} of the cloud is not finite: {:?}", points[i]),
                        "drop the camera's invalid (NaN) points before handing the cloud over",
                    )),
                    None => Ok(()),
                }
            }
            Shape::Mesh {
                vertices,
                triangles,
            } => {
                if triangles.is_empty() {
                    return Err(problem(
                        "mesh has no triangle",
                        "give at least one triangle",
                    ));
                }
                if let Some(i) = vertices
                    .iter()
                    .position(|p| p.iter().any(|v| !v.is_finite()))
                {
                    return Err(problem(
                        format!("mesh vertex {i} is not finite: {:?}", vertices[i]),
                        "remove NaN/inf vertices",
                    ));
                }
                let n = vertices.len();
                match triangles
                    .iter()
                    .position(|t| t.iter().any(|&v| v as usize >= n))
                {
                    Some(i) => Err(problem(
                        format!(
                            "mesh triangle {i} {:?} names a vertex beyond the {n} given",
                            triangles[i]
                        ),
                        "index vertices from 0",
                    )),
                    None => Ok(()),
                }
            }
        }
    }

    /// A parry shape of the same geometry and its pose in this shape's frame (for queries
    /// parry offers and this crate does not). The pose is the identity except for cylinders:
    /// parry's run along y, URDF's along z, so theirs is turned a quarter about x.
    pub fn to_parry(&self) -> Option<(Isometry3<f64>, SharedShape)> {
        self.check().ok()?;
        let shape = match self {
            Shape::Sphere { radius } => SharedShape::ball(*radius),
            Shape::Box { size } => SharedShape::cuboid(size[0] / 2.0, size[1] / 2.0, size[2] / 2.0),
            Shape::Cylinder { radius, length } => {
                let y_to_z = Isometry3::rotation(Vector3::x() * std::f64::consts::FRAC_PI_2);
                return Some((y_to_z, SharedShape::cylinder(length / 2.0, *radius)));
            }
            Shape::Capsule { radius, length } => SharedShape::capsule_z(length / 2.0, *radius),
            Shape::Convex { points } => {
                let pts: Vec<Point3<f64>> = points.iter().map(|p| Point3::from(*p)).collect();
                SharedShape::convex_hull(&pts)?
            }
            Shape::Points { points, radius } => {
                // one ball shared by every point; parry's compound keeps them in a BVH
                let ball = SharedShape::ball(*radius);
                let balls = points
                    .iter()
                    .map(|p| (Isometry3::translation(p[0], p[1], p[2]), ball.clone()))
                    .collect();
                SharedShape::compound(balls)
            }
            Shape::Mesh {
                vertices,
                triangles,
            } => {
                let vertices = vertices.iter().map(|p| Point3::from(*p)).collect();
                SharedShape::trimesh(vertices, triangles.clone()).ok()?
            }
        };
        Some((Isometry3::identity(), shape))
    }

    /// The shape placed at `local` in its parent frame, in the form the queries use.
    /// `None` when [`Shape::check`] fails.
    pub(crate) fn compile(&self, local: &Isometry3<f64>) -> Option<Compiled> {
        self.check().ok()?;
        let round = |half: f64, radius: f64| {
            let a = local * Point3::new(0.0, 0.0, -half);
            let b = local * Point3::new(0.0, 0.0, half);
            Compiled {
                center: nalgebra::center(&a, &b),
                bound: half + radius,
                geometry: Geometry::Round { a, b, radius },
            }
        };
        Some(match self {
            Shape::Sphere { radius } => round(0.0, *radius),
            Shape::Capsule { radius, length } => round(length / 2.0, *radius),
            Shape::Points { points, radius } => {
                // bounds from the points; parry's form waits for the first exact query
                let corners: Vec<Point3<f64>> = points.iter().map(|p| Point3::from(*p)).collect();
                let reach = Vector3::repeat(*radius);
                let tight =
                    parry3d_f64::bounding_volume::details::local_point_cloud_aabb_ref(&corners);
                let local_box =
                    parry3d_f64::bounding_volume::Aabb::new(tight.mins - reach, tight.maxs + reach);
                let center = tight.center();
                let bound = corners
                    .iter()
                    .map(|p| (p - center).norm())
                    .fold(0.0, f64::max)
                    + radius;
                Compiled {
                    center: local * center,
                    bound,
                    geometry: Geometry::General {
                        local: *local,
                        shape: LazyShape::cloud(self.clone(), local_box),
                        half_extents: None,
                        walk: None,
                        axial: None,
                    },
                }
            }
            _ => {
                let (frame, shape) = self.to_parry()?;
                let local = local * frame;
                let sphere = shape.compute_local_bounding_sphere();
                let half_extents = match self {
                    Shape::Box { size } => Some(Vector3::from(*size) / 2.0),
                    _ => None,
                };
                let walk = shape
                    .as_convex_polyhedron()
                    .and_then(HullWalk::new)
                    .map(Arc::new);
                let axial = match self {
                    Shape::Cylinder { radius, length } => Some(Axial {
                        outer: length / 2.0,
                        inner: (length / 2.0 >= *radius).then_some(length / 2.0 - radius),
                        radius: *radius,
                    }),
                    _ => None,
                };
                Compiled {
                    center: local * sphere.center,
                    bound: sphere.radius,
                    geometry: Geometry::General {
                        local,
                        shape: LazyShape::ready(shape),
                        half_extents,
                        walk,
                        axial,
                    },
                }
            }
        })
    }
}

/// Whether the points span a volume (not all on one plane), relative to their extent.
pub(crate) fn spans_volume(points: &[Point3<f64>]) -> bool {
    let Some(p0) = points.first() else {
        return false;
    };
    let farthest = |score: &dyn Fn(&Point3<f64>) -> f64| {
        points
            .iter()
            .map(|p| (score(p), p))
            .max_by(|a, b| a.0.total_cmp(&b.0))
            .map(|(d, p)| (d, *p))
            .unwrap_or((0.0, *p0))
    };
    let (extent, p1) = farthest(&|p| (p - p0).norm());
    if extent <= 0.0 {
        return false;
    }
    let axis = (p1 - p0) / extent;
    let (_, p2) = farthest(&|p| (p - p0).cross(&axis).norm());
    let normal = (p1 - p0).cross(&(p2 - p0));
    if normal.norm() <= 1e-12 * extent * extent {
        return false;
    }
    let normal = normal.normalize();
    let (height, _) = farthest(&|p| (p - p0).dot(&normal).abs());
    height > 1e-9 * extent
}

#[cfg(test)]
mod tests;
