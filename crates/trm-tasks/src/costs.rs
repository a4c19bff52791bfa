//! Cost functions h_i(p, q, w) ≥ 0 (Table I of Stollenga et al., IROS 2013, with the parameters
//! the paper describes). Implement [`Cost`] to add your own.

use std::path::Path;
use std::sync::Arc;

use trm_kinematics::FrameId;
use trm_kinematics::nalgebra::{Isometry3, Vector3};

use crate::context::{Anchor, BatchContext, Context, Frames};
use crate::error::{Result, TaskError};
use crate::tasks::TaskFunction;

/// A cost term. `eval` must return a value ≥ 0 (NaN marks an invalid candidate).
pub trait Cost: Send + Sync + std::fmt::Debug {
    /// A short label for breakdowns, e.g. `position r_palm_center`.
    fn label(&self) -> String;
    /// Whether the term reads the placed collision bodies.
    fn needs_collision(&self) -> bool {
        false
    }
    /// Whether the term reads collisions only through the counts of
    /// [`BatchContext::count_self`] and [`BatchContext::count_world`] (and, one candidate at a
    /// time, [`CollisionModel::count_self`](trm_collision::CollisionModel::count_self) and
    /// `count_world`): then an objective whose collision terms all do so counts with the
    /// single-precision screen (the same counts) and places no bodies.
    fn counts_collisions_only(&self) -> bool {
        false
    }
    /// The frames whose poses the term reads (`None`, the default: any). When every term and
    /// the task function say, an objective whose bodies need no placing computes only those
    /// frames (and their ancestors) in its forward kinematics.
    fn frames_read(&self) -> Option<Vec<FrameId>> {
        None
    }
    /// The cost of one candidate.
    fn eval(&self, ctx: &Context) -> f64;
    /// The cost of every candidate of a batch: `out[l]` for each lane `l < ctx.len()`. The
    /// default evaluates each lane's [`BatchContext::lane`]; override it (and
    /// [`Cost::batched`]) where the whole batch is cheaper at once. Must equal `eval` lane by
    /// lane.
    fn eval_batch(&self, ctx: &BatchContext, out: &mut [f64]) {
        for (l, o) in out[..ctx.len()].iter_mut().enumerate() {
            *o = self.eval(&ctx.lane(l));
        }
    }
    /// Whether [`Cost::eval_batch`] reads only the batch (never [`BatchContext::lane`]), so the
    /// objective need not copy each candidate's poses and bodies out of it.
    fn batched(&self) -> bool {
        false
    }
}

/// `eval`, `eval_batch` (each lane read in place) and `batched` of a cost through its
/// `value(&self, &impl Frames) -> f64`, written once for both.
macro_rules! on_frames {
    () => {
        fn eval(&self, ctx: &Context) -> f64 {
            self.value(ctx)
        }
        fn eval_batch(&self, ctx: &BatchContext, out: &mut [f64]) {
            for (l, o) in out[..ctx.len()].iter_mut().enumerate() {
                *o = self.value(&ctx.view(l));
            }
        }
        fn batched(&self) -> bool {
            true
        }
    };
}

#[inline]
fn masked_norm(v: Vector3<f64>, mask: [bool; 3]) -> f64 {
    (0..3)
        .filter(|&i| mask[i])
        .map(|i| v[i] * v[i])
        .sum::<f64>()
        .sqrt()
}

/// ‖W (q − q*)‖ over the active values, W diagonal (e.g. the torso costlier than the arms).
#[derive(Debug, Clone)]
pub struct HomePosture {
    /// q* for the active values.
    pub home: Vec<f64>,
    /// Per-value weights.
    pub weights: Vec<f64>,
}

impl Cost for HomePosture {
    fn label(&self) -> String {
        "home posture".into()
    }
    fn frames_read(&self) -> Option<Vec<FrameId>> {
        Some(Vec::new())
    }
    on_frames!();
}

impl HomePosture {
    fn value(&self, f: &impl Frames) -> f64 {
        f.q()
            .iter()
            .zip(&self.home)
            .zip(&self.weights)
            .map(|((q, h), w)| (w * (q - h)).powi(2))
            .sum::<f64>()
            .sqrt()
    }
}

/// The number of colliding pairs: self (checked link pairs) and/or with world objects.
#[derive(Debug, Clone)]
pub struct Collision {
    /// Count the robot's own pairs.
    pub self_collision: bool,
    /// Count (link, object) pairs.
    pub world: bool,
}

