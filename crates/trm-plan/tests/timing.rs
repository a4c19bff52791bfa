//! Planned paths as trajectories: blends that would collide are tightened until they do not,
//! limits hold at 1 kHz on a planned Panda path among obstacles, and the motion sampled at
//! 1 kHz stays collision-free.

use std::path::Path;

use trm_collision::{CollisionModel, Shape, World};
use trm_kinematics::RobotModel;
use trm_kinematics::nalgebra::Isometry3;
use trm_plan::{Planner, Timing};
use trm_tasks::Objective;

fn panda() -> (RobotModel, CollisionModel) {
    let path =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../models/panda-mbm/panda_spherized.ron");
    let robot = RobotModel::load(path).unwrap();
    let collision = CollisionModel::new(&robot).unwrap();
    (robot, collision)
}

/// The Panda's arm and a path of two segments turning a corner (the second also moving joint 3
/// by `twist`).
fn arm_corner(twist: f64) -> (trm_kinematics::ActiveSet, Vec<Vec<f64>>) {
    let (robot, _) = panda();
    let active = robot
        .active_set(&["panda_arm"], &robot.neutral_motors())
        .unwrap();
    let waypoints = vec![
        vec![0.0, -0.5, 0.0, -2.0, 0.0, 1.5, 0.7],
        vec![0.8, -0.5, 0.0, -2.0, 0.0, 1.5, 0.7],
        vec![0.8, 0.3, twist, -2.0 + twist, 0.0, 1.5, 0.7],
    ];
    (active, waypoints)
}

fn distance(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).powi(2))
        .sum::<f64>()
        .sqrt()
}

/// Distance of `p` to the polyline through `waypoints`.
fn off_polyline(p: &[f64], waypoints: &[Vec<f64>]) -> f64 {
    waypoints
        .windows(2)
        .map(|w| {
            let d: Vec<f64> = w[1].iter().zip(&w[0]).map(|(b, a)| b - a).collect();
            let len2: f64 = d.iter().map(|v| v * v).sum();
            let t = (p
                .iter()
                .zip(&w[0])
                .zip(&d)
                .map(|((p, a), d)| (p - a) * d)
                .sum::<f64>()
                / len2)
                .clamp(0.0, 1.0);
            let c: Vec<f64> = w[0].iter().zip(&d).map(|(a, d)| a + t * d).collect();
            distance(p, &c)
        })
        .fold(f64::INFINITY, f64::min)
}

#[test]
fn a_blend_that_is_not_free_is_tightened_until_it_is() {
    let (active, waypoints) = arm_corner(0.0);
    let timing = Timing::default();
    let deviation = |t: &trm_plan::Trajectory| {
        t.positions
            .iter()
            .map(|m| off_polyline(&active.from_motors(m), &waypoints))
            .fold(0.0, f64::max)
    };
    // everything free: the corner is cut by up to the deviation
    let free = trm_plan::timing::timed(&active, &waypoints, &timing, 0.01, |_, _| true).unwrap();
    let cut = deviation(&free);
    assert!(cut > 0.1 && cut <= timing.max_deviation + 1e-9, "{cut}");
    // anything more than 0.02 rad inside the corner "collides": the blend shrinks to fit
    let mut checks = 0;
    let tight = trm_plan::timing::timed(&active, &waypoints, &timing, 0.01, |a, b| {
        checks += 1;
        off_polyline(a, &waypoints) <= 0.02 && off_polyline(b, &waypoints) <= 0.02
    })
    .unwrap();
    assert!(checks > 1);
    let cut = deviation(&tight);
    assert!(cut > 0.005 && cut <= 0.02 + 1e-9, "{cut}");
    assert!(tight.times.last() > free.times.last());
    // nothing free near the corner: it is kept, the motion stops there
    let none = trm_plan::timing::timed(&active, &waypoints, &timing, 0.01, |_, _| false).unwrap();
    assert!(deviation(&none) < 1e-9);
    let at_corner = none
        .positions
        .iter()
        .zip(&none.velocities)
        .find(|(m, _)| distance(&active.from_motors(m), &waypoints[1]) < 1e-3)
        .map(|(_, v)| v.iter().map(|x| x.abs()).fold(0.0, f64::max))
        .unwrap();
    assert!(at_corner < 0.05, "{at_corner}");
}

