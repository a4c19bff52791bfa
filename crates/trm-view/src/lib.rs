//! Scenes for looking at what trm computes: a robot as it looks (its URDF visuals, meshes in
//! their materials' colours) and its collision shapes, the objects it holds, link poses over
//! time (postures or a motion), world objects (primitives, meshes, point clouds), roadmap task
//! points and edges coloured by cost, and a task-space path — as a versioned JSON document
//! ([`Scene`], format `trm-scene` v2) and as one self-contained HTML page that renders it with
//! three.js ([`Scene::to_html`]).
//!
//! The page's code lives in `viewer/` (an npm package: three.js and our `src/main.js`, bundled by
//! esbuild into `viewer/dist/viewer.js`). When the bundle has been built it is inlined, so the
//! page works offline; otherwise the page loads the same pinned three.js from a public CDN.
//!
//! `tools/trm-rrd` turns a scene file into a Rerun recording.
//!
//! ```
//! let model = trm_models::icub_upper_body();
//! let collision = trm_collision::CollisionModel::new(&model)?;
//! let mut scene = trm_view::Scene::new("iCub at home", &collision);
//! scene.add_frame(0.0, &model.posture("home")?.to_vec())?;
//! let html = scene.to_html(None)?;
//! assert!(html.contains("trm-scene"));
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};
use thiserror::Error;
use trm_collision::{CollisionModel, Shape, World};
use trm_kinematics::JointKind;
use trm_kinematics::nalgebra::Isometry3;
use trm_kinematics::{PoseBuffer, RobotModel};

mod subjects;
mod visuals;
pub use subjects::point3;
pub use visuals::{DEFAULT_COLOR, SceneVisual};

/// The scene format's name and version.
pub const FORMAT: &str = "trm-scene";
/// The scene format version this crate writes (it reads this one and
/// [`OLDEST_VERSION`] on: version 2 added the robot's visuals and held objects).
pub const VERSION: u32 = 2;
/// The oldest scene format version this crate reads.
pub const OLDEST_VERSION: u32 = 1;
/// The three.js version the page uses (the one `viewer/package.json` pins).
pub const THREE_VERSION: &str = "0.187.0";
/// The viewer's own code (bundled with three.js by `npm run build` in `viewer/`).
pub const VIEWER_SOURCE: &str = include_str!("../viewer/main.js");

/// Errors of scene building.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum ViewError {
    /// A scene file could not be read or written.
    #[error(transparent)]
    SceneFile(#[from] trm_io::FileError),
    /// Invalid input.
    #[error("{what}: {problem}")]
    Invalid {
        /// What was given.
        what: String,
        /// What is wrong.
        problem: String,
    },
    /// From the kinematics.
    #[error(transparent)]
    Kinematics(#[from] trm_kinematics::KinematicsError),
    /// JSON encoding.
    #[error("scene JSON: {0}")]
    Json(#[from] serde_json::Error),
    /// Reading the bundle.
    #[error("{path}: {message}")]
    Io {
        /// The file.
        path: String,
        /// The problem.
        message: String,
    },
}

/// Result alias of this crate.
pub type Result<T, E = ViewError> = std::result::Result<T, E>;

/// A pose as `[x, y, z, qx, qy, qz, qw]`.
pub type Pose = [f64; 7];

/// A collision body on a link.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneBody {
    /// Body name.
    pub name: String,
    /// Index into [`Scene::links`].
    pub link: usize,
    /// Shape, as trm-collision writes it: `{"Box": {"size": [x, y, z]}}`, `{"Sphere":
    /// {"radius": r}}`, `{"Cylinder"|"Capsule": {"radius": r, "length": l}}` (along z),
    /// `{"Convex": {"points": [...]}}`.
    pub shape: Shape,
    /// Pose of the shape in the link frame.
    pub local: Pose,
    /// The held object this body belongs to (a MoveIt attached object), if any.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub held: Option<String>,
}

/// One frame: the link poses at a time.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneFrame {
    /// Time, seconds (or an index for a set of postures).
    pub t: f64,
    /// Pose of the robot's root link in the scene (identity unless the robot stands on its
    /// feet, say).
    pub base: Pose,
    /// Joint values (one per movable joint): what the page's own forward kinematics uses.
    pub joints: Vec<f64>,
    /// World poses of [`Scene::links`].
    pub poses: Vec<Pose>,
    /// Where [`Scene::world`]'s objects are in this frame (`None`: absent), when they move;
    /// absent when they stand still.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub world: Option<Vec<Option<Pose>>>,
    /// The state of [`Scene::map`] in this frame, when it changes (a map in a moving world).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub map: Option<FrameMap>,
}

