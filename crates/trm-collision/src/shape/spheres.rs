//! Conservative sphere sets: a few spheres whose union encloses a shape completely, tighter than
//! its one bounding sphere — a sphere model of a shape (a body whose spheres all miss another
//! body cannot touch it), as sphere-based planners such as VAMP or cuRobo take robots.

use nalgebra::{Point3, Vector3};
use serde::{Deserialize, Serialize};

use super::Shape;

/// A sphere: centre and radius (metres).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Sphere {
    /// Centre.
    pub center: Point3<f64>,
    /// Radius.
    pub radius: f64,
}

/// Added to every radius so that rounding (≈ 1e-16 m on robot-sized coordinates) can never make
/// a set smaller than its shape, with room to spare for other tools' tolerances: a micrometre.
const MARGIN: f64 = 1e-6;

impl Shape {
    /// Spheres whose union encloses the shape completely, in the shape's own frame (move them by
    /// [`crate::Body::local`] for the link frame), each radius rounded up by a micrometre.
    ///
    /// A sphere is itself; a capsule gets a sphere on each cap (its own radius) and one around
    /// each piece of the cylinder between them, pieces no longer than its radius (at most
    /// 11.8 % wider than the capsule); a cylinder one per piece of its axis no longer than its diameter (both at
    /// most 64 pieces); a box is cut in two along every side at least half as long as the
    /// longest (up to 8 cells, one sphere around each); a convex hull is cut into
    /// [`CONVEX_SPHERES`] cells, each enclosed exactly ([`crate::fit::fit_convex_spheres`]); a
    /// point cloud is its points' balls, a mesh one sphere about each triangle. An empty vector
    /// for a shape that fails [`Shape::check`].
    pub fn enclosing_spheres(&self) -> Vec<Sphere> {
        if self.check().is_err() {
            return Vec::new();
        }
        match self {
            Shape::Sphere { radius } => vec![sphere(Point3::origin(), *radius)],
            Shape::Capsule { radius, length } => {
                // the caps exactly, the cylinder between them piece by piece
                let mut spheres = along_z(*length, *radius, |piece| radius.hypot(piece / 2.0));
                for z in [-length / 2.0, length / 2.0] {
                    spheres.push(sphere(Point3::new(0.0, 0.0, z), *radius));
                }
                spheres
            }
            Shape::Cylinder { radius, length } => {
                along_z(*length, 2.0 * radius, |piece| radius.hypot(piece / 2.0))
            }
            Shape::Box { size } => grid(Point3::origin(), Vector3::from(*size) / 2.0),
            Shape::Convex { points } => {
                let points: Vec<Point3<f64>> = points.iter().map(|p| Point3::from(*p)).collect();
                crate::fit::fit_convex_spheres(&points, CONVEX_SPHERES)
                    .unwrap_or_default()
                    .into_iter()
                    .map(|(center, radius)| Sphere { center, radius })
                    .collect()
            }
            Shape::Points { points, radius } => points
                .iter()
                .map(|p| sphere(Point3::from(*p), *radius))
                .collect(),
            Shape::Mesh {
                vertices,
                triangles,
            } => triangles
                .iter()
                .map(|t| {
                    let corners = t.map(|v| Point3::from(vertices[v as usize]));
                    let center =
                        Point3::from(corners.iter().map(|c| c.coords).sum::<Vector3<f64>>() / 3.0);
                    let radius = corners
                        .iter()
                        .map(|c| (c - center).norm())
                        .fold(0.0, f64::max);
                    sphere(center, radius)
                })
                .collect(),
        }
    }
}