impl Cost for Collision {
    fn label(&self) -> String {
        "collision".into()
    }
    fn frames_read(&self) -> Option<Vec<FrameId>> {
        // the bodies, when placed, are placed from every link's pose (the objective knows)
        Some(Vec::new())
    }
    fn needs_collision(&self) -> bool {
        true
    }
    fn counts_collisions_only(&self) -> bool {
        true
    }
    fn eval(&self, ctx: &Context) -> f64 {
        let mut n = 0;
        if self.self_collision {
            n += ctx.collision.count_self(ctx.placed);
        }
        if self.world {
            n += ctx.collision.count_world(ctx.placed, ctx.world);
        }
        n as f64
    }
    fn eval_batch(&self, ctx: &BatchContext, out: &mut [f64]) {
        let mut n = [0; trm_kinematics::LANES];
        if self.self_collision {
            n = ctx.count_self();
        }
        if self.world {
            let world = ctx.count_world();
            n.iter_mut().zip(world).for_each(|(n, w)| *n += w);
        }
        for (o, n) in out[..ctx.len()].iter_mut().zip(n) {
            *o = n as f64;
        }
    }
    fn batched(&self) -> bool {
        true
    }
}

/// Where a position term pulls a part.
#[derive(Debug, Clone, PartialEq)]
pub enum Region {
    /// A point: a fixed point, another part, or an object.
    Point(Anchor),
    /// An axis-aligned box in the world frame (zero cost inside).
    Box {
        /// Lower corner.
        min: [f64; 3],
        /// Upper corner.
        max: [f64; 3],
    },
    /// A ball around an anchor (zero cost inside).
    Sphere {
        /// Centre.
        center: Anchor,
        /// Radius.
        radius: f64,
    },
}

/// ‖mask ⊙ (v_part − v*)‖, or the distance to a box or ball (zero inside). Masking an axis
/// attracts to a plane (one axis off) or a line (two off).
#[derive(Debug, Clone)]
pub struct Position {
    /// The attracted frame.
    pub part: FrameId,
    /// Its name, for labels.
    pub part_name: String,
    /// The target.
    pub target: Region,
    /// Axes that count.
    pub mask: [bool; 3],
}

impl Cost for Position {
    fn label(&self) -> String {
        format!("position {}", self.part_name)
    }
    fn frames_read(&self) -> Option<Vec<FrameId>> {
        let anchor = match &self.target {
            Region::Point(a) | Region::Sphere { center: a, .. } => a.frame(),
            Region::Box { .. } => None,
        };
        Some([Some(self.part), anchor].into_iter().flatten().collect())
    }
    on_frames!();
}

impl Position {
    fn value(&self, f: &impl Frames) -> f64 {
        let v = f.position(&Anchor::Frame(self.part));
        match &self.target {
            Region::Point(a) => masked_norm(v - f.position(a), self.mask),
            Region::Box { min, max } => {
                let outside =
                    Vector3::from_fn(|i, _| (min[i] - v[i]).max(0.0) + (v[i] - max[i]).max(0.0));
                masked_norm(outside, self.mask)
            }
            Region::Sphere { center, radius } => {
                (masked_norm(v - f.position(center), self.mask) - radius).max(0.0)
            }
        }
    }
}

/// A desired direction for a part's axis.
#[derive(Debug, Clone, PartialEq)]
pub enum Direction {
    /// A fixed unit vector in the world frame.
    Fixed(Vector3<f64>),
    /// Another frame's axis (unit, in that frame).
    Axis(FrameId, Vector3<f64>),
}

/// (1 − uᵀ u*)/2 ∈ [0, 1]: 0 when the part's axis u points along u*, 1 when opposite.
#[derive(Debug, Clone)]
pub struct Orientation {
    /// The frame.
    pub part: FrameId,
    /// Its name, for labels.
    pub part_name: String,
    /// The axis, unit, in the frame.
    pub axis: Vector3<f64>,
    /// The desired direction.
    pub target: Direction,
}

impl Cost for Orientation {
    fn label(&self) -> String {
        format!("orientation {}", self.part_name)
    }
    fn frames_read(&self) -> Option<Vec<FrameId>> {
        let toward = match &self.target {
            Direction::Axis(frame, _) => Some(*frame),
            Direction::Fixed(_) => None,
        };
        Some([Some(self.part), toward].into_iter().flatten().collect())
    }
    on_frames!();
}

impl Orientation {
    fn value(&self, f: &impl Frames) -> f64 {
        let u = f.axis(self.part, &self.axis);
        let want = match &self.target {
            Direction::Fixed(d) => *d,
            Direction::Axis(frame, a) => f.axis(*frame, a),
        };
        (1.0 - u.dot(&want)) / 2.0
    }
}

