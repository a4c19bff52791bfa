//! [`RobotModel`]: a URDF tree plus motors, couplings, named frames, groups and postures.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use nalgebra::Isometry3;

use crate::batch::PoseBatch;
use crate::description::{DisableReason, FrameSpec, ModelDescription};
use crate::error::{KinematicsError, NameKind, Result, unknown};
use crate::fk::{AffineRow, FrameId, Plan, PoseBuffer, affine};
use crate::resolve::{
    DescCtx, resolve_collision_pairs, resolve_frames, resolve_groups, resolve_motion_limits,
    resolve_motors, resolve_planning, resolve_postures,
};
use crate::tree::{Ctx, Limits, Tree};

/// A motor: one optimisation variable, driving one or more joints.
#[derive(Debug, Clone, PartialEq)]
pub struct Motor {
    /// Unique name (for an uncoupled joint, the joint's name).
    pub name: String,
    /// Position limits, and velocity limit (∞ when unknown). Continuous joints get [−π, π].
    pub limits: Limits,
}

/// `joint value = offset + Σ factor · motor[index]` for one movable joint.
#[derive(Debug, Clone, PartialEq)]
pub struct Coupling {
    /// `(motor index, factor)` terms.
    pub terms: Vec<(usize, f64)>,
    /// Constant term.
    pub offset: f64,
}

/// A named frame: a link plus a fixed offset.
#[derive(Debug, Clone, PartialEq)]
pub struct NamedFrame {
    /// Unique name.
    pub name: String,
    /// The link it is attached to.
    pub link: usize,
    /// Pose of the frame in the link frame.
    pub local_offset: Isometry3<f64>,
}

/// A link pair excluded from collision checking, resolved to link indices (`links[0] < links[1]`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct DisabledCollision {
    /// The two links, by index into [`Tree::links`].
    pub links: [usize; 2],
    /// Why the pair is excluded.
    pub reason: DisableReason,
}

#[derive(Debug)]
struct ModelData {
    origin: String,
    tree: Tree,
    motors: Vec<Motor>,
    couplings: Vec<Coupling>,
    frames: Vec<NamedFrame>,
    groups: Vec<(String, Vec<usize>)>,
    postures: Vec<(String, Vec<f64>)>,
    disabled_collisions: Vec<DisabledCollision>,
    enabled_collisions: Vec<[usize; 2]>,
    /// Directories searched for `package://` meshes (the description's, resolved).
    package_paths: Vec<PathBuf>,
    /// The description's settings for sampling planners.
    planning: crate::PlanningSpec,
    /// FK over joint values.
    joint_plan: Plan,
    /// FK over motor values.
    motor_plan: Plan,
}

/// A robot: the URDF link tree, the motors that drive its joints, named frames, motor groups and
/// named postures. Cheap to clone (shared), `Send + Sync`.
///
/// Three vector spaces appear in the API:
/// * **joint values**: one per movable URDF joint, in [`RobotModel::joint_names`] order;
/// * **motor values**: one per motor, in [`RobotModel::motors`] order; joints follow motors
///   through the linear [`Coupling`]s;
/// * **active values**: the motors an [`crate::ActiveSet`] makes variables, the rest locked.
#[derive(Debug, Clone)]
pub struct RobotModel {
    data: Arc<ModelData>,
}

impl TryFrom<&urdf_rs::Robot> for RobotModel {
    type Error = KinematicsError;
    fn try_from(robot: &urdf_rs::Robot) -> Result<Self> {
        Self::build(
            robot,
            &ModelDescription::default(),
            &Ctx {
                origin: "<urdf>",
                source: None,
            },
            None,
        )
    }
}

fn parse_urdf(text: &str, origin: &str) -> Result<urdf_rs::Robot> {
    let malformed = |message: String| KinematicsError::MalformedUrdf {
        origin: origin.to_string(),
        message,
    };
    crate::check_xml_nesting(text.as_bytes(), crate::XML_NESTING_LIMIT)
        .map_err(|e| malformed(format!("{e}: flatten the file (trm's XML nesting limit)")))?;
    // urdf-rs's XML layer (RustyXML) panics on some malformed namespace declarations (found by
    // fuzzing: an attribute in a namespace bound to no prefix); that is an error, not a crash
    match quietly(|| urdf_rs::read_from_string(text)) {
        Ok(parsed) => parsed.map_err(|e| malformed(e.to_string())),
        Err(panic) => {
            let why = (panic.downcast_ref::<&str>().map(|s| s.to_string()))
                .or_else(|| panic.downcast_ref::<String>().cloned())
                .unwrap_or_else(|| "the XML parser failed".into());
            Err(malformed(format!(
                "{why} (the XML is malformed; check its xmlns declarations and prefixes)"
            )))
        }
    }
}

