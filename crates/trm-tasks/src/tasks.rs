//! Task functions g(p, q, w) → ℝᵐ (Table II of Stollenga et al., IROS 2013, plus the composites
//! the bimanual maps need). Implement [`TaskFunction`] to add your own.

use trm_kinematics::FrameId;
use trm_kinematics::nalgebra::{UnitQuaternion, Vector3};

use crate::context::{Anchor, BatchContext, Context, Frames};

/// A task function.
pub trait TaskFunction: Send + Sync + std::fmt::Debug {
    /// Output dimension m.
    fn dim(&self) -> usize;
    /// A short label.
    fn label(&self) -> String;
    /// Writes g into `out` (length `dim()`).
    fn eval(&self, ctx: &Context, out: &mut [f64]);
    /// Writes g of every candidate of a batch: lane `l`'s into `out[l·m..(l+1)·m]` (m =
    /// `dim()`). The default evaluates each lane's [`BatchContext::lane`]; override it (and
    /// [`TaskFunction::batched`]) where the whole batch is cheaper at once. Must equal `eval`
    /// lane by lane.
    fn eval_batch(&self, ctx: &BatchContext, out: &mut [f64]) {
        let m = self.dim();
        for l in 0..ctx.len() {
            self.eval(&ctx.lane(l), &mut out[l * m..(l + 1) * m]);
        }
    }
    /// Whether [`TaskFunction::eval_batch`] reads only the batch (never
    /// [`BatchContext::lane`]).
    fn batched(&self) -> bool {
        false
    }
    /// The frames whose poses the function reads (`None`, the default: any), as
    /// [`crate::Cost::frames_read`].
    fn frames_read(&self) -> Option<Vec<FrameId>> {
        None
    }
}

/// `eval`, `eval_batch` (each lane read in place) and `batched` of a task function through its
/// `write(&self, &impl Frames, out)`, written once for both.
macro_rules! on_frames {
    () => {
        fn eval(&self, ctx: &Context, out: &mut [f64]) {
            self.write(ctx, out);
        }
        fn eval_batch(&self, ctx: &BatchContext, out: &mut [f64]) {
            let m = self.dim();
            for l in 0..ctx.len() {
                self.write(&ctx.view(l), &mut out[l * m..(l + 1) * m]);
            }
        }
        fn batched(&self) -> bool {
            true
        }
    };
}

fn write_masked(v: Vector3<f64>, mask: [bool; 3], out: &mut [f64]) {
    let mut k = 0;
    for i in 0..3 {
        if mask[i] {
            out[k] = v[i];
            k += 1;
        }
    }
}

/// The frames among `anchors` (for `frames_read`).
pub(crate) fn frames_of(anchors: &[&Anchor]) -> Option<Vec<FrameId>> {
    Some(anchors.iter().filter_map(|a| a.frame()).collect())
}

fn mask_dim(mask: [bool; 3]) -> usize {
    mask.iter().filter(|m| **m).count()
}

/// The position of a part (masked): g = v_part.
#[derive(Debug, Clone)]
pub struct PositionTask {
    /// The frame.
    pub part: FrameId,
    /// Its name.
    pub part_name: String,
    /// Axes kept.
    pub mask: [bool; 3],
}

impl TaskFunction for PositionTask {
    fn dim(&self) -> usize {
        mask_dim(self.mask)
    }
    fn label(&self) -> String {
        format!("position {}", self.part_name)
    }
    fn frames_read(&self) -> Option<Vec<FrameId>> {
        Some(vec![self.part])
    }
    on_frames!();
}

impl PositionTask {
    fn write(&self, f: &impl Frames, out: &mut [f64]) {
        write_masked(f.frame_position(self.part).coords, self.mask, out);
    }
}

/// The direction of a part's axis (masked): g = R_part u, or R_ref⁻¹ R_part u in the frame of
/// a reference part.
#[derive(Debug, Clone)]
pub struct RotationTask {
    /// The frame.
    pub part: FrameId,
    /// Its name.
    pub part_name: String,
    /// The axis, unit, in the frame.
    pub axis: Vector3<f64>,
    /// Components kept.
    pub mask: [bool; 3],
    /// The reference frame and its name; the world when `None`.
    pub relative_to: Option<(FrameId, String)>,
}

impl TaskFunction for RotationTask {
    fn dim(&self) -> usize {
        mask_dim(self.mask)
    }
    fn label(&self) -> String {
        match &self.relative_to {
            Some((_, r)) => format!("rotation {} relative to {r}", self.part_name),
            None => format!("rotation {}", self.part_name),
        }
    }
    fn frames_read(&self) -> Option<Vec<FrameId>> {
        Some(
            [Some(self.part), self.relative_to.as_ref().map(|r| r.0)]
                .into_iter()
                .flatten()
                .collect(),
        )
    }
    on_frames!();
}

impl RotationTask {
    fn write(&self, f: &impl Frames, out: &mut [f64]) {
        let axis = f.axis(self.part, &self.axis);
        let axis = match &self.relative_to {
            Some((r, _)) => f.pose(*r).rotation.inverse_transform_vector(&axis),
            None => axis,
        };
        write_masked(axis, self.mask, out);
    }
}

