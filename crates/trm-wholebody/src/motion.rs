//! The whole-body problem: a kinematic, quasi-static model of a robot with both feet flat on the
//! ground (and a seat while seated), a prioritised differential-IK controller that tracks a
//! desired centre-of-mass trajectory, optionally a hand reaching a target below it, and a
//! keyframe posture task in the null space of both, and rollouts that record everything the
//! constraints and costs need.

use std::path::Path;

use crate::WholeBodyError;
use nalgebra::{
    DMatrix, DVector, Isometry3, Matrix3xX, Matrix6xX, Point3, Translation3, UnitQuaternion,
    Vector2, Vector3,
};
use serde::{Deserialize, Serialize};
use trm_collision::{CollisionModel, Other, PlacedBodies, Shape, World};
use trm_kinematics::{ActiveSet, FrameId, PoseBuffer, RobotModel};
use trm_trajectory::{RbfTrajectory, TimeLaw};

use crate::Result;
use crate::spec::{MotionSpec, Support, TrajectorySpec};

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

/// The names of the constraints, in the order of [`Rollout::constraints`]: per motor lower and
/// upper position limit, velocity and torque; the four sides of the support polygon;
/// self-collision; world collision; and, with a reach, the final distance to its target.
pub fn constraint_names(problem: &WholeBody) -> Vec<String> {
    let mut names = Vec::new();
    for m in problem.model().motors() {
        for kind in ["lower limit", "upper limit", "velocity", "torque"] {
            names.push(format!("{} {kind}", m.name));
        }
    }
    for s in ["ZMP behind", "ZMP ahead", "ZMP right", "ZMP left"] {
        names.push(s.to_string());
    }
    names.push("self-collision".into());
    names.push("world collision".into());
    if problem.reach.is_some() {
        names.push("reach target".into());
    }
    names
}

/// One simulated motion.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Rollout {
    /// Sample times, seconds.
    pub times: Vec<f64>,
    /// Phase index at each sample.
    pub phase: Vec<usize>,
    /// Motor positions, rad (one row per sample).
    pub q: Vec<Vec<f64>>,
    /// Motor velocities, rad/s.
    pub qdot: Vec<Vec<f64>>,
    /// Static torque per joint of every motor, N·m.
    pub torque: Vec<Vec<f64>>,
    /// Centre of mass in the ground frame (x forward, y left, z up), m.
    pub com: Vec<[f64; 3]>,
    /// Desired centre of mass (x, z), m.
    pub com_desired: Vec<[f64; 2]>,
    /// Position (x, y, z) of the reaching frame in the ground frame, m (empty without a reach).
    pub hand: Vec<[f64; 3]>,
    /// Cart-table zero-moment point (x, y) on the ground, m.
    pub zmp: Vec<[f64; 2]>,
    /// Conservative support polygon at each sample: [x_min, x_max, y_min, y_max].
    pub support: Vec<[f64; 4]>,
    /// Per constraint, the violation summed over the samples (Σ_t max(0, g(t))): 0 = satisfied.
    pub constraints: Vec<f64>,
    /// Per constraint, the number of samples that violate it.
    pub violated_samples: Vec<usize>,
    /// Whether the ZMP left the real (not the conservative) support polygon: the robot would tip.
    pub fallen: bool,
    /// The cost terms.
    pub costs: Costs,
}

/// The terms of φ_co before normalisation.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct Costs {
    /// Σ_i ‖p_com(i) − p*_com(i)‖ over the samples (x, z), m.
    pub com_error: f64,
    /// Σ_i Σ_joints τ² over the samples, N²m².
    pub effort: f64,
    /// Σ_i of the backward motion of the CoM along x and down along z, m.
    pub backward: f64,
    /// Final distance (x, z) of the reaching frame to its target, m (0 without a reach).
    pub reach: f64,
}

