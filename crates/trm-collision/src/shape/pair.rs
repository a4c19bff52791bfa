//! Pairwise tests between placed shapes: a bounding-sphere reject, then spheres and capsules
//! analytically (segment distance minus radii), capsule/sphere against box by the exact
//! segment–box distance, everything else through parry's SAT/GJK.

use nalgebra::{Isometry3, Point3, Unit, Vector3};
use parry3d_f64::bounding_volume::Aabb;
use parry3d_f64::query;
use parry3d_f64::query::details::closest_points_segment_segment_with_locations_nD;
use parry3d_f64::query::gjk::{self, CSOPoint, GJKResult, VoronoiSimplex};
use std::sync::Arc;

use parry3d_f64::shape::{SegmentPointLocation, Shape as ParryShape, SharedShape, SupportMap};

use super::compiled::{Axial, Compiled, Geometry, Placed, RoundShape};
use super::hull::HullWalk;
use super::segment_box::segment_box_distance_squared;

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
pub(super) fn segment_distance_squared(
    a1: &Point3<f64>,
    b1: &Point3<f64>,
    a2: &Point3<f64>,
    b2: &Point3<f64>,
) -> f64 {
    let (l1, l2) = closest_points_segment_segment_with_locations_nD((a1, b1), (a2, b2));
    (point_on(a1, b1, l1) - point_on(a2, b2, l2)).norm_squared()
}

/// True when a sphere lies outside one of a box's slabs: a cheap reject for large boxes such as
/// tables, which pass the bounding-sphere test for most bodies.
#[inline]
fn sphere_box_apart(
    center: &Point3<f64>,
    radius: f64,
    cuboid: &Placed,
    half: &Vector3<f64>,
) -> bool {
    let c = cuboid.iso.inverse_transform_point(center);
    (0..3).any(|i| c[i].abs() > half[i] + radius)
}

#[inline]
fn round_box_apart(round: &Placed, cuboid: &Placed, half: &Vector3<f64>) -> bool {
    sphere_box_apart(&round.center, round.bound, cuboid, half)
}

/// True when a sphere cannot touch a placed shape: it misses the shape's bounding sphere or,
/// for a box, one of its slabs.
#[inline]
pub(crate) fn sphere_apart(center: &Point3<f64>, radius: f64, c: &Compiled, p: &Placed) -> bool {
    let r = radius + p.bound;
    (center - p.center).norm_squared() > r * r
        || match &c.geometry {
            Geometry::General {
                half_extents: Some(h),
                ..
            } => sphere_box_apart(center, radius, p, h),
            _ => false,
        }
}

/// Squared distance between the segment of a placed round shape and a placed box.
#[inline]
fn round_box_distance_squared(round: &Placed, cuboid: &Placed, half: &Vector3<f64>) -> f64 {
    let a = cuboid.iso.inverse_transform_point(&round.a);
    let b = cuboid.iso.inverse_transform_point(&round.b);
    segment_box_distance_squared(&a, &b, half)
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
    // (clouds are general shapes without box extents: only those arms ask for them)
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
        (
            Geometry::Round { radius, .. },
            Geometry::General {
                shape, walk, axial, ..
            },
        ) => {
            if let Some(touch) = cloud_touches(c1, p1, c2, p2) {
                return touch;
            }
            round_touches(p1, *radius, shape, walk, axial, p2)
        }
        (
            Geometry::General {
                shape, walk, axial, ..
            },
            Geometry::Round { radius, .. },
        ) => {
            if let Some(touch) = cloud_touches(c2, p2, c1, p1) {
                return touch;
            }
            round_touches(p2, *radius, shape, walk, axial, p1)
        }
        (
            Geometry::General {
                shape: s1,
                half_extents: h1,
                walk: w1,
                ..
            },
            Geometry::General {
                shape: s2,
                half_extents: h2,
                walk: w2,
                ..
            },
        ) => {
            if let Some(touch) =
                cloud_touches(c1, p1, c2, p2).or_else(|| cloud_touches(c2, p2, c1, p1))
            {
                return touch;
            }
            // boxes: each bounding sphere against the other's slabs before SAT/GJK
            let apart = h2.is_some_and(|h| sphere_box_apart(&p1.center, p1.bound, p2, &h))
                || h1.is_some_and(|h| sphere_box_apart(&p2.center, p2.bound, p1, &h));
            if apart {
                return false;
            }
            // hulls: GJK with their walked support points; other pairs as parry chooses
            match (
                w1.is_some() || w2.is_some(),
                support(s1, w1),
                support(s2, w2),
            ) {
                (true, Some(g1), Some(g2)) => support_maps_intersect(&p1.iso, g1, &p2.iso, g2),
                _ => parry_intersects(&p1.iso, s1.as_ref(), &p2.iso, s2.as_ref()),
            }
        }
    }
}

