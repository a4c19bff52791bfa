//! The whole-body problem: a kinematic, quasi-static model of a robot with both feet flat on the
//! ground (and a chair while seated), a differential-IK controller that tracks a desired
//! centre-of-mass trajectory with a keyframe posture task in its null space, and rollouts that
//! record everything the constraints and costs need.

use std::path::Path;

use nalgebra::{
    Isometry3, Matrix2, Matrix3xX, Matrix6xX, Point3, Translation3, UnitQuaternion, Vector2,
    Vector3,
};
use serde::{Deserialize, Serialize};
use trm_collision::{CollisionModel, Other, PlacedBodies, Shape, World};
use trm_kinematics::{ActiveSet, FrameId, PoseBuffer, RobotModel};
use trm_tasks::TaskError;
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
    /// The chair in the ground frame, and the links allowed to touch it while it supports.
    chair: Option<(Shape, Isometry3<f64>, Vec<String>)>,
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

/// The names of the constraints, in the order of [`Rollout::constraints`].
pub fn constraint_names(model: &RobotModel) -> Vec<String> {
    let mut names = Vec::new();
    for m in model.motors() {
        for kind in ["lower limit", "upper limit", "velocity", "torque"] {
            names.push(format!("{} {kind}", m.name));
        }
    }
    for s in ["ZMP behind", "ZMP ahead", "ZMP right", "ZMP left"] {
        names.push(s.to_string());
    }
    names.push("self-collision".into());
    names.push("chair collision".into());
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
}

