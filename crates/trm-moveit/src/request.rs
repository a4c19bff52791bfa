//! MoveIt's `MotionPlanRequest`: the start state, a joint-space or task-space goal, the group
//! and the planning time; read, written, and a joint goal turned into the task-space goal it
//! implies.

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use trm_collision::Shape;
use trm_kinematics::nalgebra::{Isometry3, Translation3, UnitQuaternion};

use crate::error::MoveItError;
use crate::reader::{Reader, quote, read};
use crate::yaml::Node;

/// A joint state: names and positions.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct JointState {
    /// Joint names.
    pub names: Vec<String>,
    /// Positions, rad or m.
    pub positions: Vec<f64>,
}

impl JointState {
    /// The position of `name`, if the state gives it.
    pub fn get(&self, name: &str) -> Option<f64> {
        self.names
            .iter()
            .position(|n| n == name)
            .map(|i| self.positions[i])
    }
}

/// A joint-space goal: target positions and tolerances.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct JointGoal {
    /// Joint names.
    pub names: Vec<String>,
    /// Target positions.
    pub positions: Vec<f64>,
    /// Tolerances (below, above), rad or m.
    pub tolerances: Vec<(f64, f64)>,
}

/// How far outside its joint limits a start or goal value may lie and still be taken, clamped
/// onto the limit. URDFs round ±π to ±3.14159, so MotionBenchMaker's Fetch states at ±π lie
/// 2.7·10⁻⁶ rad outside; MoveIt moves such starts inside (its FixStartStateBounds adapter, up
/// to 0.05 rad) and samples joint goals within the bounds.
pub const LIMIT_SLACK: f64 = 1e-4;

/// A MoveIt `MotionPlanRequest` with a joint-space goal.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct MotionPlanRequest {
    /// Where it came from.
    pub origin: PathBuf,
    /// `start_state.joint_state`.
    pub start: JointState,
    /// `start_state.attached_collision_objects`: what the robot holds at the start (and
    /// carries along the motion).
    pub attached: Vec<trm_collision::AttachedObject>,
    /// `goal_constraints[0].joint_constraints` (may be empty when `pose_goal` is not).
    pub goal: JointGoal,
    /// `goal_constraints[0].position_constraints` and `orientation_constraints`: a task-space
    /// goal.
    pub pose_goal: trm_plan::pose_goal::PoseGoal,
    /// `group_name`.
    pub group: String,
    /// `allowed_planning_time`, s (`None` when absent or 0).
    pub planning_time: Option<f64>,
    /// `max_velocity_scaling_factor`, in (0, 1] (`None` when absent or 0: full speed).
    pub velocity_scaling: Option<f64>,
    /// `max_acceleration_scaling_factor`, in (0, 1] (`None` when absent or 0).
    pub acceleration_scaling: Option<f64>,
}

/// What a request asks a planner to reach ([`MotionPlanRequest::query`]).
#[derive(Debug, Clone, PartialEq)]
pub enum RequestGoal {
    /// A configuration of the planner's motors.
    Joints(Vec<f64>),
    /// A task-space goal (position and orientation constraints on links).
    Pose(trm_plan::pose_goal::PoseGoal),
}

