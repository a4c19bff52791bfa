//! Spheres against a world's objects, one per lane: the screen and the exact answer agree with
//! the `f64` queries object by object, and bad input is refused.

use super::*;
use crate::{CollisionModel, Shape, World};
use nalgebra::{Isometry3, Vector3};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// The screen of VAMP's spherized Panda (any model's screen compiles a world the same way).
fn screen() -> FastModel {
    let file = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../models/panda-mbm/panda_spherized.ron"
    );
    let robot = trm_kinematics::RobotModel::load(file).unwrap();
    FastModel::new(&CollisionModel::new(&robot).unwrap()).unwrap()
}

/// One object of every kind about the unit cube's centre: a turned box, a sphere, a capsule, a
/// cylinder (through its bounding sphere), a convex hull, a triangle mesh and a point cloud.
fn every_kind(rng: &mut ChaCha8Rng) -> World {
    let mut world = World::new();
    let at =
        |x, y, z, roll: f64| Isometry3::new(Vector3::new(x, y, z), Vector3::new(roll, 0.3, 0.0));
    let tetra = vec![
        [0.0, 0.0, 0.0],
        [0.2, 0.0, 0.0],
        [0.0, 0.2, 0.0],
        [0.0, 0.0, 0.2],
    ];
    let board = Shape::Box {
        size: [0.4, 0.3, 0.02],
    };
    let objects = [
        (
            "box",
            Shape::Box {
                size: [0.3, 0.2, 0.1],
            },
            at(0.2, 0.2, 0.2, 0.7),
        ),
        (
            "ball",
            Shape::Sphere { radius: 0.08 },
            at(0.8, 0.2, 0.3, 0.0),
        ),
        (
            "capsule",
            Shape::Capsule {
                radius: 0.05,
                length: 0.3,
            },
            at(0.2, 0.8, 0.3, 1.1),
        ),
        (
            "can",
            Shape::Cylinder {
                radius: 0.06,
                length: 0.2,
            },
            at(0.8, 0.8, 0.3, 0.4),
        ),
        (
            "hull",
            Shape::Convex {
                points: tetra.clone(),
            },
            at(0.5, 0.5, 0.8, 0.2),
        ),
        (
            "mesh",
            Shape::Mesh {
                vertices: tetra,
                triangles: vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]],
            },
            at(0.2, 0.2, 0.8, -0.5),
        ),
        (
            "cloud",
            Shape::Points {
                points: board.surface_samples(1500, rng),
                radius: 0.004,
            },
            at(0.8, 0.5, 0.7, 0.9),
        ),
    ];
    for (name, shape, pose) in objects {
        world.add(name, shape, pose).unwrap();
    }
    world
}

/// On random spheres about objects of every kind, the screen's certain lanes touch and its
/// clear lanes do not (as [`World::sphere_touches`] says), and the exact answer is its
/// answer lane by lane.
#[test]
fn spheres_touch_what_the_exact_queries_touch() {
    let mut rng = ChaCha8Rng::seed_from_u64(31);
    let world = every_kind(&mut rng);
    let fast = screen().world(&world);
    let (mut certain, mut clear, mut uncertain, mut touching) = (0, 0, 0, 0);
    for round in 0..4000 {
        let n = 1 + round % FAST_LANES;
        let radius = if round % 10 == 0 {
            0.0
        } else {
            rng.random_range(0.0..0.1)
        };
        // about an object (its pose), or anywhere about them
        let centres: Vec<[f64; 3]> = (0..n)
            .map(|_| {
                let object = &world.objects()[rng.random_range(0..world.len())];
                let about = object.pose().translation.vector;
                let spread = if rng.random_bool(0.7) { 0.25 } else { 0.7 };
                std::array::from_fn(|k| about[k] + rng.random_range(-spread..spread))
            })
            .collect();
        let mut lanes = [[f32::NAN; FAST_LANES]; 3];
        for (l, c) in centres.iter().enumerate() {
            for k in 0..3 {
                lanes[k][l] = c[k] as f32;
            }
        }
        let verdict = fast.screen_spheres(&lanes, radius as f32);
        assert_eq!(verdict.colliding & verdict.uncertain, 0);
        let mut exact = 0;
        for (l, c) in centres.iter().enumerate() {
            let touches = world.sphere_touches(*c, radius).unwrap().is_some();
            exact |= u8::from(touches) << l;
            let bit = 1 << l;
            if verdict.colliding & bit != 0 {
                assert!(touches, "round {round}: {c:?} ({radius}) touches nothing");
                certain += 1;
            } else if verdict.uncertain & bit != 0 {
                uncertain += 1;
            } else {
                assert!(!touches, "round {round}: {c:?} ({radius}) touches");
                clear += 1;
            }
        }
        // the unused lanes are NaN: uncertain, never certain
        let unused = !(((1u16 << n) - 1) as LaneMask);
        assert_eq!(verdict.colliding & unused, 0);
        assert_eq!(verdict.uncertain & unused, unused);
        let answer = fast.spheres_touching(&world, &centres, radius).unwrap();
        assert_eq!(answer, exact, "round {round}");
        touching += exact.count_ones();
    }
    // both answers, and all three verdicts, were met
    assert!(
        certain > 1000 && clear > 1000 && touching > 1000,
        "{certain} {clear} {touching}"
    );
    assert!(uncertain > 0, "no lane within the margin");
}

