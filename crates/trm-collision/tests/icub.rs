//! Known colliding and known free configurations of the shipped 41-DOF iCub, and agreement of
//! the fast path with plain parry queries.

use proptest::prelude::*;
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use trm_collision::{CollisionModel, Other, PlacedBodies, Shape, World};
use trm_kinematics::nalgebra::{Isometry3, Point3};
use trm_kinematics::{PoseBuffer, RobotModel};

struct Icub {
    robot: RobotModel,
    collision: CollisionModel,
    poses: PoseBuffer,
    placed: PlacedBodies,
}

impl Icub {
    fn new() -> Self {
        let robot = trm_models::icub_upper_body();
        let collision = CollisionModel::new(&robot).unwrap();
        Icub {
            poses: robot.pose_buffer(),
            placed: collision.placed_bodies(),
            robot,
            collision,
        }
    }

    fn home(&self) -> Vec<f64> {
        self.robot.posture("home").unwrap().to_vec()
    }

    fn set(&self, q: &mut [f64], motor: &str, degrees: f64) {
        q[self.robot.motor_index(motor).unwrap()] = degrees.to_radians();
    }

    fn pose(&mut self, q: &[f64]) {
        self.robot.forward_motors(q, &mut self.poses).unwrap();
        self.collision.place(&self.poses, &mut self.placed);
    }

    fn self_pairs(&self) -> Vec<(String, String)> {
        self.collision
            .colliding_pairs(&self.placed, &World::new())
            .into_iter()
            .map(|p| match p.other {
                Other::Body(b) => (p.body, b),
                Other::Object(o) => (p.body, o),
            })
            .collect()
    }

    fn random(&self, rng: &mut ChaCha8Rng) -> Vec<f64> {
        self.robot
            .motors()
            .iter()
            .map(|m| rng.random_range(m.limits.lower..=m.limits.upper))
            .collect()
    }

    /// Position of a frame in another link's frame.
    fn point_in(&self, frame: &str, link: &str) -> Point3<f64> {
        let p = self.poses.pose(self.robot.frame_id(frame).unwrap());
        let l = self.poses.pose(self.robot.frame_id(link).unwrap());
        l.inverse() * Point3::from(p.translation.vector)
    }

    /// Whether a frame's origin lies inside the box proxy of `link` (independent of the checker).
    fn inside_box_of(&self, frame: &str, link: &str) -> bool {
        let body = &self.collision.bodies()[self.collision.body_index(link).unwrap()];
        let Shape::Box { size } = body.shape else {
            panic!("{link} has no box proxy")
        };
        let p = body.local.inverse() * self.point_in(frame, link);
        (0..3).all(|i| p[i].abs() < size[i] / 2.0)
    }
}

#[test]
fn home_posture_is_collision_free() {
    let mut icub = Icub::new();
    icub.pose(&icub.home());
    assert_eq!(icub.self_pairs(), []);
    let d = icub.collision.min_self_distance(&icub.placed).unwrap();
    assert!(d.distance > 0.0, "{d:?}");
}

#[test]
fn fingers_close_fully_without_counting_as_collisions() {
    let mut icub = Icub::new();
    let mut q = icub.home();
    for m in icub.robot.group("hands").unwrap() {
        q[*m] = icub.robot.motors()[*m].limits.upper;
    }
    icub.pose(&q);
    assert_eq!(
        icub.collision.count_self(&icub.placed),
        0,
        "{:?}",
        icub.self_pairs()
    );
}

#[test]
fn crossed_forearms_collide() {
    let mut icub = Icub::new();
    let mut q = icub.home();
    for side in ["l", "r"] {
        icub.set(&mut q, &format!("{side}_shoulder_pitch"), -50.0);
        icub.set(&mut q, &format!("{side}_shoulder_roll"), 10.0);
        icub.set(&mut q, &format!("{side}_shoulder_yaw"), 60.0);
        icub.set(&mut q, &format!("{side}_elbow"), 90.0);
    }
    icub.pose(&q);
    let pairs = icub.self_pairs();
    assert!(
        pairs.contains(&("r_forearm".into(), "l_forearm".into())),
        "{pairs:?}"
    );
    assert!(icub.collision.any_self_collision(&icub.placed));
    // the same arms opened sideways are free
    for side in ["l", "r"] {
        icub.set(&mut q, &format!("{side}_shoulder_roll"), 60.0);
        icub.set(&mut q, &format!("{side}_shoulder_yaw"), 0.0);
    }
    icub.pose(&q);
    assert_eq!(icub.self_pairs(), []);
}

