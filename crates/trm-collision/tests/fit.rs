//! Fitted proxies enclose every point and pick the primitive the points' shape calls for.

use proptest::prelude::*;
use trm_collision::Shape;
use trm_collision::fit::{fit, worst_outside};
use trm_kinematics::nalgebra::{Isometry3, Point3, UnitQuaternion, Vector3};

/// Points on a rotated, shifted box, rod (a capsule's surface) and ball.
fn cloud(kind: usize, seed: u64, n: usize) -> Vec<Point3<f64>> {
    let mut state = seed
        .wrapping_mul(6364136223846793005)
        .wrapping_add(1442695040888963407);
    let mut next = || {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((state >> 11) as f64) / ((1u64 << 53) as f64) * 2.0 - 1.0
    };
    let pose = Isometry3::from_parts(
        Vector3::new(0.1, -0.05, 0.2).into(),
        UnitQuaternion::from_euler_angles(0.3, -0.7, 1.1),
    );
    (0..n)
        .map(|_| {
            let v = Vector3::new(next(), next(), next());
            let p = match kind {
                // a flat box 6 × 4 × 1 cm
                0 => Vector3::new(0.03 * v.x.signum(), 0.02 * v.y, 0.005 * v.z),
                // a rod: a ball of radius 1.5 cm swept over 12 cm
                1 => {
                    let w = next();
                    v.normalize() * 0.015 + Vector3::new(0.0, 0.0, 0.06 * w)
                }
                // a ball of radius 3 cm
                _ => v.normalize() * 0.03,
            };
            pose * Point3::from(p)
        })
        .collect()
}

#[test]
fn each_shape_is_fitted_by_its_own_primitive_tightly() {
    for (kind, want) in [(0, "box"), (1, "capsule"), (2, "sphere")] {
        let points = cloud(kind, 7, 2000);
        let fits = fit(&points).unwrap();
        let best = fits.best();
        assert_eq!(best.shape.kind(), want, "{fits:?}");
        for f in [&fits.sphere, &fits.capsule, &fits.cuboid] {
            assert!(worst_outside(f, &points) <= 1e-9, "{f:?}");
        }
        // within 25 % of the hull's volume for the matching primitive
        assert!(
            best.volume <= 1.25 * fits.hull_volume,
            "{want}: {} vs hull {}",
            best.volume,
            fits.hull_volume
        );
    }
    // the rod's capsule: radius and length close to the truth
    let fits = fit(&cloud(1, 3, 600)).unwrap();
    if let Shape::Capsule { radius, length } = fits.capsule.shape {
        assert!(
            (radius - 0.015).abs() < 1e-3 && (length - 0.12).abs() < 5e-3,
            "{radius} {length}"
        );
    } else {
        panic!("{:?}", fits.capsule);
    }
    assert!(fit(&[]).is_none());
    assert!(fit(&[Point3::new(f64::NAN, 0.0, 0.0)]).is_none());
    // one point: tiny primitives that still hold it
    let one = [Point3::new(0.1, 0.2, 0.3)];
    let fits = fit(&one).unwrap();
    assert!(worst_outside(fits.best(), &one) <= 1e-9);
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]
    /// Any cloud: every fit encloses every point.
    #[test]
    fn every_fit_encloses_every_point(points in prop::collection::vec(
        (-0.2f64..0.2, -0.2f64..0.2, -0.2f64..0.2), 1..60)
    ) {
        let points: Vec<Point3<f64>> = points.into_iter().map(|(x, y, z)| Point3::new(x, y, z)).collect();
        let fits = fit(&points).unwrap();
        for f in [&fits.sphere, &fits.capsule, &fits.cuboid] {
            prop_assert!(worst_outside(f, &points) <= 1e-9, "{:?}", f);
        }
    }
}

/// Sphere sets enclose the whole convex hull, inside included: checked on its vertices and on
/// 20 000 random convex combinations of two, three and four of them (surface and inside), for
/// 1, 4 and 12 spheres; more spheres are tighter; a flat cloud and a single point are covered
/// too.
#[test]
fn sphere_sets_enclose_every_point_of_the_hull_and_tighten_with_more_spheres() {
    use trm_collision::fit::fit_convex_spheres;
    let covered = |spheres: &[(Point3<f64>, f64)], p: &Point3<f64>| {
        spheres.iter().any(|(c, r)| (p - c).norm() <= *r)
    };
    for kind in 0..3 {
        let points = cloud(kind, 7, 300);
        let (vertices, _) = parry3d_f64::transformation::convex_hull(&points);
        let weights = cloud(2, 11, 20_000);
        let mut largest = Vec::new();
        for count in [1, 4, 12] {
            let spheres = fit_convex_spheres(&points, count).unwrap();
            assert!(spheres.len() <= count && !spheres.is_empty());
            assert_eq!(
                spheres.len(),
                count,
                "kind {kind}: a solid can always be cut"
            );
            for p in &vertices {
                assert!(
                    covered(&spheres, p),
                    "kind {kind}, {count} spheres: vertex {p}"
                );
            }
            for (k, w) in weights.iter().enumerate() {
                // two to four vertices mixed with positive weights
                let n = 2 + k % 3;
                let w = [w.x.abs() + 1e-3, w.y.abs() + 1e-3, w.z.abs() + 1e-3, 0.5];
                let total: f64 = w[..n].iter().sum();
                let p = (0..n).fold(Point3::origin(), |s, i| {
                    let v = vertices[(k * 7 + i * 31) % vertices.len()];
                    s + v.coords * (w[i] / total)
                });
                assert!(
                    covered(&spheres, &p),
                    "kind {kind}, {count} spheres: {p} outside"
                );
            }
            largest.push(spheres.iter().map(|s| s.1).fold(0.0, f64::max));
        }
        assert!(largest[2] < largest[0], "{largest:?}");
    }
    // flat: a square; a point
    let square: Vec<Point3<f64>> = [(0.0, 0.0), (0.1, 0.0), (0.0, 0.1), (0.1, 0.1)]
        .iter()
        .map(|&(x, y)| Point3::new(x, y, 0.0))
        .collect();
    let spheres = fit_convex_spheres(&square, 4).unwrap();
    assert!(square.iter().all(|p| covered(&spheres, p)));
    assert!(covered(&spheres, &Point3::new(0.05, 0.05, 0.0)));
    let point = [Point3::new(0.1, 0.2, 0.3)];
    assert_eq!(fit_convex_spheres(&point, 3).unwrap().len(), 1);
    assert!(fit_convex_spheres(&[], 3).is_none());
    assert!(fit_convex_spheres(&[Point3::new(f64::NAN, 0.0, 0.0)], 3).is_none());
}
