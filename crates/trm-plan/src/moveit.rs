//! MoveIt's planning inputs as YAML (the ROS message layout MotionBenchMaker and
//! `moveit_msgs` tools write): a `PlanningScene` (world collision objects made of box, sphere
//! and cylinder primitives, the allowed-collision matrix, the robot state) and a
//! `MotionPlanRequest` (start state, joint-space goal, group, planning time).
//!
//! ```
//! use trm_plan::moveit::PlanningScene;
//! let scene = PlanningScene::parse(
//!     "world:\n  collision_objects:\n    - id: shelf\n      primitives: [{type: box, dimensions: [1.2, 1, 0.04]}]\n      primitive_poses: [{position: [0.6, 0, 0.2], orientation: [0, 0, 0, 1]}]\n",
//!     "scene.yaml".as_ref(),
//! )?;
//! let world = scene.to_world()?;
//! assert_eq!(world.objects().len(), 1);
//! # Ok::<(), trm_plan::PlanError>(())
//! ```
//!
//! Each primitive becomes one world object, posed by the object's `pose` (identity when absent)
//! times its `primitive_poses` entry; an object of several primitives names them `id/0`,
//! `id/1`, …. Poses are read as `position: [x, y, z]` or `{x:, y:, z:}` and `orientation:
//! [x, y, z, w]` or `{x:, y:, z:, w:}`. Meshes, planes, cones and attached objects are refused
//! with the object named (trm's worlds hold convex primitives). Every error names the file and
//! the line.

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use trm_collision::{Shape, World};
use trm_kinematics::nalgebra::{Isometry3, Quaternion, Translation3, UnitQuaternion};

use crate::PlanError;
use crate::yaml::{self, Node};

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

/// The top-level fields of a MoveIt PlanningScene message (a document naming none of them is
/// not a scene).
const SCENE_FIELDS: [&str; 10] = [
    "name",
    "robot_state",
    "robot_model_name",
    "fixed_frame_transforms",
    "allowed_collision_matrix",
    "link_padding",
    "link_scale",
    "object_colors",
    "world",
    "is_diff",
];

/// One primitive of a collision object.
#[derive(Debug, Clone, PartialEq)]
pub struct Primitive {
    /// The shape (MoveIt's cylinders run along z, as trm's).
    pub shape: Shape,
    /// Its pose in the world frame (object pose × primitive pose).
    pub pose: Isometry3<f64>,
}

/// A collision object of the scene's world.
#[derive(Debug, Clone, PartialEq)]
pub struct CollisionObject {
    /// Its id.
    pub id: String,
    /// Its primitives.
    pub primitives: Vec<Primitive>,
    /// Line of the object in the file.
    pub line: usize,
}

/// The allowed-collision matrix of a scene: `entry_names` and, for each pair, whether it is
/// allowed (not checked).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct AllowedCollisions {
    /// Entry names (links or objects).
    pub names: Vec<String>,
    /// `allowed[i][j]`: the pair (names[i], names[j]) is not checked.
    pub allowed: Vec<Vec<bool>>,
}

impl AllowedCollisions {
    /// The allowed pairs, each once (i < j).
    pub fn allowed_pairs(&self) -> impl Iterator<Item = (&str, &str)> {
        self.allowed.iter().enumerate().flat_map(move |(i, row)| {
            row.iter()
                .enumerate()
                .skip(i + 1)
                .filter(|(_, a)| **a)
                .map(move |(j, _)| (self.names[i].as_str(), self.names[j].as_str()))
        })
    }
}