/// Whether `c1` touches the point cloud `c2` (a ball about each point), by the points near it
/// in the cloud's grid: the shape's distance to each, exact (a segment's for round shapes,
/// parry's point query for the others). `None` when `c2` is no cloud, or `c1` is one too.
fn cloud_touches(c1: &Compiled, p1: &Placed, c2: &Compiled, p2: &Placed) -> Option<bool> {
    let Geometry::General { shape, .. } = &c2.geometry else {
        return None;
    };
    let grid = shape.grid.as_ref()?;
    let r = grid.radius;
    // the other shape's bounding sphere in the cloud's frame
    let center = p2.iso.inverse_transform_point(&p1.center);
    let reach = p1.bound + r;
    Some(match &c1.geometry {
        Geometry::Round { radius, .. } => {
            let touch = (radius + r) * (radius + r);
            grid.any_near(&center, reach, |q| {
                let q = p2.iso * q;
                segment_distance_squared(&p1.a, &p1.b, &q, &q) <= touch
            })
        }
        Geometry::General { shape: s1, .. } => {
            if s1.grid.is_some() {
                return None;
            }
            grid.any_near(&center, reach, |q| {
                s1.distance_to_point(&p1.iso, &(p2.iso * q), true) <= r
            })
        }
    })
}

/// A hull's walked support points, else the shape's own support map (if it has one).
fn support<'a>(
    shape: &'a SharedShape,
    walk: &'a Option<Arc<HullWalk>>,
) -> Option<&'a dyn SupportMap> {
    match walk {
        Some(walk) => Some(&**walk),
        None => shape.as_support_map(),
    }
}

/// GJK's intersection test of two support-mapped shapes at their poses.
/// A round shape (segment `p1.a`–`p1.b` swept by `radius`) against a shape between two
/// capsules about its axis ([`Axial`]), placed at `p2`: apart when it misses the enclosing
/// capsule, touching when it reaches into the held one, each by more than [`DECIDED`];
/// `None` (ask GJK, as without them) otherwise — so the answers are GJK's to the last case.
#[inline]
fn round_axial(p1: &Placed, radius: f64, p2: &Placed, axial: &Axial) -> Option<bool> {
    let reach = radius + axial.radius;
    let along = |half: f64| {
        let (a, b) = (Point3::new(0.0, -half, 0.0), Point3::new(0.0, half, 0.0));
        segment_distance_squared(&p1.a, &p1.b, &(p2.iso * a), &(p2.iso * b))
    };
    if along(axial.outer) > (reach + DECIDED).powi(2) {
        return Some(false);
    }
    match axial.inner {
        Some(inner) if reach > DECIDED && along(inner) < (reach - DECIDED).powi(2) => Some(true),
        _ => None,
    }
}

/// Whether a round shape placed at `round` (its segment swept by `radius`) touches a general
/// shape placed at `general` that is no cloud: a cylinder (`axial`) through its capsules, then
/// its core's exact distance ([`core_cylinder_distance`]); anything flat-sided by its core's
/// distance ([`core_within`]).
fn round_touches(
    round: &Placed,
    radius: f64,
    shape: &SharedShape,
    walk: &Option<Arc<HullWalk>>,
    axial: &Option<Axial>,
    general: &Placed,
) -> bool {
    match axial {
        Some(axial) => round_axial(round, radius, general, axial).unwrap_or_else(|| {
            // a distance that is not a number touches: never called free
            let d = core_cylinder_distance(round, general, axial);
            d <= radius || d.is_nan()
        }),
        None => core_within(round, radius, shape, walk, general),
    }
}

/// Golden-section steps of [`core_cylinder_distance`]: the bracket shrinks to 0.618⁸⁰ ≈
/// 2·10⁻¹⁷ of the segment, below the last bit of its coordinates.
const GOLDEN_STEPS: usize = 80;