impl Rollout {
    /// The motion as CSV: a header `t,phase,<motor names of model>,com_x,com_z,com_desired_x,
    /// com_desired_z,zmp_x`, then one row per control step (seconds, phase index, motor
    /// positions in rad, CoM, desired CoM and ZMP in m, ground frame). `trm_plan::Trajectory`
    /// reads it back (time and motor columns).
    pub fn to_csv(&self, model: &RobotModel) -> String {
        use std::fmt::Write as _;
        let mut text = String::from("t,phase");
        for m in model.motors() {
            text.push(',');
            text.push_str(&m.name);
        }
        text.push_str(",com_x,com_z,com_desired_x,com_desired_z,zmp_x\n");
        for i in 0..self.times.len() {
            let _ = write!(text, "{:.3},{}", self.times[i], self.phase[i]);
            for v in &self.q[i] {
                let _ = write!(text, ",{v:.6}");
            }
            let _ = writeln!(
                text,
                ",{:.6},{:.6},{:.6},{:.6},{:.6}",
                self.com[i][0],
                self.com[i][2],
                self.com_desired[i][0],
                self.com_desired[i][1],
                self.zmp[i][0]
            );
        }
        text
    }

    /// Number of (sample, constraint) violations.
    pub fn violations(&self) -> usize {
        self.violated_samples.iter().sum()
    }

