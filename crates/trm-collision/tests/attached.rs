//! Held objects (MoveIt's attached collision objects) on trm's Panda: the object moves with its
//! link, is checked against the world and the robot's other links but not against its touch
//! links, turns a free straight motion into a colliding one, and the single-precision screen
//! answers as the exact model does while it is held.

use nalgebra::{Isometry3, Point3};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use trm_collision::fast::FastChecker;
use trm_collision::{AttachedObject, CollisionModel, Other, Shape, World};
use trm_kinematics::RobotModel;

fn panda() -> (RobotModel, CollisionModel) {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../models/panda/panda.ron");
    let robot = RobotModel::load(path).unwrap();
    let collision = CollisionModel::new(&robot).unwrap();
    (robot, collision)
}

/// A rod held between the fingers, along the gripper's approach axis: from 4 cm inside the
/// fingers to 30 cm beyond the fingertips' centre.
fn rod(touch_links: &[&str]) -> AttachedObject {
    AttachedObject {
        name: "rod".into(),
        link: "panda_hand_tcp".into(),
        shapes: vec![(
            Shape::Capsule {
                radius: 0.012,
                length: 0.34,
            },
            Isometry3::translation(0.0, 0.0, 0.13),
        )],
        touch_links: touch_links.iter().map(|s| s.to_string()).collect(),
    }
}

#[test]
fn a_held_object_turns_a_free_motion_into_a_colliding_one() {
    let (robot, bare) = panda();
    let active = robot.all_active();
    // spheres fitted before holding (as a planner's compiled screen has them): carried over
    let _ = FastChecker::new(&bare, active.clone()).unwrap();
    let start = active.from_motors(robot.posture("default").unwrap());
    let mut goal = start.clone();
    goal[0] += 1.0; // the whole arm turns about the base
    let tcp = robot.tree().link_index("panda_hand_tcp").unwrap();
    let at = |u: f64| -> Vec<f64> {
        start
            .iter()
            .zip(&goal)
            .map(|(a, b)| a + u * (b - a))
            .collect()
    };
    let mut poses = robot.pose_buffer();
    // a post where the rod's far end passes halfway, 25 cm beyond the fingertips
    active.forward(&at(0.5), &mut poses).unwrap();
    let tip = poses.poses()[tcp] * Point3::new(0.0, 0.0, 0.25);
    let mut world = World::new();
    let post = Shape::Capsule {
        radius: 0.02,
        length: 0.1,
    };
    world
        .add("post", post, Isometry3::translation(tip.x, tip.y, tip.z))
        .unwrap();
    let held = bare
        .with_attached(rod(&[
            "panda_hand",
            "panda_leftfinger",
            "panda_rightfinger",
        ]))
        .unwrap();
    assert_eq!(held.attached().len(), 1);
    assert_eq!(held.bodies().len(), bare.bodies().len() + 1);
    let colliding_steps = |model: &CollisionModel| {
        let (mut poses, mut placed) = (robot.pose_buffer(), model.placed_bodies());
        (0..=64)
            .filter(|&k| {
                active.forward(&at(k as f64 / 64.0), &mut poses).unwrap();
                model.place(&poses, &mut placed);
                model.is_colliding(&placed, &world)
            })
            .count()
    };
    assert_eq!(colliding_steps(&bare), 0, "the bare arm passes the post");
    assert!(colliding_steps(&held) > 0, "the rod hits it");
    // at the start the rod sits between the fingers: no collision, as the hand's links are its
    // touch links (MoveIt's way for a gripper)
    let mut placed = held.placed_bodies();
    active.forward(&start, &mut poses).unwrap();
    held.place(&poses, &mut placed);
    let pairs = held.colliding_pairs(&placed, &World::new());
    assert!(pairs.is_empty(), "{pairs:?}");
    // without touch links, the hand and the fingers touch it
    let untouchable = bare.with_attached(rod(&[])).unwrap();
    let mut placed = untouchable.placed_bodies();
    untouchable.place(&poses, &mut placed);
    let pairs = untouchable.colliding_pairs(&placed, &World::new());
    assert!(!pairs.is_empty());
    assert!(
        pairs.iter().all(|p| {
            let names = [
                p.body.as_str(),
                match &p.other {
                    Other::Body(b) => b.as_str(),
                    Other::Object(o) => o.as_str(),
                },
            ];
            names.contains(&"rod")
                && names
                    .iter()
                    .any(|n| n.contains("finger") || n.contains("hand"))
        }),
        "{pairs:?}"
    );
    // the screen sees what the exact model sees, on the motion and at random configurations
    let mut checker = FastChecker::new(&held, active.clone()).unwrap();
    let fast_world = checker.model().world(&world);
    let mut rng = ChaCha8Rng::seed_from_u64(4);
    let mut placed = held.placed_bodies();
    let mut both = 0;
    for k in 0..1500 {
        let q = if k <= 64 {
            at(k as f64 / 64.0)
        } else {
            active.random(&mut rng)
        };
        active.forward(&q, &mut poses).unwrap();
        held.place(&poses, &mut placed);
        let exact = held.is_colliding(&placed, &world);
        assert_eq!(
            checker.all_free(&q, &world, &fast_world).unwrap(),
            !exact,
            "{q:?}"
        );
        both += usize::from(exact);
    }
    assert!(both > 100 && both < 1400, "{both}");
    // put down: the same checks as before
    let released = held.without_attached("rod").unwrap();
    assert_eq!(
        released.num_checked_body_pairs(),
        bare.num_checked_body_pairs()
    );
    assert_eq!(colliding_steps(&released), 0);
}