impl Reader<'_> {
    pub(crate) fn joint_state(&self, node: &Node, what: &str) -> Result<JointState, MoveItError> {
        let names: Vec<String> = match node.get("name") {
            Some(n) => self
                .seq(n, &format!("{what}.name"))?
                .iter()
                .map(|s| self.text(s, &format!("{what}.name[]")))
                .collect::<Result<_, _>>()?,
            None => Vec::new(),
        };
        let positions = match node.get("position") {
            Some(p) => self.numbers(p, &format!("{what}.position"))?,
            None => Vec::new(),
        };
        if names.len() != positions.len() {
            return Err(self.err(
                node.line,
                format!(
                    "{what} names {} joints and gives {} positions",
                    names.len(),
                    positions.len()
                ),
                "give one position per name",
            ));
        }
        if let Some((i, n)) = names
            .iter()
            .enumerate()
            .find(|(i, n)| names[..*i].contains(n))
        {
            return Err(self.err(
                node.line,
                format!("{what}.name[{i}]: `{n}` is named twice"),
                "name each joint once",
            ));
        }
        Ok(JointState { names, positions })
    }

    /// A goal's position and orientation constraints.
    fn pose_goal(&self, goal: &Node) -> Result<trm_plan::pose_goal::PoseGoal, MoveItError> {
        use trm_plan::pose_goal::{OrientationConstraint, PositionConstraint};
        let mut out = trm_plan::pose_goal::PoseGoal::default();
        let frame = |c: &Node, here: &str| -> Result<String, MoveItError> {
            match c.get("header").and_then(|h| h.get("frame_id")) {
                Some(f) => self.text(f, &format!("{here}.header.frame_id")),
                None => Ok(String::new()),
            }
        };
        let link = |c: &Node, here: &str| -> Result<String, MoveItError> {
            let name = self.text(
                self.field(c, "link_name", here)?,
                &format!("{here}.link_name"),
            )?;
            if name.trim().is_empty() {
                return Err(self.err(c.line, format!("{here} names no link"), "give link_name"));
            }
            Ok(name)
        };
        if let Some(list) = goal.get("position_constraints") {
            for (i, c) in self.seq(list, "position_constraints")?.iter().enumerate() {
                let here = format!("goal_constraints[0].position_constraints[{i}]");
                let offset = match c.get("target_point_offset") {
                    Some(o) => {
                        self.vector(o, &format!("{here}.target_point_offset"), &["x", "y", "z"])?
                    }
                    None => vec![0.0; 3],
                };
                let region = self.field(c, "constraint_region", &here)?;
                let shapes = match region.get("primitives") {
                    Some(p) => self.seq(p, &format!("{here}.constraint_region.primitives"))?,
                    None => &[],
                };
                let poses = match region.get("primitive_poses") {
                    Some(p) => self.seq(p, &format!("{here}.constraint_region.primitive_poses"))?,
                    None => &[],
                };
                if shapes.is_empty() || shapes.len() != poses.len() {
                    return Err(self.err(
                        region.line,
                        format!(
                            "{here}.constraint_region has {} primitives and {} poses",
                            shapes.len(),
                            poses.len()
                        ),
                        "give at least one primitive and one pose per primitive (meshes are not read)",
                    ));
                }
                let mut regions = Vec::new();
                for (k, (s, p)) in shapes.iter().zip(poses).enumerate() {
                    let shape =
                        self.primitive(s, &format!("{here}.constraint_region.primitives[{k}]"))?;
                    let pose =
                        self.pose(p, &format!("{here}.constraint_region.primitive_poses[{k}]"))?;
                    regions.push((shape, pose));
                }
                out.positions.push(PositionConstraint {
                    link: link(c, &here)?,
                    frame: frame(c, &here)?,
                    offset: trm_kinematics::nalgebra::Vector3::new(offset[0], offset[1], offset[2]),
                    regions,
                });
            }
        }
        if let Some(list) = goal.get("orientation_constraints") {
            for (i, c) in self
                .seq(list, "orientation_constraints")?
                .iter()
                .enumerate()
            {
                let here = format!("goal_constraints[0].orientation_constraints[{i}]");
                let orientation = self.quaternion(
                    self.field(c, "orientation", &here)?,
                    &format!("{here}.orientation"),
                )?;
                let mut tolerance = [0.0; 3];
                for (k, axis) in ["x", "y", "z"].iter().enumerate() {
                    let key = format!("absolute_{axis}_axis_tolerance");
                    let v = self.number(self.field(c, &key, &here)?, &format!("{here}.{key}"))?;
                    if v < 0.0 {
                        return Err(self.err(
                            c.line,
                            format!("{here}.{key} is {v}"),
                            "give a tolerance of 0 or more",
                        ));
                    }
                    tolerance[k] = v;
                }
                out.orientations.push(OrientationConstraint {
                    link: link(c, &here)?,
                    frame: frame(c, &here)?,
                    orientation,
                    tolerance,
                });
            }
        }
        Ok(out)
    }
}