/// The state of a changing map in one frame: how many of the scene map's points and edges
/// exist yet (they only grow), and which are blocked (drawn red).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FrameMap {
    /// The first `nodes` points of [`SceneMap::points`] exist.
    pub nodes: usize,
    /// The first `edges` edges exist.
    pub edges: usize,
    /// Blocked points (indices below `nodes`).
    pub blocked: Vec<usize>,
    /// Blocked edges (indices below `edges`).
    pub blocked_edges: Vec<usize>,
}

/// A world object.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneObject {
    /// Name.
    pub name: String,
    /// Shape (as in [`SceneBody::shape`]).
    pub shape: Shape,
    /// World pose.
    pub pose: Pose,
}

/// A roadmap: task points coloured by cost, edges, and each point's posture.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneMap {
    /// Where each point is drawn (its task point, or a frame's position), metres.
    pub points: Vec<[f64; 3]>,
    /// Cost of each point (colour).
    pub cost: Vec<f64>,
    /// Edges as point index pairs.
    pub edges: Vec<[usize; 2]>,
    /// Joint values of each point's posture (shown on click).
    pub joints: Vec<Vec<f64>>,
}

/// What the page needs to run forward kinematics for map postures: the tree.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneKinematics {
    /// Link names in tree order (parents first).
    pub links: Vec<String>,
    /// Joints in tree order (joint i's child is link i + 1).
    pub joints: Vec<SceneJoint>,
}

/// A tree joint.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneJoint {
    /// Parent link index.
    pub parent: usize,
    /// `revolute` (also continuous), `prismatic` or `fixed`.
    pub kind: String,
    /// Joint frame in the parent link frame.
    pub origin: Pose,
    /// Unit axis in the joint frame.
    pub axis: [f64; 3],
    /// Index into a frame's `joints` (movable joints only).
    pub coordinate: Option<usize>,
}

/// A scene document.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Scene {
    /// Always [`FORMAT`].
    pub format: String,
    /// Always [`VERSION`].
    pub version: u32,
    /// The software that wrote it.
    pub generator: String,
    /// Page title.
    pub title: String,
    /// Names of the links that carry bodies or visuals (the order of every frame's poses).
    pub links: Vec<String>,
    /// Tree index of each of [`Scene::links`].
    pub link_index: Vec<usize>,
    /// Collision bodies.
    pub bodies: Vec<SceneBody>,
    /// The robot's look: its URDF visuals (empty when it has none, or in a version 1 scene).
    #[serde(default)]
    pub visuals: Vec<SceneVisual>,
    /// The visuals that could not be loaded (a mesh file not found, say), one line each: the
    /// page then shows the collision shapes.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub missing_visuals: Vec<String>,
    /// Frames (one per posture or trajectory sample).
    pub frames: Vec<SceneFrame>,
    /// World objects.
    pub world: Vec<SceneObject>,
    /// Optional roadmap.
    pub map: Option<SceneMap>,
    /// Optional task-space path (e.g. a planned motion's hand positions).
    pub path: Vec<[f64; 3]>,
    /// The kinematic tree, for the page's forward kinematics.
    pub kinematics: SceneKinematics,
    #[serde(skip)]
    model: Option<RobotModel>,
}

/// A pose as the scene stores it (position, then quaternion x, y, z, w).
pub fn pose(p: &Isometry3<f64>) -> Pose {
    let t = p.translation.vector;
    let q = p.rotation.coords; // (i, j, k, w)
    let r = |v: f64| (v * 1e7).round() / 1e7;
    [r(t.x), r(t.y), r(t.z), r(q.x), r(q.y), r(q.z), r(q.w)]
}

