//! What cost and task functions see: one candidate's active values, motors, link poses and
//! placed collision bodies, plus the world.

use trm_collision::{CollisionModel, PlacedBodies, World};
use trm_kinematics::nalgebra::{Point3, Vector3};
use trm_kinematics::{FrameId, PoseBuffer, RobotModel};

/// One evaluated candidate. Built by [`crate::Objective`] after one forward-kinematics pass.
pub struct Context<'a> {
    /// The robot.
    pub robot: &'a RobotModel,
    /// Active values (the optimisation variables).
    pub q: &'a [f64],
    /// World poses of every frame.
    pub poses: &'a PoseBuffer,
    /// Collision geometry.
    pub collision: &'a CollisionModel,
    /// Collision bodies placed at this posture (placed only when a term needs them).
    pub placed: &'a PlacedBodies,
    /// The world.
    pub world: &'a World,
}

/// A point of interest: a frame of the robot, a world object's origin, or a fixed point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Anchor {
    /// A link or named frame.
    Frame(FrameId),
    /// A world object, by index.
    Object(usize),
    /// A fixed point in the world frame.
    Point([f64; 3]),
}

impl Context<'_> {
    /// World position of an anchor.
    #[inline]
    pub fn position(&self, anchor: &Anchor) -> Point3<f64> {
        match anchor {
            Anchor::Frame(f) => Point3::from(self.poses.pose(*f).translation.vector),
            Anchor::Object(o) => Point3::from(self.world.objects()[*o].pose().translation.vector),
            Anchor::Point(p) => Point3::from(*p),
        }
    }

    /// A frame's axis (given in the frame) in world coordinates.
    #[inline]
    pub fn axis(&self, frame: FrameId, local: &Vector3<f64>) -> Vector3<f64> {
        self.poses.pose(frame).rotation * local
    }
}