/// Runs `f`, catching a panic without the panic hook printing it (on this thread; panics
/// elsewhere are reported as before): for third-party parsers that panic on some malformed
/// input (urdf-rs's XML layer, mesh-loader's COLLADA reader), so that trm reports an error.
pub fn quietly<R>(f: impl FnOnce() -> R + std::panic::UnwindSafe) -> std::thread::Result<R> {
    use std::cell::Cell;
    thread_local!(static QUIET: Cell<bool> = const { Cell::new(false) });
    static HOOK: std::sync::Once = std::sync::Once::new();
    HOOK.call_once(|| {
        let previous = std::panic::take_hook();
        std::panic::set_hook(Box::new(move |info| {
            if !QUIET.with(Cell::get) {
                previous(info);
            }
        }));
    });
    QUIET.with(|q| q.set(true));
    let result = std::panic::catch_unwind(f);
    QUIET.with(|q| q.set(false));
    result
}

impl RobotModel {
    /// Loads a model from a `.urdf` file or a `.ron` model description (which names its URDF).
    pub fn load(path: impl AsRef<Path>) -> Result<Self> {
        let path = path.as_ref();
        if path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("ron"))
        {
            Self::from_description_file(path)
        } else {
            Self::from_urdf_file(path)
        }
    }

    /// Loads a plain URDF file: every movable joint is a motor (mimic joints follow their leader).
    /// Mesh files are never opened.
    pub fn from_urdf_file(path: impl AsRef<Path>) -> Result<Self> {
        let path = path.as_ref();
        Self::from_urdf_str(&crate::error::read_text(path)?, &path.display().to_string())
    }

    /// Parses URDF text; `origin` names the text in errors (a file name or `<string>`).
    pub fn from_urdf_str(urdf: &str, origin: &str) -> Result<Self> {
        Self::from_parts(urdf, origin, &ModelDescription::default(), None)
    }

    /// Loads a model description (RON) and the URDF it names (relative to the description).
    pub fn from_description_file(path: impl AsRef<Path>) -> Result<Self> {
        let path = path.as_ref();
        let text = crate::error::read_text(path)?;
        let origin = path.display().to_string();
        let mut description = ModelDescription::from_ron(&text, &origin)?;
        let dir = path.parent().unwrap_or(Path::new("."));
        let urdf_path = dir.join(&description.urdf);
        for p in &mut description.package_paths {
            *p = dir.join(&*p);
        }
        let urdf = crate::error::read_text(&urdf_path)?;
        Self::from_parts(
            &urdf,
            &urdf_path.display().to_string(),
            &description,
            Some((&text, &origin)),
        )
    }

    /// Builds a model from URDF text and a description; `origin` names the URDF in errors and
    /// `description_text` is the description's `(text, origin)` when it came from a file.
    pub fn from_parts(
        urdf: &str,
        origin: &str,
        description: &ModelDescription,
        description_text: Option<(&str, &str)>,
    ) -> Result<Self> {
        let robot = parse_urdf(urdf, origin)?;
        Self::build(
            &robot,
            description,
            &Ctx {
                origin,
                source: Some(urdf),
            },
            description_text,
        )
    }

    fn build(
        robot: &urdf_rs::Robot,
        desc: &ModelDescription,
        ctx: &Ctx,
        desc_text: Option<(&str, &str)>,
    ) -> Result<Self> {
        let tree = Tree::from_urdf(robot, ctx)?;
        Self::assemble(tree, ctx.origin, desc, desc_text)
    }

    /// The same URDF (kinematic tree) with another description in place of this model's:
    /// motors, couplings, frames, groups, postures and collision pairs resolved anew, without
    /// parsing the URDF again. `description_text` is the description's `(text, origin)` when
    /// it came from a file, for located errors.
    pub fn with_description(
        &self,
        description: &ModelDescription,
        description_text: Option<(&str, &str)>,
    ) -> Result<Self> {
        Self::assemble(
            self.data.tree.clone(),
            &self.data.origin,
            description,
            description_text,
        )
    }

    fn assemble(
        tree: Tree,
        origin: &str,
        desc: &ModelDescription,
        desc_text: Option<(&str, &str)>,
    ) -> Result<Self> {
        let dctx = DescCtx {
            origin: desc_text.map_or("<description>", |d| d.1),
            text: desc_text.map(|d| d.0),
        };
        let (mut motors, couplings) = resolve_motors(&tree, desc, &dctx)?;
        resolve_motion_limits(&mut motors, desc, &dctx)?;
        let frames = resolve_frames(&tree, Vec::new(), &desc.frames, &dctx)?;
        let groups = resolve_groups(&motors, desc, &dctx)?;
        let postures = resolve_postures(&motors, desc, &dctx)?;
        let (disabled_collisions, enabled_collisions) =
            resolve_collision_pairs(&tree, desc, &dctx)?;
        let planning = resolve_planning(desc, &dctx)?;
        let (joint_plan, motor_plan) = compile_plans(&tree, &frames, &couplings);
        Ok(RobotModel {
            data: Arc::new(ModelData {
                package_paths: desc.package_paths.clone(),
                planning,
                origin: origin.to_string(),
                tree,
                motors,
                couplings,
                frames,
                groups,
                postures,
                disabled_collisions,
                enabled_collisions,
                joint_plan,
                motor_plan,
            }),
        })
    }

    /// The same model with more named frames (attached to links or to earlier frames), as a
    /// task spec adds them; `origin` names where they come from in errors. Pose buffers of the
    /// new model hold the new frames after the old ones.
    pub fn with_frames(&self, frames: &[FrameSpec], origin: &str) -> Result<Self> {
        let d = &*self.data;
        let ctx = DescCtx { origin, text: None };
        let all = resolve_frames(&d.tree, d.frames.clone(), frames, &ctx)?;
        let (joint_plan, motor_plan) = compile_plans(&d.tree, &all, &d.couplings);
        Ok(RobotModel {
            data: Arc::new(ModelData {
                package_paths: d.package_paths.clone(),
                planning: d.planning,
                origin: d.origin.clone(),
                tree: d.tree.clone(),
                motors: d.motors.clone(),
                couplings: d.couplings.clone(),
                frames: all,
                groups: d.groups.clone(),
                postures: d.postures.clone(),
                disabled_collisions: d.disabled_collisions.clone(),
                enabled_collisions: d.enabled_collisions.clone(),
                joint_plan,
                motor_plan,
            }),
        })
    }

    /// Directories the model description gives for `package://` meshes (resolved against the
    /// description's directory; empty for a bare URDF).
    pub fn package_paths(&self) -> &[PathBuf] {
        &self.data.package_paths
    }

    /// The description's settings for sampling planners (empty for a bare URDF).
    pub fn planning(&self) -> &crate::PlanningSpec {
        &self.data.planning
    }

    /// Where the model was loaded from (the URDF file name, or `<string>`).
    pub fn origin(&self) -> &str {
        &self.data.origin
    }

    /// The robot name from the URDF.
    pub fn name(&self) -> &str {
        &self.data.tree.name
    }

    /// The link tree.
    pub fn tree(&self) -> &Tree {
        &self.data.tree
    }

    /// Number of links.
    pub fn num_links(&self) -> usize {
        self.data.tree.links.len()
    }

    /// Number of movable joints (the length of a joint-value vector).
    pub fn num_joints(&self) -> usize {
        self.data.tree.movable.len()
    }

    /// Names of the movable joints, in joint-value order.
    pub fn joint_names(&self) -> impl ExactSizeIterator<Item = &str> {
        self.data
            .tree
            .movable
            .iter()
            .map(|&j| self.data.tree.joints[j].name.as_str())
    }

    /// The movable joint at coordinate `i`.
    pub fn joint(&self, i: usize) -> &crate::tree::Joint {
        &self.data.tree.joints[self.data.tree.movable[i]]
    }

    /// Coordinate (joint-value index) of the movable joint `name`.
    pub fn joint_index(&self, name: &str) -> Result<usize> {
        self.data
            .tree
            .joint_index(name)
            .and_then(|j| self.data.tree.joints[j].coordinate)
            .ok_or_else(|| unknown(NameKind::Joint, name, self.joint_names()))
    }

    /// Motors, in motor-value order.
    pub fn motors(&self) -> &[Motor] {
        &self.data.motors
    }

    /// Index of the motor `name`.
    pub fn motor_index(&self, name: &str) -> Result<usize> {
        self.data
            .motors
            .iter()
            .position(|m| m.name == name)
            .ok_or_else(|| {
                unknown(
                    NameKind::Motor,
                    name,
                    self.data.motors.iter().map(|m| m.name.as_str()),
                )
            })
    }

    /// The coupling of every movable joint, in joint-value order.
    pub fn couplings(&self) -> &[Coupling] {
        &self.data.couplings
    }

    /// Whether some joint is driven by anything other than exactly one motor of its own.
    pub fn is_coupled(&self) -> bool {
        self.data.motors.len() != self.num_joints()
            || self
                .data
                .couplings
                .iter()
                .any(|c| c.offset != 0.0 || c.terms.len() != 1 || c.terms[0].1 != 1.0)
    }

    /// Named frames (not including links).
    pub fn named_frames(&self) -> &[NamedFrame] {
        &self.data.frames
    }

    /// The pose-buffer index of a link or named frame.
    pub fn frame_id(&self, name: &str) -> Result<FrameId> {
        if let Some(i) = self.data.tree.link_index(name) {
            return Ok(FrameId(i));
        }
        if let Some(i) = self.data.frames.iter().position(|f| f.name == name) {
            return Ok(FrameId(self.num_links() + i));
        }
        Err(unknown(NameKind::Frame, name, self.frame_names()))
    }

    /// The link a frame (a link, or a named frame attached to a link) moves with.
    pub fn frame_link(&self, frame: FrameId) -> usize {
        let i = frame.0;
        if i < self.num_links() {
            i
        } else {
            self.data.frames[i - self.num_links()].link
        }
    }

    /// Names of all links then all named frames, in pose-buffer order.
    pub fn frame_names(&self) -> impl Iterator<Item = &str> {
        let links = self.data.tree.links.iter().map(|l| l.name.as_str());
        links.chain(self.data.frames.iter().map(|f| f.name.as_str()))
    }

    /// Number of poses a [`PoseBuffer`] holds (links + named frames).
    pub fn num_frames(&self) -> usize {
        self.num_links() + self.data.frames.len()
    }

    /// Motor groups, in declaration order.
    pub fn groups(&self) -> impl Iterator<Item = (&str, &[usize])> {
        self.data
            .groups
            .iter()
            .map(|(n, m)| (n.as_str(), m.as_slice()))
    }

    /// Motor indices of group `name`.
    pub fn group(&self, name: &str) -> Result<&[usize]> {
        self.data
            .groups
            .iter()
            .find(|(n, _)| n == name)
            .map(|(_, m)| m.as_slice())
            .ok_or_else(|| {
                unknown(
                    NameKind::Group,
                    name,
                    self.data.groups.iter().map(|(n, _)| n.as_str()),
                )
            })
    }

    /// Motor indices for a list of motor and group names, in the given order, without repeats.
    pub fn select_motors<S: AsRef<str>>(&self, names: &[S]) -> Result<Vec<usize>> {
        let mut out = Vec::new();
        for name in names {
            let name = name.as_ref();
            let found: Vec<usize> = if let Ok(g) = self.group(name) {
                g.to_vec()
            } else if let Ok(m) = self.motor_index(name) {
                vec![m]
            } else {
                let candidates = self.data.groups.iter().map(|(n, _)| n.as_str());
                let candidates = candidates.chain(self.data.motors.iter().map(|m| m.name.as_str()));
                return Err(unknown(NameKind::MotorOrGroup, name, candidates));
            };
            for m in found {
                if !out.contains(&m) {
                    out.push(m);
                }
            }
        }
        Ok(out)
    }

    /// Names of the named postures.
    pub fn posture_names(&self) -> impl Iterator<Item = &str> {
        self.data.postures.iter().map(|(n, _)| n.as_str())
    }

    /// Motor values of the named posture.
    pub fn posture(&self, name: &str) -> Result<&[f64]> {
        self.data
            .postures
            .iter()
            .find(|(n, _)| n == name)
            .map(|(_, v)| v.as_slice())
            .ok_or_else(|| unknown(NameKind::Posture, name, self.posture_names()))
    }

    /// Link pairs the description excludes from collision checking.
    pub fn disabled_collisions(&self) -> &[DisabledCollision] {
        &self.data.disabled_collisions
    }

    /// Link pairs the description forces collision checking to test (`[a, b]` link indices).
    pub fn enabled_collisions(&self) -> &[[usize; 2]] {
        &self.data.enabled_collisions
    }

    /// Every motor's name, in motor order (the columns of a full configuration).
    pub fn motor_names(&self) -> Vec<String> {
        self.data.motors.iter().map(|m| m.name.clone()).collect()
    }

    /// The `home` posture's motor values, else [`RobotModel::neutral_motors`]: where the robot
    /// rests when nothing says otherwise.
    pub fn home_motors(&self) -> Vec<f64> {
        self.posture("home")
            .map_or_else(|_| self.neutral_motors(), <[f64]>::to_vec)
    }

    /// The zero motor vector clamped into the motor limits (the default locked values).
    pub fn neutral_motors(&self) -> Vec<f64> {
        self.data
            .motors
            .iter()
            .map(|m| 0.0f64.clamp(m.limits.lower, m.limits.upper))
            .collect()
    }

    /// A pose buffer sized for this model.
    pub fn pose_buffer(&self) -> PoseBuffer {
        PoseBuffer::new(self.num_joints(), self.num_frames())
    }

    /// Joint values from motor values, through the couplings.
    pub fn motors_to_joints(&self, motors: &[f64], joints: &mut [f64]) -> Result<()> {
        check_vector("motor values", motors, self.data.motors.len(), |i| {
            &self.data.motors[i].name
        })?;
        if joints.len() != self.num_joints() {
            return Err(KinematicsError::WrongLength {
                what: "joint values",
                expected: self.num_joints(),
                got: joints.len(),
            });
        }
        for (value, c) in joints.iter_mut().zip(&self.data.couplings) {
            *value = affine(c.offset, &c.terms, motors);
        }
        Ok(())
    }

    /// Forward kinematics from joint values: the world pose (world = root link) of every link
    /// and named frame into `buffer`.
    pub fn forward_joints(&self, joints: &[f64], buffer: &mut PoseBuffer) -> Result<()> {
        check_vector("joint values", joints, self.num_joints(), |i| {
            &self.joint(i).name
        })?;
        self.check_buffer(buffer)?;
        self.data.joint_plan.run(joints, buffer);
        Ok(())
    }

    /// Forward kinematics from motor values (every motor, in [`RobotModel::motors`] order).
    pub fn forward_motors(&self, motors: &[f64], buffer: &mut PoseBuffer) -> Result<()> {
        check_vector("motor values", motors, self.data.motors.len(), |i| {
            &self.data.motors[i].name
        })?;
        self.check_buffer(buffer)?;
        self.data.motor_plan.run(motors, buffer);
        Ok(())
    }

    /// A pose batch sized for this model ([`LANES`](crate::LANES) configurations at once).
    pub fn pose_batch(&self) -> PoseBatch {
        PoseBatch::new(self.num_joints(), self.num_frames())
    }

    /// A single-precision pose block sized for this model
    /// ([`BLOCK_LANES`](crate::BLOCK_LANES) configurations at once).
    pub fn pose_block(&self) -> crate::PoseBlock {
        // a pass's inputs are joint values or motor values (all or the active ones)
        let inputs = self.num_joints().max(self.motors().len());
        crate::PoseBlock::new(inputs, self.num_joints(), self.num_frames())
    }

    pub(crate) fn check_block_buffer(&self, block: &crate::PoseBlock) -> Result<()> {
        if !block.fits(self.num_joints(), self.num_frames()) {
            return Err(KinematicsError::WrongLength {
                what: "pose block (make it with RobotModel::pose_block)",
                expected: self.num_frames(),
                got: block.lanes().len(),
            });
        }
        Ok(())
    }

    /// Forward kinematics of [`LANES`](crate::LANES) joint vectors at once, given one after the
    /// other in `joints` (`LANES × num_joints` values), into `batch`. Each lane's poses equal
    /// [`RobotModel::forward_joints`]'s to ≤ 1e-12.
    pub fn forward_joints_batch(&self, joints: &[f64], batch: &mut PoseBatch) -> Result<()> {
        check_batch("joint values", joints, self.num_joints(), |i| {
            &self.joint(i).name
        })?;
        self.check_batch_buffer(batch)?;
        self.data
            .joint_plan
            .run_batch(joints, self.num_joints(), batch);
        Ok(())
    }

    /// Forward kinematics of [`LANES`](crate::LANES) motor vectors at once (`LANES × motors`
    /// values, one vector after the other) into `batch`.
    pub fn forward_motors_batch(&self, motors: &[f64], batch: &mut PoseBatch) -> Result<()> {
        let n = self.data.motors.len();
        check_batch("motor values", motors, n, |i| &self.data.motors[i].name)?;
        self.check_batch_buffer(batch)?;
        self.data.motor_plan.run_batch(motors, n, batch);
        Ok(())
    }

    pub(crate) fn check_batch_buffer(&self, batch: &PoseBatch) -> Result<()> {
        if !batch.fits(self.num_joints(), self.num_frames()) {
            return Err(KinematicsError::WrongLength {
                what: "pose batch (make it with RobotModel::pose_batch)",
                expected: self.num_frames(),
                got: batch.len(),
            });
        }
        Ok(())
    }

    pub(crate) fn check_buffer(&self, buffer: &PoseBuffer) -> Result<()> {
        if !buffer.fits(self.num_joints(), self.num_frames()) {
            return Err(KinematicsError::WrongLength {
                what: "pose buffer (make it with RobotModel::pose_buffer)",
                expected: self.num_frames(),
                got: buffer.len(),
            });
        }
        Ok(())
    }
}

