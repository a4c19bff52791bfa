//! A second robot end to end: the Panda of example-robot-data with fitted proxies and its SRDF
//! (models/panda/), a reaching map built from specs/panda_reach.ron, and a planned motion to a
//! point off the map nodes, every segment collision-free.

use std::path::Path;

use trm_plan::{ExactGoal, Goal, PlanOptions, Planner};
use trm_roadmap::{BuildOptions, build, connect};
use trm_tasks::Problem;

#[test]
fn the_panda_builds_a_map_and_plans_through_it() {
    let spec = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../specs/panda_reach.ron");
    let problem = Problem::load(&spec).unwrap();
    assert_eq!(problem.objective.dim(), 7, "the arm group of the SRDF");
    let mut map = build(
        &problem,
        &BuildOptions {
            points: Some(80),
            ..Default::default()
        },
        |_| {},
    )
    .unwrap();
    connect(&mut map, &problem.objective, 8, 0.05).unwrap();
    assert_eq!(map.points.len(), 80);
    let mut planner = Planner::new(&problem.objective, &[&map]).unwrap();
    let node = &map.points[40].t;
    let goal: Vec<f64> = node
        .iter()
        .zip([0.01, -0.01, 0.01])
        .map(|(a, b)| a + b)
        .collect();
    let options = PlanOptions::default();
    let plan = planner
        .plan(
            &problem.start,
            &Goal::TaskPoint {
                t: goal,
                tolerance: 0.05,
            },
            &options,
        )
        .unwrap();
    assert!(
        matches!(plan.stats.exact, ExactGoal::Reached { .. }),
        "{:?}",
        plan.stats.exact
    );
    assert!(plan.stats.goal_error.unwrap() <= 1e-3);
    let active = problem.objective.active();
    let qs: Vec<Vec<f64>> = plan
        .trajectory
        .positions
        .iter()
        .map(|m| active.from_motors(m))
        .collect();
    for w in qs.windows(2) {
        assert!(planner.segment_free(&w[0], &w[1], 0.01));
    }
    // ROS-ready: the URDF's joint names
    let yaml = plan
        .trajectory
        .to_ros_yaml(&problem.robot, Path::new("panda.ros.yaml"))
        .unwrap();
    assert!(yaml.contains("panda_joint7"));
}