impl Scene {
    /// An empty scene of `collision`'s robot: its bodies, the objects it holds, its visuals
    /// (URDF `<visual>` meshes found as its collision meshes are; those that cannot be loaded
    /// are listed in [`Scene::missing_visuals`]) and its tree; no frames yet.
    pub fn new(title: &str, collision: &CollisionModel) -> Self {
        let model = collision.robot().clone();
        let tree = model.tree();
        let mut links: Vec<String> = Vec::new();
        let mut link_index = Vec::new();
        let mut slot_of = |link: usize| match link_index.iter().position(|&l| l == link) {
            Some(s) => s,
            None => {
                link_index.push(link);
                links.push(tree.links[link].name.clone());
                links.len() - 1
            }
        };
        let mut bodies = Vec::new();
        for b in collision.bodies() {
            bodies.push(SceneBody {
                name: b.name.clone(),
                link: slot_of(b.link),
                shape: b.shape.clone(),
                local: pose(&b.local),
                held: collision
                    .attached()
                    .iter()
                    .find(|o| o.holds(&b.name))
                    .map(|o| o.name.clone()),
            });
        }
        let loaded = visuals::load(collision);
        let visuals = loaded
            .parts
            .into_iter()
            .map(|v| SceneVisual {
                link: slot_of(v.link),
                ..v
            })
            .collect();
        let kinematics = SceneKinematics {
            links: tree.links.iter().map(|l| l.name.clone()).collect(),
            joints: tree
                .joints
                .iter()
                .map(|j| SceneJoint {
                    parent: j.parent,
                    kind: match j.kind {
                        JointKind::Prismatic => "prismatic",
                        JointKind::Fixed => "fixed",
                        _ => "revolute",
                    }
                    .into(),
                    origin: pose(&j.local_origin),
                    axis: [j.axis.x, j.axis.y, j.axis.z],
                    coordinate: j.coordinate,
                })
                .collect(),
        };
        Scene {
            format: FORMAT.into(),
            version: VERSION,
            generator: format!("trm {}", env!("CARGO_PKG_VERSION")),
            title: title.into(),
            links,
            link_index,
            bodies,
            visuals,
            missing_visuals: loaded.missing,
            frames: Vec::new(),
            world: Vec::new(),
            map: None,
            path: Vec::new(),
            kinematics,
            model: Some(model),
        }
    }

    fn model(&self) -> Result<&RobotModel> {
        self.model.as_ref().ok_or_else(|| ViewError::Invalid {
            what: "scene".into(),
            problem: "read from JSON: it has no robot model to add frames with".into(),
        })
    }

    /// Joint values for motor values `motors`; fills `buffer` with the link poses.
    fn posture(&self, motors: &[f64], buffer: &mut PoseBuffer) -> Result<Vec<f64>> {
        let model = self.model()?;
        if motors.len() != model.motors().len() || motors.iter().any(|v| !v.is_finite()) {
            return Err(ViewError::Invalid {
                what: "posture".into(),
                problem: format!(
                    "{} finite motor values needed, got {}",
                    model.motors().len(),
                    motors.len()
                ),
            });
        }
        let mut joints = vec![0.0; model.num_joints()];
        model.motors_to_joints(motors, &mut joints)?;
        model.all_active().forward(motors, buffer)?;
        Ok(joints)
    }

    /// Adds a frame at time `t` for motor values `motors` (every motor of the model).
    pub fn add_frame(&mut self, t: f64, motors: &[f64]) -> Result<()> {
        self.add_frame_at(t, motors, &Isometry3::identity())
    }

    /// Adds a frame with the robot's root link at `base` in the scene.
    pub fn add_frame_at(&mut self, t: f64, motors: &[f64], base: &Isometry3<f64>) -> Result<()> {
        let mut buffer = self.model()?.pose_buffer();
        let joints = self.posture(motors, &mut buffer)?;
        let poses = self
            .link_index
            .iter()
            .map(|&l| pose(&(base * buffer.poses()[l])))
            .collect();
        self.frames.push(SceneFrame {
            t,
            base: pose(base),
            joints,
            poses,
            world: None,
            map: None,
        });
        Ok(())
    }

    /// Adds the world's objects.
    pub fn set_world(&mut self, world: &World) {
        self.world = world
            .objects()
            .iter()
            .map(|o| SceneObject {
                name: o.name().into(),
                shape: o.shape().clone(),
                pose: pose(o.pose()),
            })
            .collect();
    }

    /// Sets the roadmap: for each point its drawn position, cost and motor values; and edges.
    pub fn set_map(
        &mut self,
        points: Vec<[f64; 3]>,
        cost: Vec<f64>,
        postures: &[Vec<f64>],
        edges: Vec<[usize; 2]>,
    ) -> Result<()> {
        let n = points.len();
        if cost.len() != n || postures.len() != n {
            return Err(ViewError::Invalid {
                what: "map".into(),
                problem: format!(
                    "{n} points, {} costs, {} postures",
                    cost.len(),
                    postures.len()
                ),
            });
        }
        if let Some(e) = edges.iter().find(|e| e[0] >= n || e[1] >= n) {
            return Err(ViewError::Invalid {
                what: "map".into(),
                problem: format!("edge {e:?} names a point beyond {n}"),
            });
        }
        let model = self.model()?;
        let mut joints = Vec::with_capacity(n);
        for q in postures {
            let mut j = vec![0.0; model.num_joints()];
            model.motors_to_joints(q, &mut j)?;
            joints.push(j.iter().map(|v| (v * 1e6).round() / 1e6).collect());
        }
        self.map = Some(SceneMap {
            points,
            cost,
            edges,
            joints,
        });
        Ok(())
    }