    /// Total violation Σ_j Σ_t max(0, g_j(t)) (the bootstrap fitness φ_bs, to minimise).
    pub fn total_violation(&self) -> f64 {
        self.constraints.iter().sum()
    }
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

impl WholeBody {
    /// Loads a spec file (the model path is relative to it).
    pub fn load(path: impl AsRef<Path>) -> Result<Self> {
        let path = path.as_ref();
        let (spec, text) = MotionSpec::load(path)?;
        let origin = path.display().to_string();
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
        let neutral = model.neutral_motors();
        let start = deg_map(&model, &neutral, &spec.start);
        let mut keyframes = Vec::new();
        let mut previous = start.clone();
        for p in &spec.phases {
            let k = deg_map(&model, &previous, &p.keyframe);
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
        let mut velocity = Vec::with_capacity(n);
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
        // the ground frame from the start posture: midway between the sole centres, z along
        // the sole normal, x along the sole's forward axis
        let mut poses = model.pose_buffer();
        active.forward(&start, &mut poses)?;
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

    /// Simulates the motion for `params` with the phase end times `ends` (the last one is the
    /// duration): the controller, every constraint at every sample and the cost terms.
    pub fn rollout(&self, params: &[f64], ends: &[f64]) -> Result<Rollout> {
        let spec = &self.spec;
        if ends.len() != spec.phases.len() {
            return Err(WholeBodyError::Invalid {
                what: "phase ends".into(),
                problem: format!("{} ends for {} phases", ends.len(), spec.phases.len()),
            });
        }
        let duration = *ends.last().expect("at least one phase");
        let dt = spec.dt;
        let steps = (duration / dt).round() as usize;
        let times: Vec<f64> = (0..=steps).map(|i| i as f64 * dt).collect();
        let desired = self.desired_com(params, duration, &times)?;
        let n = self.active.len();
        let nc = constraint_names(self).len();
        let mut out = Rollout {
            constraints: vec![0.0; nc],
            violated_samples: vec![0; nc],
            ..Default::default()
        };
        let mut frame = Frame::new(self);
        let mut q = self.start.clone();
        let mut world = self.world()?;
        let mut g = vec![0.0; nc];
        let mut qdot = vec![0.0; n];
        let mut hand_start: Option<Vector2<f64>> = None;
        let ctl = &spec.controller;
        for (i, &t) in times.iter().enumerate() {
            let phase = ends
                .iter()
                .position(|&e| t < e - 1e-9)
                .unwrap_or(ends.len() - 1);
            let t0 = if phase == 0 { 0.0 } else { ends[phase - 1] };
            let support = spec.phases[phase].support;
            let locked = &self.locked[phase];
            let (_, com) = frame.update(self, &q);
            let min_jerk = |tau: f64| {
                let tau = tau.clamp(0.0, 1.0);
                tau * tau * tau * (10.0 - 15.0 * tau + 6.0 * tau * tau)
            };
            let blend = min_jerk((t - t0) / (ends[phase] - t0));
            let blend_next = min_jerk((t + dt - t0) / (ends[phase] - t0));
            let columns = |j: &Matrix3xX<f64>| {
                DMatrix::from_fn(2, n, |r, k| if locked[k] { 0.0 } else { j[(2 * r, k)] })
            };
            // 1. the centre of mass (x, z) along the desired trajectory
            let (now, next) = (desired[i], desired[(i + 1).min(steps)]);
            let feedforward = Vector2::new(next[0] - now[0], next[1] - now[1]) / dt;
            let error = Vector2::new(now[0] - com.x, now[1] - com.z);
            let mut tasks = vec![(
                columns(&frame.com_jacobian),
                DVector::from_column_slice((feedforward + error * ctl.com_gain).as_slice()),
            )];
            // 2. the hand along a minimum-jerk line to its target during its phase
            if let Some((hand_frame, target, reach_phase)) = self.reach {
                let p = frame.point(self, hand_frame);
                out.hand.push([p.x, p.y, p.z]);
                if phase == reach_phase {
                    let from = *hand_start.get_or_insert(Vector2::new(p.x, p.z));
                    let (want, want_next) = (
                        from + (target - from) * blend,
                        from + (target - from) * blend_next,
                    );
                    let v = (want_next - want) / dt
                        + (want - Vector2::new(p.x, p.z)) * self.reach_gain();
                    tasks.push((
                        columns(&frame.point_jacobian),
                        DVector::from_column_slice(v.as_slice()),
                    ));
                }
            }
            // 3. the posture: minimum-jerk blend from the previous keyframe to this one
            let from = if phase == 0 {
                &self.start
            } else {
                &self.keyframes[phase - 1]
            };
            let to = &self.keyframes[phase];
            let posture = DVector::from_fn(n, |k, _| {
                if locked[k] {
                    0.0
                } else {
                    ctl.posture_gain * (from[k] + (to[k] - from[k]) * blend - q[k])
                }
            });
            let command = trm_kinematics::ik::prioritised_velocities(&tasks, &posture, ctl.damping);
            let filter = if ctl.smoothing > 0.0 {
                (dt / ctl.smoothing).min(1.0)
            } else {
                1.0
            };
            for k in 0..n {
                qdot[k] += filter * (command[k] - qdot[k]);
            }
            // static torques per joint: the motors hold the robot's weight, ∂(m g z_com)/∂q
            // (legs resting on the seat carry nothing while it supports them)
            let jn = &frame.com_jacobian;
            let torque: Vec<f64> = (0..n)
                .map(|k| {
                    if locked[k] {
                        0.0
                    } else {
                        self.mass * G * jn[(2, k)] / self.joints_per_motor[k]
                    }
                })
                .collect();
            // constraints at this sample (ZMP after the loop: it needs the CoM acceleration)
            g.fill(0.0);
            for k in 0..n {
                g[4 * k] = self.lower[k] - q[k];
                g[4 * k + 1] = q[k] - self.upper[k];
                g[4 * k + 2] = qdot[k].abs() - self.velocity[k];
                g[4 * k + 3] = torque[k].abs() - self.torque[k];
            }
            let base = 4 * n + 4;
            g[base] = self.self_penetration(&mut frame);
            g[base + 1] = self.world_penetration(&mut frame, &mut world, support);
            if let (Some((_, target, _)), Some(h)) = (self.reach, out.hand.last()) {
                if i == steps {
                    let d = (Vector2::new(h[0], h[2]) - target).norm();
                    g[base + 2] = d - spec.reach.as_ref().map_or(0.0, |r| r.tolerance);
                }
            }
            for (c, v) in g.iter().enumerate() {
                if *v > 0.0 {
                    out.constraints[c] += v;
                    out.violated_samples[c] += 1;
                }
            }
            out.times.push(t);
            out.phase.push(phase);
            out.q.push(q.clone());
            out.qdot.push(qdot.clone());
            out.torque.push(torque);
            out.com.push([com.x, com.y, com.z]);
            out.com_desired.push(now);
            out.support.push(self.support_polygon(support));
            for k in 0..n {
                q[k] += qdot[k] * dt;
            }
        }
        // ZMP of the cart-table model from the CoM's acceleration (central differences)
        let zi = 4 * n;
        for i in 0..out.com.len() {
            let acc = if i == 0 || i + 1 == out.com.len() {
                [0.0, 0.0]
            } else {
                let (a, b, c) = (out.com[i - 1], out.com[i], out.com[i + 1]);
                [
                    (a[0] - 2.0 * b[0] + c[0]) / (dt * dt),
                    (a[1] - 2.0 * b[1] + c[1]) / (dt * dt),
                ]
            };
            let c = out.com[i];
            let zmp = [c[0] - c[2] * acc[0] / G, c[1] - c[2] * acc[1] / G];
            let s = out.support[i];
            let gz = [s[0] - zmp[0], zmp[0] - s[1], s[2] - zmp[1], zmp[1] - s[3]];
            for (c, v) in gz.iter().enumerate() {
                if *v > 0.0 {
                    out.constraints[zi + c] += v;
                    out.violated_samples[zi + c] += 1;
                }
            }
            let real = self.real_polygon(spec.phases[out.phase[i]].support);
            if zmp[0] < real[0] || zmp[0] > real[1] || zmp[1] < real[2] || zmp[1] > real[3] {
                out.fallen = true;
            }
            out.zmp.push(zmp);
        }
        out.costs = costs(&out);
        if let (Some((_, target, _)), Some(h)) = (self.reach, out.hand.last()) {
            out.costs.reach = (Vector2::new(h[0], h[2]) - target).norm();
        }
        Ok(out)
    }

    /// The hand-tuned reference rollout.
    pub fn hand_tuned(&self) -> Result<Rollout> {
        let TrajectorySpec { ends, params } = &self.spec.hand_tuned;
        self.rollout(params, ends)
    }

    /// Phase end times of the optimised motion.
    pub fn ends(&self) -> Vec<f64> {
        self.spec.phases.iter().map(|p| p.end).collect()
    }
}

impl WholeBody {
    /// The world objects, in the ground frame (x forward, y left, z up, between the soles).
    pub fn ground_world(&self) -> &World {
        &self.ground_world
    }

    /// A copy of the world for a rollout; [`WholeBody::world_penetration`] moves its objects
    /// into the root frame at every step.
    fn world(&self) -> Result<World> {
        Ok(self.ground_world.clone())
    }

    fn reach_gain(&self) -> f64 {
        self.spec.reach.as_ref().map_or(0.0, |r| r.gain)
    }

    /// Total penetration depth of the robot with itself at the posture in `frame` (0 if free).
    fn self_penetration(&self, frame: &mut Frame) -> f64 {
        self.collision.place(&frame.poses, &mut frame.placed);
        if !self.spec.limits.self_collision || !self.collision.any_self_collision(&frame.placed) {
            return 0.0;
        }
        self.collision
            .colliding_pairs(&frame.placed, &World::new())
            .iter()
            .map(|p| -p.distance)
            .sum::<f64>()
            .max(1e-9)
    }

    /// Total penetration depth of the robot with the world objects (the seat's contact links
    /// excepted while it supports), after [`WholeBody::self_penetration`] placed the bodies.
    fn world_penetration(&self, frame: &mut Frame, world: &mut World, support: Support) -> f64 {
        if self.ground_world.is_empty() {
            return 0.0;
        }
        let ground_to_root = frame.root_in_ground.inverse();
        for (i, o) in self.ground_world.objects().iter().enumerate() {
            let _ = world.set_pose_at(i, ground_to_root * o.pose());
        }
        if !self.collision.any_world_collision(&frame.placed, world) {
            return 0.0;
        }
        let seated = support == Support::FeetAndSeat;
        self.collision
            .colliding_pairs(&frame.placed, world)
            .iter()
            .filter(|p| match (&p.other, &self.seat) {
                (Other::Object(o), Some((seat, contacts, _))) if seated && o == seat => {
                    let link = self.collision.bodies()[p.body_index].link;
                    !contacts
                        .iter()
                        .any(|c| self.model().tree().links[link].name == *c)
                }
                (Other::Object(_), _) => true,
                _ => false,
            })
            .map(|p| -p.distance)
            .sum::<f64>()
            .max(0.0)
    }

    /// Re-checks a recorded rollout against every constraint without the controller's own
    /// bookkeeping: motor limits from the model, velocities from differences of the recorded
    /// positions, torques from central differences of the potential energy m g z_com, the ZMP
    /// from the recorded CoM, collisions from fresh queries. Returns one line per violated
    /// constraint (empty = feasible).
    pub fn verify(&self, r: &Rollout) -> Vec<String> {
        let mut found = std::collections::BTreeMap::<String, (usize, f64)>::new();
        let mut note = |what: String, t: f64| {
            found.entry(what).or_insert((0, t)).0 += 1;
        };
        let model = self.model();
        let dt = self.spec.dt;
        let mut frame = Frame::new(self);
        let mut world = self.world().unwrap_or_default();
        let h = 1e-6;
        let r_len = r.q.len();
        for (i, q) in r.q.iter().enumerate() {
            let t = r.times[i];
            let phase = &self.spec.phases[r.phase[i]];
            for (k, m) in model.motors().iter().enumerate() {
                if q[k] < m.limits.lower - 1e-12 || q[k] > m.limits.upper + 1e-12 {
                    note(format!("{} position", m.name), t);
                }
                if i + 1 < r.q.len()
                    && ((r.q[i + 1][k] - q[k]) / dt).abs() > self.velocity[k] + 1e-9
                {
                    note(format!("{} velocity", m.name), t);
                }
                if !phase.locked.contains(&m.name) {
                    let (mut up, mut down) = (q.clone(), q.clone());
                    up[k] += h;
                    down[k] -= h;
                    let dz = (self.com_at(&up)[2] - self.com_at(&down)[2]) / (2.0 * h);
                    let tau = self.mass * G * dz / self.joints_per_motor[k];
                    if tau.abs() > self.torque[k] * (1.0 + 1e-6) {
                        note(format!("{} torque", m.name), t);
                    }
                }
            }
            if i > 0 && i + 1 < r.com.len() {
                let (a, b, c) = (r.com[i - 1], r.com[i], r.com[i + 1]);
                let ax = (a[0] - 2.0 * b[0] + c[0]) / (dt * dt);
                let x = b[0] - b[2] * ax / G;
                let s = self.support_polygon(phase.support);
                if x < s[0] - 1e-9 || x > s[1] + 1e-9 || b[1] < s[2] || b[1] > s[3] {
                    note("ZMP outside the support polygon".into(), t);
                }
            }
            frame.update(self, q);
            if self.self_penetration(&mut frame) > 0.0 {
                note("self-collision".into(), t);
            }
            if self.world_penetration(&mut frame, &mut world, phase.support) > 0.0 {
                note("world collision".into(), t);
            }
            if let (Some((hand, target, _)), Some(r)) = (self.reach, &self.spec.reach) {
                if i + 1 == r_len {
                    let p = frame.point(self, hand);
                    if (Vector2::new(p.x, p.z) - target).norm() > r.tolerance + 1e-9 {
                        note("reach target missed".into(), t);
                    }
                }
            }
        }
        found
            .into_iter()
            .map(|(what, (n, t))| format!("{what}: {n} samples, first at t = {t:.2} s"))
            .collect()
    }
}

/// The cost terms of a rollout.
fn costs(r: &Rollout) -> Costs {
    let mut c = Costs::default();
    for i in 0..r.times.len() {
        let (p, d) = (r.com[i], r.com_desired[i]);
        c.com_error += ((p[0] - d[0]).powi(2) + (p[2] - d[1]).powi(2)).sqrt();
        c.effort += r.torque[i].iter().map(|t| t * t).sum::<f64>();
        if i > 0 {
            let prev = r.com[i - 1];
            c.backward += (prev[0] - p[0]).max(0.0) + (prev[2] - p[2]).max(0.0);
        }
    }
    c
}

/// Per-sample kinematic quantities in the ground frame.
#[derive(Debug, Clone)]
struct Frame {
    poses: PoseBuffer,
    placed: PlacedBodies,
    /// Jacobians in the root frame (scratch).
    root_jacobian: Matrix3xX<f64>,
    frame_jacobian: Matrix6xX<f64>,
    sole: Matrix6xX<f64>,
    sole_origin: Point3<f64>,
    /// CoM Jacobian in the ground frame with the left foot fixed (3 × n).
    com_jacobian: Matrix3xX<f64>,
    /// Jacobian of the last [`Frame::point`] in the ground frame with the left foot fixed.
    point_jacobian: Matrix3xX<f64>,
    root_in_ground: Isometry3<f64>,
}

impl Frame {
    fn new(p: &WholeBody) -> Self {
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
    fn update(&mut self, p: &WholeBody, q: &[f64]) -> (f64, Point3<f64>) {
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
    fn point(&mut self, p: &WholeBody, frame_id: FrameId) -> Point3<f64> {
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
    fn relative_to_sole(&self, c: &Point3<f64>, out: &mut Matrix3xX<f64>) {
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