/// (1 − uᵀ (v_t − v)/‖v_t − v‖)/2: the part's axis points at the target; plus, optionally,
/// |‖v_t − v‖ − d| to hold it at distance d.
#[derive(Debug, Clone)]
pub struct Pointing {
    /// The pointing frame.
    pub part: FrameId,
    /// Its name, for labels.
    pub part_name: String,
    /// The axis, unit, in the frame.
    pub axis: Vector3<f64>,
    /// What to point at.
    pub target: Anchor,
    /// Optional distance to keep.
    pub distance: Option<f64>,
}

impl Cost for Pointing {
    fn label(&self) -> String {
        format!("pointing {}", self.part_name)
    }
    fn frames_read(&self) -> Option<Vec<FrameId>> {
        Some(
            [Some(self.part), self.target.frame()]
                .into_iter()
                .flatten()
                .collect(),
        )
    }
    on_frames!();
}

impl Pointing {
    fn value(&self, f: &impl Frames) -> f64 {
        let v = f.position(&Anchor::Frame(self.part));
        let to = f.position(&self.target) - v;
        let norm = to.norm();
        let u = f.axis(self.part, &self.axis);
        let aim = if norm > 0.0 {
            (1.0 - u.dot(&to) / norm) / 2.0
        } else {
            0.0
        };
        aim + self.distance.map_or(0.0, |d| (norm - d).abs())
    }
}

/// max(0, d − ‖mask ⊙ (v_a − v_b)‖)/d: pushes two anchors apart until they are d apart.
#[derive(Debug, Clone)]
pub struct Repel {
    /// First anchor.
    pub a: Anchor,
    /// Second anchor.
    pub b: Anchor,
    /// Label text.
    pub names: String,
    /// Distance from which repulsion starts.
    pub min_distance: f64,
    /// Axes that count.
    pub mask: [bool; 3],
}

impl Cost for Repel {
    fn label(&self) -> String {
        format!("repel {}", self.names)
    }
    fn frames_read(&self) -> Option<Vec<FrameId>> {
        crate::tasks::frames_of(&[&self.a, &self.b])
    }
    on_frames!();
}

impl Repel {
    fn value(&self, f: &impl Frames) -> f64 {
        let d = masked_norm(f.position(&self.a) - f.position(&self.b), self.mask);
        (self.min_distance - d).max(0.0) / self.min_distance
    }
}

/// Σ over active values of how far they enter the margin band inside their limits, in margins:
/// (max(0, lower + m − q) + max(0, q − upper + m))/m.
#[derive(Debug, Clone)]
pub struct JointLimits {
    /// Lower limits of the active values.
    pub lower: Vec<f64>,
    /// Upper limits.
    pub upper: Vec<f64>,
    /// Margin (radians).
    pub margin: f64,
}

impl Cost for JointLimits {
    fn label(&self) -> String {
        "joint limits".into()
    }
    fn frames_read(&self) -> Option<Vec<FrameId>> {
        Some(Vec::new())
    }
    on_frames!();
}

impl JointLimits {
    fn value(&self, f: &impl Frames) -> f64 {
        let m = self.margin;
        f.q()
            .iter()
            .zip(self.lower.iter().zip(&self.upper))
            .map(|(q, (l, u))| ((l + m - q).max(0.0) + (q - u + m).max(0.0)) / m)
            .sum()
    }
}

/// ‖q − q_start‖: minimal displacement from a start posture.
#[derive(Debug, Clone)]
pub struct Displacement {
    /// The start, active values.
    pub start: Vec<f64>,
}

impl Cost for Displacement {
    fn label(&self) -> String {
        "displacement".into()
    }
    fn frames_read(&self) -> Option<Vec<FrameId>> {
        Some(Vec::new())
    }
    on_frames!();
}

impl Displacement {
    fn value(&self, f: &impl Frames) -> f64 {
        f.q()
            .iter()
            .zip(&self.start)
            .map(|(q, s)| (q - s).powi(2))
            .sum::<f64>()
            .sqrt()
    }
}

/// A map of a part's feasible poses relative to a world object, seen as a cost: 0 on the map,
/// growing away from it. Task maps of feasible grasps (trm-taskmap's `TaskMap`, Gienger et al.)
/// implement it; this crate knows nothing else about them.
pub trait PoseMap: Send + Sync + std::fmt::Debug {
    /// The cost of the part's pose relative to the object.
    fn cost(&self, relative: &Isometry3<f64>) -> f64;
}

