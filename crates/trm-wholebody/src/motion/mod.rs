//! The whole-body problem: a kinematic, quasi-static model of a robot with both feet flat on the
//! ground (and a seat while seated), a prioritised differential-IK controller that tracks a
//! desired centre-of-mass trajectory, optionally a hand reaching a target below it, and a
//! keyframe posture task in the null space of both, and rollouts that record everything the
//! constraints and costs need.

//!
//! Setup and the model's quantities live here; `rollout` runs the controller and records a
//! motion, `constraints` measures collisions and re-checks a rollout independently, `frame`
//! holds the per-sample kinematics (Jacobians with the foot fixed).

use std::path::Path;

use crate::WholeBodyError;
use nalgebra::{Isometry3, Point3, Translation3, UnitQuaternion, Vector2, Vector3};
use trm_collision::{CollisionModel, Shape, World};
use trm_kinematics::{ActiveSet, FrameId, RobotModel};
use trm_trajectory::{RbfTrajectory, TimeLaw};

use crate::Result;
use crate::spec::{MotionSpec, SpecErr, Support};

mod constraints;
mod frame;
mod rollout;

pub use constraints::constraint_names;
pub use rollout::{Costs, Rollout};

use frame::Frame;

/// Standard gravity, m/s².
pub const G: f64 = 9.81;

/// A whole-body motion problem built from a [`MotionSpec`]: model, contacts, keyframes, limits.
#[derive(Debug, Clone)]
pub struct WholeBody {
    spec: MotionSpec,
    active: ActiveSet,
    collision: CollisionModel,
    feet: (FrameId, FrameId),
    /// Pose of the ground frame in the left sole frame.
    sole_to_ground: Isometry3<f64>,
    /// World objects with their poses in the ground frame.
    ground_world: World,
    /// The seat: object name, links allowed to touch it while it supports, its x extent.
    seat: Option<(String, Vec<String>, [f64; 2])>,
    /// The reaching frame, its target (x, z) and phase index.
    reach: Option<(FrameId, Vector2<f64>, usize)>,
    start: Vec<f64>,
    keyframes: Vec<Vec<f64>>,
    locked: Vec<Vec<bool>>,
    lower: Vec<f64>,
    upper: Vec<f64>,
    velocity: Vec<f64>,
    torque: Vec<f64>,
    /// Joints each motor drives (torques are reported per joint).
    joints_per_motor: Vec<f64>,
    mass: f64,
    com_start: Vector2<f64>,
    com_end: Vector2<f64>,
    /// Feet polygon in the ground frame: x from heel to toe, y from right to left edge.
    feet_box: [f64; 4],
}

fn deg_map(
    model: &RobotModel,
    base: &[f64],
    map: &std::collections::BTreeMap<String, f64>,
) -> Vec<f64> {
    let mut q = base.to_vec();
    for (name, v) in map {
        if let Ok(i) = model.motor_index(name) {
            q[i] = v.to_radians();
        }
    }
    q
}

/// The start posture, each phase's keyframe, and the motor limits they keep to.
struct Postures {
    start: Vec<f64>,
    keyframes: Vec<Vec<f64>>,
    lower: Vec<f64>,
    upper: Vec<f64>,
}

/// The start posture and each phase's keyframe (motor values; a keyframe's unnamed motors where
/// the previous left them), all within the motor limits; and the limits.
fn postures(spec: &MotionSpec, model: &RobotModel, spec_err: &SpecErr<'_>) -> Result<Postures> {
    let neutral = model.neutral_motors();
    let start = deg_map(model, &neutral, &spec.start);
    let mut keyframes = Vec::new();
    let mut previous = start.clone();
    for p in &spec.phases {
        let k = deg_map(model, &previous, &p.keyframe);
        previous = k.clone();
        keyframes.push(k);
    }
    let (lower, upper): (Vec<f64>, Vec<f64>) = model
        .motors()
        .iter()
        .map(|m| (m.limits.lower, m.limits.upper))
        .unzip();
    for (field, (name, q)) in std::iter::once(("start".to_string(), ("start", &start))).chain(
        spec.phases
            .iter()
            .zip(&keyframes)
            .enumerate()
            .map(|(i, (p, k))| (format!("phases[{i}].keyframe"), (p.name.as_str(), k))),
    ) {
        for (i, v) in q.iter().enumerate() {
            if *v < lower[i] - 1e-9 || *v > upper[i] + 1e-9 {
                return Err(spec_err(
                    &format!("{field}.{}", model.motors()[i].name),
                    format!(
                        "posture `{name}` puts `{}` at {:.1}°, outside [{:.1}°, {:.1}°]",
                        model.motors()[i].name,
                        v.to_degrees(),
                        lower[i].to_degrees(),
                        upper[i].to_degrees()
                    ),
                    "keep postures inside the motor limits",
                ));
            }
        }
    }
    Ok(Postures {
        start,
        keyframes,
        lower,
        upper,
    })
}