    /// Sets the task-space path.
    pub fn set_path(&mut self, path: Vec<[f64; 3]>) {
        self.path = path;
    }

    /// The scene as JSON; a scene that would not read back ([`Scene::check`]) is refused.
    pub fn to_json(&self) -> Result<String> {
        self.check()?;
        Ok(serde_json::to_string(self)?)
    }

    /// Reads a scene (of version [`OLDEST_VERSION`] to [`VERSION`]), checking its format and
    /// version (the one versioned-JSON reader of trm, [`trm_io::parse_versioned_since`]) and
    /// its content ([`Scene::check`]).
    pub fn from_json(text: &str) -> Result<Self> {
        Self::parse(std::path::Path::new("<scene>"), text)
    }

    /// Reads a scene file.
    pub fn load(path: impl AsRef<std::path::Path>) -> Result<Self> {
        let path = path.as_ref();
        let text = trm_io::read_input(path).map_err(|e| ViewError::Io {
            path: path.display().to_string(),
            message: e.to_string(),
        })?;
        Self::parse(path, &text)
    }

    fn parse(path: &std::path::Path, text: &str) -> Result<Self> {
        let mut scene: Scene =
            trm_io::parse_versioned_since(path, text, FORMAT, OLDEST_VERSION, VERSION)?;
        scene.version = VERSION;
        scene.check().map_err(|e| match e {
            ViewError::Invalid { what, problem } => ViewError::Invalid {
                what: format!("{}: {what}", path.display()),
                problem,
            },
            other => other,
        })?;
        Ok(scene)
    }

    /// Checks that the parts fit together: bodies on existing links, one pose per link in every
    /// frame and one value per movable joint, map arrays of one length with edges between its
    /// points, a tree whose parents come first, and finite numbers everywhere.
    pub fn check(&self) -> Result<()> {
        let bad = |what: String, problem: &str| {
            Err(ViewError::Invalid {
                what,
                problem: problem.to_string(),
            })
        };
        let finite = |values: &[f64]| values.iter().all(|v| v.is_finite());
        let links = self.links.len();
        let tree = self.kinematics.links.len();
        if self.link_index.len() != links
            || (tree > 0 && self.link_index.iter().any(|&l| l >= tree))
        {
            return bad(
                "link_index".into(),
                "needs one tree index per link, each naming a link of the tree",
            );
        }
        for (i, b) in self.bodies.iter().enumerate() {
            if b.link >= links || !finite(&b.local) {
                return bad(
                    format!("bodies[{i}]"),
                    "names no link or has a non-finite pose",
                );
            }
        }
        for (i, v) in self.visuals.iter().enumerate() {
            let color_ok = v.color.iter().all(|c| (0.0..=1.0).contains(c));
            if v.link >= links || !finite(&v.local) || !color_ok {
                return bad(
                    format!("visuals[{i}]"),
                    "names no link, or has a non-finite pose or a colour outside 0..=1",
                );
            }
        }
        let shapes = (self.bodies.iter().map(|b| ("bodies", &b.shape)))
            .chain(self.visuals.iter().map(|v| ("visuals", &v.shape)))
            .chain(self.world.iter().map(|o| ("world", &o.shape)));
        let mut counts = std::collections::HashMap::new();
        for (list, shape) in shapes {
            let i = counts.entry(list).or_insert(0usize);
            if let Err(p) = shape.check() {
                return bad(format!("{list}[{i}].shape"), &p.problem);
            }
            *i += 1;
        }
        let coordinates = self
            .kinematics
            .joints
            .iter()
            .filter(|j| j.coordinate.is_some())
            .count();
        for (i, j) in self.kinematics.joints.iter().enumerate() {
            let ok = j.parent <= i
                && j.coordinate.is_none_or(|c| c < coordinates)
                && finite(&j.origin)
                && finite(&j.axis);
            if !ok {
                return bad(
                    format!("kinematics.joints[{i}]"),
                    "has a parent after it, a coordinate out of range or a non-finite number",
                );
            }
        }
        for (i, f) in self.frames.iter().enumerate() {
            let joints_ok = self.kinematics.joints.is_empty() || f.joints.len() == coordinates;
            let ok = f.poses.len() == links
                && joints_ok
                && f.t.is_finite()
                && finite(&f.base)
                && finite(&f.joints)
                && f.poses.iter().all(|p| finite(p));
            if !ok {
                return bad(
                    format!("frames[{i}]"),
                    "needs one finite pose per link and one finite value per movable joint",
                );
            }
        }
        let points = self.map.as_ref().map_or(0, |m| m.points.len());
        let edges = self.map.as_ref().map_or(0, |m| m.edges.len());
        for (i, f) in self.frames.iter().enumerate() {
            let world_ok = f.world.as_ref().is_none_or(|w| {
                w.len() == self.world.len() && w.iter().flatten().all(|p| finite(p))
            });
            let map_ok = f.map.as_ref().is_none_or(|m| {
                m.nodes <= points
                    && m.edges <= edges
                    && m.blocked.iter().all(|&b| b < m.nodes)
                    && m.blocked_edges.iter().all(|&b| b < m.edges)
            });
            if !(world_ok && map_ok) {
                return bad(
                    format!("frames[{i}]"),
                    "needs one finite pose or null per world object, and map counts and blocked indices within the scene's map",
                );
            }
        }
        for (i, o) in self.world.iter().enumerate() {
            if !finite(&o.pose) {
                return bad(format!("world[{i}]"), "has a non-finite pose");
            }
        }
        if let Some(m) = &self.map {
            let n = m.points.len();
            let ok = m.cost.len() == n
                && m.joints.len() == n
                && m.points.iter().all(|p| finite(p))
                && finite(&m.cost)
                && m.joints.iter().all(|q| finite(q))
                && m.edges.iter().all(|e| e[0] < n && e[1] < n);
            if !ok {
                return bad(
                    "map".into(),
                    "needs one finite cost and posture per point and edges between its points",
                );
            }
        }
        if !self.path.iter().all(|p| finite(p)) {
            return bad("path".into(), "holds a non-finite point");
        }
        Ok(())
    }