/// Writes a task-space goal as one goal constraint's position and orientation constraints.
fn write_pose_goal(out: &mut String, goal: &trm_plan::pose_goal::PoseGoal) -> Result<(), String> {
    let pose = |p: &Isometry3<f64>| {
        let t = p.translation.vector;
        let q = p.rotation.quaternion();
        format!(
            "{{position: {{x: {:?}, y: {:?}, z: {:?}}}, orientation: {{x: {:?}, y: {:?}, z: {:?}, w: {:?}}}}}",
            t.x, t.y, t.z, q.i, q.j, q.k, q.w
        )
    };
    let header = |frame: &str| {
        if frame.is_empty() {
            String::new()
        } else {
            format!("\n        header: {{frame_id: {}}}", quote(frame))
        }
    };
    let mut first = true;
    let mut item = |out: &mut String| {
        out.push_str(if first { "  - " } else { "    " });
        first = false;
    };
    if !goal.positions.is_empty() {
        item(out);
        out.push_str("position_constraints:\n");
        for c in &goal.positions {
            let mut primitives = Vec::new();
            for (shape, _) in &c.regions {
                primitives.push(match shape {
                    Shape::Box { size } => format!(
                        "{{type: 1, dimensions: [{:?}, {:?}, {:?}]}}",
                        size[0], size[1], size[2]
                    ),
                    Shape::Sphere { radius } => format!("{{type: 2, dimensions: [{radius:?}]}}"),
                    Shape::Cylinder { radius, length } => {
                        format!("{{type: 3, dimensions: [{length:?}, {radius:?}]}}")
                    }
                    other => return Err(format!("a {} region", other.kind())),
                });
            }
            let poses: Vec<String> = c.regions.iter().map(|(_, p)| pose(p)).collect();
            let _ = writeln!(
                out,
                "      - link_name: {}{}\n        target_point_offset: {{x: {:?}, y: {:?}, z: {:?}}}\n        constraint_region:\n          primitives: [{}]\n          primitive_poses: [{}]\n        weight: 1.0",
                quote(&c.link),
                header(&c.frame),
                c.offset.x,
                c.offset.y,
                c.offset.z,
                primitives.join(", "),
                poses.join(", ")
            );
        }
    }
    if !goal.orientations.is_empty() {
        item(out);
        out.push_str("orientation_constraints:\n");
        for c in &goal.orientations {
            let q = c.orientation.quaternion();
            let _ = writeln!(
                out,
                "      - link_name: {}{}\n        orientation: {{x: {:?}, y: {:?}, z: {:?}, w: {:?}}}\n        absolute_x_axis_tolerance: {:?}\n        absolute_y_axis_tolerance: {:?}\n        absolute_z_axis_tolerance: {:?}\n        parameterization: 1\n        weight: 1.0",
                quote(&c.link),
                header(&c.frame),
                q.i,
                q.j,
                q.k,
                q.w,
                c.tolerance[0],
                c.tolerance[1],
                c.tolerance[2]
            );
        }
    }
    Ok(())
}

