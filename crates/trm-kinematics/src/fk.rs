//! Forward kinematics: one pass over the links in topological order into a caller-owned buffer.

use nalgebra::{Isometry3, Translation3, Unit, UnitQuaternion, Vector3};

use crate::model::FrameId;

/// How a step moves its child relative to the joint frame.
#[derive(Debug, Clone, Copy)]
pub(crate) enum Motion {
    Fixed,
    Revolute { axis: Unit<Vector3<f64>>, coordinate: usize },
    Prismatic { axis: Vector3<f64>, coordinate: usize },
}

/// One link (or named frame) of the FK pass: `pose[k + 1] = pose[parent] · origin · motion(q)`.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Step {
    pub parent: usize,
    pub local_origin: Isometry3<f64>,
    pub motion: Motion,
}

/// Caller-owned scratch for forward kinematics: the joint values of the last pass and the world
/// pose of every link and named frame (index = [`FrameId::index`]). Reuse it: FK does not allocate.
#[derive(Debug, Clone)]
pub struct PoseBuffer {
    pub(crate) joint_values: Vec<f64>,
    pub(crate) poses: Vec<Isometry3<f64>>,
}

impl PoseBuffer {
    pub(crate) fn new(num_joints: usize, num_frames: usize) -> Self {
        PoseBuffer { joint_values: vec![0.0; num_joints], poses: vec![Isometry3::identity(); num_frames] }
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

    /// Joint values (one per movable joint) of the last pass.
    pub fn joint_values(&self) -> &[f64] {
        &self.joint_values
    }
}

/// The FK pass. `poses[0]` (the root) stays the identity.
#[inline]
pub(crate) fn run_steps(steps: &[Step], q: &[f64], poses: &mut [Isometry3<f64>]) {
    debug_assert_eq!(poses.len(), steps.len() + 1);
    poses[0] = Isometry3::identity();
    for (k, step) in steps.iter().enumerate() {
        let base = poses[step.parent] * step.local_origin;
        poses[k + 1] = match step.motion {
            Motion::Fixed => base,
            Motion::Revolute { axis, coordinate } => base * UnitQuaternion::from_axis_angle(&axis, q[coordinate]),
            Motion::Prismatic { axis, coordinate } => base * Translation3::from(axis * q[coordinate]),
        };
    }
}