#[test]
fn bad_attachments_say_what_is_wrong() {
    let (_, bare) = panda();
    let mut wrong_link = rod(&[]);
    wrong_link.link = "panda_hnd".into();
    let e = bare.with_attached(wrong_link).unwrap_err().to_string();
    assert!(
        e.contains("panda_hnd") && e.contains("did you mean `panda_hand`"),
        "{e}"
    );
    let e = bare
        .with_attached(rod(&["panda_leftfingr"]))
        .unwrap_err()
        .to_string();
    assert!(e.contains("did you mean `panda_leftfinger`"), "{e}");
    let held = bare.with_attached(rod(&[])).unwrap();
    let e = held.with_attached(rod(&[])).unwrap_err().to_string();
    assert!(e.contains("`rod` already names a body"), "{e}");
    let mut cloud = rod(&[]);
    cloud.shapes = vec![(
        Shape::Points {
            points: vec![[0.0; 3]],
            radius: 0.01,
        },
        Isometry3::identity(),
    )];
    let e = bare.with_attached(cloud).unwrap_err().to_string();
    assert!(e.contains("cannot be a points"), "{e}");
    let e = held.without_attached("rood").unwrap_err().to_string();
    assert!(e.contains("did you mean `rod`"), "{e}");
    let mut lost = rod(&[]);
    lost.shapes[0].1.translation.vector.x = f64::NAN;
    let e = bare.with_attached(lost).unwrap_err().to_string();
    assert!(e.contains("pose of shape 0 is not finite"), "{e}");
    let mut empty = rod(&[]);
    empty.shapes.clear();
    assert!(
        bare.with_attached(empty)
            .unwrap_err()
            .to_string()
            .contains("no shape")
    );
}

/// A camera's cloud of the robot and a table: filtering the robot's own points out keeps
/// every table point and drops every point on the robot's bodies.
#[test]
fn the_robots_own_points_are_filtered_out_of_a_cloud() {
    let (robot, collision) = panda();
    let active = robot.all_active();
    let q = active.from_motors(robot.posture("default").unwrap());
    let (mut poses, mut placed) = (robot.pose_buffer(), collision.placed_bodies());
    active.forward(&q, &mut poses).unwrap();
    collision.place(&poses, &mut placed);
    let mut rng = ChaCha8Rng::seed_from_u64(9);
    let on_robot: Vec<[f64; 3]> = collision
        .bodies()
        .iter()
        .flat_map(|b| {
            let pose = poses.poses()[b.link] * b.local;
            b.shape
                .surface_samples(200, &mut rng)
                .into_iter()
                .map(move |p| (pose * Point3::from(p)).coords.into())
        })
        .collect();
    let table = Shape::Box {
        size: [0.6, 0.8, 0.04],
    };
    let on_table: Vec<[f64; 3]> = table
        .surface_samples(2000, &mut rng)
        .into_iter()
        .map(|p| [p[0] + 0.9, p[1], p[2] + 0.3])
        .collect();
    let cloud: Vec<[f64; 3]> = on_robot.iter().chain(&on_table).copied().collect();
    let kept = collision.points_off_robot(&placed, &cloud, 0.01);
    assert_eq!(
        kept,
        on_table,
        "{} robot points left",
        kept.len() - on_table.len().min(kept.len())
    );
}
