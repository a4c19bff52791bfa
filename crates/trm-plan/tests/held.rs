//! A planner holding an object (trm's Panda with a rod between its fingers): queries plan
//! around what the rod would hit, an invalid start names the held object, and putting it
//! down gives the bare robot's planner back.

use trm_collision::{AttachedObject, CollisionModel, Shape, World};
use trm_kinematics::RobotModel;
use trm_kinematics::nalgebra::{Isometry3, Point3};
use trm_plan::Planner;

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
fn a_held_object_is_planned_around_and_named() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../models/panda/panda.ron");
    let robot = RobotModel::load(path).unwrap();
    let collision = CollisionModel::new(&robot).unwrap();
    let default = robot.posture("default").unwrap().to_vec();
    let active = robot.active_set(&["arm"], &default).unwrap();
    let objective =
        trm_tasks::Objective::new(active.clone(), collision.clone(), Default::default());
    let mut planner = Planner::new(&objective, &[]).unwrap();
    let start = active.from_motors(&default);
    let mut goal = start.clone();
    goal[0] += 1.0;
    // a post where the rod's far end passes halfway along the straight motion
    let mut poses = robot.pose_buffer();
    let mid: Vec<f64> = start
        .iter()
        .zip(&goal)
        .map(|(a, b)| 0.5 * (a + b))
        .collect();
    active.forward(&mid, &mut poses).unwrap();
    let tcp = robot.tree().link_index("panda_hand_tcp").unwrap();
    let tip = poses.poses()[tcp] * Point3::new(0.0, 0.0, 0.25);
    let mut world = World::new();
    let post = Shape::Capsule {
        radius: 0.02,
        length: 0.1,
    };
    world
        .add("post", post, Isometry3::translation(tip.x, tip.y, tip.z))
        .unwrap();
    planner.set_world(world.clone());
    let options = planner.rrt_options().unwrap();
    let bare = planner.connect(&start, &goal, &options).unwrap();
    assert_eq!(bare.path.len(), 2, "the bare arm goes straight");
    let before = planner.rrt_options().unwrap();
    planner
        .attach(rod(&[
            "panda_hand",
            "panda_leftfinger",
            "panda_rightfinger",
        ]))
        .unwrap();
    let sized = planner.rrt_options().unwrap();
    assert!(
        sized.resolution < before.resolution,
        "a longer lever, finer checks"
    );
    let held = planner.connect(&start, &goal, &sized).unwrap();
    assert!(held.path.len() > 2, "the rod goes around the post");
    // every piece of the path is free for the robot holding the rod
    let model = planner.objective().collision().clone();
    let mut placed = model.placed_bodies();
    for w in held.path.windows(2) {
        for k in 0..=200 {
            let u = k as f64 / 200.0;
            let q: Vec<f64> = w[0]
                .iter()
                .zip(&w[1])
                .map(|(a, b)| a + u * (b - a))
                .collect();
            active.forward(&q, &mut poses).unwrap();
            model.place(&poses, &mut placed);
            assert!(!model.is_colliding(&placed, &world));
        }
    }
    // held without touch links, the rod touches the hand at the start: named
    planner.detach("rod").unwrap();
    planner.attach(rod(&[])).unwrap();
    let e = planner
        .connect(&start, &goal, &sized)
        .unwrap_err()
        .to_string();
    assert!(e.contains("held object `rod` (on `panda_hand_tcp`)"), "{e}");
    assert!(e.contains("every link but its touch links"), "{e}");
    // put down: the bare robot's planner again
    assert!(planner.set_attached(Vec::new()).unwrap());
    assert!(planner.attached().is_empty());
    assert_eq!(planner.rrt_options().unwrap(), before);
    assert_eq!(
        planner.connect(&start, &goal, &options).unwrap().path.len(),
        2
    );
}