impl MotionPlanRequest {
    /// Parses a request's YAML; `origin` names it in errors. The goal is the first goal
    /// constraint's joint constraints; position and orientation constraints are refused (not
    /// read yet).
    pub fn parse(text: &str, origin: &Path) -> Result<Self, MoveItError> {
        let r = Reader { origin };
        let doc = r.parse(text)?;
        let mut request = MotionPlanRequest {
            origin: origin.to_path_buf(),
            ..Default::default()
        };
        if let Some(start) = doc.get("start_state") {
            if let Some(js) = start.get("joint_state") {
                request.start = r.joint_state(js, "start_state.joint_state")?;
            }
            request.attached = r.attached_objects(start, "start_state")?;
        }
        let goals = r.seq(
            r.field(&doc, "goal_constraints", "the request")?,
            "goal_constraints",
        )?;
        let Some(goal) = goals.first() else {
            return Err(r.err(
                doc.line,
                "goal_constraints is empty",
                "give one goal constraint with joint constraints",
            ));
        };
        if goal
            .get("visibility_constraints")
            .and_then(Node::items)
            .is_some_and(|l| !l.is_empty())
        {
            return Err(r.err(
                goal.line,
                "the goal has visibility_constraints",
                "give the goal as joint constraints or position and orientation constraints",
            ));
        }
        request.pose_goal = r.pose_goal(goal)?;
        let joints = match goal.get("joint_constraints") {
            Some(j) => r.seq(j, "goal_constraints[0].joint_constraints")?,
            None => &[],
        };
        if !joints.is_empty() && !request.pose_goal.is_empty() {
            return Err(r.err(
                goal.line,
                "the goal has joint constraints and position or orientation constraints",
                "give either joint constraints or a task-space goal (both at once are not read)",
            ));
        }
        if joints.is_empty() && request.pose_goal.is_empty() {
            return Err(r.err(
                goal.line,
                "the goal has no joint, position or orientation constraints",
                "give a joint constraint per joint of the group, or a task-space goal",
            ));
        }
        for (i, c) in joints.iter().enumerate() {
            let here = format!("goal_constraints[0].joint_constraints[{i}]");
            let name = r.text(
                r.field(c, "joint_name", &here)?,
                &format!("{here}.joint_name"),
            )?;
            if request.goal.names.contains(&name) {
                return Err(r.err(
                    c.line,
                    format!("joint `{name}` is constrained twice"),
                    "constrain each joint once",
                ));
            }
            let position = r.number(r.field(c, "position", &here)?, &format!("{here}.position"))?;
            let tolerance = |k: &str| -> Result<f64, MoveItError> {
                match c.get(k) {
                    Some(t) => {
                        let v = r.number(t, &format!("{here}.{k}"))?;
                        if v < 0.0 {
                            return Err(r.err(
                                t.line,
                                format!("{here}.{k} is {v}"),
                                "give a tolerance of 0 or more",
                            ));
                        }
                        Ok(v)
                    }
                    None => Ok(0.0),
                }
            };
            request
                .goal
                .tolerances
                .push((tolerance("tolerance_below")?, tolerance("tolerance_above")?));
            request.goal.names.push(name);
            request.goal.positions.push(position);
        }
        if let Some(g) = doc.get("group_name") {
            request.group = r.text(g, "group_name")?;
        }
        if let Some(t) = doc.get("allowed_planning_time") {
            let v = r.number(t, "allowed_planning_time")?;
            if v < 0.0 {
                return Err(r.err(
                    t.line,
                    format!("allowed_planning_time is {v}"),
                    "give seconds, 0 or more (0: no limit given)",
                ));
            }
            request.planning_time = (v > 0.0).then_some(v);
        }
        request.velocity_scaling = r.factor(&doc, "max_velocity_scaling_factor")?;
        request.acceleration_scaling = r.factor(&doc, "max_acceleration_scaling_factor")?;
        Ok(request)
    }