/// Each motor's velocity limit: the spec's, else the model's (finite and positive).
fn velocity_limits(
    spec: &MotionSpec,
    model: &RobotModel,
    spec_err: &SpecErr<'_>,
) -> Result<Vec<f64>> {
    let mut velocity = Vec::with_capacity(model.motors().len());
    for m in model.motors() {
        let model_limit = Some(m.limits.velocity).filter(|v| v.is_finite());
        match spec.limits.velocity.get(&m.name).copied().or(model_limit) {
            Some(v) if v > 0.0 => velocity.push(v),
            _ => {
                return Err(spec_err(
                    "limits.velocity",
                    format!("no velocity limit for motor `{}`", m.name),
                    "add it to limits.velocity (rad/s)",
                ));
            }
        }
    }
    Ok(velocity)
}

/// The ground frame in the left sole's frame (midway between the sole centres, z up along the
/// sole normal, x along the sole's forward axis) at the start posture, and half the gap between
/// the soles; an error when the soles are not side by side on one plane.
fn ground_frame(
    active: &ActiveSet,
    start: &[f64],
    feet: (FrameId, FrameId),
    spec_err: &SpecErr<'_>,
) -> Result<(Isometry3<f64>, f64)> {
    // the ground frame from the start posture: midway between the sole centres, z along
    // the sole normal, x along the sole's forward axis
    let mut poses = active.model().pose_buffer();
    active.forward(start, &mut poses)?;
    let (left, right) = (poses.pose(feet.0), poses.pose(feet.1));
    let offset = left.inverse_transform_point(&Point3::from(right.translation.vector));
    // (the iCub's legs are symmetric to 0.1 mm)
    if offset.z.abs() > 1e-3 || offset.x.abs() > 1e-3 {
        return Err(spec_err(
            "feet",
            format!(
                "the soles are not side by side on one plane at the start posture (right sole at {:?} in the left sole frame)",
                offset.coords.as_slice()
            ),
            "choose frames on both soles of a symmetric posture",
        ));
    }
    // z up: if the sole frame's z points into the ground, turn it about x (keeping x, the
    // toe direction)
    let pelvis = left.inverse_transform_point(&Point3::origin());
    let turn = if pelvis.z < 0.0 {
        UnitQuaternion::from_axis_angle(&Vector3::x_axis(), std::f64::consts::PI)
    } else {
        UnitQuaternion::identity()
    };
    let sole_to_ground =
        Isometry3::from_parts(Translation3::new(offset.x / 2.0, offset.y / 2.0, 0.0), turn);
    let half_gap = offset.y.abs() / 2.0;
    Ok((sole_to_ground, half_gap))
}

impl WholeBody {
    /// Loads a spec file (the model path is relative to it).
    pub fn load(path: impl AsRef<Path>) -> Result<Self> {
        Self::load_with_budgets(path, None, None)
    }

    /// [`WholeBody::load`] with the optimiser's budgets replaced where given (`rollouts`,
    /// `bootstrap_rollouts`), checked as the spec's own values are.
    pub fn load_with_budgets(
        path: impl AsRef<Path>,
        rollouts: Option<u64>,
        bootstrap_rollouts: Option<u64>,
    ) -> Result<Self> {
        let path = path.as_ref();
        let (mut spec, text) = MotionSpec::load(path)?;
        if let Some(r) = rollouts {
            spec.optimiser.rollouts = r;
        }
        if let Some(b) = bootstrap_rollouts {
            spec.optimiser.bootstrap_rollouts = b;
        }
        let origin = path.display().to_string();
        spec.check(&text, &origin)?;
        let base = path.parent().unwrap_or(Path::new("."));
        let model = trm_models::load(&spec.model, base)?;
        Self::new(spec, model, &origin, &text)
    }