impl AllowedCollisions {
    /// `collision` with this matrix applied to the robot's link pairs, as MoveIt applies a
    /// planning scene's matrix over the SRDF's: a pair it allows is not checked, a pair it
    /// does not allow is checked. Entries that are not links of the robot (world objects: trm
    /// checks every body against every object) are skipped and named in the returned notes.
    /// `None` when nothing changes.
    pub fn apply(
        &self,
        collision: &trm_collision::CollisionModel,
    ) -> Result<(Option<trm_collision::CollisionModel>, Vec<String>), PlanError> {
        let tree = collision.robot().tree();
        let ids: Vec<Option<usize>> = self.names.iter().map(|n| tree.link_index(n)).collect();
        let notes: Vec<String> = self
            .names
            .iter()
            .zip(&ids)
            .filter(|(_, id)| id.is_none())
            .map(|(n, _)| {
                format!("allowed_collision_matrix: `{n}` is not a link of the robot (skipped)")
            })
            .collect();
        let mut acm = collision.acm().clone();
        let mut changed = false;
        for (i, row) in self.allowed.iter().enumerate() {
            for (j, &allowed) in row.iter().enumerate().skip(i + 1) {
                let (Some(a), Some(b)) = (ids[i], ids[j]) else {
                    continue;
                };
                if a == b || allowed != acm.is_checked(a, b) {
                    continue;
                }
                changed = true;
                if allowed {
                    acm.disable(a, b, trm_kinematics::DisableReason::User);
                } else {
                    acm.enable(a, b);
                }
            }
        }
        let applied = changed.then(|| collision.with_acm(acm)).transpose()?;
        Ok((applied, notes))
    }
}

/// A MoveIt `PlanningScene`.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct PlanningScene {
    /// Where it came from.
    pub origin: PathBuf,
    /// `name`.
    pub name: String,
    /// `robot_model_name`.
    pub robot_model_name: String,
    /// `world.collision_objects`.
    pub objects: Vec<CollisionObject>,
    /// `allowed_collision_matrix`, when given.
    pub allowed_collisions: Option<AllowedCollisions>,
    /// `robot_state.joint_state`, when given.
    pub robot_state: Option<JointState>,
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

/// A MoveIt `MotionPlanRequest` with a joint-space goal.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct MotionPlanRequest {
    /// Where it came from.
    pub origin: PathBuf,
    /// `start_state.joint_state`.
    pub start: JointState,
    /// `goal_constraints[0].joint_constraints` (may be empty when `pose_goal` is not).
    pub goal: JointGoal,
    /// `goal_constraints[0].position_constraints` and `orientation_constraints`: a task-space
    /// goal.
    pub pose_goal: crate::pose_goal::PoseGoal,
    /// `group_name`.
    pub group: String,
    /// `allowed_planning_time`, s (`None` when absent or 0).
    pub planning_time: Option<f64>,
}

/// Reads fields of one file, naming the file and line in errors.
struct Reader<'a> {
    origin: &'a Path,
}