/// Reads the pose map a spec's `TaskMap(file: …)` cost names (`Err`: what is wrong with it).
pub type PoseMapLoader = fn(&Path) -> std::result::Result<Arc<dyn PoseMap>, String>;

/// Readers of the files a spec may name that other crates own, passed where a spec is
/// resolved ([`crate::Problem::load_with`]): a spec whose costs name such a file fails with a
/// located error when its reader is not given. `Default` gives none.
#[derive(Debug, Clone, Copy, Default)]
pub struct SpecLoaders {
    /// Reads the pose maps of `TaskMap(file: …)` costs (`trm_taskmap::loaders()` gives it).
    pub pose_maps: Option<PoseMapLoader>,
}

/// The task-map cost (Gienger et al., eq. 18–19): c_map = (x − x_map)ᵀ W (x − x_map) where x is
/// the part's pose relative to a world object (position, rotation vector) and x_map the nearest
/// feasible point of a task map — "anywhere on the handle" instead of one target.
#[derive(Debug, Clone)]
pub struct TaskMapCost {
    /// The map.
    pub map: Arc<dyn PoseMap>,
    /// The part whose pose is compared (e.g. the hand).
    pub part: FrameId,
    /// Its name.
    pub part_name: String,
    /// The world object the map is expressed relative to.
    pub object: usize,
}

impl Cost for TaskMapCost {
    fn label(&self) -> String {
        format!("task map {}", self.part_name)
    }
    fn frames_read(&self) -> Option<Vec<FrameId>> {
        Some(vec![self.part])
    }
    on_frames!();
}

impl TaskMapCost {
    fn value(&self, f: &impl Frames) -> f64 {
        let object = f.world().objects()[self.object].pose();
        let relative = object.inverse() * f.pose(self.part);
        self.map.cost(&relative)
    }
}

/// ‖g(q) − t*‖ for the objective's task function g and a task-space point t* (Euclidean, in the
/// task's units): the exact goal of a planned path. Task functions of up to
/// [`TaskTarget::MAX_DIM`] outputs (evaluated on the stack, no allocation).
#[derive(Debug, Clone)]
pub struct TaskTarget {
    task: std::sync::Arc<dyn TaskFunction>,
    target: Vec<f64>,
}

impl TaskTarget {
    /// The largest task dimension.
    pub const MAX_DIM: usize = 16;

    /// A target for `task`: one finite value per task output.
    pub fn new(task: std::sync::Arc<dyn TaskFunction>, target: &[f64]) -> Result<Self> {
        let m = task.dim();
        let invalid = |problem: String| TaskError::Invalid {
            what: format!("target of `{}`", task.label()),
            problem,
        };
        if m > Self::MAX_DIM {
            return Err(invalid(format!(
                "the task has {m} outputs; at most {} are supported",
                Self::MAX_DIM
            )));
        }
        if target.len() != m {
            return Err(invalid(format!(
                "{} values for a task of {m} outputs",
                target.len()
            )));
        }
        if target.iter().any(|v| !v.is_finite()) {
            return Err(invalid(format!("{target:?} is not finite")));
        }
        Ok(TaskTarget {
            task,
            target: target.to_vec(),
        })
    }
}

impl Cost for TaskTarget {
    fn label(&self) -> String {
        format!("target of {}", self.task.label())
    }
    fn frames_read(&self) -> Option<Vec<FrameId>> {
        self.task.frames_read()
    }
    fn eval(&self, ctx: &Context) -> f64 {
        let mut g = [0.0; Self::MAX_DIM];
        let g = &mut g[..self.target.len()];
        self.task.eval(ctx, g);
        self.distance(g)
    }
    fn eval_batch(&self, ctx: &BatchContext, out: &mut [f64]) {
        let m = self.target.len();
        let mut g = [0.0; Self::MAX_DIM * trm_kinematics::LANES];
        self.task.eval_batch(ctx, &mut g[..m * ctx.len()]);
        for (o, g) in out[..ctx.len()].iter_mut().zip(g.chunks_exact(m.max(1))) {
            *o = self.distance(&g[..m]);
        }
    }
    fn batched(&self) -> bool {
        self.task.batched()
    }
}

impl TaskTarget {
    /// ‖g − t*‖.
    fn distance(&self, g: &[f64]) -> f64 {
        g.iter()
            .zip(&self.target)
            .map(|(a, b)| (a - b).powi(2))
            .sum::<f64>()
            .sqrt()
    }
}
