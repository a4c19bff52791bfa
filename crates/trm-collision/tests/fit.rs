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

/// Sphere sets: a hull's surface sampled every `step` lies within `step` of a sample, and the
/// spheres (radii padded by `step`) enclose every point of the surface: checked on points drawn
/// on the hull's triangles, far denser than the samples. More spheres are tighter.
#[test]
fn sphere_sets_enclose_the_whole_hull_surface_and_tighten_with_more_spheres() {
    use trm_collision::fit::{fit_sphere_set, hull_surface_points};
    for kind in 0..3 {
        let points = cloud(kind, 7, 300);
        let step = 0.004;
        let surface = hull_surface_points(&points, step);
        assert!(surface.len() > points.len() / 4, "{}", surface.len());
        let dense = hull_surface_points(&points, step / 8.0);
        let mut largest = Vec::new();
        for count in [1, 4, 12] {
            let spheres = fit_sphere_set(&surface, count, step).unwrap();
            assert!(spheres.len() <= count && !spheres.is_empty());
            for p in &dense {
                let inside = spheres.iter().any(|(c, r)| (p - c).norm() <= r + 1e-12);
                assert!(inside, "kind {kind}, {count} spheres: {p} outside");
            }
            largest.push(spheres.iter().map(|s| s.1).fold(0.0, f64::max));
        }
        assert!(largest[2] < largest[0], "{largest:?}");
    }
    assert!(fit_sphere_set(&[], 3, 0.01).is_none());
    assert!(fit_sphere_set(&[Point3::new(f64::NAN, 0.0, 0.0)], 3, 0.01).is_none());
}