impl Shape {
    /// Spheres wholly inside the shape, in its own frame, each radius rounded down by a
    /// micrometre: whatever touches one of them touches the shape. One about the centre of each
    /// of its [`Shape::enclosing_spheres`] (and, for a convex hull, one about the mean of its
    /// points), as large as the shape's surface allows, dropped where that is under two
    /// micrometres; none for a shape that fails [`Shape::check`]. A capsule's are spheres of its
    /// radius along its segment, a sphere's is itself, a point cloud's its points' balls; a mesh
    /// (a surface) has none.
    pub fn inscribed_spheres(&self) -> Vec<Sphere> {
        match self {
            _ if self.check().is_err() => return Vec::new(),
            Shape::Points { points, radius } => {
                return points
                    .iter()
                    .map(|p| Sphere {
                        center: Point3::from(*p),
                        radius: radius - MARGIN,
                    })
                    .collect();
            }
            Shape::Mesh { .. } => return Vec::new(),
            _ => {}
        }
        let mut centres: Vec<Point3<f64>> = self
            .enclosing_spheres()
            .into_iter()
            .map(|s| s.center)
            .collect();
        // a convex hull's faces as (outward normal, offset): inside is n·x ≤ offset
        let mut planes: Vec<(Vector3<f64>, f64)> = Vec::new();
        if let Shape::Convex { points } = self {
            let points: Vec<Point3<f64>> = points.iter().map(|p| Point3::from(*p)).collect();
            let Some(hull) = parry3d_f64::shape::ConvexPolyhedron::from_convex_hull(&points) else {
                return Vec::new();
            };
            let (vertices, on_face) = (hull.points(), hull.vertices_adj_to_face());
            planes = hull
                .faces()
                .iter()
                .map(|f| {
                    let v = vertices[on_face[f.first_vertex_or_edge as usize] as usize];
                    (f.normal.into_inner(), f.normal.dot(&v.coords))
                })
                .collect();
            centres.push(Point3::from(
                points.iter().map(|p| p.coords).sum::<Vector3<f64>>() / points.len() as f64,
            ));
        }
        // distance from a point inside the shape to its surface (≤ 0 outside)
        let depth = |c: &Point3<f64>| match *self {
            Shape::Sphere { radius } => radius - c.coords.norm(),
            Shape::Capsule { radius, length } => {
                radius
                    - c.coords
                        .xy()
                        .norm()
                        .hypot((c.z.abs() - length / 2.0).max(0.0))
            }
            Shape::Cylinder { radius, length } => {
                (radius - c.coords.xy().norm()).min(length / 2.0 - c.z.abs())
            }
            Shape::Box { size } => (0..3)
                .map(|i| size[i] / 2.0 - c[i].abs())
                .fold(f64::INFINITY, f64::min),
            Shape::Convex { .. } => planes
                .iter()
                .map(|(n, offset)| offset - n.dot(&c.coords))
                .fold(f64::INFINITY, f64::min),
            Shape::Points { .. } | Shape::Mesh { .. } => f64::NEG_INFINITY,
        };
        centres
            .into_iter()
            .filter_map(|center| {
                let depth = depth(&center);
                (depth > 2.0 * MARGIN).then_some(Sphere {
                    center,
                    radius: depth - MARGIN,
                })
            })
            .collect()
    }
}

fn sphere(center: Point3<f64>, radius: f64) -> Sphere {
    Sphere {
        center,
        radius: radius + MARGIN,
    }
}

/// Spheres of a convex hull's set ([`Shape::enclosing_spheres`]): on the MotionBenchMaker
/// Panda's hulls, 8 a link leave 616 of its 700 problems valid as a sphere model (16: the same
/// 616, 1.4× slower to plan).
pub const CONVEX_SPHERES: usize = 8;

/// Most pieces a capsule or cylinder is cut into (a needle gets longer pieces, not millions).
const MAX_PIECES: f64 = 64.0;

/// Spheres centred on the pieces of the z segment of `length` (centred on the origin), cut into
/// pieces no longer than `longest` (at most [`MAX_PIECES`]); `radius(piece length)` encloses one
/// piece's part of the shape.
fn along_z(length: f64, longest: f64, radius: impl Fn(f64) -> f64) -> Vec<Sphere> {
    let pieces = (length / longest).ceil().clamp(1.0, MAX_PIECES) as usize;
    let piece = length / pieces as f64;
    (0..pieces)
        .map(|k| {
            let z = -length / 2.0 + piece * (k as f64 + 0.5);
            sphere(Point3::new(0.0, 0.0, z), radius(piece))
        })
        .collect()
}