    /// The request as YAML in the layout [`MotionPlanRequest::parse`] reads (start state, one
    /// goal of joint constraints with their tolerances, group, planning time; numbers in their
    /// shortest exact form). Refuses a goal or start that is not one finite value per name.
    pub fn to_yaml(&self) -> Result<String, MoveItError> {
        let refuse = |problem: &str| MoveItError::Invalid {
            path: self.origin.clone(),
            line: 0,
            problem: format!("not written: {problem}"),
            fix: "give one finite value (and two tolerances of 0 or more) per joint name".into(),
        };
        crate::scene::check_attached(&self.attached).map_err(|p| MoveItError::Invalid {
            path: self.origin.clone(),
            line: 0,
            problem: format!("not written: {p}"),
            fix: "give held objects MoveIt's shapes at finite poses".into(),
        })?;
        let (s, g) = (&self.start, &self.goal);
        if s.names.len() != s.positions.len() || s.positions.iter().any(|v| !v.is_finite()) {
            return Err(refuse("the start is not one finite value per name"));
        }
        let task_space = !self.pose_goal.is_empty();
        if (g.names.is_empty() && !task_space)
            || g.names.len() != g.positions.len()
            || g.names.len() != g.tolerances.len()
            || g.positions.iter().any(|v| !v.is_finite())
            || g.tolerances
                .iter()
                .any(|(a, b)| !(a.is_finite() && b.is_finite() && *a >= 0.0 && *b >= 0.0))
        {
            return Err(refuse(
                "the goal is not one finite value and two tolerances per name",
            ));
        }
        let mut out = String::new();
        if !self.group.is_empty() {
            let _ = writeln!(out, "group_name: {}", quote(&self.group));
        }
        if let Some(t) = self.planning_time {
            let _ = writeln!(out, "allowed_planning_time: {t:?}");
        }
        if let Some(f) = self.velocity_scaling {
            let _ = writeln!(out, "max_velocity_scaling_factor: {f:?}");
        }
        if let Some(f) = self.acceleration_scaling {
            let _ = writeln!(out, "max_acceleration_scaling_factor: {f:?}");
        }
        let names: Vec<String> = s.names.iter().map(|n| quote(n)).collect();
        let positions: Vec<String> = s.positions.iter().map(|v| format!("{v:?}")).collect();
        let _ = writeln!(
            out,
            "start_state:\n  joint_state:\n    name: [{}]\n    position: [{}]",
            names.join(", "),
            positions.join(", ")
        );
        crate::scene::write_attached(&mut out, &self.attached);
        if task_space {
            out.push_str("goal_constraints:\n");
            write_pose_goal(&mut out, &self.pose_goal).map_err(|p| refuse(&p))?;
            return Ok(out);
        }
        out.push_str("goal_constraints:\n  - joint_constraints:\n");
        for ((name, position), (below, above)) in
            g.names.iter().zip(&g.positions).zip(&g.tolerances)
        {
            let _ = writeln!(
                out,
                "      - joint_name: {}\n        position: {position:?}\n        tolerance_below: {below:?}\n        tolerance_above: {above:?}",
                quote(name)
            );
        }
        Ok(out)
    }

