//! The task-map cost in the catalogue: NGIK brings the hand onto a map of feasible grasp poses
//! ("anywhere along the stick") instead of a single target.

use std::path::Path;

use trm_taskmap::{ExploreOptions, Metric, explore, to_params};
use trm_tasks::{Problem, solve};

#[test]
fn ngik_brings_the_hand_onto_a_task_map() {
    let loaders = trm_taskmap::loaders();
    let robot = trm_models::icub_upper_body();
    let mut poses = robot.pose_buffer();
    robot
        .forward_motors(robot.posture("home").unwrap(), &mut poses)
        .unwrap();
    let hand = *poses.pose(robot.frame_id("r_hand").unwrap());
    // a stick along world y, 6 cm in front of and 4 cm above the hand at home
    let stick = hand.translation.vector + trm_kinematics::nalgebra::Vector3::new(-0.06, 0.0, 0.04);
    let stick_pose = trm_kinematics::nalgebra::Isometry3::from_parts(
        stick.into(),
        trm_kinematics::nalgebra::UnitQuaternion::from_euler_angles(
            std::f64::consts::FRAC_PI_2,
            0.0,
            0.0,
        ),
    );
    let home_rel = to_params(&(stick_pose.inverse() * hand));
    // feasible: hand on the stick's axis (its local z), anywhere along 16 cm, orientation within
    // 0.3 rad (per component) of the home orientation
    let feasible = move |g: &[f64; 6]| {
        let off_axis = g[0].abs().max(g[1].abs());
        let turn = (3..6)
            .map(|k| (g[k] - home_rel[k]).abs())
            .fold(0.0, f64::max);
        (0.01 - off_axis).min(0.08 - g[2].abs()).min(0.3 - turn)
    };
    let g0 = [0.0, 0.0, 0.0, home_rel[3], home_rel[4], home_rel[5]];
    let half = [0.02, 0.02, 0.1, 0.4, 0.4, 0.4];
    let settings = ExploreOptions {
        iterations: 3000,
        ..ExploreOptions::around(g0, half)
    };
    let map = explore(&[g0], &settings, &Metric::default(), feasible).unwrap();
    let dir = std::env::temp_dir().join(format!("trm-tasks-taskmap-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    map.save(dir.join("stick.taskmap.json")).unwrap();
    let spec = format!(
        "(model: \"icub_upper_body\", active: [\"torso\", \"right_arm\"],
          world: (objects: [(name: \"stick\", shape: Capsule(radius: 0.01, length: 0.16), xyz: ({}, {}, {}), rpy: (1.5707963267948966, 0, 0))]),
          costs: [
            (weight: 0.05, cost: HomePosture()),
            (weight: 1000.0, cost: TaskMap(file: \"stick.taskmap.json\", part: \"r_hand\", object: \"stick\")),
          ],
          solver: (max_evaluations: 20000, seed: 2))",
        stick.x, stick.y, stick.z
    );
    let problem = Problem::from_ron_with(&spec, "stick.ron", &dir, &loaders).unwrap();
    let start_cost = problem
        .objective
        .eval(&problem.start, &mut problem.objective.scratch());
    let s = solve(&problem.objective, &problem.start, &problem.spec.solver).unwrap();
    let c_map = s
        .breakdown
        .iter()
        .find(|t| t.label.starts_with("task map"))
        .unwrap()
        .value;
    assert!(start_cost > 1.0, "{start_cost}");
    // the task-map term reads a batch's lanes in place, giving what one evaluation gives
    let objective = &problem.objective;
    let mut rng = <rand_chacha::ChaCha8Rng as rand::SeedableRng>::seed_from_u64(8);
    let qs: Vec<Vec<f64>> = (0..9)
        .map(|_| objective.active().random(&mut rng))
        .collect();
    let mut scratch = objective.scratch();
    let mut batch = vec![0.0; qs.len()];
    objective.eval_batch(&qs, &mut scratch, &mut batch);
    for (q, b) in qs.iter().zip(&batch) {
        assert_eq!(objective.eval(q, &mut scratch).to_bits(), b.to_bits());
    }
    assert!(c_map < 1e-4, "c_map {c_map} (from {start_cost})");
    // a missing map file is a located error
    let bad = spec.replace("stick.taskmap.json", "nope.json");
    let e = Problem::from_ron_with(&bad, "stick.ron", &dir, &loaders)
        .unwrap_err()
        .to_string();
    assert!(e.contains("nope.json") && e.contains("explore"), "{e}");
    std::fs::remove_dir_all(&dir).unwrap();
    let _ = Path::new(".");
}