/// Spheres around the cells of the box `center ± half`, cut in two along every side at least
/// half as long as the longest.
fn grid(center: Point3<f64>, half: Vector3<f64>) -> Vec<Sphere> {
    let longest = half.max();
    let cuts = half.map(|h| if h >= 0.5 * longest { 2usize } else { 1 });
    let cell = Vector3::new(
        half.x / cuts.x as f64,
        half.y / cuts.y as f64,
        half.z / cuts.z as f64,
    );
    let radius = cell.norm();
    let mut out = Vec::with_capacity(cuts.iter().product());
    for i in 0..cuts.x {
        for j in 0..cuts.y {
            for k in 0..cuts.z {
                let offset = Vector3::new(
                    cell.x * (2 * i + 1) as f64 - half.x,
                    cell.y * (2 * j + 1) as f64 - half.y,
                    cell.z * (2 * k + 1) as f64 - half.z,
                );
                out.push(sphere(center + offset, radius));
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// Whether every sample lies in some sphere of the shape's set. Samples are points of the
    /// shape's box (unit coordinates scaled to its half extents), kept when inside the shape,
    /// and surface points (parry's support point along each sample taken as a direction).
    fn encloses(shape: &Shape, samples: &[Vector3<f64>]) -> bool {
        let spheres = shape.enclosing_spheres();
        let (frame, parry) = shape.to_parry().expect("valid shape");
        let aabb = parry.compute_local_aabb();
        let inside = samples.iter().filter_map(|u| {
            let p = aabb.center() + aabb.half_extents().component_mul(u);
            parry.contains_local_point(&p).then_some(p)
        });
        let support = parry.as_support_map().expect("convex");
        let surface = samples.iter().filter_map(|u| {
            nalgebra::Unit::try_new(*u, 1e-9).map(|dir| support.local_support_point_toward(&dir))
        });
        inside
            .chain(surface)
            .map(|p| frame * p)
            .all(|p| spheres.iter().any(|s| (p - s.center).norm() <= s.radius))
    }

    fn shape() -> impl Strategy<Value = Shape> {
        let size = 0.005..0.5f64;
        prop_oneof![
            size.clone().prop_map(|radius| Shape::Sphere { radius }),
            (size.clone(), 0.0..0.6f64)
                .prop_map(|(radius, length)| Shape::Capsule { radius, length }),
            (size.clone(), size.clone())
                .prop_map(|(radius, length)| Shape::Cylinder { radius, length }),
            [size.clone(), size.clone(), size.clone()].prop_map(|size| Shape::Box { size }),
            proptest::collection::vec([-0.3..0.3f64, -0.3..0.3, -0.3..0.3], 8..16)
                .prop_map(|points| Shape::Convex { points })
                .prop_filter("spans a volume", |s| s.check().is_ok()),
        ]
    }

    proptest! {
        #[test]
        fn every_point_of_a_shape_lies_in_one_of_its_spheres(
            shape in shape(),
            samples in proptest::collection::vec([-1.0..=1.0f64, -1.0..=1.0, -1.0..=1.0], 256),
        ) {
            let samples: Vec<_> = samples.into_iter().map(Vector3::from).collect();
            prop_assert!(encloses(&shape, &samples));
        }
    }

    proptest! {
        /// Every inscribed sphere of a hull lies inside it: its points along 64 directions are
        /// inside the hull, and a hull that spans a volume gets at least one.
        #[test]
        fn inscribed_spheres_lie_inside_the_hull(
            points in proptest::collection::vec([-0.3..0.3f64, -0.3..0.3, -0.3..0.3], 8..40),
            directions in proptest::collection::vec([-1.0..=1.0f64, -1.0..=1.0, -1.0..=1.0], 64),
        ) {
            let shape = Shape::Convex { points };
            prop_assume!(shape.check().is_ok());
            let (_, parry) = shape.to_parry().expect("valid shape");
            let inscribed = shape.inscribed_spheres();
            prop_assert!(!inscribed.is_empty());
            for s in &inscribed {
                prop_assert!(s.radius > 0.0);
                for u in &directions {
                    let Some(u) = nalgebra::Unit::try_new(Vector3::from(*u), 1e-9) else {
                        continue;
                    };
                    let p = s.center + u.into_inner() * s.radius;
                    prop_assert!(parry.contains_local_point(&p), "{:?} r {}", s.center, s.radius);
                }
            }
        }
    }

    proptest! {
        #[test]
        fn inscribed_spheres_of_primitives_lie_inside_and_touch_the_surface(
            kind in 0..4usize,
            a in 0.005..0.3f64,
            b in 0.005..0.3f64,
            c in 0.005..0.3f64,
            directions in proptest::collection::vec([-1.0..=1.0f64, -1.0..=1.0, -1.0..=1.0], 32),
        ) {
            let shape = match kind {
                0 => Shape::Sphere { radius: a },
                1 => Shape::Capsule { radius: a, length: b },
                2 => Shape::Cylinder { radius: a, length: b },
                _ => Shape::Box { size: [a, b, c] },
            };
            let (frame, parry) = shape.to_parry().expect("valid shape");
            let inscribed = shape.inscribed_spheres();
            prop_assert!(!inscribed.is_empty());
            for s in &inscribed {
                // inside: every point of its surface is in the shape
                for u in &directions {
                    let Some(u) = nalgebra::Unit::try_new(Vector3::from(*u), 1e-9) else {
                        continue;
                    };
                    let p = frame.inverse_transform_point(&(s.center + u.into_inner() * s.radius));
                    prop_assert!(parry.contains_local_point(&p), "{shape:?}: {s:?}");
                }
                // as large as the surface allows: a micrometre from it (parry projects a point
                // inside a cylinder onto its side even where a cap is nearer: not checked there)
                if kind != 2 {
                    let centre = frame.inverse_transform_point(&s.center);
                    let gap = parry.distance_to_local_point(&centre, false).abs() - s.radius;
                    prop_assert!((0.5 * MARGIN..=1.5 * MARGIN).contains(&gap), "{shape:?}: {gap}");
                }
            }
            if let Shape::Capsule { radius, .. } | Shape::Sphere { radius } = shape {
                prop_assert!(inscribed.iter().all(|s| s.radius == radius - MARGIN));
            }
        }
    }

    #[test]
    fn corners_and_cap_tips_lie_on_the_spheres_within_the_margin() {
        let size = [0.17, 0.18, 0.21];
        let spheres = Shape::Box { size }.enclosing_spheres();
        assert_eq!(spheres.len(), 8);
        let reach = |p: Point3<f64>| {
            spheres
                .iter()
                .map(|s| (p - s.center).norm() - s.radius)
                .fold(f64::INFINITY, f64::min)
        };
        let corner = Point3::new(0.085, -0.09, 0.105);
        assert!(
            (-2.0 * MARGIN..=0.0).contains(&reach(corner)),
            "{}",
            reach(corner)
        );
        let flat = Shape::Box {
            size: [0.08, 0.03, 0.07],
        }
        .enclosing_spheres();
        assert_eq!(flat.len(), 4, "the short side is not cut");
        let capsule = Shape::Capsule {
            radius: 0.05,
            length: 0.12,
        }
        .enclosing_spheres();
        assert_eq!(capsule.len(), 5, "3 pieces and 2 caps");
        let tip = Point3::new(0.0, 0.0, 0.06 + 0.05);
        let nearest = capsule
            .iter()
            .map(|s| (tip - s.center).norm() - s.radius)
            .fold(f64::INFINITY, f64::min);
        assert!((-2.0 * MARGIN..=0.0).contains(&nearest), "{nearest}");
        let needle = Shape::Capsule {
            radius: 1e-9,
            length: 1.0,
        }
        .enclosing_spheres();
        assert_eq!(
            needle.len(),
            66,
            "a needle is cut into a bounded number of pieces"
        );
        let tip = Point3::new(0.0, 0.0, 0.5 + 1e-9);
        assert!(needle.iter().any(|s| (tip - s.center).norm() <= s.radius));
        assert!(
            Shape::Box {
                size: [0.1, f64::NAN, 0.1]
            }
            .enclosing_spheres()
            .is_empty()
        );
    }

    #[test]
    fn a_set_is_tighter_than_the_bounding_sphere() {
        for shape in [
            Shape::Box {
                size: [0.24, 0.23, 0.28],
            },
            Shape::Cylinder {
                radius: 0.02,
                length: 0.3,
            },
            Shape::Capsule {
                radius: 0.02,
                length: 0.3,
            },
        ] {
            let bound = shape
                .to_parry()
                .unwrap()
                .1
                .compute_local_bounding_sphere()
                .radius;
            let largest = shape
                .enclosing_spheres()
                .iter()
                .map(|s| s.radius)
                .fold(0.0, f64::max);
            assert!(largest < 0.6 * bound, "{shape:?}: {largest} vs {bound}");
        }
    }
}