/// iCub's elbow limit (106°) stops the forearm before it reaches the upper arm, so the proxies
/// keep a gap over the whole range and the generated matrix marks the pair `never`.
#[test]
fn the_elbow_limit_keeps_forearm_and_upper_arm_apart() {
    let mut icub = Icub::new();
    let (upper, fore) = (
        icub.collision.body_index("l_upper_arm").unwrap(),
        icub.collision.body_index("l_forearm").unwrap(),
    );
    let links = [
        icub.collision.bodies()[upper].link,
        icub.collision.bodies()[fore].link,
    ];
    assert_eq!(
        icub.collision.acm().reason(links[0], links[1]),
        Some(trm_collision::DisableReason::Never)
    );
    let mut q = icub.home();
    let mut gaps = Vec::new();
    for elbow in [15.0, 45.0, 75.0, 106.0] {
        icub.set(&mut q, "l_elbow", elbow);
        icub.pose(&q);
        gaps.push(icub.collision.body_distance(&icub.placed, upper, fore));
    }
    assert!(gaps.iter().all(|&g| g > 0.0 && g < 0.02), "{gaps:?}");
    assert!(gaps[3] < gaps[1], "folding narrows the gap: {gaps:?}");
}

/// Seeded random arm configurations until `found` holds; panics if none within `tries`.
fn search(icub: &mut Icub, seed: u64, tries: usize, found: impl Fn(&Icub) -> bool) -> Vec<f64> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    for _ in 0..tries {
        let q = icub.random(&mut rng);
        icub.pose(&q);
        if found(icub) {
            return q;
        }
    }
    panic!("no configuration found in {tries} samples");
}

#[test]
fn a_hand_inside_the_chest_collides() {
    let mut icub = Icub::new();
    let q = search(&mut icub, 1, 200_000, |i| {
        i.inside_box_of("r_palm_center", "chest")
    });
    icub.pose(&q);
    let pairs = icub.self_pairs();
    assert!(
        pairs
            .iter()
            .any(|(a, b)| a == "chest" && b.starts_with("r_hand")),
        "{pairs:?}"
    );
}

#[test]
fn fingertips_pressed_into_the_other_palm_collide() {
    let mut icub = Icub::new();
    let q = search(&mut icub, 2, 400_000, |i| {
        i.inside_box_of("l_index_fingertip", "r_hand")
    });
    icub.pose(&q);
    let pairs = icub.self_pairs();
    assert!(
        pairs
            .iter()
            .any(|(a, b)| a == "r_hand" && b == "l_hand_index_3"),
        "{pairs:?}"
    );
}

#[test]
fn a_hand_inside_a_table_collides_with_it_and_a_lowered_table_does_not() {
    let mut icub = Icub::new();
    icub.pose(&icub.home());
    let palm = icub.point_in("r_palm_center", "root_link");
    let mut world = World::new();
    let table = Shape::Box {
        size: [0.4, 0.6, 0.04],
    };
    world
        .add(
            "table",
            table,
            Isometry3::translation(palm.x, palm.y, palm.z),
        )
        .unwrap();
    let count = icub.collision.count_world(&icub.placed, &world);
    assert!(count > 0);
    let pairs = icub.collision.colliding_pairs(&icub.placed, &world);
    assert!(pairs.iter().any(|p| p.body == "r_hand"
        && p.other == Other::Object("table".into())
        && p.distance < 0.0));
    assert!(icub.collision.is_colliding(&icub.placed, &world));
    world
        .set_pose(
            "table",
            Isometry3::translation(palm.x, palm.y, palm.z - 0.3),
        )
        .unwrap();
    assert_eq!(icub.collision.count_world(&icub.placed, &world), 0);
    let gap = icub.collision.object_distance(
        &icub.placed,
        icub.collision.body_index("r_hand").unwrap(),
        &world,
        0,
    );
    assert!(gap > 0.1 && gap < 0.3, "{gap}");
}

