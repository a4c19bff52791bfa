//! Reaching a stick with an exact target versus with its task map (the paper's Fig. 7 study,
//! small): both optimisations lower the cost; the map lets the hand end anywhere on the stick.

use trm_collision::{CollisionModel, World};
mod common;
use trm_kinematics::nalgebra::{Isometry3, Vector3};
use trm_taskmap::{
    ExploreOptions, Hand, Metric, MotionGoal, MotionOptions, ReachProblem, explore, find_grasp,
};

#[test]
fn reaching_with_a_task_map_ends_on_the_map_and_costs_less() {
    let model = trm_models::icub_upper_body();
    let collision = CollisionModel::new(&model).unwrap();
    let hand = Hand::icub(&model, &collision, "r").unwrap();
    let stick = common::stick();
    let (g0, _) = find_grasp(
        &hand,
        &stick,
        [-0.15, -0.12, -0.08],
        [0.05, 0.12, 0.15],
        3000,
        0,
    )
    .unwrap();
    let settings = ExploreOptions {
        iterations: 600,
        restarts: 0,
        ..ExploreOptions::around(g0, [0.1, 0.1, 0.2, 1.0, 1.0, 1.0])
    };
    let quality = |g: &[f64; 6]| hand.quality(&stick, g);
    let map = explore(&[g0], &settings, &Metric::default(), quality).unwrap();
    // the stick stands upright in front of the robot's right side (iCub: x back, y right, z up)
    let object = Isometry3::new(Vector3::new(-0.3, 0.2, 0.05), Vector3::new(0.0, 0.0, 0.0));
    let active = model
        .active_set(&["torso", "right_arm"], model.posture("home").unwrap())
        .unwrap();
    let start = active.from_motors(model.posture("home").unwrap());
    let world = World::new();
    let problem = |goal| ReachProblem {
        active: &active,
        collision: &collision,
        world: &world,
        hand: model.frame_id("r_hand").unwrap(),
        object,
        start: start.clone(),
        goal,
        settings: MotionOptions::default(),
    };
    let exact = problem(MotionGoal::Target(g0));
    let with_map = problem(MotionGoal::Map(&map));
    let (a, trace_a) = exact.optimize(12, 1e-3);
    let (b, trace_b) = with_map.optimize(12, 1e-3);
    println!(
        "exact: cost {:.4} limits {:.4} end {:.5}; map: cost {:.4} limits {:.4} end {:.5}; {} map points",
        a.cost,
        a.limits,
        a.end,
        b.cost,
        b.limits,
        b.end,
        map.points.len()
    );
    assert!(trace_a.last().unwrap().0 <= trace_a[0].0 && trace_b.last().unwrap().0 <= trace_b[0].0);
    assert!(
        b.cost <= a.cost + 1e-9,
        "the map goal can never cost more than its centre point"
    );
    assert!(a.trajectory.len() == 31 && b.trajectory.len() == 31);
    // a sampling optimiser works as an alternative
    let c = with_map.optimize_sampling("xnes", 0.02, 300, 1).unwrap();
    assert!(c.cost <= with_map.simulate(&with_map.initial_attractors()).cost);
}

/// The numerical gradient RPROP uses is consistent: central differences at two step sizes agree
/// where the cost is smooth (no collision changes along the way).
#[test]
fn central_difference_gradients_are_consistent_across_step_sizes() {
    let model = trm_models::icub_upper_body();
    let collision = CollisionModel::new(&model).unwrap();
    let active = model
        .active_set(&["torso", "right_arm"], model.posture("home").unwrap())
        .unwrap();
    let world = World::new();
    let target = [-0.02, -0.08, 0.03, 0.1, -0.2, -1.6];
    let problem = ReachProblem {
        active: &active,
        collision: &collision,
        world: &world,
        hand: model.frame_id("r_hand").unwrap(),
        object: Isometry3::new(Vector3::new(-0.3, 0.2, 0.05), Vector3::zeros()),
        start: active.from_motors(model.posture("home").unwrap()),
        goal: MotionGoal::Target(target),
        settings: MotionOptions::default(),
    };
    let x = problem.initial_attractors();
    let gradient = |h: f64| -> Vec<f64> {
        (0..x.len())
            .map(|i| {
                let (mut xp, mut xm) = (x.clone(), x.clone());
                xp[i] += h;
                xm[i] -= h;
                (problem.simulate(&xp).cost - problem.simulate(&xm).cost) / (2.0 * h)
            })
            .collect()
    };
    let (coarse, fine) = (gradient(1e-3), gradient(1e-4));
    let scale = fine.iter().map(|g| g.abs()).fold(0.0, f64::max);
    for (a, b) in coarse.iter().zip(&fine) {
        assert!((a - b).abs() < 0.02 * scale, "{a} vs {b} (scale {scale})");
    }
}