/// The distance from the core of a round shape placed at `round` (its segment, or its centre)
/// to the solid cylinder placed at `cylinder` (`axial`: about its local y axis, half height
/// `outer`, radius `radius`), 0 where they meet. A point's distance to the cylinder is exact
/// (radial and axial excess, each clamped at 0), and along the segment it is a convex function
/// of the place (the distance to a convex set), so a golden-section search finds its least
/// value to the last bit, where GJK on the curved side stalls near contact (parry 0.25 gave 0
/// for capsules 0.2–0.5 µm from a cylinder, and 4.5 µm for one 0.2 µm away).
fn core_cylinder_distance(round: &Placed, cylinder: &Placed, axial: &Axial) -> f64 {
    let a = cylinder.iso.inverse_transform_point(&round.a);
    let b = cylinder.iso.inverse_transform_point(&round.b);
    let at = |t: f64| {
        let p = a + t * (b - a);
        let radial = (p.x.hypot(p.z) - axial.radius).max(0.0);
        let along = (p.y.abs() - axial.outer).max(0.0);
        radial.hypot(along)
    };
    if a == b {
        return at(0.0);
    }
    let golden = (5f64.sqrt() - 1.0) / 2.0;
    let (mut lo, mut hi) = (0.0, 1.0);
    let (mut x1, mut x2) = (hi - golden * (hi - lo), lo + golden * (hi - lo));
    let (mut f1, mut f2) = (at(x1), at(x2));
    for _ in 0..GOLDEN_STEPS {
        if f1 <= f2 {
            (hi, x2, f2) = (x2, x1, f1);
            x1 = hi - golden * (hi - lo);
            f1 = at(x1);
        } else {
            (lo, x1, f1) = (x1, x2, f2);
            x2 = lo + golden * (hi - lo);
            f2 = at(x2);
        }
    }
    f1.min(f2).min(at(0.0)).min(at(1.0))
}

/// Whether the core of a round shape placed at `round` lies within `radius` of a flat-sided
/// general shape placed at `general` ([`core_distance`] ≤ `radius`), with GJK's early exits:
/// a support plane farther than `radius` (apart) or the core touching the shape; the full
/// distance only when GJK ends between the two. A triangle mesh: each triangle whose box
/// meets the core's grown by `radius`.
fn core_within(
    round: &Placed,
    radius: f64,
    shape: &SharedShape,
    walk: &Option<Arc<HullWalk>>,
    general: &Placed,
) -> bool {
    let (frame, core) = Compiled::round_core(round);
    let pos12 = frame.inv_mul(&general.iso);
    let within = |g: &dyn SupportMap| {
        let dir =
            Unit::try_new(pos12.translation.vector, f64::EPSILON).unwrap_or(Vector3::x_axis());
        let mut simplex = VoronoiSimplex::new();
        simplex.reset(CSOPoint::from_shapes(&pos12, &core, g, &dir));
        match gjk::closest_points(&pos12, &core, g, radius, false, &mut simplex) {
            GJKResult::Intersection => true,
            // a support plane farther than `radius` (GJK gives up after 100 iterations with
            // the x axis: asked again below)
            GJKResult::NoIntersection(axis) if axis != Vector3::x_axis() => false,
            // near `radius`, or GJK stalled: the distance itself
            _ => query::details::distance_support_map_support_map(&pos12, &core, g) <= radius,
        }
    };
    if let Some(g) = support(shape, walk) {
        return within(g);
    }
    let Some(mesh) = shape.as_trimesh() else {
        return core_distance(round, shape, walk, general) <= radius;
    };
    // the core's box grown by the radius, in the mesh's frame
    let (a, b) = (
        general.iso.inverse_transform_point(&round.a),
        general.iso.inverse_transform_point(&round.b),
    );
    let grow = Vector3::repeat(radius);
    let reach = Aabb::new(a.inf(&b) - grow, a.sup(&b) + grow);
    mesh.bvh()
        .intersect_aabb(&reach)
        .any(|t| within(&mesh.triangle(t)))
}

/// The distance from the core of a round shape placed at `round` (its segment, or its centre)
/// to a flat-sided general shape placed at `general` (0 where they touch): GJK between a
/// segment and a polytope or a triangle ends on their exact features, where GJK on the swept
/// shape itself stalls micrometres from contact (parry 0.25 missed penetrations of a capsule
/// into a triangle of up to 13 µm). Not for curved shapes: against a cylinder's side GJK's
/// distance strays by micrometres too.
fn core_distance(
    round: &Placed,
    shape: &SharedShape,
    walk: &Option<Arc<HullWalk>>,
    general: &Placed,
) -> f64 {
    let (frame, core) = Compiled::round_core(round);
    match support(shape, walk) {
        Some(g) => {
            query::details::distance_support_map_support_map(&frame.inv_mul(&general.iso), &core, g)
        }
        // triangle meshes and compounds: their parts' distances, through their trees
        None => query::distance(&frame, &core, &general.iso, shape.as_ref()).unwrap_or(0.0),
    }
}

