//! MoveIt's `PlanningScene`: world collision objects made of primitives, the allowed-collision
//! matrix and the robot state; read, written and turned into a trm world.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use trm_collision::{AttachedObject, Shape, World};
use trm_kinematics::nalgebra::Isometry3;

use crate::error::MoveItError;
use crate::reader::{Reader, quote, read};
use crate::request::JointState;
use crate::yaml::Node;

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
    /// `allowed[i][j]`: the pair (`names[i]`, `names[j]`) is not checked.
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

/// Whether the model disables a pair with this reason for a fact of geometry (adjacent links,
/// colliding at the default posture, in almost every sample or in none), rather than by hand.
fn geometric(reason: trm_kinematics::DisableReason) -> bool {
    use trm_kinematics::DisableReason::{Adjacent, Always, Default, Never};
    matches!(reason, Adjacent | Always | Default | Never)
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
    ) -> Result<(Option<trm_collision::CollisionModel>, Vec<String>), MoveItError> {
        let (acm, notes) = self.over(collision);
        let applied = acm.map(|acm| collision.with_acm(acm)).transpose()?;
        Ok((applied, notes))
    }

    /// The matrix [`AllowedCollisions::apply`] gives `collision` (`None` when nothing changes),
    /// and its notes.
    ///
    /// The rule, for a matrix written for other geometry than the model's (a scene made for a
    /// robot's meshes, applied to its sphere model): a pair the scene allows is not checked; a
    /// pair it checks is checked, except where the model's own matrix disables it for a fact
    /// of geometry — adjacent links, links colliding at the default posture or in (almost)
    /// every sample, or in none (MoveIt's "never": the links cannot meet within the joint
    /// limits, so a coarser model's bodies overlapping there is the model's error, not a
    /// collision); those stay disabled and a note counts them. Pairs the model disables by
    /// hand are checked as the scene asks.
    pub fn over(
        &self,
        collision: &trm_collision::CollisionModel,
    ) -> (Option<trm_collision::AllowedCollisionMatrix>, Vec<String>) {
        let tree = collision.robot().tree();
        let ids: Vec<Option<usize>> = self.names.iter().map(|n| tree.link_index(n)).collect();
        let mut notes: Vec<String> = self
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
        let mut kept = Vec::new();
        for (i, row) in self.allowed.iter().enumerate() {
            for (j, &allowed) in row.iter().enumerate().skip(i + 1) {
                let (Some(a), Some(b)) = (ids[i], ids[j]) else {
                    continue;
                };
                if a == b || allowed != acm.is_checked(a, b) {
                    continue;
                }
                if allowed {
                    acm.disable(a, b, trm_kinematics::DisableReason::User);
                } else if let Some(reason) = acm.reason(a, b).filter(|r| geometric(*r)) {
                    kept.push(format!(
                        "`{}`–`{}` ({})",
                        self.names[i],
                        self.names[j],
                        reason.as_str()
                    ));
                    continue;
                } else {
                    acm.enable(a, b);
                }
                changed = true;
            }
        }
        if !kept.is_empty() {
            let shown = kept.len().min(3);
            notes.push(format!(
                "allowed_collision_matrix: {} it checks {} disabled, as this model disables {} for a fact of geometry: {}{}",
                if kept.len() == 1 { "1 pair".to_string() } else { format!("{} pairs", kept.len()) },
                if kept.len() == 1 { "stays" } else { "stay" },
                if kept.len() == 1 { "it" } else { "them" },
                kept[..shown].join(", "),
                if kept.len() > shown { ", …" } else { "" }
            ));
        }
        (changed.then_some(acm), notes)
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
    /// `robot_state.attached_collision_objects`: what the robot holds (poses in the frames of
    /// the links holding them).
    pub attached: Vec<AttachedObject>,
}