    /// The page at `out` ([`Scene::to_html`] with `bundle`) and the scene's JSON beside it
    /// (`out` with `.json`), each with its contents, for the caller to write (together, as a
    /// command puts its outputs in place): what `trm view` and Python's `trm.view` write.
    pub fn page_files(&self, out: &Path, bundle: Option<&str>) -> Result<Vec<(PathBuf, String)>> {
        Ok(vec![
            (out.with_extension("json"), self.to_json()?),
            (out.to_path_buf(), self.to_html(bundle)?),
        ])
    }

    /// One self-contained HTML page that renders the scene. `bundle`: the built viewer
    /// (`viewer/dist/viewer.js`), inlined; `None`: our source as a module that imports the
    /// pinned three.js from a public CDN.
    pub fn to_html(&self, bundle: Option<&str>) -> Result<String> {
        // `</` cannot appear inside a <script>: JSON escapes it as `<\/`
        let json = self.to_json()?.replace("</", "<\\/");
        let title = self
            .title
            .replace('&', "&amp;")
            .replace('<', "&lt;")
            .replace('>', "&gt;");
        let script = match bundle {
            Some(code) => format!(
                "<script>{}</script>",
                code.replace("</script", "<\\/script")
            ),
            None => format!(
                "<script type=\"importmap\">{{\"imports\": {{\"three\": \"https://cdn.jsdelivr.net/npm/three@{v}/build/three.module.js\", \"three/addons/\": \"https://cdn.jsdelivr.net/npm/three@{v}/examples/jsm/\"}}}}</script>\n<script type=\"module\">{}</script>",
                VIEWER_SOURCE,
                v = THREE_VERSION
            ),
        };
        Ok(format!(
            "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<title>{title}</title>\n<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n<meta name=\"generator\" content=\"{}\">\n</head>\n<body>\n<script id=\"trm-scene\" type=\"application/json\">{json}</script>\n{script}\n</body>\n</html>\n",
            self.generator
        ))
    }
}

/// The built viewer bundle, `viewer/dist/viewer.js` under `repo`, if `npm run build` made it.
pub fn find_bundle(repo: &Path) -> Result<Option<String>> {
    let path = repo.join("viewer/dist/viewer.js");
    if !path.is_file() {
        return Ok(None);
    }
    std::fs::read_to_string(&path)
        .map(Some)
        .map_err(|e| ViewError::Io {
            path: path.display().to_string(),
            message: e.to_string(),
        })
}
