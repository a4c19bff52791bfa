//! Shapes, their compiled hot-path form, and the pairwise tests between placed shapes.

use nalgebra::{Isometry3, Point3, Translation3, Vector3};
use parry3d_f64::query;
use parry3d_f64::query::details::closest_points_segment_segment_with_locations_nD;
use parry3d_f64::shape::{Ball, Capsule, SegmentPointLocation, Shape as ParryShape, SharedShape};
use serde::{Deserialize, Serialize};

/// A convex collision shape in its own frame, with URDF conventions: boxes, cylinders and
/// capsules are centred on the origin, cylinders and capsules run along z. Lengths in metres.
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
    /// The shape's kind as written in files.
    pub fn kind(&self) -> &'static str {
        match self {
            Shape::Sphere { .. } => "sphere",
            Shape::Box { .. } => "box",
            Shape::Cylinder { .. } => "cylinder",
            Shape::Capsule { .. } => "capsule",
            Shape::Convex { .. } => "convex",
        }
    }

    /// Checks that every size is finite and the shape has a volume.
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
        }
    }

    /// A parry shape of the same geometry (for queries parry offers and this crate does not).
    pub fn to_parry(&self) -> Option<SharedShape> {
        self.check().ok()?;
        Some(match self {
            Shape::Sphere { radius } => SharedShape::ball(*radius),
            Shape::Box { size } => SharedShape::cuboid(size[0] / 2.0, size[1] / 2.0, size[2] / 2.0),
            Shape::Cylinder { radius, length } => SharedShape::cylinder(length / 2.0, *radius),
            Shape::Capsule { radius, length } => SharedShape::capsule_z(length / 2.0, *radius),
            Shape::Convex { points } => {
                let pts: Vec<Point3<f64>> = points.iter().map(|p| Point3::from(*p)).collect();
                SharedShape::convex_hull(&pts)?
            }
        })
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
            _ => {
                let shape = self.to_parry()?;
                let sphere = shape.compute_local_bounding_sphere();
                let half_extents = match self {
                    Shape::Box { size } => Some(Vector3::from(*size) / 2.0),
                    _ => None,
                };
                Compiled {
                    center: local * sphere.center,
                    bound: sphere.radius,
                    geometry: Geometry::General {
                        local: *local,
                        shape,
                        half_extents,
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

/// A shape in the form the hot path uses, fixed in a parent frame (a link or the world).
#[derive(Clone)]
pub(crate) struct Compiled {
    /// Bounding-sphere centre in the parent frame.
    pub center: Point3<f64>,
    /// Bounding-sphere radius.
    pub bound: f64,
    pub geometry: Geometry,
}

#[derive(Clone)]
pub(crate) enum Geometry {
    /// A segment swept by a ball (a ball when `a == b`), end points in the parent frame:
    /// tested analytically.
    Round {
        a: Point3<f64>,
        b: Point3<f64>,
        radius: f64,
    },
    /// Any other convex shape at `local`: tested by parry, except boxes (`half_extents`)
    /// against round shapes, which are tested analytically.
    General {
        local: Isometry3<f64>,
        shape: SharedShape,
        half_extents: Option<Vector3<f64>>,
    },
}

impl std::fmt::Debug for Compiled {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Compiled")
            .field("center", &self.center)
            .field("bound", &self.bound)
            .finish_non_exhaustive()
    }
}

/// A compiled shape moved into the world frame.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Placed {
    /// Bounding-sphere centre.
    pub center: Point3<f64>,
    /// Bounding-sphere radius.
    pub bound: f64,
    /// Round shapes: segment ends; general shapes: unused.
    pub a: Point3<f64>,
    pub b: Point3<f64>,
    /// General shapes: the shape's pose; round shapes: unused.
    pub iso: Isometry3<f64>,
}

impl Default for Placed {
    fn default() -> Self {
        Placed {
            center: Point3::origin(),
            bound: 0.0,
            a: Point3::origin(),
            b: Point3::origin(),
            iso: Isometry3::identity(),
        }
    }
}

impl Compiled {
    /// Moves the shape by the parent frame's world pose.
    #[inline]
    pub fn place(&self, parent: &Isometry3<f64>, out: &mut Placed) {
        match &self.geometry {
            Geometry::Round { a, b, .. } => {
                out.a = parent * a;
                out.b = parent * b;
                out.center = nalgebra::center(&out.a, &out.b);
            }
            Geometry::General { local, .. } => {
                out.iso = parent * local;
                out.center = parent * self.center;
            }
        }
        out.bound = self.bound;
    }

    /// A parry shape and pose for a round shape placed at `p` (ball when degenerate).
    fn round_as_parry(p: &Placed, radius: f64) -> (Isometry3<f64>, RoundShape) {
        if p.a == p.b {
            (
                Isometry3::from_parts(Translation3::from(p.a.coords), Default::default()),
                RoundShape::Ball(Ball::new(radius)),
            )
        } else {
            (
                Isometry3::identity(),
                RoundShape::Capsule(Capsule::new(p.a, p.b, radius)),
            )
        }
    }
}

enum RoundShape {
    Ball(Ball),
    Capsule(Capsule),
}

impl RoundShape {
    fn shape(&self) -> &dyn ParryShape {
        match self {
            RoundShape::Ball(b) => b,
            RoundShape::Capsule(c) => c,
        }
    }
}

#[inline]
fn point_on(a: &Point3<f64>, b: &Point3<f64>, loc: SegmentPointLocation) -> Point3<f64> {
    match loc {
        SegmentPointLocation::OnVertex(0) => *a,
        SegmentPointLocation::OnVertex(_) => *b,
        SegmentPointLocation::OnEdge([u, v]) => Point3::from(a.coords * u + b.coords * v),
    }
}

/// Squared distance between segments `[a1, b1]` and `[a2, b2]`.
#[inline]
fn segment_distance_squared(
    a1: &Point3<f64>,
    b1: &Point3<f64>,
    a2: &Point3<f64>,
    b2: &Point3<f64>,
) -> f64 {
    let (l1, l2) = closest_points_segment_segment_with_locations_nD((a1, b1), (a2, b2));
    (point_on(a1, b1, l1) - point_on(a2, b2, l2)).norm_squared()
}

/// True when a round shape's bounding sphere lies outside one of a box's slabs: a cheap reject
/// for large boxes such as tables, which pass the bounding-sphere test for most bodies.
#[inline]
fn round_box_apart(round: &Placed, cuboid: &Placed, half: &Vector3<f64>) -> bool {
    let c = cuboid.iso.inverse_transform_point(&round.center);
    (0..3).any(|i| c[i].abs() > half[i] + round.bound)
}

/// Squared distance between the segment of a placed round shape and a placed box.
#[inline]
fn round_box_distance_squared(round: &Placed, cuboid: &Placed, half: &Vector3<f64>) -> f64 {
    let a = cuboid.iso.inverse_transform_point(&round.a);
    let b = cuboid.iso.inverse_transform_point(&round.b);
    segment_box_distance_squared(&a, &b, half)
}

/// Squared distance between the segment `[a, b]` and the box `|x_i| ≤ h_i`, exactly: the squared
/// distance is convex and piecewise quadratic along the segment, with pieces separated where the
/// segment crosses a face plane; each piece is minimised in closed form.
pub(crate) fn segment_box_distance_squared(
    a: &Point3<f64>,
    b: &Point3<f64>,
    h: &Vector3<f64>,
) -> f64 {
    let d = b - a;
    let excess = |t: f64| {
        let p = a + d * t;
        (0..3)
            .map(|i| {
                let e = p[i].abs() - h[i];
                if e > 0.0 { e * e } else { 0.0 }
            })
            .sum::<f64>()
    };
    let mut ts = [0.0f64; 8];
    ts[1] = 1.0;
    let mut n = 2;
    for i in 0..3 {
        if d[i] != 0.0 {
            for side in [-h[i], h[i]] {
                let t = (side - a[i]) / d[i];
                if t > 0.0 && t < 1.0 {
                    ts[n] = t;
                    n += 1;
                }
            }
        }
    }
    let ts = &mut ts[..n];
    ts.sort_unstable_by(f64::total_cmp);
    let mut best = f64::INFINITY;
    for w in ts.windows(2) {
        let (t0, t1) = (w[0], w[1]);
        let mid = a + d * (0.5 * (t0 + t1));
        let (mut num, mut den) = (0.0, 0.0);
        for i in 0..3 {
            let bound = if mid[i] > h[i] {
                h[i]
            } else if mid[i] < -h[i] {
                -h[i]
            } else {
                continue;
            };
            num += (bound - a[i]) * d[i];
            den += d[i] * d[i];
        }
        let t = if den > 0.0 {
            (num / den).clamp(t0, t1)
        } else {
            0.5 * (t0 + t1)
        };
        best = best.min(excess(t));
        if best == 0.0 {
            break;
        }
    }
    best
}

/// True when the bounding spheres of two placed shapes are disjoint.
#[inline(always)]
pub(crate) fn bounds_apart(p: &Placed, q: &Placed) -> bool {
    let r = p.bound + q.bound;
    (p.center - q.center).norm_squared() > r * r
}

/// Whether two placed shapes touch or overlap (call after [`bounds_apart`] said no).
#[inline]
pub(crate) fn intersects(c1: &Compiled, p1: &Placed, c2: &Compiled, p2: &Placed) -> bool {
    match (&c1.geometry, &c2.geometry) {
        (Geometry::Round { radius: r1, .. }, Geometry::Round { radius: r2, .. }) => {
            let r = r1 + r2;
            segment_distance_squared(&p1.a, &p1.b, &p2.a, &p2.b) <= r * r
        }
        (
            Geometry::Round { radius, .. },
            Geometry::General {
                half_extents: Some(h),
                ..
            },
        ) => {
            !round_box_apart(p1, p2, h) && round_box_distance_squared(p1, p2, h) <= radius * radius
        }
        (
            Geometry::General {
                half_extents: Some(h),
                ..
            },
            Geometry::Round { radius, .. },
        ) => {
            !round_box_apart(p2, p1, h) && round_box_distance_squared(p2, p1, h) <= radius * radius
        }
        (Geometry::Round { radius, .. }, Geometry::General { shape, .. }) => {
            let (iso, round) = Compiled::round_as_parry(p1, *radius);
            parry_intersects(&iso, round.shape(), &p2.iso, shape.as_ref())
        }
        (Geometry::General { shape, .. }, Geometry::Round { radius, .. }) => {
            let (iso, round) = Compiled::round_as_parry(p2, *radius);
            parry_intersects(&p1.iso, shape.as_ref(), &iso, round.shape())
        }
        (Geometry::General { shape: s1, .. }, Geometry::General { shape: s2, .. }) => {
            parry_intersects(&p1.iso, s1.as_ref(), &p2.iso, s2.as_ref())
        }
    }
}

fn parry_intersects(
    i1: &Isometry3<f64>,
    s1: &dyn ParryShape,
    i2: &Isometry3<f64>,
    s2: &dyn ParryShape,
) -> bool {
    // Every shape this crate builds is convex with a support map, which parry always supports.
    query::intersection_test(i1, s1, i2, s2).unwrap_or(true)
}

/// Signed distance between two placed shapes: the gap when apart, minus the penetration depth
/// when they overlap.
pub(crate) fn signed_distance(c1: &Compiled, p1: &Placed, c2: &Compiled, p2: &Placed) -> f64 {
    if let (Geometry::Round { radius: r1, .. }, Geometry::Round { radius: r2, .. }) =
        (&c1.geometry, &c2.geometry)
    {
        return segment_distance_squared(&p1.a, &p1.b, &p2.a, &p2.b).sqrt() - r1 - r2;
    }
    let round_box = match (&c1.geometry, &c2.geometry) {
        (
            Geometry::Round { radius, .. },
            Geometry::General {
                half_extents: Some(h),
                ..
            },
        ) => Some((round_box_distance_squared(p1, p2, h), *radius)),
        (
            Geometry::General {
                half_extents: Some(h),
                ..
            },
            Geometry::Round { radius, .. },
        ) => Some((round_box_distance_squared(p2, p1, h), *radius)),
        _ => None,
    };
    if let Some((squared, radius)) = round_box {
        if squared > 0.0 {
            return squared.sqrt() - radius;
        }
    }
    let own = |c: &Compiled, p: &Placed| -> (Isometry3<f64>, Option<RoundShape>) {
        match &c.geometry {
            Geometry::Round { radius, .. } => {
                let (iso, s) = Compiled::round_as_parry(p, *radius);
                (iso, Some(s))
            }
            Geometry::General { .. } => (p.iso, None),
        }
    };
    let (i1, r1) = own(c1, p1);
    let (i2, r2) = own(c2, p2);
    let s1: &dyn ParryShape = match (&r1, &c1.geometry) {
        (Some(r), _) => r.shape(),
        (None, Geometry::General { shape, .. }) => shape.as_ref(),
        (None, Geometry::Round { .. }) => unreachable!("round shapes always get a parry twin"),
    };
    let s2: &dyn ParryShape = match (&r2, &c2.geometry) {
        (Some(r), _) => r.shape(),
        (None, Geometry::General { shape, .. }) => shape.as_ref(),
        (None, Geometry::Round { .. }) => unreachable!("round shapes always get a parry twin"),
    };
    let gap = query::distance(&i1, s1, &i2, s2).unwrap_or(0.0);
    if gap > 0.0 {
        return gap;
    }
    query::contact(&i1, s1, &i2, s2, 0.0)
        .ok()
        .flatten()
        .map_or(0.0, |c| c.dist.min(0.0))
}

/// Converts a URDF `<geometry>` into a [`Shape`]; meshes are loaded by the caller.
pub(crate) fn from_urdf(geometry: &trm_kinematics::urdf_rs::Geometry) -> Option<Shape> {
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

#[cfg(test)]
mod tests {
    use super::*;

    fn placed(shape: &Shape, pose: Isometry3<f64>) -> (Compiled, Placed) {
        let c = shape.compile(&Isometry3::identity()).unwrap();
        let mut p = Placed::default();
        c.place(&pose, &mut p);
        (c, p)
    }

    fn at(x: f64, y: f64, z: f64) -> Isometry3<f64> {
        Isometry3::translation(x, y, z)
    }

    #[test]
    fn capsule_capsule_distance_is_segment_distance_minus_radii() {
        let cap = Shape::Capsule {
            radius: 0.1,
            length: 1.0,
        };
        let (c1, p1) = placed(&cap, at(0.0, 0.0, 0.0));
        let (c2, p2) = placed(&cap, at(0.5, 0.0, 0.0));
        assert!((signed_distance(&c1, &p1, &c2, &p2) - 0.3).abs() < 1e-12);
        assert!(!intersects(&c1, &p1, &c2, &p2));
        let (c3, p3) = placed(&cap, at(0.15, 0.0, 0.0));
        assert!((signed_distance(&c1, &p1, &c3, &p3) + 0.05).abs() < 1e-12);
        assert!(intersects(&c1, &p1, &c3, &p3));
    }

    #[test]
    fn analytic_and_parry_agree_on_round_pairs() {
        let cap = Shape::Capsule {
            radius: 0.05,
            length: 0.3,
        };
        let parry_cap = cap.to_parry().unwrap();
        for k in 0..50 {
            let t = k as f64 * 0.37;
            let pose = Isometry3::new(
                Vector3::new(0.1 * t.sin(), 0.08 * t.cos(), 0.05 * (2.0 * t).sin()),
                Vector3::new(t, 0.5 * t, -0.3 * t),
            );
            let (c1, p1) = placed(&cap, Isometry3::identity());
            let (c2, p2) = placed(&cap, pose);
            let ours = signed_distance(&c1, &p1, &c2, &p2);
            let theirs = query::distance(
                &Isometry3::identity(),
                parry_cap.as_ref(),
                &pose,
                parry_cap.as_ref(),
            )
            .unwrap();
            if ours > 0.0 {
                assert!((ours - theirs).abs() < 1e-9, "{ours} vs {theirs}");
            } else {
                assert_eq!(theirs, 0.0);
            }
            let hit = query::intersection_test(
                &Isometry3::identity(),
                parry_cap.as_ref(),
                &pose,
                parry_cap.as_ref(),
            )
            .unwrap();
            assert_eq!(intersects(&c1, &p1, &c2, &p2), hit);
        }
    }

    #[test]
    fn box_and_sphere_penetration_is_negative() {
        let table = Shape::Box {
            size: [1.0, 1.0, 0.1],
        };
        let ball = Shape::Sphere { radius: 0.1 };
        let (c1, p1) = placed(&table, at(0.0, 0.0, 0.0));
        let (c2, p2) = placed(&ball, at(0.0, 0.0, 0.1));
        assert!((signed_distance(&c1, &p1, &c2, &p2) + 0.05).abs() < 1e-9);
        let (c3, p3) = placed(&ball, at(0.0, 0.0, 0.3));
        assert!((signed_distance(&c1, &p1, &c3, &p3) - 0.15).abs() < 1e-9);
        assert!(intersects(&c1, &p1, &c2, &p2));
        assert!(!intersects(&c1, &p1, &c3, &p3));
    }

    #[test]
    fn segment_box_distance_matches_parry() {
        let cuboid = Shape::Box {
            size: [0.3, 0.2, 0.1],
        };
        let parry_box = cuboid.to_parry().unwrap();
        let h = Vector3::new(0.15, 0.1, 0.05);
        let mut state = 12345u64;
        let mut uniform = || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((state >> 11) as f64 / (1u64 << 53) as f64) * 0.8 - 0.4
        };
        for _ in 0..2000 {
            let a = Point3::new(uniform(), uniform(), uniform());
            let b = Point3::new(uniform(), uniform(), uniform());
            let ours = segment_box_distance_squared(&a, &b, &h).sqrt();
            let segment = parry3d_f64::shape::Segment::new(a, b);
            let theirs = query::distance(
                &Isometry3::identity(),
                &segment,
                &Isometry3::identity(),
                parry_box.as_ref(),
            )
            .unwrap();
            assert!((ours - theirs).abs() < 1e-9, "{a} {b}: {ours} vs {theirs}");
        }
    }

    #[test]
    fn degenerate_shapes_are_rejected() {
        for s in [
            Shape::Sphere { radius: 0.0 },
            Shape::Box {
                size: [1.0, -1.0, 1.0],
            },
            Shape::Cylinder {
                radius: 0.1,
                length: f64::NAN,
            },
            Shape::Capsule {
                radius: 0.1,
                length: -0.2,
            },
            Shape::Convex {
                points: vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 1.0, 0.0]],
            },
        ] {
            assert!(s.check().is_err(), "{s:?}");
            assert!(s.compile(&Isometry3::identity()).is_none());
        }
    }
}
