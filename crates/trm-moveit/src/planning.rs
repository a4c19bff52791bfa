//! MoveIt's inputs applied to a [`trm_plan::Planner`], and a planned motion written in the
//! files MoveIt and ROS 2 read: what `trm plan` and Python's `trm.Planner` share.

use std::path::{Path, PathBuf};

use trm_kinematics::RobotModel;
use trm_plan::rrt::RrtOptions;
use trm_plan::{Connection, PlanError, Planner, Timing, Trajectory};

use crate::{JointLimitsFile, MotionPlanRequest, RequestGoal, Scene};

impl Scene {
    /// Makes this the planner's scene: its world, its allowed-collision matrix and what the
    /// robot holds in it (checks are made again only where these change). Returns the notes on
    /// the matrix's entries that are not links of the robot.
    pub fn apply_to(self, planner: &mut Planner) -> Result<Vec<String>, PlanError> {
        planner.set_world(self.world);
        planner.set_acm(self.acm)?;
        planner.set_attached(self.attached)?;
        Ok(self.notes)
    }
}

impl MotionPlanRequest {
    /// Holds the objects the request's start state holds, beside (by name, over) what the robot
    /// holds already.
    pub fn hold_on(&self, planner: &mut Planner) -> Result<(), PlanError> {
        planner.hold(&self.attached).map(drop)
    }
}

impl RequestGoal {
    /// A path from `start` to this goal: [`Planner::connect`] to a configuration,
    /// [`Planner::connect_to_pose`] to a task-space goal.
    pub fn connect(
        &self,
        planner: &mut Planner,
        start: &[f64],
        options: &RrtOptions,
    ) -> Result<Connection, PlanError> {
        match self {
            RequestGoal::Joints(q) => planner.connect(start, q, options),
            RequestGoal::Pose(pose) => planner.connect_to_pose(start, pose, options),
        }
    }
}

/// How planned paths are timed, as a user sets it: [`Timing`]'s limits, blends and sampling,
/// a `joint_limits.yaml` whose limits replace the robot's, and scaling factors that win over a
/// request's, which win over the file's defaults (then 1), as MoveIt resolves them.
#[derive(Debug, Clone, Default)]
pub struct TimingSettings {
    /// Everything but the limits file and the scaling factors (its own factors are not read).
    pub timing: Timing,
    /// MoveIt's `joint_limits.yaml`, when given.
    pub joint_limits: Option<JointLimitsFile>,
    /// Factor on every velocity limit, (0, 1], when the user set one.
    pub velocity_scaling: Option<f64>,
    /// Factor on every acceleration limit, (0, 1], when the user set one.
    pub acceleration_scaling: Option<f64>,
}

impl TimingSettings {
    /// The timing of one query (`request`: the MoveIt request it answers, if any).
    pub fn timing(&self, request: Option<&MotionPlanRequest>) -> Timing {
        let file = self.joint_limits.as_ref();
        Timing {
            velocity_scaling: self
                .velocity_scaling
                .or(request.and_then(|r| r.velocity_scaling))
                .or(file.and_then(|f| f.velocity_scaling))
                .unwrap_or(1.0),
            acceleration_scaling: self
                .acceleration_scaling
                .or(request.and_then(|r| r.acceleration_scaling))
                .or(file.and_then(|f| f.acceleration_scaling))
                .unwrap_or(1.0),
            limits: file.map(|f| f.limits.clone()).unwrap_or_default(),
            ..self.timing.clone()
        }
    }
}

/// Refuses, before any planning, a trajectory output that cannot be written: an empty path, a
/// `.json` path (the CSV goes to `out`, its JSON beside it with a `.json` extension), or a
/// place where any of [`trajectory_files`]' files cannot go (a directory or a symlink there, a
/// directory that cannot be written in). `setting` names where `out` was given (`--out`).
pub fn check_trajectory_out(setting: &str, out: &Path) -> Result<(), PlanError> {
    let invalid = |problem: &str| PlanError::InvalidOptions {
        what: format!("{setting} {}", out.display()),
        problem: format!("{problem}\n  fix: give a .csv path"),
    };
    if out.as_os_str().is_empty() {
        return Err(invalid("is empty"));
    }
    if out.extension().is_some_and(|e| e == "json") {
        return Err(invalid(
            "is the trajectory CSV's path and its JSON goes beside it with a .json extension",
        ));
    }
    for path in [
        out.to_path_buf(),
        out.with_extension("json"),
        out.with_extension("ros.yaml"),
        out.with_extension("response.yaml"),
    ] {
        trm_io::check_output(&path).map_err(|source| PlanError::Io { path, source })?;
    }
    Ok(())
}

/// A planned trajectory as the files `trm plan --out traj.csv` writes, each with its contents
/// (written by the caller, so that a command can put them in place together): `out` (CSV),
/// beside it `.json`, `.ros.yaml` (a ROS 2 JointTrajectory) and, given the group and the
/// planning time (s), `.response.yaml` (a MoveIt MotionPlanResponse).
pub fn trajectory_files(
    trajectory: &Trajectory,
    robot: &RobotModel,
    response: Option<(&str, f64)>,
    out: &Path,
) -> Result<Vec<(PathBuf, String)>, PlanError> {
    let json = out.with_extension("json");
    let ros = out.with_extension("ros.yaml");
    let mut files = vec![
        (out.to_path_buf(), trajectory.to_csv(out)?),
        (json.clone(), trajectory.to_json(&json)?),
        (ros.clone(), trajectory.to_ros_yaml(robot, &ros)?),
    ];
    if let Some((group, seconds)) = response {
        let path = out.with_extension("response.yaml");
        let yaml = crate::motion_plan_response_yaml(trajectory, robot, group, seconds, &path)?;
        files.push((path, yaml));
    }
    Ok(files)
}

/// What each of [`trajectory_files`]' files is, for a report: "a.csv, a.json, a.ros.yaml (ROS 2
/// JointTrajectory), a.response.yaml (MoveIt MotionPlanResponse)".
pub fn describe_files(files: &[(PathBuf, String)]) -> String {
    let what = [
        "",
        "",
        " (ROS 2 JointTrajectory)",
        " (MoveIt MotionPlanResponse)",
    ];
    files
        .iter()
        .zip(what)
        .map(|((path, _), what)| format!("{}{what}", path.display()))
        .collect::<Vec<_>>()
        .join(", ")
}