/// A part's pose, 6-D: (position, scale · log(R_ref⁻¹ R_part)) — the rotation vector of the
/// part's orientation relative to a reference, in the reference frame.
#[derive(Debug, Clone)]
pub struct PoseTask {
    /// The frame.
    pub part: FrameId,
    /// Its name.
    pub part_name: String,
    /// Metres per radian.
    pub scale: f64,
    /// The reference orientation, inverted.
    pub reference_inverse: UnitQuaternion<f64>,
}

impl TaskFunction for PoseTask {
    fn dim(&self) -> usize {
        6
    }
    fn label(&self) -> String {
        format!("pose {}", self.part_name)
    }
    fn frames_read(&self) -> Option<Vec<FrameId>> {
        Some(vec![self.part])
    }
    on_frames!();
}

impl PoseTask {
    fn write(&self, f: &impl Frames, out: &mut [f64]) {
        let pose = f.pose(self.part);
        let p = pose.translation.vector;
        let r = (self.reference_inverse * pose.rotation).scaled_axis() * self.scale;
        out[..6].copy_from_slice(&[p.x, p.y, p.z, r.x, r.y, r.z]);
    }
}

/// ‖v_a − v_b‖.
#[derive(Debug, Clone)]
pub struct DistanceTask {
    /// First anchor.
    pub a: Anchor,
    /// Second anchor.
    pub b: Anchor,
    /// Label text.
    pub names: String,
}

impl TaskFunction for DistanceTask {
    fn dim(&self) -> usize {
        1
    }
    fn label(&self) -> String {
        format!("distance {}", self.names)
    }
    fn frames_read(&self) -> Option<Vec<FrameId>> {
        frames_of(&[&self.a, &self.b])
    }
    on_frames!();
}

impl DistanceTask {
    fn write(&self, f: &impl Frames, out: &mut [f64]) {
        out[0] = (f.position(&self.a) - f.position(&self.b)).norm();
    }
}

/// atan2(u₂ᵀ(v_a − v_b), u₁ᵀ(v_a − v_b)): the angle of the vector from b to a projected on the
/// plane spanned by u₁, u₂ (world frame).
#[derive(Debug, Clone)]
pub struct AngleTask {
    /// First anchor.
    pub a: Anchor,
    /// Second anchor.
    pub b: Anchor,
    /// Label text.
    pub names: String,
    /// First plane axis.
    pub u1: Vector3<f64>,
    /// Second plane axis.
    pub u2: Vector3<f64>,
}

impl TaskFunction for AngleTask {
    fn dim(&self) -> usize {
        1
    }
    fn label(&self) -> String {
        format!("angle {}", self.names)
    }
    fn frames_read(&self) -> Option<Vec<FrameId>> {
        frames_of(&[&self.a, &self.b])
    }
    on_frames!();
}

impl AngleTask {
    fn write(&self, f: &impl Frames, out: &mut [f64]) {
        let v = f.position(&self.a) - f.position(&self.b);
        out[0] = self.u2.dot(&v).atan2(self.u1.dot(&v));
    }
}

/// The midpoint of two anchors (masked): bimanual maps.
#[derive(Debug, Clone)]
pub struct MidpointTask {
    /// First anchor.
    pub a: Anchor,
    /// Second anchor.
    pub b: Anchor,
    /// Label text.
    pub names: String,
    /// Axes kept.
    pub mask: [bool; 3],
}

impl TaskFunction for MidpointTask {
    fn dim(&self) -> usize {
        mask_dim(self.mask)
    }
    fn label(&self) -> String {
        format!("midpoint {}", self.names)
    }
    fn frames_read(&self) -> Option<Vec<FrameId>> {
        frames_of(&[&self.a, &self.b])
    }
    on_frames!();
}

impl MidpointTask {
    fn write(&self, f: &impl Frames, out: &mut [f64]) {
        let m = (f.position(&self.a).coords + f.position(&self.b).coords) / 2.0;
        write_masked(m, self.mask, out);
    }
}

/// The unit direction of a virtual rod from a to b (masked): bimanual rotation maps.
#[derive(Debug, Clone)]
pub struct RodDirectionTask {
    /// First anchor.
    pub a: Anchor,
    /// Second anchor.
    pub b: Anchor,
    /// Label text.
    pub names: String,
    /// Components kept.
    pub mask: [bool; 3],
}

impl TaskFunction for RodDirectionTask {
    fn dim(&self) -> usize {
        mask_dim(self.mask)
    }
    fn label(&self) -> String {
        format!("rod direction {}", self.names)
    }
    fn frames_read(&self) -> Option<Vec<FrameId>> {
        frames_of(&[&self.a, &self.b])
    }
    on_frames!();
}

impl RodDirectionTask {
    fn write(&self, f: &impl Frames, out: &mut [f64]) {
        let v = f.position(&self.b) - f.position(&self.a);
        let n = v.norm();
        let u = if n > 0.0 { v / n } else { Vector3::zeros() };
        write_masked(u, self.mask, out);
    }
}