/// A ball just inside or just outside contact with a box, a ball and a cloud's point: the
/// exact query tells them apart to the nanometre, and the screen never calls them wrongly.
#[test]
fn contact_is_measured_exactly() {
    let mut world = World::new();
    world
        .add("box", Shape::Box { size: [1.0; 3] }, Isometry3::identity())
        .unwrap();
    world
        .add(
            "ball",
            Shape::Sphere { radius: 0.1 },
            Isometry3::translation(0.0, 3.0, 0.0),
        )
        .unwrap();
    let cloud = Shape::Points {
        points: vec![[0.0, 0.0, 0.0]],
        radius: 0.01,
    };
    world
        .add("cloud", cloud, Isometry3::translation(0.0, 0.0, 3.0))
        .unwrap();
    let fast = screen().world(&world);
    let r = 0.05;
    for (object, surface) in [
        (0, [0.5 + r, 0.0, 0.0]),
        (1, [0.0, 3.1 + r, 0.0]),
        (2, [0.0, 0.0, 3.01 + r]),
    ] {
        for (shift, touches) in [(-1e-9, true), (1e-9, false)] {
            let mut c = surface;
            let k = if object == 0 { 0 } else { object };
            c[k] += shift;
            let expected = touches.then_some(object);
            assert_eq!(world.sphere_touches(c, r).unwrap(), expected, "{c:?}");
            assert_eq!(
                fast.spheres_touching(&world, &[c], r).unwrap(),
                u8::from(touches)
            );
        }
    }
}

/// NaN, an infinite or negative radius and more than a block of centres are refused, naming
/// the value; the unchecked query counts a lane it cannot measure as touching.
#[test]
fn sphere_queries_refuse_bad_input() {
    let mut rng = ChaCha8Rng::seed_from_u64(32);
    let world = every_kind(&mut rng);
    let fast = screen().world(&world);
    let far = [5.0, 5.0, 5.0];
    let message = |e: CollisionError| e.to_string();
    let nan = fast
        .spheres_touching(&world, &[far, [0.0, f64::NAN, 0.0]], 0.1)
        .unwrap_err();
    assert!(message(nan).contains("coordinate 1 of a sphere's centre"));
    for radius in [-0.1, f64::INFINITY, f64::NAN] {
        let e = world.sphere_touches(far, radius).unwrap_err();
        assert!(message(e).contains("radius"), "{radius}");
    }
    let e = fast
        .spheres_touching(&world, &[far; FAST_LANES + 1], 0.1)
        .unwrap_err();
    assert!(message(e).contains("at most 8"));
    assert_eq!(
        fast.spheres_touching(&world, &[far; FAST_LANES], 0.1)
            .unwrap(),
        0
    );
    assert_eq!(fast.spheres_touching(&world, &[], 0.1).unwrap(), 0);
    assert!(fast.spheres_touching(&world, &[], -0.1).is_err());
    let unmeasured = [far, [f64::NAN, 0.0, 0.0], far];
    assert_eq!(
        fast.spheres_touching_unchecked(&world, &unmeasured, 0.1),
        0b010
    );
}
