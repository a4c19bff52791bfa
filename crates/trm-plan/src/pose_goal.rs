//! Task-space goals: MoveIt's position and orientation constraints on links, checked on a
//! posture and met by configurations found with damped least-squares IK from the start and
//! then from seeded random configurations.

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use trm_collision::Shape;
use trm_kinematics::nalgebra::{DMatrix, DVector, Isometry3, Matrix3xX, Matrix6xX, Point3};
use trm_kinematics::nalgebra::{UnitQuaternion, Vector3};
use trm_kinematics::{ActiveSet, KinematicsError, PoseBuffer, RobotModel};

/// A point fixed to a link that must lie in one of some regions (MoveIt's
/// `PositionConstraint`; the regions in the robot's root frame).
#[derive(Debug, Clone, PartialEq)]
pub struct PositionConstraint {
    /// The link.
    pub link: String,
    /// The frame the regions are given in (`header.frame_id`; empty: the robot's root).
    pub frame: String,
    /// The point, in the link's frame (`target_point_offset`).
    pub offset: Vector3<f64>,
    /// The regions (box, sphere, cylinder) with their poses; the point must be in one.
    pub regions: Vec<(Shape, Isometry3<f64>)>,
}

/// How a link must be turned (MoveIt's `OrientationConstraint`): the rotation from `orientation`
/// to the link's, as a rotation vector, within `tolerance` per axis (MoveIt's ROTATION_VECTOR
/// parameterization; for the small tolerances goals use, XYZ Euler angles agree with it).
#[derive(Debug, Clone, PartialEq)]
pub struct OrientationConstraint {
    /// The link.
    pub link: String,
    /// The frame the orientation is given in (`header.frame_id`; empty: the robot's root).
    pub frame: String,
    /// The orientation in the robot's root frame.
    pub orientation: UnitQuaternion<f64>,
    /// Tolerances about x, y, z (rad).
    pub tolerance: [f64; 3],
}

/// A task-space goal: every constraint must hold.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct PoseGoal {
    /// Position constraints.
    pub positions: Vec<PositionConstraint>,
    /// Orientation constraints.
    pub orientations: Vec<OrientationConstraint>,
}

/// Whether `local` (in the region's frame) lies inside `shape`.
fn inside(shape: &Shape, local: &Point3<f64>) -> bool {
    match shape {
        Shape::Box { size } => (0..3).all(|i| local[i].abs() <= 0.5 * size[i]),
        Shape::Sphere { radius } => local.coords.norm() <= *radius,
        Shape::Cylinder { radius, length } | Shape::Capsule { radius, length } => {
            local.z.abs() <= 0.5 * length && local.x.hypot(local.y) <= *radius
        }
        _ => false,
    }
}

impl OrientationConstraint {
    /// The link's orientation error, a rotation vector in world axes (zero where within
    /// tolerance).
    fn error(&self, current: &UnitQuaternion<f64>) -> Vector3<f64> {
        let error = (self.orientation * current.inverse()).scaled_axis();
        let local = (self.orientation.inverse() * current).scaled_axis();
        if (0..3).all(|i| local[i].abs() <= self.tolerance[i]) {
            Vector3::zeros()
        } else {
            error
        }
    }
}

impl PoseGoal {
    /// The first frame a constraint is given in other than `root` (the robot's root link): trm
    /// plans in the root frame, so such a goal is refused.
    pub fn foreign_frame(&self, root: &str) -> Option<&str> {
        self.positions
            .iter()
            .map(|c| c.frame.as_str())
            .chain(self.orientations.iter().map(|c| c.frame.as_str()))
            .find(|f| !f.is_empty() && *f != root)
    }

    /// Whether there is no constraint.
    pub fn is_empty(&self) -> bool {
        self.positions.is_empty() && self.orientations.is_empty()
    }

