//! Robots of your own end to end: the Panda (models/panda/) and the TALOS humanoid
//! (models/talos/) of example-robot-data, each with fitted proxies and its SRDF, build a
//! reaching map from their spec and plan a motion to a point off the map nodes, every segment
//! collision-free, written as a ROS JointTrajectory with the URDF's joint names.

use std::path::Path;

use trm_plan::{ExactGoal, Goal, PlanOptions, Planner};
use trm_roadmap::{BuildOptions, Builder, connect};
use trm_tasks::Problem;

/// Builds `points` of `spec`'s map (`dim` active motors), plans to just off node `node` and
/// checks the motion; `joint` is a joint name the ROS trajectory must carry.
fn builds_a_map_and_plans_through_it(
    spec: &str,
    dim: usize,
    points: usize,
    node: usize,
    joint: &str,
) {
    let spec = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../specs")
        .join(spec);
    let problem = Problem::load(&spec).unwrap();
    assert_eq!(problem.objective.dim(), dim, "the SRDF's group");
    let mut map = Builder::new(
        &problem,
        &BuildOptions {
            points: Some(points),
            ..Default::default()
        },
    )
    .run(|_| {})
    .unwrap();
    connect(&mut map, &problem.objective, 8, 0.05).unwrap();
    assert!(map.points.len() >= points);
    let mut planner = Planner::new(&problem.objective, &[&map]).unwrap();
    let node = &map.points[node].t;
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
        .to_ros_yaml(&problem.robot, Path::new("robot.ros.yaml"))
        .unwrap();
    assert!(yaml.contains(joint));
}

#[test]
fn the_panda_builds_a_map_and_plans_through_it() {
    builds_a_map_and_plans_through_it("panda_reach.ron", 7, 80, 40, "panda_joint7");
}

#[test]
fn the_talos_humanoid_builds_a_map_and_plans_through_it() {
    // torso and right arm (the SRDF's r_arm_torso), the rest in the half-sitting posture
    builds_a_map_and_plans_through_it("talos_reach.ron", 9, 80, 40, "arm_right_7_joint");
}

/// RRT-Connect's settings sized by the robot: VAMP's hand-tuned 1 rad and 1/32 rad and its
/// 4 rad dynamic domains on its Panda; the iCub upper body (shorter levers, 41 motors) checks
/// less densely, steps shorter and samples wider domains; a robot's own description overrides
/// them.
#[test]
fn planner_settings_are_sized_by_the_robot() {
    use trm_collision::CollisionModel;
    use trm_kinematics::RobotModel;
    use trm_plan::rrt::RrtOptions;

    let models = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../models");
    let sized = |robot: &RobotModel, group: &[&str]| {
        let collision = CollisionModel::new(robot).unwrap();
        let active = robot.active_set(group, &robot.neutral_motors()).unwrap();
        RrtOptions::for_robot(&collision, &active).unwrap()
    };
    let panda = RobotModel::load(models.join("panda-mbm/panda_spherized.ron")).unwrap();
    let options = sized(&panda, &["panda_arm"]);
    assert!((options.range - 1.0).abs() < 0.02, "{options:?}");
    assert!((1.0 / options.resolution - 32.0).abs() < 0.7, "{options:?}");
    // VAMP's dynamic domains on the 7-motor arm, wider as distances grow with the motors
    assert_eq!(options.domain_radius, 4.0);

    let icub = trm_models::icub_upper_body();
    let all: Vec<&str> = icub.motors().iter().map(|m| m.name.as_str()).collect();
    let icub_options = sized(&icub, &all);
    assert!(
        icub_options.resolution > options.resolution,
        "{icub_options:?}"
    );
    assert!(icub_options.range < options.range, "{icub_options:?}");
    let wide = 4.0 * (all.len() as f64 / 7.0).sqrt();
    assert!(
        (icub_options.domain_radius - wide).abs() < 1e-12,
        "{icub_options:?}"
    );

    // the description's own settings win, each on its own
    let mut description = trm_kinematics::ModelDescription::default();
    description.planning.range = Some(0.5);
    let own = panda.with_description(&description, None).unwrap();
    let own_options = sized(&own, &["panda_joint1", "panda_joint2"]);
    assert_eq!(own_options.range, 0.5);
    assert!(own_options.resolution > 0.0 && own_options.resolution != 0.5);
    description.planning.domain_radius = Some(2.5);
    let own = panda.with_description(&description, None).unwrap();
    assert_eq!(sized(&own, &["panda_joint1"]).domain_radius, 2.5);
}
