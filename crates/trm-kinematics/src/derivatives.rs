//! Kinematic derivatives: geometric Jacobians of frames and points, the centre of mass and its
//! Jacobian, and gravity torques — all with respect to the active motors (couplings included),
//! from a pose buffer filled by forward kinematics.

use nalgebra::{Matrix3xX, Matrix6xX, Point3, Vector3};

use crate::ActiveSet;
use crate::fk::FrameId;
use crate::fk::PoseBuffer;
use crate::tree::JointKind;

/// Standard gravity in the world frame when z is up, m/s².
pub const GRAVITY: Vector3<f64> = Vector3::new(0.0, 0.0, -9.81);

impl ActiveSet {
    /// Calls `f(active index, factor, joint)` for every active motor that drives a movable joint
    /// on the path from the root to `link`.
    fn for_each_ancestor_column(&self, link: usize, mut f: impl FnMut(usize, f64, usize)) {
        let tree = self.model().tree();
        let mut l = link;
        while let Some(j) = tree.links[l].parent_joint {
            if let Some(c) = tree.joints[j].coordinate {
                for &(k, factor) in &self.rows()[c].1 {
                    f(k, factor, j);
                }
            }
            l = tree.joints[j].parent;
        }
    }

    /// World axis and origin of joint `j` at the posture in `poses`.
    fn joint_axis(&self, poses: &PoseBuffer, j: usize) -> (Vector3<f64>, Point3<f64>) {
        let joint = &self.model().tree().joints[j];
        let child = &poses.poses()[joint.child];
        (
            child.rotation * joint.axis.into_inner(),
            Point3::from(child.translation.vector),
        )
    }

    /// The 3 × n Jacobian of the world velocity of a point fixed to `link` (given in world
    /// coordinates) with respect to the active values. `out` is resized to 3 × len if needed.
    pub fn point_jacobian(
        &self,
        poses: &PoseBuffer,
        link: usize,
        point: &Point3<f64>,
        out: &mut Matrix3xX<f64>,
    ) {
        if out.ncols() != self.len() {
            *out = Matrix3xX::zeros(self.len());
        }
        out.fill(0.0);
        let kinds = &self.model().tree().joints;
        self.for_each_ancestor_column(link, |k, factor, j| {
            let (a, p) = self.joint_axis(poses, j);
            let column = match kinds[j].kind {
                JointKind::Prismatic => a,
                _ => a.cross(&(point - p)),
            };
            let mut c = out.column_mut(k);
            c += column * factor;
        });
    }

    /// The 6 × n geometric Jacobian of `frame` (a link or named frame): rows 0–2 the world
    /// velocity of its origin, rows 3–5 its angular velocity, both in world axes (Pinocchio's
    /// LOCAL_WORLD_ALIGNED), with respect to the active values. `out` is resized to 6 × len if needed.
    pub fn jacobian(&self, poses: &PoseBuffer, frame: FrameId, out: &mut Matrix6xX<f64>) {
        if out.ncols() != self.len() {
            *out = Matrix6xX::zeros(self.len());
        }
        out.fill(0.0);
        let link = self.model().frame_link(frame);
        let origin = Point3::from(poses.pose(frame).translation.vector);
        let kinds = &self.model().tree().joints;
        self.for_each_ancestor_column(link, |k, factor, j| {
            let (a, p) = self.joint_axis(poses, j);
            let (linear, angular) = match kinds[j].kind {
                JointKind::Prismatic => (a, Vector3::zeros()),
                _ => (a.cross(&(origin - p)), a),
            };
            let mut c = out.column_mut(k);
            c.fixed_rows_mut::<3>(0).axpy(factor, &linear, 1.0);
            c.fixed_rows_mut::<3>(3).axpy(factor, &angular, 1.0);
        });
    }