    /// Whether the posture whose link poses are `poses` meets every constraint.
    pub fn met(&self, robot: &RobotModel, poses: &PoseBuffer) -> Result<bool, KinematicsError> {
        for c in &self.positions {
            let p = poses.pose(robot.frame_id(&c.link)?) * Point3::from(c.offset);
            if !c
                .regions
                .iter()
                .any(|(s, pose)| inside(s, &pose.inverse_transform_point(&p)))
            {
                return Ok(false);
            }
        }
        for c in &self.orientations {
            let r = poses.pose(robot.frame_id(&c.link)?).rotation;
            if c.error(&r).norm() > 0.0 {
                return Ok(false);
            }
        }
        Ok(true)
    }

    /// A configuration of `active` that meets the goal and that `free` accepts: damped
    /// least-squares IK from `start`, then from random configurations drawn from `seed`,
    /// `attempts` starts in all. `None` when none is found.
    pub fn solve(
        &self,
        active: &ActiveSet,
        start: &[f64],
        seed: u64,
        attempts: usize,
        mut free: impl FnMut(&[f64]) -> bool,
    ) -> Result<Option<Vec<f64>>, KinematicsError> {
        const ITERATIONS: usize = 300;
        const DAMPING: f64 = 0.02;
        const MAX_STEP: f64 = 0.2;
        let robot = active.model();
        let (lower, upper) = active.bounds();
        let frames = |link: &str| robot.frame_id(link);
        let positions: Vec<_> = self
            .positions
            .iter()
            .map(|c| Ok((frames(&c.link)?, c)))
            .collect::<Result<_, KinematicsError>>()?;
        let orientations: Vec<_> = self
            .orientations
            .iter()
            .map(|c| Ok((frames(&c.link)?, c)))
            .collect::<Result<_, KinematicsError>>()?;
        let rows = 3 * (positions.len() + orientations.len());
        let n = active.len();
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let mut poses = robot.pose_buffer();
        let (mut point_j, mut frame_j) = (Matrix3xX::zeros(n), Matrix6xX::zeros(n));
        for attempt in 0..attempts {
            let mut q = if attempt == 0 {
                start.to_vec()
            } else {
                active.random(&mut rng)
            };
            for _ in 0..ITERATIONS {
                active.forward(&q, &mut poses)?;
                if self.met(robot, &poses)? {
                    if free(&q) {
                        return Ok(Some(q));
                    }
                    break;
                }
                let mut j = DMatrix::zeros(rows, n);
                let mut e = DVector::zeros(rows);
                for (k, (frame, c)) in positions.iter().enumerate() {
                    let pose = poses.pose(*frame);
                    let p = pose * Point3::from(c.offset);
                    let inside_any = c
                        .regions
                        .iter()
                        .any(|(s, r)| inside(s, &r.inverse_transform_point(&p)));
                    let target = c.regions[0].1.translation.vector;
                    let err = if inside_any {
                        Vector3::zeros()
                    } else {
                        target - p.coords
                    };
                    active.point_jacobian(&poses, robot.frame_link(*frame), &p, &mut point_j);
                    j.view_mut((3 * k, 0), (3, n)).copy_from(&point_j);
                    e.rows_mut(3 * k, 3).copy_from(&err);
                }
                let base = 3 * positions.len();
                for (k, (frame, c)) in orientations.iter().enumerate() {
                    let err = c.error(&poses.pose(*frame).rotation);
                    active.jacobian(&poses, *frame, &mut frame_j);
                    j.view_mut((base + 3 * k, 0), (3, n))
                        .copy_from(&frame_j.rows(3, 3));
                    e.rows_mut(base + 3 * k, 3).copy_from(&err);
                }
                let Some(pinv) = trm_kinematics::ik::damped_pseudo_inverse(&j, DAMPING) else {
                    break;
                };
                let dq = pinv * e;
                let largest = dq.amax();
                let scale = if largest > MAX_STEP {
                    MAX_STEP / largest
                } else {
                    1.0
                };
                for (i, v) in q.iter_mut().enumerate() {
                    *v = (*v + scale * dq[i]).clamp(lower[i], upper[i]);
                }
            }
        }
        Ok(None)
    }
}