/// How far from touching the analytic tests in front of GJK decide (1 µm: far beyond GJK's
/// own tolerance, so that GJK answers every case it might answer otherwise).
const DECIDED: f64 = 1e-6;

fn support_maps_intersect(
    i1: &Isometry3<f64>,
    g1: &dyn SupportMap,
    i2: &Isometry3<f64>,
    g2: &dyn SupportMap,
) -> bool {
    query::details::intersection_test_support_map_support_map(&i1.inv_mul(i2), g1, g2)
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

/// [`signed_distance`] of two placed shapes, faster for convex hulls (GJK and EPA over the
/// hulls' vertex walks: parry's polyhedra scan every vertex per support point); `touching`
/// says whether they touch ([`intersects`]).
pub(crate) fn hull_signed_distance(
    c1: &Compiled,
    p1: &Placed,
    c2: &Compiled,
    p2: &Placed,
    touching: bool,
) -> f64 {
    if let (Geometry::General { walk: Some(w1), .. }, Geometry::General { walk: Some(w2), .. }) =
        (&c1.geometry, &c2.geometry)
    {
        let pos12 = p1.iso.inv_mul(&p2.iso);
        return if touching {
            query::details::contact_support_map_support_map(&pos12, &**w1, &**w2, 0.0)
                .map_or(0.0, |c| c.dist.min(0.0))
        } else {
            query::details::distance_support_map_support_map(&pos12, &**w1, &**w2)
        };
    }
    signed_distance(c1, p1, c2, p2)
}

/// Signed distance between two placed shapes: the gap when apart, minus the penetration depth
/// when they overlap.
pub(crate) fn signed_distance(c1: &Compiled, p1: &Placed, c2: &Compiled, p2: &Placed) -> f64 {
    if let (Geometry::Round { radius: r1, .. }, Geometry::Round { radius: r2, .. }) =
        (&c1.geometry, &c2.geometry)
    {
        return segment_distance_squared(&p1.a, &p1.b, &p2.a, &p2.b).sqrt() - r1 - r2;
    }
    // a round shape against a general one, the round one first
    let round_general = match (&c1.geometry, &c2.geometry) {
        (Geometry::Round { radius, .. }, Geometry::General { .. }) => Some((p1, *radius, c2, p2)),
        (Geometry::General { .. }, Geometry::Round { radius, .. }) => Some((p2, *radius, c1, p1)),
        _ => None,
    };
    if let Some(distance) = round_general
        .and_then(|(round, radius, general, at)| round_signed_distance(round, radius, general, at))
    {
        return distance;
    }
    with_parry(c1, p1, c2, p2, |i1, s1, i2, s2| {
        // closest points, not `query::distance`: parry 0.25's cuboid–cuboid distance
        // overestimates the gap (dimforge/parry#431)
        if let Ok(query::ClosestPoints::WithinMargin(a, b)) =
            query::closest_points(i1, s1, i2, s2, f64::MAX)
        {
            return (a - b).norm();
        }
        query::contact(i1, s1, i2, s2, 0.0)
            .ok()
            .flatten()
            .map_or(0.0, |c| c.dist.min(0.0))
    })
}

/// The signed distance between a round shape placed at `round` (its segment swept by
/// `radius`) and a general shape `general` placed at `at`, where it needs no parry: a box by
/// the segment's exact distance, a cylinder ([`core_cylinder_distance`]) or a flat-sided shape
/// ([`core_distance`]; GJK's distance to a cylinder's curved side strays micrometres) by its
/// core's, each while the core stays out (the distance less the radius is then the depth too,
/// where the radius reaches in). `None` otherwise: a cloud, or the core inside.
fn round_signed_distance(
    round: &Placed,
    radius: f64,
    general: &Compiled,
    at: &Placed,
) -> Option<f64> {
    let Geometry::General {
        shape,
        walk,
        axial,
        half_extents,
        ..
    } = &general.geometry
    else {
        return None;
    };
    if let Some(h) = half_extents {
        let squared = round_box_distance_squared(round, at, h);
        if squared > 0.0 {
            return Some(squared.sqrt() - radius);
        }
    }
    let core = match axial {
        Some(axial) => core_cylinder_distance(round, at, axial),
        None if shape.grid.is_none() => core_distance(round, shape, walk, at),
        None => return None,
    };
    (core > 0.0).then_some(core - radius)
}

/// Calls `f` with both placed shapes in parry's form (round shapes get their parry twin).
fn with_parry<R>(
    c1: &Compiled,
    p1: &Placed,
    c2: &Compiled,
    p2: &Placed,
    f: impl FnOnce(&Isometry3<f64>, &dyn ParryShape, &Isometry3<f64>, &dyn ParryShape) -> R,
) -> R {
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
    f(&i1, s1, &i2, s2)
}

/// Closest points of two placed shapes (world frame).
pub(crate) struct Closest {
    /// Signed distance.
    pub distance: f64,
    /// On shape 1.
    pub point1: Point3<f64>,
    /// On shape 2.
    pub point2: Point3<f64>,
    /// Unit normal from 1 towards 2.
    pub normal: Vector3<f64>,
}

/// Closest points of two placed shapes whose signed distance is below `margin`; `None` when
/// they are farther apart (bounding spheres first).
pub(crate) fn proximity(
    c1: &Compiled,
    p1: &Placed,
    c2: &Compiled,
    p2: &Placed,
    margin: f64,
) -> Option<Closest> {
    if (p1.center - p2.center).norm() - p1.bound - p2.bound >= margin {
        return None;
    }
    if let (Geometry::Round { radius: r1, .. }, Geometry::Round { radius: r2, .. }) =
        (&c1.geometry, &c2.geometry)
    {
        // exact: the segments' closest points, moved out by the radii
        let (l1, l2) =
            closest_points_segment_segment_with_locations_nD((&p1.a, &p1.b), (&p2.a, &p2.b));
        let (s1, s2) = (point_on(&p1.a, &p1.b, l1), point_on(&p2.a, &p2.b, l2));
        let between = s2 - s1;
        let length = between.norm();
        let distance = length - r1 - r2;
        if distance >= margin {
            return None;
        }
        // coincident axes: any direction separates them
        let normal = if length > 1e-12 {
            between / length
        } else {
            Vector3::x()
        };
        return Some(Closest {
            distance,
            point1: s1 + normal * *r1,
            point2: s2 - normal * *r2,
            normal,
        });
    }
    with_parry(c1, p1, c2, p2, |i1, s1, i2, s2| {
        let c = query::contact(i1, s1, i2, s2, margin).ok().flatten()?;
        (c.dist < margin).then(|| Closest {
            distance: c.dist,
            point1: c.point1,
            point2: c.point2,
            normal: c.normal1.into_inner(),
        })
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shape::Shape;
    use rand::{RngExt, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// Balls and capsules against cylinders, both ways round: the enclosing and held capsules
    /// answer as parry's GJK does, and each of the three outcomes (apart, touching, ask GJK)
    /// is reached.
    #[test]
    fn round_shapes_against_cylinders_answer_as_parry() {
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        let mut outcomes = [0usize; 3];
        for k in 0..20_000 {
            let cylinder = Shape::Cylinder {
                radius: rng.random_range(0.005..0.1),
                length: rng.random_range(0.005..0.4),
            };
            let radius = rng.random_range(0.005..0.08);
            let round = if k % 4 == 0 {
                Shape::Sphere { radius }
            } else {
                Shape::Capsule {
                    radius,
                    length: rng.random_range(0.01..0.3),
                }
            };
            let mut pose = |spread: f64| {
                let t = Vector3::from_fn(|_, _| rng.random_range(-spread..spread));
                let axis = Vector3::from_fn(|_, _| rng.random_range(-3.0..3.0));
                Isometry3::new(t, axis)
            };
            let (c1, c2) = (
                round.compile(&pose(0.1)).unwrap(),
                cylinder.compile(&pose(0.1)).unwrap(),
            );
            let (mut p1, mut p2) = (Placed::default(), Placed::default());
            c1.place(&pose(0.15), &mut p1);
            c2.place(&pose(0.15), &mut p2);
            let Geometry::General {
                shape,
                axial: Some(axial),
                ..
            } = &c2.geometry
            else {
                panic!("a cylinder compiles with its capsules");
            };
            let (iso, r) = Compiled::round_as_parry(&p1, radius);
            let depth = query::contact(&iso, r.shape(), &p2.iso, shape.as_ref(), 1e-9)
                .unwrap()
                .map(|c| c.dist);
            if depth.is_some_and(|d| d.abs() < 1e-12) {
                continue;
            }
            let parry = parry_intersects(&iso, r.shape(), &p2.iso, shape.as_ref());
            assert_eq!(intersects(&c1, &p1, &c2, &p2), parry, "case {k}");
            assert_eq!(intersects(&c2, &p2, &c1, &p1), parry, "case {k}");
            outcomes[match round_axial(&p1, radius, &p2, axial) {
                Some(false) => 0,
                Some(true) => 1,
                None => 2,
            }] += 1;
        }
        assert!(outcomes.iter().all(|&n| n > 200), "{outcomes:?}");
    }
}