    /// Builds the problem from a parsed spec and its model (`origin`/`text` locate errors).
    pub fn new(spec: MotionSpec, model: RobotModel, origin: &str, text: &str) -> Result<Self> {
        spec.check_names(&model, origin, text)?;
        let spec_err = |field: &str, problem: String, fix: &str| {
            WholeBodyError::spec(text, origin, field, problem, fix)
        };
        let active = model.all_active();
        let n = active.len();
        let collision = CollisionModel::new(&model)?;
        let feet = (model.frame_id(&spec.feet.0)?, model.frame_id(&spec.feet.1)?);
        let Postures {
            start,
            keyframes,
            lower,
            upper,
        } = postures(&spec, &model, &spec_err)?;
        let velocity = velocity_limits(&spec, &model, &spec_err)?;
        let torque: Vec<f64> = model
            .motors()
            .iter()
            .map(|m| spec.limits.torque[&m.name])
            .collect();
        let joints_per_motor: Vec<f64> = (0..n)
            .map(|i| {
                model
                    .couplings()
                    .iter()
                    .filter(|c| c.terms.iter().any(|&(k, _)| k == i))
                    .count()
                    .max(1) as f64
            })
            .collect();
        let locked = spec
            .phases
            .iter()
            .map(|p| {
                model
                    .motors()
                    .iter()
                    .map(|m| p.locked.contains(&m.name))
                    .collect()
            })
            .collect();
        let (sole_to_ground, half_gap) = ground_frame(&active, &start, feet, &spec_err)?;
        let (length, width) = spec.sole;
        let feet_box = [
            -length / 2.0,
            length / 2.0,
            -half_gap - width / 2.0,
            half_gap + width / 2.0,
        ];
        let ground_world = World::from_spec_in(&spec.world, origin, text, "world.objects")?;
        let seat = spec.seat.as_ref().and_then(|seat| {
            spec.world
                .objects
                .iter()
                .find(|o| o.name == seat.object)
                .and_then(|o| match o.shape {
                    Shape::Box { size } => Some((
                        seat.object.clone(),
                        seat.contacts.clone(),
                        [o.xyz[0] - size[0] / 2.0, o.xyz[0] + size[0] / 2.0],
                    )),
                    _ => None,
                })
        });
        let reach = match &spec.reach {
            Some(r) => Some((
                model.frame_id(&r.frame)?,
                Vector2::new(r.target.0, r.target.1),
                spec.phases
                    .iter()
                    .position(|p| p.name == r.phase)
                    .unwrap_or(spec.phases.len() - 1),
            )),
            None => None,
        };
        let mut problem = WholeBody {
            active,
            collision,
            feet,
            sole_to_ground,
            ground_world,
            seat,
            reach,
            start,
            keyframes,
            locked,
            lower,
            upper,
            velocity,
            torque,
            joints_per_motor,
            mass: 0.0,
            com_start: Vector2::zeros(),
            com_end: Vector2::zeros(),
            feet_box,
            spec,
        };
        let mut frame = Frame::new(&problem);
        let (mass, com) = frame.update(&problem, &problem.start.clone());
        problem.mass = mass;
        problem.com_start = Vector2::new(com.x, com.z);
        let end = problem.keyframes.last().cloned().unwrap_or_default();
        let (_, com) = frame.update(&problem, &end);
        problem.com_end = Vector2::new(com.x, com.z);
        Ok(problem)
    }

    /// Centre of mass (x, y, z) in the ground frame at motor positions `q`, with the feet flat.
    pub fn com_at(&self, q: &[f64]) -> [f64; 3] {
        let mut frame = Frame::new(self);
        let (_, c) = frame.update(self, q);
        [c.x, c.y, c.z]
    }