#[test]
fn a_planned_panda_motion_keeps_its_limits_and_stays_free_at_1_khz() {
    let (robot, collision) = panda();
    let active = robot
        .active_set(&["panda_arm"], &robot.neutral_motors())
        .unwrap();
    // a shelf between the start and the goal
    let mut world = World::new();
    world
        .add(
            "shelf",
            Shape::Box {
                size: [0.6, 0.6, 0.04],
            },
            Isometry3::translation(0.45, 0.0, 0.45),
        )
        .unwrap();
    let objective = Objective::new(active.clone(), collision, world);
    let mut planner = Planner::new(&objective, &[]).unwrap();
    let start = vec![-1.0, 0.3, 0.0, -1.8, 0.0, 2.1, 0.7];
    let goal = vec![1.0, 0.6, 0.0, -1.5, 0.0, 2.1, 0.7];
    assert!(planner.is_free(&start) && planner.is_free(&goal));
    let options = trm_plan::rrt::RrtOptions {
        seed: 3,
        ..planner.rrt_options().unwrap()
    };
    let found = planner.connect(&start, &goal, &options).unwrap();
    assert!(
        found.path.len() >= 3,
        "the shelf is in the way: corners to blend"
    );
    let timing = Timing {
        sample_period: 1e-3,
        default_acceleration: 1.875,
        ..Default::default()
    };
    // (MoveIt's lowest Panda acceleration limit, on every joint; sampled at 1 kHz)
    let t = planner.trajectory(&found.path, &timing).unwrap();
    let limits = timing.joint_limits(&active).unwrap();
    for (v, a) in t.velocities.iter().zip(&t.accelerations) {
        let (v, a) = (active.from_motors(v), active.from_motors(a));
        for j in 0..v.len() {
            assert!(v[j].abs() <= limits.velocity[j] * (1.0 + 1e-6));
            assert!(a[j].abs() <= limits.acceleration[j] * (1.0 + 1e-6));
        }
    }
    let resolution = planner.rrt_options().unwrap().resolution;
    let samples: Vec<Vec<f64>> = t.positions.iter().map(|m| active.from_motors(m)).collect();
    for w in samples.windows(2) {
        assert!(planner.segment_free(&w[0], &w[1], resolution / 2.0));
    }
    assert!(distance(samples.last().unwrap(), &goal) == 0.0);
}

#[test]
fn a_jerk_limited_motion_keeps_the_jerk_limits_and_the_path() {
    let (active, waypoints) = arm_corner(0.2);
    let timing = Timing {
        jerk_limited: true,
        default_jerk: 5.0,
        sample_period: 1e-3,
        ..Default::default()
    };
    let t = trm_plan::timing::timed(&active, &waypoints, &timing, 0.01, |_, _| true).unwrap();
    let optimal = trm_plan::timing::timed(
        &active,
        &waypoints,
        &Timing {
            jerk_limited: false,
            ..timing.clone()
        },
        0.01,
        |_, _| true,
    )
    .unwrap();
    assert!(t.times.last() > optimal.times.last());
    // the mean jerk over each millisecond (the accelerations' differences) within the limit
    let accelerations: Vec<Vec<f64>> = t
        .accelerations
        .iter()
        .map(|a| active.from_motors(a))
        .collect();
    for (w, dt) in accelerations.windows(2).zip(t.times.windows(2)) {
        for (a1, a0) in w[1].iter().zip(&w[0]) {
            let jerk = (a1 - a0) / (dt[1] - dt[0]);
            assert!(jerk.abs() <= 5.0 * (1.0 + 1e-6), "{jerk}");
        }
    }
    // on the polyline, never off it
    for m in &t.positions {
        assert!(off_polyline(&active.from_motors(m), &waypoints) < 1e-9);
    }
}

#[test]
fn a_bad_check_resolution_is_refused_not_looped_on() {
    let (active, waypoints) = arm_corner(0.0);
    for resolution in [0.0, -1.0, f64::NAN] {
        let e = trm_plan::timing::timed(
            &active,
            &waypoints,
            &Timing::default(),
            resolution,
            |_, _| true,
        )
        .unwrap_err();
        assert!(e.to_string().contains("resolution"), "{e}");
    }
}
