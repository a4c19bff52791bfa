//! Certified motion checks: sound on real models (a motion proved free has no colliding
//! configuration when sampled a thousand times finer than planners do; a collision is reported
//! at a configuration that collides), blind to nothing a coarse sampling misses, and honest
//! about grazing motions.

use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use trm_collision::prove::Prover;
use trm_collision::{
    Certificate, Certifier, CollisionModel, Contact, Levers, Shape, World, edge::distance,
};
use trm_kinematics::RobotModel;
use trm_kinematics::nalgebra::Isometry3;

fn model(file: &str) -> RobotModel {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../models")
        .join(file);
    RobotModel::load(path).unwrap()
}

/// Boxes and spheres scattered around the robot's base.
fn clutter(rng: &mut ChaCha8Rng, count: usize, reach: f64) -> World {
    let mut world = World::new();
    for i in 0..count {
        let shape = if i % 2 == 0 {
            Shape::Box {
                size: [
                    rng.random_range(0.05..0.3),
                    rng.random_range(0.05..0.3),
                    rng.random_range(0.05..0.3),
                ],
            }
        } else {
            Shape::Sphere {
                radius: rng.random_range(0.03..0.15),
            }
        };
        let p = [
            rng.random_range(-reach..reach),
            rng.random_range(-reach..reach),
            rng.random_range(-reach..reach),
        ];
        world
            .add(
                &format!("o{i}"),
                shape,
                Isometry3::translation(p[0], p[1], p[2]),
            )
            .unwrap();
    }
    world
}

/// Random motions among clutter: each certificate (the [`Certifier`]'s, or with `fast` the
/// [`Prover`]'s) checked against a dense sampling of the motion with the exact model. Returns
/// (free, colliding, unproved) counts.
fn soundness(robot: &RobotModel, motions: usize, seed: u64, fast: bool) -> [usize; 3] {
    let collision = CollisionModel::new(robot).unwrap();
    let active = robot.all_active();
    let mut certifier = Certifier::new(&collision, &active).unwrap();
    let mut prover = Prover::new(&collision, &active, World::new()).unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let (lower, upper) = active.bounds();
    let (mut poses, mut placed) = (robot.pose_buffer(), collision.placed_bodies());
    let mut colliding_at = |q: &[f64], world: &World| {
        active.forward(q, &mut poses).unwrap();
        collision.place(&poses, &mut placed);
        collision.is_colliding(&placed, world)
    };
    let mut counts = [0; 3];
    let mut done = 0;
    while done < motions {
        let world = clutter(&mut rng, 8, 0.8);
        let a = active.random(&mut rng);
        if colliding_at(&a, &world) {
            continue;
        }
        let step: Vec<f64> = (0..a.len()).map(|_| rng.random_range(-0.4..0.4)).collect();
        let b: Vec<f64> = (0..a.len())
            .map(|i| (a[i] + step[i]).clamp(lower[i], upper[i]))
            .collect();
        done += 1;
        let certificate = if fast {
            prover.set_world(world.clone());
            prover.segment(&a, &b).unwrap()
        } else {
            certifier.segment(&world, &a, &b).unwrap()
        };
        let at = |u: f64| -> Vec<f64> { a.iter().zip(&b).map(|(x, y)| x + u * (y - x)).collect() };
        match certificate {
            Certificate::Free => {
                // a thousand times finer than a planner's 1/32 rad
                let samples = (distance(&a, &b) / 3e-5).ceil() as usize;
                for s in 0..=samples {
                    let u = s as f64 / samples as f64;
                    assert!(
                        !colliding_at(&at(u), &world),
                        "proved free but colliding at {u}"
                    );
                }
                counts[0] += 1;
            }
            Certificate::Collides { at: u, pair } => {
                assert!(
                    colliding_at(&at(u), &world),
                    "no collision at {u}: {pair:?}"
                );
                counts[1] += 1;
            }
            Certificate::Unproved {
                at: u, clearance, ..
            } => {
                assert!(!colliding_at(&at(u), &world) && clearance < certifier.floor());
                counts[2] += 1;
            }
        }
    }
    counts
}

#[test]
fn proofs_hold_on_the_fitted_panda() {
    for fast in [false, true] {
        let counts = soundness(&model("panda/panda.ron"), 40, 1, fast);
        // both verdicts occur: the test can fail either way
        assert!(counts[0] >= 5 && counts[1] >= 5, "{counts:?}");
    }
}

#[test]
fn proofs_hold_on_the_icub_upper_body() {
    for fast in [false, true] {
        let counts = soundness(&model("icub_upper_body.ron"), 12, 2, fast);
        assert!(counts[0] >= 2 && counts[1] >= 2, "{counts:?}");
    }
}

/// The fast proofs on VAMP's sphere Panda (the model the planner's benchmark proves paths
/// of): sound, and both verdicts occur.
#[test]
fn fast_proofs_hold_on_the_sphere_panda() {
    let counts = soundness(&model("panda-mbm/panda_spherized.ron"), 80, 3, true);
    assert!(counts[0] >= 10 && counts[1] >= 5, "{counts:?}");
}