impl Reader<'_> {
    /// A `shape_msgs/SolidPrimitive` (box, sphere, cylinder; by name or number).
    pub(crate) fn primitive(&self, s: &Node, here: &str) -> Result<Shape, MoveItError> {
        let kind = self.text(self.field(s, "type", here)?, &format!("{here}.type"))?;
        let d = self.numbers(
            self.field(s, "dimensions", here)?,
            &format!("{here}.dimensions"),
        )?;
        let need = |n: usize, names: &str| -> Result<(), MoveItError> {
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

    fn object(&self, node: &Node, k: usize) -> Result<CollisionObject, MoveItError> {
        let what = format!("world.collision_objects[{k}]");
        let id = self.object_id(node, &what)?;
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
        Ok(CollisionObject {
            primitives: self.shapes(node, &what)?,
            id,
            line: node.line,
        })
    }

    /// A collision object's `id` (not empty).
    fn object_id(&self, node: &Node, what: &str) -> Result<String, MoveItError> {
        let id = self.text(self.field(node, "id", what)?, &format!("{what}.id"))?;
        if id.trim().is_empty() {
            return Err(self.err(
                node.line,
                format!("{what} has an empty id"),
                "give every object an id",
            ));
        }
        Ok(id)
    }

    /// A collision object's primitives and meshes, each posed by the object's `pose`
    /// (identity when absent) times its own.
    fn shapes(&self, node: &Node, what: &str) -> Result<Vec<Primitive>, MoveItError> {
        for unsupported in ["planes", "subframe_names"] {
            if node
                .get(unsupported)
                .and_then(Node::items)
                .is_some_and(|l| !l.is_empty())
            {
                return Err(self.err(
                    node.line,
                    format!("{what} has {unsupported}"),
                    "trm's worlds hold primitives, meshes and point clouds: replace planes by thin boxes",
                ));
            }
        }
        let object_pose = match node.get("pose") {
            Some(p) => self.pose(p, &format!("{what}.pose"))?,
            None => Isometry3::identity(),
        };
        let mut primitives = Vec::new();
        for (list, poses, meshes) in [
            ("primitives", "primitive_poses", false),
            ("meshes", "mesh_poses", true),
        ] {
            let list_of = |key: &str| match node.get(key) {
                Some(p) => self.seq(p, &format!("{what}.{key}")),
                None => Ok(&[][..]),
            };
            let (shapes, poses_of) = (list_of(list)?, list_of(poses)?);
            if shapes.len() != poses_of.len() {
                return Err(self.err(
                    node.line,
                    format!(
                        "{what} has {} {list} and {} {poses}",
                        shapes.len(),
                        poses_of.len()
                    ),
                    format!("give one pose per entry of {list}"),
                ));
            }
            for (i, (s, p)) in shapes.iter().zip(poses_of).enumerate() {
                let here = format!("{what}.{list}[{i}]");
                let shape = if meshes {
                    self.mesh(s, &here)?
                } else {
                    self.primitive(s, &here)?
                };
                let pose = object_pose * self.pose(p, &format!("{what}.{poses}[{i}]"))?;
                primitives.push(Primitive { shape, pose });
            }
        }
        if primitives.is_empty() {
            return Err(self.err(
                node.line,
                format!("{what} has no primitive and no mesh"),
                "give at least one primitive (and its pose) or mesh (and its pose)",
            ));
        }
        Ok(primitives)
    }

    /// A `shape_msgs/Mesh` (`vertices` as points, `triangles` as `vertex_indices`), or — trm's
    /// extension — a mesh file: `resource: "package://…/x.stl"` (or a path, relative to the
    /// scene) with an optional `scale: [x, y, z]`.
    fn mesh(&self, node: &Node, here: &str) -> Result<Shape, MoveItError> {
        if let Some(resource) = node.get("resource") {
            let uri = self.text(resource, &format!("{here}.resource"))?;
            let scale = match node.get("scale") {
                Some(s) => self.vector(s, &format!("{here}.scale"), &["x", "y", "z"])?,
                None => vec![1.0; 3],
            };
            let dir = self.origin.parent();
            let paths = trm_collision::CollisionOptions::with_ros_package_path(Vec::new());
            let path = trm_collision::mesh::resolve_mesh(&uri, dir, &paths.package_paths).map_err(|tried| {
                self.err(
                    resource.line,
                    format!("{here}: `{uri}` is not found (tried {tried:?})"),
                    "give a path relative to the scene, or a package:// URI whose package is on ROS_PACKAGE_PATH",
                )
            })?;
            let (vertices, triangles) =
                trm_collision::mesh::triangles_of_mesh(&path, [scale[0], scale[1], scale[2]])
                    .map_err(|e| {
                        self.err(
                            resource.line,
                            format!("{here}: {}: {e}", path.display()),
                            "give an STL, OBJ or COLLADA mesh",
                        )
                    })?;
            return Ok(Shape::Mesh {
                vertices,
                triangles,
            });
        }
        let vertices = self
            .seq(
                self.field(node, "vertices", here)?,
                &format!("{here}.vertices"),
            )?
            .iter()
            .enumerate()
            .map(|(i, v)| {
                let p = self.vector(v, &format!("{here}.vertices[{i}]"), &["x", "y", "z"])?;
                Ok([p[0], p[1], p[2]])
            })
            .collect::<Result<Vec<_>, MoveItError>>()?;
        let triangles = self
            .seq(
                self.field(node, "triangles", here)?,
                &format!("{here}.triangles"),
            )?
            .iter()
            .enumerate()
            .map(|(i, t)| {
                let at = format!("{here}.triangles[{i}]");
                let indices = t.get("vertex_indices").unwrap_or(t);
                let v = self.numbers(indices, &at)?;
                let index = |x: f64| {
                    (x >= 0.0 && x.fract() == 0.0 && (x as usize) < vertices.len())
                        .then_some(x as u32)
                };
                match v.as_slice() {
                    [a, b, c] => match (index(*a), index(*b), index(*c)) {
                        (Some(a), Some(b), Some(c)) => Ok([a, b, c]),
                        _ => Err(self.err(
                            t.line,
                            format!("{at} is {v:?}, beyond the {} vertices", vertices.len()),
                            "index vertices from 0",
                        )),
                    },
                    _ => Err(self.err(
                        t.line,
                        format!("{at} has {} indices", v.len()),
                        "give three vertex indices per triangle",
                    )),
                }
            })
            .collect::<Result<Vec<_>, MoveItError>>()?;
        let shape = Shape::Mesh {
            vertices,
            triangles,
        };
        shape
            .check()
            .map_err(|p| self.err(node.line, format!("{here}: {}", p.problem), p.fix))?;
        Ok(shape)
    }

    /// A `moveit_msgs/AttachedCollisionObject`: the object's shapes in its link's frame.
    fn attached(&self, node: &Node, k: usize) -> Result<AttachedObject, MoveItError> {
        let what = format!("attached_collision_objects[{k}]");
        let link = self.text(
            self.field(node, "link_name", &what)?,
            &format!("{what}.link_name"),
        )?;
        let object = self.field(node, "object", &what)?;
        let name = self.object_id(object, &format!("{what}.object"))?;
        let what = format!("held object `{name}`");
        let frame = object
            .get("header")
            .and_then(|h| h.get("frame_id"))
            .and_then(Node::scalar)
            .unwrap_or("");
        if !frame.is_empty() && frame.trim_start_matches('/') != link {
            return Err(self.err(
                object.line,
                format!("{what} is posed in frame `{frame}`, not in its link `{link}`"),
                "give the held object's poses in the frame of the link holding it",
            ));
        }
        let touch_links = match node.get("touch_links") {
            Some(t) => self
                .seq(t, &format!("{what}.touch_links"))?
                .iter()
                .map(|l| self.text(l, "a touch link"))
                .collect::<Result<_, _>>()?,
            None => Vec::new(),
        };
        Ok(AttachedObject {
            shapes: (self.shapes(object, &what)?.into_iter())
                .map(|p| (p.shape, p.pose))
                .collect(),
            name,
            link,
            touch_links,
        })
    }

    /// The `attached_collision_objects` of a robot state (none when absent).
    pub(crate) fn attached_objects(
        &self,
        state: &Node,
        what: &str,
    ) -> Result<Vec<AttachedObject>, MoveItError> {
        let Some(list) = state.get("attached_collision_objects") else {
            return Ok(Vec::new());
        };
        let list = self.seq(list, &format!("{what}.attached_collision_objects"))?;
        let mut held: Vec<AttachedObject> = Vec::new();
        for (k, node) in list.iter().enumerate() {
            let object = self.attached(node, k)?;
            if held.iter().any(|o| o.name == object.name) {
                return Err(self.err(
                    node.line,
                    format!("held object `{}` is given twice", object.name),
                    "give every held object its own id",
                ));
            }
            held.push(object);
        }
        Ok(held)
    }

    fn allowed(&self, node: &Node) -> Result<AllowedCollisions, MoveItError> {
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
    pub fn parse(text: &str, origin: &Path) -> Result<Self, MoveItError> {
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
            scene.attached = r.attached_objects(state, "robot_state")?;
        }
        Ok(scene)
    }

    /// Reads a scene file (at most [`trm_io::MAX_INPUT_BYTES`]).
    pub fn load(path: impl AsRef<Path>) -> Result<Self, MoveItError> {
        let path = path.as_ref();
        Self::parse(&read(path)?, path)
    }

    /// The world of the scene: one object per primitive (`id`, or `id/k` for an object of
    /// several).
    pub fn to_world(&self) -> Result<World, MoveItError> {
        let mut world = World::new();
        for o in &self.objects {
            for (k, p) in o.primitives.iter().enumerate() {
                let name = if o.primitives.len() == 1 {
                    o.id.clone()
                } else {
                    format!("{}/{k}", o.id)
                };
                world
                    .add(&name, p.shape.clone(), p.pose)
                    .map_err(|e| MoveItError::Invalid {
                        path: self.origin.clone(),
                        line: o.line,
                        problem: format!("object `{}`: {e}", o.id),
                        fix: "give positive finite dimensions and finite poses, and unique ids"
                            .into(),
                    })?;
            }
        }
        Ok(world)
    }

    /// The scene as YAML in the layout [`PlanningScene::parse`] reads (a round trip keeps every
    /// field it reads; numbers are written in their shortest exact form; meshes inline).
    /// Refuses what the reader refuses: shapes other than boxes, spheres, cylinders and meshes,
    /// invalid dimensions or poses, repeated ids, a robot state with non-finite values or one
    /// value short, a non-square allowed-collision matrix.
    pub fn to_yaml(&self) -> Result<String, MoveItError> {
        let refuse = |problem: String, fix: &str| MoveItError::Invalid {
            path: self.origin.clone(),
            line: 0,
            problem: format!("not written: {problem}"),
            fix: fix.into(),
        };
        self.to_world()?;
        check_attached(&self.attached)
            .map_err(|p| refuse(p, "give held objects MoveIt's shapes at finite poses"))?;
        let world = (self.objects.iter()).map(|o| {
            (
                &o.id,
                o.primitives.iter().map(|p| &p.shape).collect::<Vec<_>>(),
            )
        });
        for (id, shapes) in world {
            if shapes.is_empty() {
                return Err(refuse(format!("object `{id}` has no shape"), "give it one"));
            }
            if let Some(shape) = shapes.iter().find(|s| {
                !matches!(
                    s,
                    Shape::Box { .. }
                        | Shape::Sphere { .. }
                        | Shape::Cylinder { .. }
                        | Shape::Mesh { .. }
                ) || s.check().is_err()
            }) {
                return Err(refuse(
                    format!(
                        "object `{id}` holds a {} that MoveIt cannot carry or that is invalid",
                        shape.kind()
                    ),
                    "MoveIt scenes hold boxes, spheres, cylinders and meshes",
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
        let _ = writeln!(out, "name: {}", quote(&self.name));
        let _ = writeln!(out, "robot_model_name: {}", quote(&self.robot_model_name));
        if self.robot_state.is_some() || !self.attached.is_empty() {
            let _ = writeln!(out, "robot_state:");
        }
        if let Some(state) = &self.robot_state {
            let names: Vec<String> = state.names.iter().map(|n| quote(n)).collect();
            let _ = writeln!(
                out,
                "  joint_state:\n    name: [{}]\n    position: [{}]",
                names.join(", "),
                list(&state.positions)
            );
        }
        write_attached(&mut out, &self.attached);
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
            let shapes: Vec<(&Shape, &Isometry3<f64>)> =
                o.primitives.iter().map(|p| (&p.shape, &p.pose)).collect();
            let _ = write!(out, "    - ");
            write_object(&mut out, "      ", &o.id, &shapes);
        }
        Ok(out)
    }
}

/// Numbers in their shortest exact form, comma-separated.
fn list(v: &[f64]) -> String {
    v.iter()
        .map(|x| format!("{x:?}"))
        .collect::<Vec<_>>()
        .join(", ")
}

/// Whether held objects can be written as MoveIt reads them: at least one shape each, every
/// shape a valid box, sphere, cylinder or mesh, every pose finite; else what is wrong.
pub(crate) fn check_attached(attached: &[AttachedObject]) -> Result<(), String> {
    for o in attached {
        let name = &o.name;
        if o.shapes.is_empty() {
            return Err(format!("held object `{name}` has no shape"));
        }
        for (shape, pose) in &o.shapes {
            let movable = matches!(
                shape,
                Shape::Box { .. }
                    | Shape::Sphere { .. }
                    | Shape::Cylinder { .. }
                    | Shape::Mesh { .. }
            );
            if !movable || shape.check().is_err() {
                return Err(format!(
                    "held object `{name}` holds a {} that MoveIt cannot carry or that is invalid",
                    shape.kind()
                ));
            }
            let numbers = pose
                .translation
                .vector
                .iter()
                .chain(pose.rotation.coords.iter());
            if !numbers.into_iter().all(|v| v.is_finite()) {
                return Err(format!(
                    "held object `{name}` has a pose that is not finite"
                ));
            }
        }
    }
    Ok(())
}

/// `attached_collision_objects:` under a robot state (nothing when there are none).
pub(crate) fn write_attached(out: &mut String, attached: &[AttachedObject]) {
    if attached.is_empty() {
        return;
    }
    let _ = writeln!(out, "  attached_collision_objects:");
    for o in attached {
        let touch: Vec<String> = o.touch_links.iter().map(|l| quote(l)).collect();
        let _ = write!(
            out,
            "    - link_name: {}\n      touch_links: [{}]\n      object:\n        ",
            quote(&o.link),
            touch.join(", ")
        );
        let shapes: Vec<(&Shape, &Isometry3<f64>)> = o.shapes.iter().map(|(s, p)| (s, p)).collect();
        write_object(out, "        ", &o.name, &shapes);
    }
}

/// A collision object's fields (`id`, primitives and meshes with their poses), each line
/// indented by `indent` but the first (written where the caller stands).
fn write_object(out: &mut String, indent: &str, id: &str, shapes: &[(&Shape, &Isometry3<f64>)]) {
    let _ = writeln!(out, "id: {}", quote(id));
    let pose = |out: &mut String, p: &Isometry3<f64>| {
        let t = p.translation.vector;
        let q = p.rotation.coords; // x, y, z, w
        let _ = writeln!(
            out,
            "{indent}  - position: [{}]\n{indent}    orientation: [{}]",
            list(&[t.x, t.y, t.z]),
            list(&[q.x, q.y, q.z, q.w])
        );
    };
    let (meshes, primitives): (Vec<_>, Vec<_>) = shapes
        .iter()
        .partition(|(s, _)| matches!(s, Shape::Mesh { .. }));
    if !primitives.is_empty() {
        let _ = writeln!(out, "{indent}primitives:");
        for (shape, _) in &primitives {
            let (kind, d) = match shape {
                Shape::Box { size } => ("box", size.to_vec()),
                Shape::Sphere { radius } => ("sphere", vec![*radius]),
                Shape::Cylinder { radius, length } => ("cylinder", vec![*length, *radius]),
                _ => unreachable!("checked by to_yaml"),
            };
            let _ = writeln!(
                out,
                "{indent}  - type: {kind}\n{indent}    dimensions: [{}]",
                list(&d)
            );
        }
        let _ = writeln!(out, "{indent}primitive_poses:");
        for (_, p) in &primitives {
            pose(out, p);
        }
    }
    if !meshes.is_empty() {
        let _ = writeln!(out, "{indent}meshes:");
        for (shape, _) in &meshes {
            let Shape::Mesh {
                vertices,
                triangles,
            } = shape
            else {
                unreachable!("partitioned")
            };
            let vertices: Vec<String> = vertices.iter().map(|v| format!("[{}]", list(v))).collect();
            let triangles: Vec<String> = triangles
                .iter()
                .map(|t| format!("[{}, {}, {}]", t[0], t[1], t[2]))
                .collect();
            let _ = writeln!(
                out,
                "{indent}  - vertices: [{}]\n{indent}    triangles: [{}]",
                vertices.join(", "),
                triangles.join(", ")
            );
        }
        let _ = writeln!(out, "{indent}mesh_poses:");
        for (_, p) in &meshes {
            pose(out, p);
        }
    }
}
