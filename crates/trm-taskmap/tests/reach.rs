//! Reaching a stick on a table with an exact target versus with its task map (the paper's Fig. 7
//! study, small), and the analytic gradient against central differences.

use trm_collision::{CollisionModel, Shape, World};
mod common;
use trm_kinematics::nalgebra::{Isometry3, Vector3};
use trm_taskmap::{
    ExploreOptions, Hand, Metric, MotionGoal, MotionOptions, ReachProblem, TaskMap, explore,
    find_grasp, grasp_axis,
};

struct Fixture {
    model: trm_kinematics::RobotModel,
    collision: CollisionModel,
    map: TaskMap,
    g0: [f64; 6],
    table: World,
}

fn fixture() -> Fixture {
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
    let mut table = World::new();
    table
        .add(
            "table",
            Shape::Box {
                size: [0.5, 0.8, 0.04],
            },
            Isometry3::translation(-0.4, 0.0, -0.22),
        )
        .unwrap();
    Fixture {
        model,
        collision,
        map,
        g0,
        table,
    }
}

fn problem<'a>(
    f: &'a Fixture,
    active: &'a trm_kinematics::ActiveSet,
    goal: MotionGoal<'a>,
) -> ReachProblem<'a> {
    ReachProblem {
        active,
        collision: &f.collision,
        world: &f.table,
        hand: f.model.frame_id("r_hand").unwrap(),
        grasp_axis: grasp_axis(&f.map, &common::stick()).unwrap(),
        // the stick stands upright on the table (top 20 cm below the root), in front of the
        // robot's right side near the end of its reach (iCub: x back, y right, z up)
        object: Isometry3::new(Vector3::new(-0.45, 0.2, -0.03), Vector3::zeros()),
        start: active.from_motors(f.model.posture("home").unwrap()),
        goal,
        settings: MotionOptions::default(),
    }
}

#[test]
fn reaching_with_a_task_map_ends_on_the_map_and_costs_less() {
    let f = fixture();
    let active = f
        .model
        .active_set(&["torso", "right_arm"], f.model.posture("home").unwrap())
        .unwrap();
    let centre = f.map.center_grasp().unwrap();
    let exact = problem(&f, &active, MotionGoal::Target(centre));
    let with_map = problem(&f, &active, MotionGoal::Map(&f.map));
    // the same attractors (both start towards the centre grasp): the map can only cost less
    let x0 = exact.initial_attractors();
    assert_eq!(x0, with_map.initial_attractors());
    assert!(with_map.simulate(&x0).cost <= exact.simulate(&x0).cost);
    let (a, trace_a) = exact.optimize(20);
    let (b, trace_b) = with_map.optimize(20);
    println!(
        "exact: cost {:.4} (from {:.4}) limits {:.4} end {:.5} min distance {:.3}; map: cost {:.4} (from {:.4}) limits {:.4} end {:.5} min distance {:.3}; {} map points",
        a.cost,
        trace_a[0].0,
        a.limits,
        a.end,
        a.min_distance,
        b.cost,
        trace_b[0].0,
        b.limits,
        b.end,
        b.min_distance,
        f.map.points.len()
    );
    // the analytic gradient steers RPROP downhill: a clear gain, not just no loss
    assert!(trace_a.last().unwrap().0 < 0.8 * trace_a[0].0);
    assert!(trace_b.last().unwrap().0 < 0.8 * trace_b[0].0);
    assert!(b.cost <= 1.05 * a.cost, "{} vs {}", b.cost, a.cost);
    assert_eq!(a.trajectory.len(), MotionOptions::default().steps + 1);
    assert_eq!(a.collisions + b.collisions, 0, "the table is avoided");
    // a sampling optimiser works as an alternative
    let c = with_map.optimize_sampling("xnes", 0.02, 300, 1).unwrap();
    assert!(c.cost <= with_map.simulate(&with_map.initial_attractors()).cost);
}

/// The analytic O(T) gradient agrees with central differences (the oracle): it drops only the
/// change of J⁺ within a step, as the paper's partial derivatives do.
#[test]
fn the_analytic_gradient_matches_central_differences() {
    let f = fixture();
    let active = f
        .model
        .active_set(&["torso", "right_arm"], f.model.posture("home").unwrap())
        .unwrap();
    for goal in [MotionGoal::Target(f.g0), MotionGoal::Map(&f.map)] {
        let p = problem(&f, &active, goal);
        let x = p.initial_attractors();
        assert_eq!(x.len(), 12 * 5);
        let (m, analytic) = p.gradient(&x);
        assert_eq!(
            m,
            p.simulate(&x),
            "the gradient pass simulates the same motion"
        );
        let numeric = p.numerical_gradient(&x, 1e-5);
        let dot: f64 = analytic.iter().zip(&numeric).map(|(a, b)| a * b).sum();
        let norm = |v: &[f64]| v.iter().map(|a| a * a).sum::<f64>().sqrt();
        let cosine = dot / (norm(&analytic) * norm(&numeric));
        let error = analytic
            .iter()
            .zip(&numeric)
            .map(|(a, b)| (a - b).powi(2))
            .sum::<f64>()
            .sqrt()
            / norm(&numeric);
        println!("cosine {cosine:.5}, relative error {error:.4}");
        assert!(
            cosine > 0.99 && error < 0.1,
            "cosine {cosine}, error {error}"
        );
    }
}

#[test]
fn an_object_is_placed_from_three_or_four_finite_numbers() {
    let at = trm_taskmap::placement(&[0.1, 0.2, 0.3, std::f64::consts::FRAC_PI_2]).unwrap();
    assert!((at.translation.vector - Vector3::new(0.1, 0.2, 0.3)).norm() < 1e-15);
    assert!((at.rotation.angle() - std::f64::consts::FRAC_PI_2).abs() < 1e-12);
    for bad in [&[0.0, 0.0][..], &[0.0, f64::NAN, 0.0], &[0.0; 5]] {
        let e = trm_taskmap::placement(bad).unwrap_err().to_string();
        assert!(e.contains("(x, y, z) or (x, y, z, yaw)"), "{e}");
    }
}
