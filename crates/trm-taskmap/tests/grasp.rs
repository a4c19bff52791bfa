//! The kinematic grasp evaluation on the iCub's right hand and a stick (a capsule), and a task
//! map explored with it.

use trm_collision::CollisionModel;
mod common;
use common::stick;
use trm_kinematics::nalgebra::{Isometry3, Vector3};
use trm_taskmap::{ExploreOptions, Hand, Metric, explore, to_params, to_pose};

/// A power grasp found by sampling (object pose in the hand frame).
fn known_grasp() -> Isometry3<f64> {
    let object_in_hand = Isometry3::new(
        Vector3::new(-0.09337, -0.06488, 0.05840),
        Vector3::new(3.00366, 0.47626, 0.86391),
    );
    object_in_hand.inverse()
}

fn hand() -> Hand {
    let model = trm_models::icub_upper_body();
    let collision = CollisionModel::new(&model).unwrap();
    Hand::icub(&model, &collision, "r").unwrap()
}

#[test]
fn a_power_grasp_touches_with_thumb_and_opposed_fingers_and_bad_poses_fail() {
    let hand = hand();
    let good = hand.evaluate(&stick(), &known_grasp());
    assert!(good.success, "{good:?}");
    assert!(
        good.quality > 0.5
            && good.touching.contains(&"thumb".to_string())
            && good.touching.len() >= 3
    );
    assert_eq!(
        hand.evaluate(&stick(), &known_grasp()),
        good,
        "deterministic"
    );
    // the stick far from the hand: nothing touches
    let away = Isometry3::translation(0.5, 0.0, 0.0) * known_grasp();
    let r = hand.evaluate(&stick(), &away);
    assert!(!r.success && r.touching.is_empty(), "{r:?}");
    // the stick through the palm: penetration
    let through = Isometry3::translation(0.0, 0.0, 0.0);
    let r = hand.evaluate(&stick(), &through);
    assert!(!r.success, "{r:?}");
    assert!(
        hand.open_distances(&stick(), &through)
            .iter()
            .any(|(_, d)| *d < -0.01)
    );
}

#[test]
fn grasps_along_the_stick_form_a_task_map() {
    let hand = hand();
    let g0 = to_params(&known_grasp());
    // sliding along the stick (its z axis) keeps the grasp feasible
    let slid = to_params(&(Isometry3::translation(0.0, 0.0, 0.05) * known_grasp()));
    assert!(hand.evaluate(&stick(), &to_pose(&slid)).success);
    let settings = ExploreOptions {
        iterations: 250,
        restarts: 0,
        step: 0.015,
        ..ExploreOptions::around(g0, [0.05, 0.05, 0.12, 0.3, 0.3, 0.3])
    };
    let quality = |g: &[f64; 6]| hand.quality(&stick(), g);
    let map = explore(&[g0], &settings, &Metric::default(), quality).unwrap();
    assert!(map.points.len() > 10, "{} points", map.points.len());
    let (lo, hi) = map
        .points
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), p| {
            (a.min(p.g[2]), b.max(p.g[2]))
        });
    assert!(
        hi - lo > 0.04,
        "the map spreads along the stick: z in [{lo}, {hi}]"
    );
    assert!(map.points.iter().all(|p| p.value > 0.0));
}

#[test]
fn a_model_without_the_icub_hand_is_an_error_not_a_panic() {
    let arm = trm_models::planar_arm();
    let collision = CollisionModel::new(&arm).unwrap();
    let e = Hand::icub(&arm, &collision, "r").unwrap_err().to_string();
    assert!(e.contains("r_thumb_proximal"), "{e}");
    // every motor there but no hand links: the link is named
    let icub = trm_models::icub_upper_body();
    let collision = CollisionModel::new(&icub).unwrap();
    assert!(Hand::icub(&icub, &collision, "x").is_err());
}
