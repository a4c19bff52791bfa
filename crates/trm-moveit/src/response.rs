//! A planned trajectory as a MoveIt `moveit_msgs/msg/MotionPlanResponse` in YAML.

use std::path::Path;

use trm_kinematics::RobotModel;
use trm_plan::{PlanError, Trajectory};

/// `trajectory` of `robot` as a MoveIt `MotionPlanResponse` (ROS 2) in YAML: `trajectory_start`
/// (the first waypoint's joints), `group_name`, `trajectory.joint_trajectory` (the ROS 2
/// `JointTrajectory` of [`Trajectory::to_ros_yaml`], indented), `planning_time` (s) and
/// `error_code: {val: 1}` (SUCCESS). `path` names the file it is for.
pub fn motion_plan_response_yaml(
    trajectory: &Trajectory,
    robot: &RobotModel,
    group: &str,
    planning_time: f64,
    path: &Path,
) -> Result<String, PlanError> {
    let joint_trajectory = trajectory.to_ros_yaml(robot, path)?;
    let body: Vec<&str> = joint_trajectory
        .lines()
        .filter(|l| !l.starts_with('#'))
        .collect();
    // the first point's positions are the start state's, for the joints the trajectory names
    let names = body
        .iter()
        .find_map(|l| l.strip_prefix("joint_names: "))
        .unwrap_or("[]");
    let first = body
        .iter()
        .find_map(|l| l.trim_start().strip_prefix("- positions: "))
        .unwrap_or("[]");
    let quoted = group.replace('\\', "\\\\").replace('"', "\\\"");
    let mut out = String::from("# moveit_msgs/msg/MotionPlanResponse (ROS 2), written by trm\n");
    out.push_str(&format!(
        "trajectory_start:\n  joint_state:\n    name: {names}\n    position: {first}\ngroup_name: \"{quoted}\"\ntrajectory:\n  joint_trajectory:\n"
    ));
    for line in body {
        out.push_str("    ");
        out.push_str(line);
        out.push('\n');
    }
    out.push_str(&format!(
        "planning_time: {}\nerror_code:\n  val: 1\n",
        trm_kinematics::ros::yaml_float(planning_time)
    ));
    Ok(out)
}
