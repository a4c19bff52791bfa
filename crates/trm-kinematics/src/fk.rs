//! Forward kinematics: one pass over the links in topological order into a caller-owned buffer.
//!
//! A [`Plan`] is compiled once per model (joint values as input) and once per
//! [`crate::ActiveSet`] (active motor values as input). Compilation folds joints whose value does
//! not depend on the input into fixed transforms and gives joints with the same value (coupled
//! finger phalanges) one shared *slot*, so each distinct angle costs one `sin_cos`.

use std::collections::HashMap;

use nalgebra::{Isometry3, Quaternion, Translation3, UnitQuaternion, Vector3};

use crate::tree::{JointKind, Tree};

/// One link or named frame: `pose[k + 1] = pose[parent] · local`, where, with the slot's
/// `(s, c, d)` — the sine and cosine of half the angle for revolute joints, the displacement for
/// prismatic ones, `(0, 1, 0)` for fixed transforms —
/// `local.rotation = c·rotation + s·axis_quat` (= rotation ⊗ (c, s·axis)) and
/// `local.translation = translation + d·axis_in_parent`. Every step runs the same branch-free code.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Step {
    pub(crate) parent: u32,
    pub(crate) child: u32,
    pub(crate) slot: u32,
    pub(crate) rotation: Quaternion<f64>,
    pub(crate) axis_quat: Quaternion<f64>,
    pub(crate) translation: Vector3<f64>,
    pub(crate) axis_in_parent: Vector3<f64>,
}

impl Step {
    fn fixed(parent: usize, origin: Isometry3<f64>) -> Step {
        Step {
            parent: parent as u32,
            child: 0,
            slot: 0,
            rotation: *origin.rotation.quaternion(),
            axis_quat: Quaternion::new(0.0, 0.0, 0.0, 0.0),
            translation: origin.translation.vector,
            axis_in_parent: Vector3::zeros(),
        }
    }
}

/// Index of a pose in a [`PoseBuffer`]: a link (`0..num_links`) or a named frame after them.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct FrameId(pub(crate) usize);

impl FrameId {
    /// Position in the pose buffer.
    pub fn index(self) -> usize {
        self.0
    }
}

/// `constant + Σ factor · input[index]`: the one evaluation of a joint's affine map over motor
/// or active values (couplings, locked motors and the compiled FK pass all use it).
#[inline]
pub(crate) fn affine(constant: f64, terms: &[(usize, f64)], input: &[f64]) -> f64 {
    let mut v = constant;
    for &(k, f) in terms {
        v += f * input[k];
    }
    v
}

/// A compiled FK pass: an affine map from an input vector to slot values, and the steps.
#[derive(Debug, Clone)]
pub(crate) struct Plan {
    /// Per slot: constant and range into `terms` (of the half angle for revolute slots).
    pub(crate) rows: Vec<(f64, u32, u32)>,
    /// `(input index, factor)`.
    pub(crate) terms: Vec<(usize, f64)>,
    /// Whether a slot is a revolute angle (needs its half-angle sine and cosine). Slot 0 is
    /// the constant `(0, 1, 0)` of fixed transforms.
    pub(crate) revolute: Vec<bool>,
    pub(crate) steps: Vec<Step>,
    /// The steps' constants rounded to `f32`, for single-precision blocks (rounded once here,
    /// not in every block).
    pub(crate) steps32: Vec<StepConstants<f32>>,
}

/// A step's constants in the precision of a pass: its rotation and axis quaternions
/// (`w, i, j, k`), translation and axis in the parent frame.
#[derive(Debug, Clone, Copy)]
pub(crate) struct StepConstants<T> {
    pub(crate) rotation: [T; 4],
    pub(crate) axis_quat: [T; 4],
    pub(crate) translation: [T; 3],
    pub(crate) axis_in_parent: [T; 3],
}

impl StepConstants<f32> {
    fn of(step: &Step) -> Self {
        let (r, b) = (&step.rotation, &step.axis_quat);
        let (t, a) = (&step.translation, &step.axis_in_parent);
        StepConstants {
            rotation: [r.w, r.i, r.j, r.k].map(|v| v as f32),
            axis_quat: [b.w, b.i, b.j, b.k].map(|v| v as f32),
            translation: [t.x, t.y, t.z].map(|v| v as f32),
            axis_in_parent: [a.x, a.y, a.z].map(|v| v as f32),
        }
    }
}

/// Identifies joints that always share a value: (constant bits, (input, factor bits) terms,
/// revolute).
type SlotKey = (u64, Vec<(usize, u64)>, bool);

/// `joint value = constant + Σ factor · input[index]`, per movable joint.
pub(crate) struct AffineRow<'a> {
    pub constant: f64,
    pub terms: &'a [(usize, f64)],
}