/// Wherever a padded model is free of a world, the model's every body keeps at least the
/// margin from every object, and its answers on the screen are its exact model's (its spheres
/// grown, not fitted again): on the iCub (capsules, boxes, spheres), the fitted Panda and the
/// Panda's mesh hulls. A margin that is not a positive distance is refused.
#[test]
fn a_padded_model_free_keeps_the_margin() {
    let files = [
        ("icub_upper_body.ron", 4, 24),
        ("panda/panda.ron", 5, 10),
        ("panda-mbm/panda.ron", 6, 10),
    ];
    for (file, seed, objects) in files {
        let robot = model(file);
        let collision = CollisionModel::new(&robot).unwrap();
        let active = robot.all_active();
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let world = clutter(&mut rng, objects, 0.6);
        let margin = 0.02;
        let padded = collision.padded(margin, &[]).unwrap();
        let mut screen = trm_collision::WorldChecker::new(&padded, &active, world.clone()).unwrap();
        let (mut poses, mut placed, mut grown) = (
            robot.pose_buffer(),
            collision.placed_bodies(),
            padded.placed_bodies(),
        );
        let (mut free, mut near) = (0, 0);
        for _ in 0..400 {
            let q = active.random(&mut rng);
            active.forward(&q, &mut poses).unwrap();
            collision.place(&poses, &mut placed);
            padded.place(&poses, &mut grown);
            let exact = !padded.any_world_collision(&grown, &world);
            assert_eq!(screen.free(&q), exact && !padded.any_self_collision(&grown));
            let closest = (0..collision.bodies().len())
                .flat_map(|b| (0..world.len()).map(move |o| (b, o)))
                .map(|(b, o)| collision.object_distance(&placed, b, &world, o))
                .fold(f64::INFINITY, f64::min);
            if exact {
                free += 1;
                assert!(closest >= margin - 1e-9, "{file}: {closest} < {margin}");
            } else if closest > 0.0 {
                near += 1;
            }
        }
        // free configurations, and some within the margin that the padding catches
        assert!(free >= 20 && near >= 5, "{file}: {free} free, {near} near");
        for bad in [0.0, -0.01, f64::NAN] {
            let e = collision.padded(bad, &[]).unwrap_err().to_string();
            assert!(e.contains("positive distance"), "{e}");
        }
    }
}

/// The fast proof finds the collision between two samples a planner would check, and proves
/// the same motion away from the post.
#[test]
fn a_fast_proof_finds_a_collision_between_samples() {
    let (robot, collision) = arm();
    let mut world = World::new();
    let post = Shape::Cylinder {
        radius: 0.005,
        length: 1.0,
    };
    world
        .add("post", post, Isometry3::translation(1.0, 0.0, 0.0))
        .unwrap();
    let mut prover = Prover::new(&collision, &robot.all_active(), world).unwrap();
    assert!(matches!(
        prover.segment(&[-0.1], &[0.1]).unwrap(),
        Certificate::Collides {
            pair: Contact::Object(0, 0),
            ..
        }
    ));
    assert!(prover.segment(&[0.2], &[1.5]).unwrap().is_free());
    // bad configurations are located errors: outside the limits, not a number, wrong length
    for (a, b, says) in [
        (vec![0.2], vec![9.0], "outside its limits"),
        (vec![f64::NAN], vec![0.2], "value 0 is NaN"),
        (vec![0.2], vec![f64::INFINITY], "value 0 is inf"),
        (
            vec![0.2, 0.1],
            vec![0.2],
            "2 values for 1 active coordinates",
        ),
    ] {
        let e = prover.segment(&a, &b).unwrap_err().to_string();
        assert!(e.contains(says), "{e}");
    }
}

/// A planar arm of one 1 m link (revolute about z) with a 5 cm sphere at its end.
fn arm() -> (RobotModel, CollisionModel) {
    let urdf = r#"<robot name="arm">
      <link name="base"/>
      <link name="a"><collision><origin xyz="1 0 0"/><geometry><sphere radius="0.05"/></geometry></collision></link>
      <joint name="j" type="revolute"><parent link="base"/><child link="a"/>
        <axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
    </robot>"#;
    let robot = RobotModel::from_urdf_str(urdf, "<arm>").unwrap();
    let collision = CollisionModel::new(&robot).unwrap();
    (robot, collision)
}