/// Checks a batch of [`LANES`](crate::LANES) vectors of `n` values each, one after the other:
/// length and finiteness; `name(i)` names entry `i` of a vector in errors.
pub(crate) fn check_batch<'a>(
    what: &'static str,
    values: &[f64],
    n: usize,
    name: impl Fn(usize) -> &'a str,
) -> Result<()> {
    check_lanes(what, values, n, crate::LANES, name)
}

/// Checks `lanes` vectors of `n` finite values, one after the other in `values`.
pub(crate) fn check_lanes<'a>(
    what: &'static str,
    values: &[f64],
    n: usize,
    lanes: usize,
    name: impl Fn(usize) -> &'a str,
) -> Result<()> {
    if values.len() != lanes * n {
        return Err(KinematicsError::WrongLength {
            what,
            expected: lanes * n,
            got: values.len(),
        });
    }
    for lane in values.chunks(n.max(1)) {
        check_vector(what, lane, n, &name)?;
    }
    Ok(())
}

/// Checks length and finiteness of a vector; `name(i)` names entry `i` in errors.
pub(crate) fn check_vector<'a>(
    what: &'static str,
    values: &[f64],
    expected: usize,
    name: impl Fn(usize) -> &'a str,
) -> Result<()> {
    if values.len() != expected {
        return Err(KinematicsError::WrongLength {
            what,
            expected,
            got: values.len(),
        });
    }
    if let Some(index) = values.iter().position(|v| !v.is_finite()) {
        return Err(KinematicsError::NonFinite {
            what,
            index,
            name: name(index).to_string(),
            value: values[index],
        });
    }
    Ok(())
}

/// The compiled forward passes over joint values and over motor values.
fn compile_plans(tree: &Tree, frames: &[NamedFrame], couplings: &[Coupling]) -> (Plan, Plan) {
    let frame_offsets: Vec<_> = frames.iter().map(|f| (f.link, f.local_offset)).collect();
    let identity: Vec<[(usize, f64); 1]> = (0..tree.movable.len()).map(|c| [(c, 1.0)]).collect();
    let joint_rows: Vec<AffineRow> = identity
        .iter()
        .map(|t| AffineRow {
            constant: 0.0,
            terms: t,
        })
        .collect();
    let joint_plan = Plan::compile(tree, &frame_offsets, &joint_rows);
    let motor_rows: Vec<AffineRow> = couplings
        .iter()
        .map(|c| AffineRow {
            constant: c.offset,
            terms: &c.terms,
        })
        .collect();
    let motor_plan = Plan::compile(tree, &frame_offsets, &motor_rows);
    (joint_plan, motor_plan)
}