impl Rollout {
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
        let model = if spec.model == "icub_sagittal" {
            trm_models::icub_sagittal()
        } else {
            RobotModel::load(base.join(&spec.model))?
        };
        Self::new(spec, model, &origin, &text)
    }

    /// Builds the problem from a parsed spec and its model (`origin`/`text` locate errors).
    pub fn new(spec: MotionSpec, model: RobotModel, origin: &str, text: &str) -> Result<Self> {
        spec.check_names(&model, origin, text)?;
        let spec_err = |field: &str, problem: String, fix: &str| TaskError::Spec {
            origin: origin.to_string(),
            position: trm_tasks::spec::locate(text, field),
            field: field.to_string(),
            problem,
            fix: fix.to_string(),
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
        for (name, q) in std::iter::once(("start", &start)).chain(
            spec.phases
                .iter()
                .zip(&keyframes)
                .map(|(p, k)| (p.name.as_str(), k)),
        ) {
            for (i, v) in q.iter().enumerate() {
                if *v < lower[i] - 1e-9 || *v > upper[i] + 1e-9 {
                    return Err(spec_err(
                        if name == "start" { "start" } else { "keyframe" },
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
                        "velocity",
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
        let chair = spec.chair.as_ref().map(|c| {
            (
                Shape::Box { size: c.size },
                Isometry3::translation(c.centre[0], c.centre[1], c.centre[2]),
                c.contacts.clone(),
            )
        });
        let mut problem = WholeBody {
            active,
            collision,
            feet,
            sole_to_ground,
            chair,
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
        if let (Support::FeetAndChair, Some(c)) = (support, &self.spec.chair) {
            b[0] = b[0].min(c.centre[0] - c.size[0] / 2.0);
            b[1] = b[1].max(c.centre[0] + c.size[0] / 2.0);
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
            return Err(TaskError::Invalid {
                what: "trajectory parameters".into(),
                problem: format!("need {} finite values, got {:?}", 3 * r, params),
            });
        }
        let traj_err = |e: trm_trajectory::TrajectoryError| TaskError::Invalid {
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
            return Err(TaskError::Invalid {
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
        let names = constraint_names(self.model());
        let nc = names.len();
        let mut out = Rollout {
            constraints: vec![0.0; nc],
            violated_samples: vec![0; nc],
            ..Default::default()
        };
        let mut frame = Frame::new(self);
        let mut q = self.start.clone();
        let mut world = World::new();
        if let Some((shape, _, _)) = &self.chair {
            world
                .add("chair", shape.clone(), Isometry3::identity())
                .map_err(TaskError::from)?;
        }
        let empty = World::new();
        let mut g = vec![0.0; nc];
        let mut qdot = vec![0.0; n];
        let (kc, kq, damping) = (
            spec.controller.com_gain,
            spec.controller.posture_gain,
            spec.controller.damping,
        );
        for (i, &t) in times.iter().enumerate() {
            let phase = ends
                .iter()
                .position(|&e| t < e - 1e-9)
                .unwrap_or(ends.len() - 1);
            let t0 = if phase == 0 { 0.0 } else { ends[phase - 1] };
            let support = spec.phases[phase].support;
            let locked = &self.locked[phase];
            let (_, com) = frame.update(self, &q);
            // posture reference: minimum-jerk blend from the previous keyframe to this one
            let from = if phase == 0 {
                &self.start
            } else {
                &self.keyframes[phase - 1]
            };
            let to = &self.keyframes[phase];
            let tau = ((t - t0) / (ends[phase] - t0)).clamp(0.0, 1.0);
            let blend = tau * tau * tau * (10.0 - 15.0 * tau + 6.0 * tau * tau);
            // CoM task, x and z rows of the CoM Jacobian in the ground frame
            let jn = &frame.com_jacobian;
            let mut jj = nalgebra::DMatrix::<f64>::zeros(2, n);
            for k in 0..n {
                if !locked[k] {
                    jj[(0, k)] = jn[(0, k)];
                    jj[(1, k)] = jn[(2, k)];
                }
            }
            let next = desired[(i + 1).min(steps)];
            let now = desired[i];
            let feedforward = if i < steps {
                Vector2::new(next[0] - now[0], next[1] - now[1]) / dt
            } else {
                Vector2::zeros()
            };
            let error = Vector2::new(now[0] - com.x, now[1] - com.z);
            let v = feedforward + error * kc;
            let jjt = &jj * jj.transpose();
            let m = Matrix2::new(jjt[(0, 0)], jjt[(0, 1)], jjt[(1, 0)], jjt[(1, 1)])
                + Matrix2::identity() * damping * damping;
            let inv = m.try_inverse().unwrap_or_else(Matrix2::zeros);
            let pinv = jj.transpose() * nalgebra::DMatrix::from_column_slice(2, 2, inv.as_slice());
            let posture = nalgebra::DVector::from_fn(n, |k, _| {
                if locked[k] {
                    0.0
                } else {
                    kq * (from[k] + (to[k] - from[k]) * blend - q[k])
                }
            });
            let task = &pinv * nalgebra::DVector::from_column_slice(v.as_slice());
            let null = &posture - &pinv * (&jj * &posture);
            let filter = if spec.controller.smoothing > 0.0 {
                (dt / spec.controller.smoothing).min(1.0)
            } else {
                1.0
            };
            for k in 0..n {
                qdot[k] += filter * (task[k] + null[k] - qdot[k]);
            }
            // static torques per joint: the motors hold the robot's weight, ∂(m g z_com)/∂q
            // (legs resting on the chair carry nothing while it supports them)
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
            self.collision.place(&frame.poses, &mut frame.placed);
            if spec.limits.self_collision && self.collision.any_self_collision(&frame.placed) {
                g[base] = self
                    .collision
                    .colliding_pairs(&frame.placed, &empty)
                    .iter()
                    .map(|p| -p.distance)
                    .sum::<f64>()
                    .max(1e-6);
            }
            if let Some((_, pose, contacts)) = &self.chair {
                world
                    .set_pose("chair", frame.root_in_ground.inverse() * pose)
                    .map_err(TaskError::from)?;
                if self.collision.any_world_collision(&frame.placed, &world) {
                    let allowed = support == Support::FeetAndChair;
                    g[base + 1] = self
                        .collision
                        .colliding_pairs(&frame.placed, &world)
                        .iter()
                        .filter(|p| matches!(p.other, Other::Object(_)))
                        .filter(|p| {
                            let link = p.body.split('#').next().unwrap_or(&p.body);
                            !(allowed && contacts.iter().any(|c| c == link))
                        })
                        .map(|p| -p.distance)
                        .sum::<f64>();
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
        let mut world = World::new();
        if let Some((shape, _, _)) = &self.chair {
            let _ = world.add("chair", shape.clone(), Isometry3::identity());
        }
        let h = 1e-6;
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
            self.collision.place(&frame.poses, &mut frame.placed);
            if self.spec.limits.self_collision && self.collision.count_self(&frame.placed) > 0 {
                note("self-collision".into(), t);
            }
            if let Some((_, pose, contacts)) = &self.chair {
                let _ = world.set_pose("chair", frame.root_in_ground.inverse() * pose);
                let allowed = phase.support == Support::FeetAndChair;
                let touching = self
                    .collision
                    .colliding_pairs(&frame.placed, &world)
                    .into_iter()
                    .any(|p| {
                        let link = p.body.split('#').next().unwrap_or(&p.body).to_string();
                        matches!(p.other, Other::Object(_))
                            && !(allowed && contacts.contains(&link))
                    });
                if touching {
                    note("chair collision".into(), t);
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
    com_root: Matrix3xX<f64>,
    sole: Matrix6xX<f64>,
    /// CoM Jacobian in the ground frame with the left foot fixed (3 × n).
    com_jacobian: Matrix3xX<f64>,
    root_in_ground: Isometry3<f64>,
}

impl Frame {
    fn new(p: &WholeBody) -> Self {
        let n = p.active.len();
        Frame {
            poses: p.model().pose_buffer(),
            placed: p.collision.placed_bodies(),
            com_root: Matrix3xX::zeros(n),
            sole: Matrix6xX::zeros(n),
            com_jacobian: Matrix3xX::zeros(n),
            root_in_ground: Isometry3::identity(),
        }
    }

    /// FK at `q`; returns the mass and the CoM in the ground frame and fills the Jacobian.
    fn update(&mut self, p: &WholeBody, q: &[f64]) -> (f64, Point3<f64>) {
        p.active.forward_unchecked(q, &mut self.poses);
        let sole_pose = *self.poses.pose(p.feet.0);
        let ground_in_root = sole_pose * p.sole_to_ground;
        self.root_in_ground = ground_in_root.inverse();
        let (mass, c) = p.active.center_of_mass(&self.poses);
        p.active.com_jacobian(&self.poses, &mut self.com_root);
        p.active.jacobian(&self.poses, p.feet.0, &mut self.sole);
        // velocity of the CoM relative to the (fixed) sole: J_c − J_v + [c − o]× J_ω
        let r = c - Point3::from(sole_pose.translation.vector);
        let rot = self.root_in_ground.rotation.to_rotation_matrix();
        for k in 0..self.com_root.ncols() {
            let v = Vector3::new(self.sole[(0, k)], self.sole[(1, k)], self.sole[(2, k)]);
            let w = Vector3::new(self.sole[(3, k)], self.sole[(4, k)], self.sole[(5, k)]);
            let rel = self.com_root.column(k) - v + r.cross(&w);
            self.com_jacobian.set_column(k, &(rot * rel));
        }
        (mass, self.root_in_ground * c)
    }
}