/// A thin post the arm's sphere sweeps through between two samples a planner would check: the
/// samples are free, the motion is not.
#[test]
fn a_collision_between_samples_is_found() {
    let (robot, collision) = arm();
    let mut world = World::new();
    world
        .add(
            "post",
            Shape::Cylinder {
                radius: 0.005,
                length: 1.0,
            },
            Isometry3::translation(1.0, 0.0, 0.0),
        )
        .unwrap();
    let active = robot.all_active();
    let mut certifier = Certifier::new(&collision, &active).unwrap();
    // ±0.1 rad: the sphere's centre 10 cm either side of the post, both ends free
    match certifier.segment(&world, &[-0.1], &[0.1]).unwrap() {
        Certificate::Collides { at, pair } => {
            assert_eq!(pair, Contact::Object(0, 0));
            assert!((at - 0.5).abs() < 0.3, "{at}");
        }
        other => panic!("{other:?}"),
    }
    // the same motion away from the post is proved
    assert!(certifier.segment(&world, &[0.2], &[1.5]).unwrap().is_free());
    let path = certifier
        .path(&world, &[vec![1.5], vec![0.2], vec![-0.2]])
        .unwrap();
    assert!(matches!(
        path.failure,
        Some((1, Certificate::Collides { .. }))
    ));
}

/// A motion that ends a tenth of the floor from an obstacle is not proved (and not called
/// colliding); with a floor below that gap it is proved.
#[test]
fn a_grazing_motion_is_unproved_not_free() {
    let (robot, collision) = arm();
    let mut world = World::new();
    // the sphere at q = 0 reaches x = 1.05; the wall starts 1e-7 m beyond
    world
        .add(
            "wall",
            Shape::Box {
                size: [0.1, 1.0, 1.0],
            },
            Isometry3::translation(1.05 + 1e-7 + 0.05, 0.0, 0.0),
        )
        .unwrap();
    let active = robot.all_active();
    let mut certifier = Certifier::new(&collision, &active).unwrap();
    match certifier.segment(&world, &[-0.5], &[0.0]).unwrap() {
        Certificate::Unproved { at, clearance, .. } => {
            assert!(at > 0.99, "{at}");
            assert!(clearance > 0.0 && clearance < 1e-6, "{clearance}");
        }
        other => panic!("{other:?}"),
    }
    let mut fine = certifier.with_floor(1e-8).unwrap();
    assert_eq!(
        fine.segment(&world, &[-0.5], &[0.0]).unwrap(),
        Certificate::Free
    );
}

/// Bad input: a wrong length, NaN, a floor that is not a positive distance.
#[test]
fn bad_input_is_an_error() {
    let (robot, collision) = arm();
    let mut certifier = Certifier::new(&collision, &robot.all_active()).unwrap();
    let world = World::new();
    let e = certifier
        .segment(&world, &[0.0, 1.0], &[0.0])
        .unwrap_err()
        .to_string();
    assert!(e.contains("2 values for 1 active"), "{e}");
    let e = certifier
        .path(&world, &[vec![0.0], vec![f64::NAN]])
        .unwrap_err()
        .to_string();
    assert!(e.contains("NaN"), "{e}");
    let e = certifier
        .segment(&world, &[0.0], &[3.5])
        .unwrap_err()
        .to_string();
    assert!(e.contains("outside") && e.contains("j"), "{e}");
    for floor in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        let e = certifier.clone().with_floor(floor).unwrap_err().to_string();
        assert!(e.contains("floor"), "{e}");
    }
}

/// The relative lever arms bound how fast two bodies' distance changes, on trm's Panda and the
/// iCub upper body (coupled motors, a shared torso).
#[test]
fn relative_levers_bound_distance_changes() {
    for file in ["panda/panda.ron", "icub_upper_body.ron"] {
        let robot = model(file);
        let collision = CollisionModel::new(&robot).unwrap();
        let active = robot.all_active();
        let levers = Levers::new(&collision, &active).unwrap();
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        let (mut poses, mut p0, mut p1) = (
            robot.pose_buffer(),
            collision.placed_bodies(),
            collision.placed_bodies(),
        );
        let bodies = collision.bodies();
        let mut lambda = vec![0.0; active.len()];
        let mut tightest = 0.0f64;
        for _ in 0..200 {
            let q0 = active.random(&mut rng);
            let q1: Vec<f64> = q0.iter().map(|x| x + rng.random_range(-0.2..0.2)).collect();
            active.forward(&q0, &mut poses).unwrap();
            collision.place(&poses, &mut p0);
            active.forward(&q1, &mut poses).unwrap();
            collision.place(&poses, &mut p1);
            for _ in 0..20 {
                let (a, b) = (
                    rng.random_range(0..bodies.len()),
                    rng.random_range(0..bodies.len()),
                );
                if bodies[a].link == bodies[b].link {
                    continue;
                }
                levers.relative_into(bodies[a].link, bodies[b].link, &mut lambda);
                let bound: f64 = lambda
                    .iter()
                    .zip(q0.iter().zip(&q1))
                    .map(|(l, (x, y))| l * (y - x).abs())
                    .sum();
                let change =
                    (collision.body_distance(&p1, a, b) - collision.body_distance(&p0, a, b)).abs();
                assert!(change <= bound + 1e-9, "{file}: {change} > {bound}");
                tightest = tightest.max(change / bound.max(1e-12));
            }
        }
        assert!(tightest > 0.2, "{file}: at most {tightest} of the bound");
    }
}