    /// The derivatives of `frame`'s 6 × n Jacobian (as [`ActiveSet::jacobian`]) with respect to
    /// each active value: `out[k]` = ∂J/∂q_k (the kinematic Hessian, in Pinocchio's
    /// LOCAL_WORLD_ALIGNED convention). `out` is resized to n matrices of 6 × n if needed.
    ///
    /// A joint moves what lies beyond it: a revolute joint i with world axis aᵢ through pᵢ turns
    /// directions v by aᵢ × v and points x by aᵢ × (x − pᵢ); a prismatic one shifts points by
    /// aᵢ. Column j's derivative follows from its axis, origin and the frame's origin.
    pub fn jacobian_derivatives(
        &self,
        poses: &PoseBuffer,
        frame: FrameId,
        out: &mut Vec<Matrix6xX<f64>>,
    ) {
        let n = self.len();
        if out.len() != n || out.iter().any(|m| m.ncols() != n) {
            *out = vec![Matrix6xX::zeros(n); n];
        }
        for m in out.iter_mut() {
            m.fill(0.0);
        }
        let link = self.model().frame_link(frame);
        let origin = Point3::from(poses.pose(frame).translation.vector);
        let kinds = &self.model().tree().joints;
        // (active index, factor, joint kind is prismatic, axis, joint origin), frame first
        let mut chain = Vec::new();
        self.for_each_ancestor_column(link, |k, factor, j| {
            let (a, p) = self.joint_axis(poses, j);
            chain.push((k, factor, kinds[j].kind == JointKind::Prismatic, a, p));
        });
        // what joint i does to a direction and to a point
        let turn = |i: usize, v: &Vector3<f64>| -> Vector3<f64> {
            let (_, _, prismatic, a, _) = chain[i];
            if prismatic {
                Vector3::zeros()
            } else {
                a.cross(v)
            }
        };
        let shift = |i: usize, x: &Point3<f64>| -> Vector3<f64> {
            let (_, _, prismatic, a, p) = chain[i];
            if prismatic { a } else { a.cross(&(x - p)) }
        };
        for (j, &(kj, fj, prismatic_j, aj, pj)) in chain.iter().enumerate() {
            for (i, &(ki, fi, ..)) in chain.iter().enumerate() {
                // joint i lies before j (nearer the root) when it comes later in `chain`
                let before = i > j;
                let (linear, angular) = match (prismatic_j, before) {
                    (true, true) => (turn(i, &aj), Vector3::zeros()),
                    (true, false) => (Vector3::zeros(), Vector3::zeros()),
                    (false, true) => {
                        // the axis turns, the lever arm p − pⱼ turns with it
                        let da = turn(i, &aj);
                        let lever = origin - pj;
                        let d_lever = if chain[i].2 {
                            Vector3::zeros()
                        } else {
                            chain[i].3.cross(&lever)
                        };
                        (da.cross(&lever) + aj.cross(&d_lever), da)
                    }
                    (false, false) => (aj.cross(&shift(i, &origin)), Vector3::zeros()),
                };
                let mut c = out[ki].column_mut(kj);
                c.fixed_rows_mut::<3>(0).axpy(fi * fj, &linear, 1.0);
                c.fixed_rows_mut::<3>(3).axpy(fi * fj, &angular, 1.0);
            }
        }
    }

    /// Mass and centre of mass of every link's subtree (index = link), in world coordinates.
    fn subtree_masses(&self, poses: &PoseBuffer) -> Vec<(f64, Vector3<f64>)> {
        let tree = self.model().tree();
        // mass and mass-weighted position, accumulated from the leaves (children follow parents)
        let mut acc: Vec<(f64, Vector3<f64>)> = tree
            .links
            .iter()
            .zip(poses.poses())
            .map(|(l, pose)| {
                let m = l.inertial.mass;
                (m, m * (pose * Point3::from(l.inertial.com)).coords)
            })
            .collect();
        for i in (1..tree.links.len()).rev() {
            if let Some(parent) = tree.links[i].parent {
                let (m, mc) = acc[i];
                acc[parent].0 += m;
                acc[parent].1 += mc;
            }
        }
        acc
    }

    /// Total mass and world centre of mass of the robot at the posture in `poses`.
    pub fn center_of_mass(&self, poses: &PoseBuffer) -> (f64, Point3<f64>) {
        let (m, mc) = self.subtree_masses(poses)[0];
        let c = if m > 0.0 { mc / m } else { Vector3::zeros() };
        (m, Point3::from(c))
    }

    /// The 3 × n Jacobian of the centre of mass with respect to the active values.
    pub fn com_jacobian(&self, poses: &PoseBuffer, out: &mut Matrix3xX<f64>) {
        if out.ncols() != self.len() {
            *out = Matrix3xX::zeros(self.len());
        }
        out.fill(0.0);
        let sub = self.subtree_masses(poses);
        let total = sub[0].0;
        if total <= 0.0 {
            return;
        }
        self.for_each_joint(|k, factor, j| {
            let child = self.model().tree().joints[j].child;
            let (m, mc) = sub[child];
            if m <= 0.0 {
                return;
            }
            let (a, p) = self.joint_axis(poses, j);
            let column = match self.model().tree().joints[j].kind {
                JointKind::Prismatic => a * m,
                _ => a.cross(&(mc - m * p.coords)),
            };
            let mut c = out.column_mut(k);
            c.axpy(factor / total, &column, 1.0);
        });
    }

    /// Generalised gravity torques g(q) with respect to the active values: the torques that hold
    /// the posture against `gravity` (world frame, e.g. [`GRAVITY`]); Pinocchio's
    /// `computeGeneralizedGravity`. `out` has one value per active motor.
    pub fn gravity_torques(&self, poses: &PoseBuffer, gravity: &Vector3<f64>, out: &mut [f64]) {
        out.fill(0.0);
        let sub = self.subtree_masses(poses);
        self.for_each_joint(|k, factor, j| {
            let child = self.model().tree().joints[j].child;
            let (m, mc) = sub[child];
            let (a, p) = self.joint_axis(poses, j);
            // the weight of the subtree, −m g, at its centre of mass
            let weight = -gravity * m;
            let tau = match self.model().tree().joints[j].kind {
                JointKind::Prismatic => a.dot(&weight),
                _ => a.dot(&(mc - m * p.coords).cross(&(-gravity))),
            };
            out[k] += factor * tau;
        });
    }

    /// Calls `f(active index, factor, joint)` for every (active motor, movable joint) coupling.
    fn for_each_joint(&self, mut f: impl FnMut(usize, f64, usize)) {
        let tree = self.model().tree();
        for (c, &j) in tree.movable.iter().enumerate() {
            for &(k, factor) in &self.rows()[c].1 {
                f(k, factor, j);
            }
        }
    }
}
