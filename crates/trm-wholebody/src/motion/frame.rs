//! Per-sample kinematics in the ground frame: poses, placed bodies, the centre of mass and the
//! Jacobians of points and the CoM with the left foot fixed.

use nalgebra::{Isometry3, Matrix3xX, Matrix6xX, Point3, Vector3};
use trm_collision::PlacedBodies;
use trm_kinematics::{FrameId, PoseBuffer};

use super::*;

/// Per-sample kinematic quantities in the ground frame.
#[derive(Debug, Clone)]
pub(super) struct Frame {
    pub(super) poses: PoseBuffer,
    pub(super) placed: PlacedBodies,
    /// Jacobians in the root frame (scratch).
    pub(super) root_jacobian: Matrix3xX<f64>,
    pub(super) frame_jacobian: Matrix6xX<f64>,
    pub(super) sole: Matrix6xX<f64>,
    pub(super) sole_origin: Point3<f64>,
    /// CoM Jacobian in the ground frame with the left foot fixed (3 × n).
    pub(super) com_jacobian: Matrix3xX<f64>,
    /// Jacobian of the last [`Frame::point`] in the ground frame with the left foot fixed.
    pub(super) point_jacobian: Matrix3xX<f64>,
    pub(super) root_in_ground: Isometry3<f64>,
}

impl Frame {
    pub(super) fn new(p: &WholeBody) -> Self {
        let n = p.active.len();
        Frame {
            poses: p.model().pose_buffer(),
            placed: p.collision.placed_bodies(),
            root_jacobian: Matrix3xX::zeros(n),
            frame_jacobian: Matrix6xX::zeros(n),
            sole: Matrix6xX::zeros(n),
            sole_origin: Point3::origin(),
            com_jacobian: Matrix3xX::zeros(n),
            point_jacobian: Matrix3xX::zeros(n),
            root_in_ground: Isometry3::identity(),
        }
    }

    /// FK at `q`; returns the mass and the CoM in the ground frame and fills its Jacobian.
    pub(super) fn update(&mut self, p: &WholeBody, q: &[f64]) -> (f64, Point3<f64>) {
        p.active.forward_unchecked(q, &mut self.poses);
        let sole_pose = *self.poses.pose(p.feet.0);
        self.root_in_ground = (sole_pose * p.sole_to_ground).inverse();
        self.sole_origin = Point3::from(sole_pose.translation.vector);
        p.active.jacobian(&self.poses, p.feet.0, &mut self.sole);
        let (mass, c) = p.active.center_of_mass(&self.poses);
        p.active.com_jacobian(&self.poses, &mut self.root_jacobian);
        let mut out = std::mem::take(&mut self.com_jacobian);
        self.relative_to_sole(&c, &mut out);
        self.com_jacobian = out;
        (mass, self.root_in_ground * c)
    }

    /// Position of `frame_id`'s origin in the ground frame; fills `point_jacobian`. Call after
    /// [`Frame::update`].
    pub(super) fn point(&mut self, p: &WholeBody, frame_id: FrameId) -> Point3<f64> {
        p.active
            .jacobian(&self.poses, frame_id, &mut self.frame_jacobian);
        let origin = Point3::from(self.poses.pose(frame_id).translation.vector);
        for k in 0..self.frame_jacobian.ncols() {
            for r in 0..3 {
                self.root_jacobian[(r, k)] = self.frame_jacobian[(r, k)];
            }
        }
        let mut out = std::mem::take(&mut self.point_jacobian);
        self.relative_to_sole(&origin, &mut out);
        self.point_jacobian = out;
        self.root_in_ground * origin
    }

    /// `out` = the ground-frame Jacobian of point `c` whose root-frame Jacobian is in
    /// `root_jacobian`, with the left sole fixed: R (J_c − J_v + [c − o]× J_ω).
    pub(super) fn relative_to_sole(&self, c: &Point3<f64>, out: &mut Matrix3xX<f64>) {
        let r = c - self.sole_origin;
        let rot = self.root_in_ground.rotation.to_rotation_matrix();
        if out.ncols() != self.root_jacobian.ncols() {
            *out = Matrix3xX::zeros(self.root_jacobian.ncols());
        }
        for k in 0..self.root_jacobian.ncols() {
            let v = Vector3::new(self.sole[(0, k)], self.sole[(1, k)], self.sole[(2, k)]);
            let w = Vector3::new(self.sole[(3, k)], self.sole[(4, k)], self.sole[(5, k)]);
            let rel = self.root_jacobian.column(k) - v + r.cross(&w);
            out.set_column(k, &(rot * rel));
        }
    }
}