impl Plan {
    /// Compiles the FK of `tree` plus named frames `(link, offset)`, with each movable joint's
    /// value given by `rows[coordinate]` over some input vector.
    pub fn compile(tree: &Tree, frames: &[(usize, Isometry3<f64>)], rows: &[AffineRow]) -> Plan {
        let mut plan = Plan {
            rows: vec![(0.0, 0, 0)],
            terms: Vec::new(),
            revolute: vec![false],
            steps: Vec::new(),
            steps32: Vec::new(),
        };
        let mut slot_of: HashMap<SlotKey, u32> = HashMap::new();
        for joint in &tree.joints {
            let origin = joint.local_origin;
            let motion = match (joint.kind, joint.coordinate) {
                (JointKind::Fixed, _) | (_, None) => None,
                (kind, Some(c)) => {
                    let row = &rows[c];
                    let revolute = kind != JointKind::Prismatic;
                    if row.terms.iter().all(|&(_, f)| f == 0.0) {
                        // Constant: fold into the origin.
                        let local = joint_transform(joint.kind, &joint.axis, row.constant);
                        plan.steps.push(Step::fixed(joint.parent, origin * local));
                        continue;
                    }
                    let key: Vec<(usize, u64)> =
                        row.terms.iter().map(|&(k, f)| (k, f.to_bits())).collect();
                    let slot = *slot_of
                        .entry((row.constant.to_bits(), key, revolute))
                        .or_insert_with(|| {
                            // a revolute slot's value is its half angle (what its sine and
                            // cosine take): the halves of the constant and factors give it
                            // exactly (halving is exact in binary floating point)
                            let scale = if revolute { 0.5 } else { 1.0 };
                            let start = plan.terms.len() as u32;
                            plan.terms
                                .extend(row.terms.iter().map(|&(k, f)| (k, scale * f)));
                            let end = plan.terms.len() as u32;
                            plan.rows.push((scale * row.constant, start, end));
                            plan.revolute.push(revolute);
                            plan.rows.len() as u32 - 1
                        });
                    Some((revolute, slot))
                }
            };
            let mut step = Step::fixed(joint.parent, origin);
            match motion {
                None => {}
                Some((true, slot)) => {
                    let a = joint.axis;
                    step.slot = slot;
                    step.axis_quat =
                        origin.rotation.quaternion() * Quaternion::new(0.0, a.x, a.y, a.z);
                }
                Some((false, slot)) => {
                    step.slot = slot;
                    step.axis_in_parent = origin.rotation * joint.axis.into_inner();
                }
            }
            plan.steps.push(step);
        }
        for &(link, offset) in frames {
            plan.steps.push(Step::fixed(link, offset));
        }
        // Step k poses entry k + 1. Run the steps level by level (breadth-first): steps of one
        // level are independent, so the processor overlaps them instead of waiting on each
        // parent pose in long chains (fingers).
        let mut depth = vec![0u32; plan.steps.len() + 1];
        for (k, step) in plan.steps.iter_mut().enumerate() {
            step.child = k as u32 + 1;
            depth[k + 1] = depth[step.parent as usize] + 1;
        }
        plan.steps.sort_by_key(|s| depth[s.child as usize]);
        plan.steps32 = plan.steps.iter().map(StepConstants::of).collect();
        plan
    }

    /// The plan computing only the pose entries `keep` marks and their ancestors (the others
    /// are left as they were), with only the joint values those need.
    pub(crate) fn pruned(&self, keep: &[bool]) -> Plan {
        // steps run parents first: walking them backwards marks every ancestor of a kept entry
        let mut needed = keep.to_vec();
        needed.resize(self.steps.len() + 1, false);
        for step in self.steps.iter().rev() {
            if needed[step.child as usize] {
                needed[step.parent as usize] = true;
            }
        }
        let mut plan = Plan {
            rows: vec![self.rows[0]],
            terms: self.terms.clone(),
            revolute: vec![self.revolute[0]],
            steps: Vec::new(),
            steps32: Vec::new(),
        };
        // slot 0 (fixed transforms) stays 0; the others renumbered in order of first use
        let mut slot_of = vec![None; self.rows.len()];
        slot_of[0] = Some(0);
        for (step, constants) in self.steps.iter().zip(&self.steps32) {
            if !needed[step.child as usize] {
                continue;
            }
            let old = step.slot as usize;
            let slot = *slot_of[old].get_or_insert_with(|| {
                plan.rows.push(self.rows[old]);
                plan.revolute.push(self.revolute[old]);
                plan.rows.len() as u32 - 1
            });
            plan.steps.push(Step { slot, ..*step });
            plan.steps32.push(*constants);
        }
        plan
    }

    /// Number of distinct joint values the pass computes.
    pub fn num_slots(&self) -> usize {
        self.rows.len() - 1
    }