/// Plain parry on every checked body pair, without bounding spheres or analytic tests.
fn reference_count(icub: &Icub) -> usize {
    let c = &icub.collision;
    let shapes: Vec<_> = c
        .bodies()
        .iter()
        .map(|b| {
            let (frame, shape) = b.shape.to_parry().unwrap();
            (b.link, icub.poses.poses()[b.link] * b.local * frame, shape)
        })
        .collect();
    let mut links = std::collections::BTreeSet::new();
    for (i, (la, pa, sa)) in shapes.iter().enumerate() {
        for (lb, pb, sb) in &shapes[i + 1..] {
            if c.acm().is_checked(*la, *lb)
                && parry3d_f64::query::intersection_test(pa, sa.as_ref(), pb, sb.as_ref()).unwrap()
            {
                links.insert((*la.min(lb), *la.max(lb)));
            }
        }
    }
    links.len()
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(300))]

    #[test]
    fn fast_counts_agree_with_plain_parry_and_with_each_other(seed in any::<u64>()) {
        let mut icub = Icub::new();
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let q = icub.random(&mut rng);
        icub.pose(&q);
        let n = icub.collision.count_self(&icub.placed);
        prop_assert_eq!(n, reference_count(&icub));
        prop_assert_eq!(icub.collision.any_self_collision(&icub.placed), n > 0);
        let pairs = icub.collision.colliding_pairs(&icub.placed, &World::new());
        prop_assert!(pairs.iter().all(|p| p.distance <= 1e-9));
        let min = icub.collision.min_self_distance(&icub.placed).unwrap().distance;
        if min.abs() > 1e-9 {
            prop_assert_eq!(min < 0.0, n > 0, "min distance {}", min);
        }
    }
}

/// `near_pairs` lists every checked pair and body–object pair closer than the margin, with the
/// signed distance the other queries give and closest points that lie that far apart along the
/// normal.
#[test]
fn near_pairs_agree_with_the_distance_queries() {
    let mut icub = Icub::new();
    let mut world = World::new();
    world
        .add(
            "table",
            Shape::Box {
                size: [0.5, 0.8, 0.04],
            },
            Isometry3::translation(-0.3, 0.0, -0.1),
        )
        .unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    let margin = 0.05;
    let (mut near, mut listed, mut overlapping) = (Vec::new(), 0, 0);
    for _ in 0..50 {
        let q = icub.random(&mut rng);
        icub.pose(&q);
        icub.collision
            .near_pairs(&icub.placed, &world, margin, &mut near);
        for p in &near {
            let d = if p.is_object {
                icub.collision
                    .object_distance(&icub.placed, p.body, &world, p.other)
            } else {
                icub.collision.body_distance(&icub.placed, p.body, p.other)
            };
            // exact for capsule pairs; GJK's tolerance where a box or hull is involved
            assert!((p.distance - d).abs() < 1e-4, "{} vs {d}", p.distance);
            assert!(p.distance < margin);
            // the other's point lies `distance` along the normal from the body's
            let along = (p.other_point - p.point).dot(&p.normal);
            assert!(
                (along - p.distance).abs() < 1e-4,
                "{along} vs {}",
                p.distance
            );
            assert!((p.normal.norm() - 1.0).abs() < 1e-9);
            overlapping += usize::from(p.distance < 0.0);
        }
        listed += near.len();
        // the closest checked pair is among them when it is within the margin
        if let Some(best) = icub.collision.min_self_distance(&icub.placed) {
            if best.distance < margin {
                assert!(
                    near.iter()
                        .any(|p| !p.is_object && (p.distance - best.distance).abs() < 1e-4),
                    "the closest pair is missing"
                );
            }
        }
    }
    assert!(
        listed > 100 && overlapping > 0,
        "{listed} pairs, {overlapping} overlapping"
    );
}

#[test]
fn every_body_lies_inside_its_enclosing_spheres_in_the_link_frame() {
    let robot = trm_models::icub_upper_body();
    let c = CollisionModel::new(&robot).unwrap();
    for (i, b) in c.bodies().iter().enumerate() {
        let spheres = c.enclosing_spheres(i);
        assert!(!spheres.is_empty(), "{}", b.name);
        let (frame, shape) = b.shape.to_parry().unwrap();
        let support = shape.as_support_map().unwrap();
        // 400 directions spread over the sphere (a Fibonacci lattice)
        for k in 0..400 {
            let z = 1.0 - (2 * k + 1) as f64 / 400.0;
            let phi = k as f64 * std::f64::consts::PI * (3.0 - 5f64.sqrt());
            let r = (1.0 - z * z).sqrt();
            let dir = nalgebra::Unit::new_normalize(nalgebra::Vector3::new(
                r * phi.cos(),
                r * phi.sin(),
                z,
            ));
            let p = b.local * frame * support.local_support_point_toward(&dir);
            assert!(
                spheres.iter().any(|s| (p - s.center).norm() <= s.radius),
                "{}: {p} outside every sphere",
                b.name
            );
        }
    }
}