    /// Position (x, y, z) of a link or named frame's origin in the ground frame at motor
    /// positions `q`, with the feet flat.
    pub fn point_at(&self, q: &[f64], frame: &str) -> Result<[f64; 3]> {
        let id = self.model().frame_id(frame)?;
        let mut f = Frame::new(self);
        f.update(self, q);
        let p = f.point(self, id);
        Ok([p.x, p.y, p.z])
    }

    /// Pose of the robot's root link in the ground frame at motor positions `q` (feet flat).
    pub fn root_pose(&self, q: &[f64]) -> Isometry3<f64> {
        let mut f = Frame::new(self);
        f.update(self, q);
        f.root_in_ground
    }

    /// The robot's collision model.
    pub fn collision(&self) -> &CollisionModel {
        &self.collision
    }

    /// The start posture and the keyframe ending each phase, motor positions in rad.
    pub fn keyframes(&self) -> (&[f64], &[Vec<f64>]) {
        (&self.start, &self.keyframes)
    }

    /// The spec.
    pub fn spec(&self) -> &MotionSpec {
        &self.spec
    }

    /// The robot model.
    pub fn model(&self) -> &RobotModel {
        self.active.model()
    }

    /// Number of optimisation parameters (3 × rbfs).
    pub fn num_params(&self) -> usize {
        3 * self.spec.rbfs
    }

    /// Total mass, kg.
    pub fn mass(&self) -> f64 {
        self.mass
    }

    /// Start and end centre of mass (x, z) in the ground frame: the trajectory's waypoints.
    pub fn com_waypoints(&self) -> (Vector2<f64>, Vector2<f64>) {
        (self.com_start, self.com_end)
    }

    /// The feet polygon [x_min, x_max, y_min, y_max] in the ground frame.
    pub fn feet_polygon(&self) -> [f64; 4] {
        self.feet_box
    }

    /// The conservative support polygon of a phase's support.
    pub fn support_polygon(&self, support: Support) -> [f64; 4] {
        let mut b = self.real_polygon(support);
        let m = self.spec.support_margin;
        b[0] += m;
        b[1] -= m;
        b[2] += m;
        b[3] -= m;
        b
    }

    fn real_polygon(&self, support: Support) -> [f64; 4] {
        let mut b = self.feet_box;
        if let (Support::FeetAndSeat, Some((_, _, x))) = (support, &self.seat) {
            b[0] = b[0].min(x[0]);
            b[1] = b[1].max(x[1]);
        }
        b
    }

    /// The desired centre-of-mass trajectory (x, z) at `times` for `params` over `duration`:
    /// two RBF networks with exact waypoints at the start and end CoM, run through an RBF time
    /// law. The x and z parameters are fractions of the start-to-end displacement, so 0 … 1
    /// spans the motion whatever the robot's size.
    pub fn desired_com(
        &self,
        params: &[f64],
        duration: f64,
        times: &[f64],
    ) -> Result<Vec<[f64; 2]>> {
        let r = self.spec.rbfs;
        if params.len() != 3 * r || params.iter().any(|p| !p.is_finite()) {
            return Err(WholeBodyError::Invalid {
                what: "trajectory parameters".into(),
                problem: format!("need {} finite values, got {:?}", 3 * r, params),
            });
        }
        let traj_err = |e: trm_trajectory::TrajectoryError| WholeBodyError::Invalid {
            what: "trajectory".into(),
            problem: e.to_string(),
        };
        let (a, b) = (self.com_start, self.com_end);
        let mut out = vec![[0.0; 2]; times.len()];
        let law = TimeLaw::new(duration, r, 2000).map_err(traj_err)?;
        let phases = law.phases(&params[2 * r..], times).map_err(traj_err)?;
        let warped: Vec<f64> = phases.iter().map(|s| s * duration).collect();
        for axis in 0..2 {
            let rbf = RbfTrajectory::new(0.0, duration, r, &[(0.0, a[axis]), (duration, b[axis])])
                .map_err(traj_err)?;
            let weights: Vec<f64> = params[axis * r..(axis + 1) * r]
                .iter()
                .map(|f| a[axis] + (b[axis] - a[axis]) * f)
                .collect();
            let values = rbf.sample(&weights, &warped).map_err(traj_err)?;
            for (o, v) in out.iter_mut().zip(values) {
                o[axis] = v;
            }
        }
        Ok(out)
    }
}