    /// Runs the pass on `input` into `buffer`. Lengths must have been checked.
    #[inline]
    pub fn run(&self, input: &[f64], buffer: &mut PoseBuffer) {
        let slots = &mut buffer.slots[..self.rows.len()];
        for ((out, &(constant, start, end)), &revolute) in
            slots.iter_mut().zip(&self.rows).zip(&self.revolute)
        {
            let v = affine(constant, &self.terms[start as usize..end as usize], input);
            *out = if revolute {
                let (s, c) = v.sin_cos();
                [s, c, 0.0]
            } else {
                [0.0, 1.0, v]
            };
        }
        let slots = &buffer.slots;
        let poses = &mut buffer.poses;
        poses[0] = Isometry3::identity();
        for step in &self.steps {
            let parent = poses[step.parent as usize];
            let [s, c, d] = slots[step.slot as usize];
            let (r, b) = (&step.rotation, &step.axis_quat);
            let local = Quaternion::new(
                c * r.w + s * b.w,
                c * r.i + s * b.i,
                c * r.j + s * b.j,
                c * r.k + s * b.k,
            );
            let translation = step.translation + step.axis_in_parent * d;
            let pr = parent.rotation.quaternion();
            poses[step.child as usize] = Isometry3::from_parts(
                Translation3::from(rotate(pr, &translation) + parent.translation.vector),
                UnitQuaternion::new_unchecked(multiply(pr, &local)),
            );
        }
    }
}

/// The motion of a joint at a given value.
fn joint_transform(
    kind: JointKind,
    axis: &nalgebra::Unit<Vector3<f64>>,
    value: f64,
) -> Isometry3<f64> {
    match kind {
        JointKind::Prismatic => Isometry3::from_parts(
            Translation3::from(axis.into_inner() * value),
            UnitQuaternion::identity(),
        ),
        JointKind::Fixed => Isometry3::identity(),
        _ => Isometry3::from_parts(
            Translation3::identity(),
            UnitQuaternion::from_axis_angle(axis, value),
        ),
    }
}

#[inline(always)]
fn multiply(a: &Quaternion<f64>, b: &Quaternion<f64>) -> Quaternion<f64> {
    Quaternion::new(
        a.w * b.w - a.i * b.i - a.j * b.j - a.k * b.k,
        a.w * b.i + a.i * b.w + a.j * b.k - a.k * b.j,
        a.w * b.j - a.i * b.k + a.j * b.w + a.k * b.i,
        a.w * b.k + a.i * b.j - a.j * b.i + a.k * b.w,
    )
}

/// Rotates `v` by the unit quaternion `q`: `v + w·t + u×t` with `t = 2 u×v`.
#[inline(always)]
fn rotate(q: &Quaternion<f64>, v: &Vector3<f64>) -> Vector3<f64> {
    let (w, x, y, z) = (q.w, q.i, q.j, q.k);
    let tx = 2.0 * (y * v.z - z * v.y);
    let ty = 2.0 * (z * v.x - x * v.z);
    let tz = 2.0 * (x * v.y - y * v.x);
    Vector3::new(
        v.x + w * tx + (y * tz - z * ty),
        v.y + w * ty + (z * tx - x * tz),
        v.z + w * tz + (x * ty - y * tx),
    )
}

/// Caller-owned scratch for forward kinematics: the world pose of every link and named frame
/// (index = [`FrameId::index`]). Reuse it: FK does not allocate.
#[derive(Debug, Clone)]
pub struct PoseBuffer {
    pub(crate) slots: Vec<[f64; 3]>,
    pub(crate) poses: Vec<Isometry3<f64>>,
}

impl PoseBuffer {
    /// Whether the buffer was made for a model with these many joints and frames.
    pub fn fits(&self, num_joints: usize, num_frames: usize) -> bool {
        self.poses.len() == num_frames && self.slots.len() == num_joints + 1
    }

    /// Number of poses (links and named frames).
    pub fn len(&self) -> usize {
        self.poses.len()
    }

    /// Whether the buffer holds no pose.
    pub fn is_empty(&self) -> bool {
        self.poses.is_empty()
    }

    pub(crate) fn new(num_joints: usize, num_frames: usize) -> Self {
        PoseBuffer {
            slots: vec![[0.0, 1.0, 0.0]; num_joints + 1],
            poses: vec![Isometry3::identity(); num_frames],
        }
    }

    /// World pose of a link or named frame.
    #[inline]
    pub fn pose(&self, frame: FrameId) -> &Isometry3<f64> {
        &self.poses[frame.0]
    }

    /// World poses of all links then all named frames.
    pub fn poses(&self) -> &[Isometry3<f64>] {
        &self.poses
    }
}