    /// This request with its joint goal replaced by the task-space goal it implies: `link`'s pose
    /// at the goal configuration (the start's values for the other motors), as a cube of side
    /// `position_tolerance` (m) around its origin and `orientation_tolerance` (rad) about each
    /// axis, in the robot's root frame.
    pub fn to_task_space(
        &self,
        robot: &trm_kinematics::RobotModel,
        link: &str,
        position_tolerance: f64,
        orientation_tolerance: f64,
    ) -> Result<Self, MoveItError> {
        for (what, v) in [
            ("position tolerance", position_tolerance),
            ("orientation tolerance", orientation_tolerance),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return Err(MoveItError::InvalidOptions {
                    what: what.into(),
                    problem: format!("{v}: give a finite value above 0"),
                });
            }
        }
        if !self.pose_goal.is_empty() || self.goal.names.is_empty() {
            return Err(MoveItError::Invalid {
                path: self.origin.clone(),
                line: 0,
                problem: "the goal is not joint constraints".into(),
                fix: "give a request with a joint goal to turn into a task-space goal".into(),
            });
        }
        let frame = robot.frame_id(link)?;
        let (mut motors, _) = motors_from_state(robot, &self.start, &robot.neutral_motors());
        for (name, v) in self.goal.names.iter().zip(&self.goal.positions) {
            motors[robot.motor_index(name)?] = *v;
        }
        let mut poses = robot.pose_buffer();
        robot.forward_motors(&motors, &mut poses)?;
        let pose = *poses.pose(frame);
        let root = robot.tree().links[0].name.clone();
        let mut out = self.clone();
        out.goal = JointGoal::default();
        out.pose_goal = trm_plan::pose_goal::PoseGoal {
            positions: vec![trm_plan::pose_goal::PositionConstraint {
                link: link.to_string(),
                frame: root.clone(),
                offset: Default::default(),
                regions: vec![(
                    Shape::Box {
                        size: [position_tolerance; 3],
                    },
                    Isometry3::from_parts(
                        Translation3::from(pose.translation.vector),
                        UnitQuaternion::identity(),
                    ),
                )],
            }],
            orientations: vec![trm_plan::pose_goal::OrientationConstraint {
                link: link.to_string(),
                frame: root,
                orientation: pose.rotation,
                tolerance: [orientation_tolerance; 3],
            }],
        };
        Ok(out)
    }

    /// The motors a planner for this request moves — the goal's joints, or for a task-space
    /// goal the request's group — and the others held where the start state puts them (`base`,
    /// one value per motor, where it is silent), clamped into their limits: the active set a
    /// planner for this request is made with (see [`MotionPlanRequest::joint_query`]).
    pub fn active_set(
        &self,
        robot: &trm_kinematics::RobotModel,
        base: &[f64],
    ) -> Result<trm_kinematics::ActiveSet, MoveItError> {
        let invalid = |problem: String, fix: &str| MoveItError::Invalid {
            path: self.origin.clone(),
            line: 0,
            problem,
            fix: fix.into(),
        };
        let (start, _) = motors_from_state(robot, &self.start, base);
        let held: Vec<f64> = robot
            .motors()
            .iter()
            .zip(&start)
            .map(|(m, v)| v.clamp(m.limits.lower, m.limits.upper))
            .collect();
        let mut moving = Vec::new();
        if self.goal.names.is_empty() {
            // a task-space goal moves the request's group
            if self.group.is_empty() {
                return Err(invalid(
                    "a task-space goal without group_name".into(),
                    "give group_name: the group whose joints move",
                ));
            }
            moving = robot
                .group(&self.group)
                .map_err(|e| {
                    invalid(
                        format!("group_name: {e}"),
                        "give a group of this robot model (its description's groups)",
                    )
                })?
                .to_vec();
        }
        for name in &self.goal.names {
            let i = robot.motor_index(name).map_err(|e| {
                invalid(
                    format!("the goal constrains `{name}`: {e}"),
                    "give a request for this robot model",
                )
            })?;
            moving.push(i);
        }
        Ok(trm_kinematics::ActiveSet::new(
            robot.clone(),
            moving,
            &held,
        )?)
    }

    /// The request's start and goal in `active`'s coordinates (a planner's): its joint goal
    /// ([`MotionPlanRequest::joint_query`]) or, when it constrains no joint, its task-space
    /// goal, with the start checked as for a joint goal.
    pub fn query(
        &self,
        active: &trm_kinematics::ActiveSet,
    ) -> Result<(Vec<f64>, RequestGoal), MoveItError> {
        if self.goal.names.is_empty() && !self.pose_goal.is_empty() {
            let start = self.start_in(active)?;
            return Ok((start, RequestGoal::Pose(self.pose_goal.clone())));
        }
        let (start, goal) = self.joint_query(active)?;
        Ok((start, RequestGoal::Joints(goal)))
    }

    /// The request's start and joint goal in `active`'s coordinates (a planner's): the start
    /// state's values of the active motors, the goal's by name. An error names what does not
    /// fit: a task-space goal, a goal that constrains a motor the set does not move or leaves
    /// one of them out, a start that misses an active motor or puts one the set holds fixed
    /// elsewhere (by more than 1e-9).
    pub fn joint_query(
        &self,
        active: &trm_kinematics::ActiveSet,
    ) -> Result<(Vec<f64>, Vec<f64>), MoveItError> {
        let names: Vec<&str> = active.names().collect();
        let moved = names.join(", ");
        if self.goal.names.is_empty() {
            return Err(self.invalid(
                "a task-space goal, where joint goals are taken".into(),
                "give joint_constraints for the planner's motors",
            ));
        }
        let mut goal = vec![f64::NAN; names.len()];
        for (name, value) in self.goal.names.iter().zip(&self.goal.positions) {
            let k = names.iter().position(|n| n == name).ok_or_else(|| {
                self.invalid(
                    format!("the goal constrains `{name}`, which the planner does not move (it moves {moved})"),
                    "give a planner that moves the request's goal joints",
                )
            })?;
            goal[k] = *value;
        }
        if let Some(k) = goal.iter().position(|v| v.is_nan()) {
            return Err(self.invalid(
                format!("the goal leaves `{}` out", names[k]),
                "constrain every motor the planner moves",
            ));
        }
        let start = self.start_in(active)?;
        self.within_limits(active, "goal", &mut goal)?;
        Ok((start, goal))
    }

    /// The start state's values of `active`'s motors, checked: every moving motor given, the
    /// held ones where `active` holds them, within the limits (clamped within
    /// [`LIMIT_SLACK`]).
    fn start_in(&self, active: &trm_kinematics::ActiveSet) -> Result<Vec<f64>, MoveItError> {
        let fixed = active.to_motors(&vec![0.0; active.len()]);
        let robot = active.model();
        let (motors, _) = motors_from_state(robot, &self.start, &fixed);
        let moving = active.motor_indices();
        for (i, (m, (&held, &given))) in robot
            .motors()
            .iter()
            .zip(fixed.iter().zip(&motors))
            .enumerate()
        {
            if moving.contains(&i) {
                if !self.start.names.contains(&m.name) {
                    return Err(self.invalid(
                        format!(
                            "the start state does not give `{}`, which the planner moves",
                            m.name
                        ),
                        "give every moving joint in start_state.joint_state",
                    ));
                }
            } else if (held - given).abs() > 1e-9 {
                return Err(self.invalid(
                    format!(
                        "the start state puts `{}` at {given}; the planner holds it at {held}",
                        m.name
                    ),
                    "make the planner with this start state's values for the motors it does not move",
                ));
            }
        }
        let mut start = active.from_motors(&motors);
        self.within_limits(active, "start", &mut start)?;
        Ok(start)
    }

    /// Checks that `q` (`what`: start or goal, in `active`'s coordinates) lies within the
    /// joint limits (up to [`LIMIT_SLACK`]) and clamps it onto them.
    fn within_limits(
        &self,
        active: &trm_kinematics::ActiveSet,
        what: &str,
        q: &mut [f64],
    ) -> Result<(), MoveItError> {
        let robot = active.model();
        for (v, &i) in q.iter_mut().zip(active.motor_indices()) {
            let (m, limits) = (&robot.motors()[i], &robot.motors()[i].limits);
            if !(limits.lower - LIMIT_SLACK..=limits.upper + LIMIT_SLACK).contains(v) {
                return Err(self.invalid(
                    format!(
                        "the {what} puts `{}` at {v}, outside its limits [{}, {}]",
                        m.name, limits.lower, limits.upper
                    ),
                    "give values within the joint limits",
                ));
            }
            *v = v.clamp(limits.lower, limits.upper);
        }
        Ok(())
    }

    /// An error about this request (no line: the request as a whole).
    fn invalid(&self, problem: String, fix: &str) -> MoveItError {
        MoveItError::Invalid {
            path: self.origin.clone(),
            line: 0,
            problem,
            fix: fix.into(),
        }
    }

    /// Reads a request file (at most [`trm_io::MAX_INPUT_BYTES`]).
    pub fn load(path: impl AsRef<Path>) -> Result<Self, MoveItError> {
        let path = path.as_ref();
        Self::parse(&read(path)?, path)
    }
}

/// Values of `state` for the motors of `robot` it names (other names are skipped and
/// returned): the robot's motor vector with `base` where the state is silent.
pub fn motors_from_state(
    robot: &trm_kinematics::RobotModel,
    state: &JointState,
    base: &[f64],
) -> (Vec<f64>, Vec<String>) {
    let mut motors = base.to_vec();
    let mut skipped = Vec::new();
    let index: BTreeMap<&str, usize> = robot
        .motors()
        .iter()
        .enumerate()
        .map(|(i, m)| (m.name.as_str(), i))
        .collect();
    for (name, value) in state.names.iter().zip(&state.positions) {
        match index.get(name.as_str()) {
            Some(&i) => motors[i] = *value,
            None => skipped.push(name.clone()),
        }
    }
    (motors, skipped)
}