impl Reader<'_> {
    fn err(&self, line: usize, problem: impl Into<String>, fix: impl Into<String>) -> PlanError {
        PlanError::InvalidMoveIt {
            path: self.origin.to_path_buf(),
            line,
            problem: problem.into(),
            fix: fix.into(),
        }
    }

    fn parse(&self, text: &str) -> Result<Node, PlanError> {
        let doc = yaml::parse(text).map_err(|p| {
            self.err(
                p.line,
                format!("not readable YAML: {}", p.problem),
                "write the message as ROS's YAML layout does",
            )
        })?;
        if !matches!(doc.value, yaml::Value::Map(_)) {
            return Err(self.err(
                doc.line,
                format!("the document is {}", doc.kind()),
                "give a mapping of the message's fields",
            ));
        }
        Ok(doc)
    }

    fn field<'n>(&self, node: &'n Node, key: &str, what: &str) -> Result<&'n Node, PlanError> {
        node.get(key).ok_or_else(|| {
            self.err(
                node.line,
                format!("{what} has no `{key}`"),
                format!("give `{key}`"),
            )
        })
    }

    fn seq<'n>(&self, node: &'n Node, what: &str) -> Result<&'n [Node], PlanError> {
        node.items().ok_or_else(|| {
            self.err(
                node.line,
                format!("{what} is {}, not a list", node.kind()),
                format!("give {what} as a list"),
            )
        })
    }

    fn text(&self, node: &Node, what: &str) -> Result<String, PlanError> {
        node.scalar().map(str::to_string).ok_or_else(|| {
            self.err(
                node.line,
                format!("{what} is {}", node.kind()),
                format!("give {what} as a string"),
            )
        })
    }

    fn number(&self, node: &Node, what: &str) -> Result<f64, PlanError> {
        node.scalar()
            .and_then(|s| s.trim().parse::<f64>().ok())
            .filter(|v| v.is_finite())
            .ok_or_else(|| {
                self.err(
                    node.line,
                    format!(
                        "{what} is `{}`, not a finite number",
                        node.scalar().unwrap_or(node.kind())
                    ),
                    "give a finite number",
                )
            })
    }

    fn numbers(&self, node: &Node, what: &str) -> Result<Vec<f64>, PlanError> {
        self.seq(node, what)?
            .iter()
            .enumerate()
            .map(|(i, n)| self.number(n, &format!("{what}[{i}]")))
            .collect()
    }

    /// `[x, y, z]` or `{x:, y:, z:}` (and `w` for quaternions).
    fn vector(&self, node: &Node, what: &str, keys: &[&str]) -> Result<Vec<f64>, PlanError> {
        let values = if node.items().is_some() {
            self.numbers(node, what)?
        } else {
            keys.iter()
                .map(|k| self.number(self.field(node, k, what)?, &format!("{what}.{k}")))
                .collect::<Result<_, _>>()?
        };
        if values.len() != keys.len() {
            return Err(self.err(
                node.line,
                format!("{what} has {} values", values.len()),
                format!("give {} values ({})", keys.len(), keys.join(", ")),
            ));
        }
        Ok(values)
    }

    fn pose(&self, node: &Node, what: &str) -> Result<Isometry3<f64>, PlanError> {
        let p = match node.get("position") {
            Some(p) => self.vector(p, &format!("{what}.position"), &["x", "y", "z"])?,
            None => vec![0.0; 3],
        };
        let rotation = match node.get("orientation") {
            Some(o) => self.quaternion(o, &format!("{what}.orientation"))?,
            None => UnitQuaternion::identity(),
        };
        Ok(Isometry3::from_parts(
            Translation3::new(p[0], p[1], p[2]),
            rotation,
        ))
    }

    /// A `geometry_msgs/Quaternion` (x, y, z, w), of norm 1 within 10 %.
    fn quaternion(&self, node: &Node, what: &str) -> Result<UnitQuaternion<f64>, PlanError> {
        let q = self.vector(node, what, &["x", "y", "z", "w"])?;
        let quaternion = Quaternion::new(q[3], q[0], q[1], q[2]);
        let norm = quaternion.norm();
        if !(0.9..=1.1).contains(&norm) {
            return Err(self.err(
                node.line,
                format!("{what} has norm {norm:.4}"),
                "give a unit quaternion [x, y, z, w]",
            ));
        }
        Ok(UnitQuaternion::new_normalize(quaternion))
    }

    fn joint_state(&self, node: &Node, what: &str) -> Result<JointState, PlanError> {
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
    fn pose_goal(&self, goal: &Node) -> Result<crate::pose_goal::PoseGoal, PlanError> {
        use crate::pose_goal::{OrientationConstraint, PositionConstraint};
        let mut out = crate::pose_goal::PoseGoal::default();
        let frame = |c: &Node, here: &str| -> Result<String, PlanError> {
            match c.get("header").and_then(|h| h.get("frame_id")) {
                Some(f) => self.text(f, &format!("{here}.header.frame_id")),
                None => Ok(String::new()),
            }
        };
        let link = |c: &Node, here: &str| -> Result<String, PlanError> {
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

    /// A `shape_msgs/SolidPrimitive` (box, sphere, cylinder; by name or number).
    fn primitive(&self, s: &Node, here: &str) -> Result<Shape, PlanError> {
        let kind = self.text(self.field(s, "type", here)?, &format!("{here}.type"))?;
        let d = self.numbers(
            self.field(s, "dimensions", here)?,
            &format!("{here}.dimensions"),
        )?;
        let need = |n: usize, names: &str| -> Result<(), PlanError> {
            if d.len() == n && d.iter().all(|v| *v > 0.0) {
                Ok(())
            } else {
                Err(self.err(
                    s.line,
                    format!("{here}: a {kind} with dimensions {d:?}"),
                    format!("give {n} positive dimensions ({names})"),
                ))
            }
        };
        // shape_msgs/SolidPrimitive: BOX = 1, SPHERE = 2, CYLINDER = 3, CONE = 4
        let shape = match kind.to_ascii_lowercase().as_str() {
            "box" | "1" => {
                need(3, "x, y, z")?;
                Shape::Box {
                    size: [d[0], d[1], d[2]],
                }
            }
            "sphere" | "2" => {
                need(1, "radius")?;
                Shape::Sphere { radius: d[0] }
            }
            "cylinder" | "3" => {
                need(2, "height, radius")?;
                Shape::Cylinder {
                    radius: d[1],
                    length: d[0],
                }
            }
            _ => {
                return Err(self.err(
                    s.line,
                    format!("{here} is a `{kind}`"),
                    "use box, sphere or cylinder (cones and other primitives are not supported)",
                ));
            }
        };
        Ok(shape)
    }

    fn object(&self, node: &Node, k: usize) -> Result<CollisionObject, PlanError> {
        let what = format!("world.collision_objects[{k}]");
        let id = self.text(self.field(node, "id", &what)?, &format!("{what}.id"))?;
        if id.trim().is_empty() {
            return Err(self.err(
                node.line,
                format!("{what} has an empty id"),
                "give every object an id",
            ));
        }
        let what = format!("object `{id}`");
        if let Some(op) = node.get("operation").and_then(Node::scalar) {
            if !matches!(op, "0" | "ADD" | "add" | "\x00") {
                return Err(self.err(
                    node.line,
                    format!("{what} has operation `{op}`"),
                    "a scene file adds objects (operation 0, ADD)",
                ));
            }
        }
        for unsupported in ["meshes", "planes", "subframe_names"] {
            if node
                .get(unsupported)
                .and_then(Node::items)
                .is_some_and(|l| !l.is_empty())
            {
                return Err(self.err(
                    node.line,
                    format!("{what} has {unsupported}"),
                    "trm's worlds hold boxes, spheres and cylinders: replace meshes and planes by primitives",
                ));
            }
        }
        let object_pose = match node.get("pose") {
            Some(p) => self.pose(p, &format!("{what}.pose"))?,
            None => Isometry3::identity(),
        };
        let shapes = match node.get("primitives") {
            Some(p) => self.seq(p, &format!("{what}.primitives"))?,
            None => &[],
        };
        let poses = match node.get("primitive_poses") {
            Some(p) => self.seq(p, &format!("{what}.primitive_poses"))?,
            None => &[],
        };
        if shapes.is_empty() || shapes.len() != poses.len() {
            return Err(self.err(
                node.line,
                format!(
                    "{what} has {} primitives and {} primitive poses",
                    shapes.len(),
                    poses.len()
                ),
                "give at least one primitive and one pose per primitive",
            ));
        }
        let mut primitives = Vec::new();
        for (i, (s, p)) in shapes.iter().zip(poses).enumerate() {
            let here = format!("{what}.primitives[{i}]");
            let shape = self.primitive(s, &here)?;
            let pose = object_pose * self.pose(p, &format!("{what}.primitive_poses[{i}]"))?;
            primitives.push(Primitive { shape, pose });
        }
        Ok(CollisionObject {
            id,
            primitives,
            line: node.line,
        })
    }

    fn allowed(&self, node: &Node) -> Result<AllowedCollisions, PlanError> {
        let what = "allowed_collision_matrix";
        let names: Vec<String> = match node.get("entry_names") {
            Some(n) => self
                .seq(n, "allowed_collision_matrix.entry_names")?
                .iter()
                .map(|s| self.text(s, "an entry name"))
                .collect::<Result<_, _>>()?,
            None => Vec::new(),
        };
        let rows = match node.get("entry_values") {
            Some(v) => self.seq(v, "allowed_collision_matrix.entry_values")?,
            None => &[],
        };
        if rows.len() != names.len() {
            return Err(self.err(
                node.line,
                format!(
                    "{what}: {} rows for {} entry names",
                    rows.len(),
                    names.len()
                ),
                "give one row per entry name",
            ));
        }
        let mut allowed = Vec::new();
        for (i, row) in rows.iter().enumerate() {
            let here = format!("{what}.entry_values[{i}]");
            let values = match row.get("enabled") {
                Some(e) => self.seq(e, &here)?,
                None => self.seq(row, &here)?,
            };
            if values.len() != names.len() {
                return Err(self.err(
                    row.line,
                    format!(
                        "{here} has {} values for {} names",
                        values.len(),
                        names.len()
                    ),
                    "give one value per entry name",
                ));
            }
            let parsed: Vec<bool> = values
                .iter()
                .map(|v| match v.scalar() {
                    Some("true" | "True" | "1") => Ok(true),
                    Some("false" | "False" | "0") => Ok(false),
                    _ => Err(self.err(
                        v.line,
                        format!(
                            "{here}: `{}` is not true or false",
                            v.scalar().unwrap_or(v.kind())
                        ),
                        "give true or false",
                    )),
                })
                .collect::<Result<_, _>>()?;
            allowed.push(parsed);
        }
        for i in 0..names.len() {
            for j in 0..i {
                if allowed[i][j] != allowed[j][i] {
                    return Err(self.err(
                        rows[i].line,
                        format!(
                            "{what}: ({}, {}) is {} one way and {} the other",
                            names[i], names[j], allowed[i][j], allowed[j][i]
                        ),
                        "give a symmetric matrix",
                    ));
                }
            }
        }
        Ok(AllowedCollisions { names, allowed })
    }
}

impl PlanningScene {
    /// Parses a scene's YAML; `origin` names it in errors.
    pub fn parse(text: &str, origin: &Path) -> Result<Self, PlanError> {
        let r = Reader { origin };
        let doc = r.parse(text)?;
        if let crate::yaml::Value::Map(entries) = &doc.value {
            if !entries.is_empty()
                && !entries
                    .iter()
                    .any(|(k, _)| SCENE_FIELDS.contains(&k.as_str()))
            {
                let request =
                    doc.get("goal_constraints").is_some() || doc.get("start_state").is_some();
                return Err(r.err(
                    doc.line,
                    if request {
                        "this is a motion plan request, not a planning scene".to_string()
                    } else {
                        format!("no planning-scene field ({})", SCENE_FIELDS.join(", "))
                    },
                    "give a MoveIt PlanningScene (MotionBenchMaker's sceneNNNN.yaml)",
                ));
            }
        }
        let mut scene = PlanningScene {
            origin: origin.to_path_buf(),
            ..Default::default()
        };
        if let Some(n) = doc.get("name") {
            scene.name = r.text(n, "name")?;
        }
        if let Some(n) = doc.get("robot_model_name") {
            scene.robot_model_name = r.text(n, "robot_model_name")?;
        }
        if let Some(world) = doc.get("world") {
            if let Some(objects) = world.get("collision_objects") {
                for (k, o) in r
                    .seq(objects, "world.collision_objects")?
                    .iter()
                    .enumerate()
                {
                    let object = r.object(o, k)?;
                    if let Some(first) = scene.objects.iter().find(|f| f.id == object.id) {
                        return Err(r.err(
                            o.line,
                            format!(
                                "object `{}` is given twice (first at line {})",
                                object.id, first.line
                            ),
                            "give every object its own id",
                        ));
                    }
                    scene.objects.push(object);
                }
            }
        }
        if let Some(acm) = doc.get("allowed_collision_matrix") {
            scene.allowed_collisions = Some(r.allowed(acm)?);
        }
        if let Some(state) = doc.get("robot_state") {
            if let Some(js) = state.get("joint_state") {
                scene.robot_state = Some(r.joint_state(js, "robot_state.joint_state")?);
            }
            if state
                .get("attached_collision_objects")
                .and_then(Node::items)
                .is_some_and(|l| !l.is_empty())
            {
                return Err(r.err(
                    state.line,
                    "the robot state has attached collision objects",
                    "detach them into the world (trm does not carry objects with the robot yet)",
                ));
            }
        }
        Ok(scene)
    }

    /// Reads a scene file (at most [`trm_io::MAX_INPUT_BYTES`]).
    pub fn load(path: impl AsRef<Path>) -> Result<Self, PlanError> {
        let path = path.as_ref();
        Self::parse(&read(path)?, path)
    }

    /// The world of the scene: one object per primitive (`id`, or `id/k` for an object of
    /// several).
    pub fn to_world(&self) -> Result<World, PlanError> {
        let mut world = World::new();
        for o in &self.objects {
            for (k, p) in o.primitives.iter().enumerate() {
                let name = if o.primitives.len() == 1 {
                    o.id.clone()
                } else {
                    format!("{}/{k}", o.id)
                };
                world.add(&name, p.shape.clone(), p.pose).map_err(|e| {
                    PlanError::InvalidMoveIt {
                        path: self.origin.clone(),
                        line: o.line,
                        problem: format!("object `{}`: {e}", o.id),
                        fix: "give positive finite dimensions and finite poses, and unique ids"
                            .into(),
                    }
                })?;
            }
        }
        Ok(world)
    }

    /// The scene as YAML in the layout [`PlanningScene::parse`] reads (a round trip keeps every
    /// field it reads; numbers are written in their shortest exact form). Refuses what the
    /// reader refuses: shapes other than boxes, spheres and cylinders, invalid dimensions or
    /// poses, repeated ids, a robot state with non-finite values or one value short, a
    /// non-square allowed-collision matrix.
    pub fn to_yaml(&self) -> Result<String, PlanError> {
        let refuse = |problem: String, fix: &str| PlanError::InvalidMoveIt {
            path: self.origin.clone(),
            line: 0,
            problem: format!("not written: {problem}"),
            fix: fix.into(),
        };
        self.to_world()?;
        for o in &self.objects {
            if o.primitives.is_empty() {
                return Err(refuse(
                    format!("object `{}` has no primitive", o.id),
                    "give it one",
                ));
            }
            if let Some(p) = o.primitives.iter().find(|p| {
                !matches!(
                    p.shape,
                    Shape::Box { .. } | Shape::Sphere { .. } | Shape::Cylinder { .. }
                )
            }) {
                return Err(refuse(
                    format!("object `{}` holds a {:?}", o.id, p.shape),
                    "MoveIt scenes hold boxes, spheres and cylinders",
                ));
            }
        }
        if let Some(state) = &self.robot_state {
            if state.names.len() != state.positions.len()
                || state.positions.iter().any(|v| !v.is_finite())
            {
                return Err(refuse(
                    "the robot state's positions are not one finite value per name".into(),
                    "give one finite position per joint name",
                ));
            }
        }
        if let Some(acm) = &self.allowed_collisions {
            let n = acm.names.len();
            if acm.allowed.len() != n || acm.allowed.iter().any(|r| r.len() != n) {
                return Err(refuse(
                    "the allowed-collision matrix is not square over its names".into(),
                    "give one row of one value per name for every name",
                ));
            }
        }
        let mut out = String::new();
        let list = |v: &[f64]| {
            v.iter()
                .map(|x| format!("{x:?}"))
                .collect::<Vec<_>>()
                .join(", ")
        };
        let _ = writeln!(out, "name: {}", quote(&self.name));
        let _ = writeln!(out, "robot_model_name: {}", quote(&self.robot_model_name));
        if let Some(state) = &self.robot_state {
            let names: Vec<String> = state.names.iter().map(|n| quote(n)).collect();
            let _ = writeln!(
                out,
                "robot_state:\n  joint_state:\n    name: [{}]\n    position: [{}]",
                names.join(", "),
                list(&state.positions)
            );
        }
        if let Some(acm) = &self.allowed_collisions {
            let names: Vec<String> = acm.names.iter().map(|n| quote(n)).collect();
            let _ = writeln!(
                out,
                "allowed_collision_matrix:\n  entry_names: [{}]\n  entry_values:{}",
                names.join(", "),
                if acm.allowed.is_empty() { " []" } else { "" }
            );
            for row in &acm.allowed {
                let _ = writeln!(
                    out,
                    "    - [{}]",
                    row.iter()
                        .map(|b| b.to_string())
                        .collect::<Vec<_>>()
                        .join(", ")
                );
            }
        }
        let _ = writeln!(
            out,
            "world:\n  collision_objects:{}",
            if self.objects.is_empty() { " []" } else { "" }
        );
        for o in &self.objects {
            let _ = writeln!(out, "    - id: {}\n      primitives:", quote(&o.id));
            for p in &o.primitives {
                let (kind, d) = match &p.shape {
                    Shape::Box { size } => ("box", size.to_vec()),
                    Shape::Sphere { radius } => ("sphere", vec![*radius]),
                    Shape::Cylinder { radius, length } => ("cylinder", vec![*length, *radius]),
                    _ => unreachable!("checked above"),
                };
                let _ = writeln!(
                    out,
                    "        - type: {kind}\n          dimensions: [{}]",
                    list(&d)
                );
            }
            let _ = writeln!(out, "      primitive_poses:");
            for p in &o.primitives {
                let t = p.pose.translation.vector;
                let q = p.pose.rotation.coords; // x, y, z, w
                let _ = writeln!(
                    out,
                    "        - position: [{}]\n          orientation: [{}]",
                    list(&[t.x, t.y, t.z]),
                    list(&[q.x, q.y, q.z, q.w])
                );
            }
        }
        Ok(out)
    }
}

/// Writes a task-space goal as one goal constraint's position and orientation constraints.
fn write_pose_goal(out: &mut String, goal: &crate::pose_goal::PoseGoal) -> Result<(), String> {
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

/// A file's text, as every trm reader reads input (regular files, size-limited).
fn read(path: &Path) -> Result<String, PlanError> {
    trm_io::read_input(path).map_err(|source| PlanError::Io {
        path: path.to_path_buf(),
        source,
    })
}

/// A YAML double-quoted string.
fn quote(s: &str) -> String {
    let mut out = String::from("\"");
    for c in s.chars() {
        match c {
            '"' => out.push_str("\\\""),
            '\\' => out.push_str("\\\\"),
            c if c.is_control() => {
                let _ = write!(out, "\\u{:04x}", c as u32);
            }
            c => out.push(c),
        }
    }
    out.push('"');
    out
}

impl MotionPlanRequest {
    /// Parses a request's YAML; `origin` names it in errors. The goal is the first goal
    /// constraint's joint constraints; position and orientation constraints are refused (not
    /// read yet).
    pub fn parse(text: &str, origin: &Path) -> Result<Self, PlanError> {
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
            let tolerance = |k: &str| -> Result<f64, PlanError> {
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
        Ok(request)
    }

    /// The request as YAML in the layout [`MotionPlanRequest::parse`] reads (start state, one
    /// goal of joint constraints with their tolerances, group, planning time; numbers in their
    /// shortest exact form). Refuses a goal or start that is not one finite value per name.
    pub fn to_yaml(&self) -> Result<String, PlanError> {
        let refuse = |problem: &str| PlanError::InvalidMoveIt {
            path: self.origin.clone(),
            line: 0,
            problem: format!("not written: {problem}"),
            fix: "give one finite value (and two tolerances of 0 or more) per joint name".into(),
        };
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
        let names: Vec<String> = s.names.iter().map(|n| quote(n)).collect();
        let positions: Vec<String> = s.positions.iter().map(|v| format!("{v:?}")).collect();
        let _ = writeln!(
            out,
            "start_state:\n  joint_state:\n    name: [{}]\n    position: [{}]",
            names.join(", "),
            positions.join(", ")
        );
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
    ) -> Result<Self, PlanError> {
        for (what, v) in [
            ("position tolerance", position_tolerance),
            ("orientation tolerance", orientation_tolerance),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return Err(PlanError::InvalidOptions {
                    what: what.into(),
                    problem: format!("{v}: give a finite value above 0"),
                });
            }
        }
        if !self.pose_goal.is_empty() || self.goal.names.is_empty() {
            return Err(PlanError::InvalidMoveIt {
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
        out.pose_goal = crate::pose_goal::PoseGoal {
            positions: vec![crate::pose_goal::PositionConstraint {
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
            orientations: vec![crate::pose_goal::OrientationConstraint {
                link: link.to_string(),
                frame: root,
                orientation: pose.rotation,
                tolerance: [orientation_tolerance; 3],
            }],
        };
        Ok(out)
    }

    /// Reads a request file (at most [`trm_io::MAX_INPUT_BYTES`]).
    pub fn load(path: impl AsRef<Path>) -> Result<Self, PlanError> {
        let path = path.as_ref();
        Self::parse(&read(path)?, path)
    }
}

/// A world from a file: a MoveIt planning scene (`.yaml`/`.yml`, its collision objects) or
/// trm's RON world (anything else).
pub fn load_world(path: impl AsRef<Path>) -> Result<World, PlanError> {
    let path = path.as_ref();
    match path.extension().and_then(|e| e.to_str()) {
        Some("yaml" | "yml") => PlanningScene::load(path)?.to_world(),
        _ => Ok(World::load(path)?),
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
