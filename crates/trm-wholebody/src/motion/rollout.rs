//! Rollouts: the prioritised controller run over the motion, every constraint and cost term
//! recorded at every sample.

use crate::WholeBodyError;
use nalgebra::{DMatrix, DVector, Matrix3xX, Vector2};
use serde::{Deserialize, Serialize};
use trm_kinematics::RobotModel;

use crate::Result;
use crate::spec::TrajectorySpec;

use super::*;

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
    /// The motion as a ROS 2 `trajectory_msgs/msg/JointTrajectory` in YAML
    /// ([`trm_kinematics::ros::joint_trajectory_yaml`]): every control step with its joint
    /// positions and velocities. Refuses a rollout holding a non-finite value.
    pub fn to_ros_yaml(&self, model: &RobotModel) -> Result<String, crate::WholeBodyError> {
        trm_kinematics::ros::joint_trajectory_yaml(
            model,
            &self.times,
            &self.q,
            Some(&self.qdot),
            None,
        )
        .map_err(|e| crate::WholeBodyError::Invalid {
            what: "the rollout".into(),
            problem: format!("{e}; not written as ROS YAML"),
        })
    }

    /// The motion as CSV: a header `t,phase,<motor names of model>,com_x,com_z,com_desired_x,
    /// com_desired_z,zmp_x`, then one row per control step (seconds, phase index, motor
    /// positions in rad, CoM, desired CoM and ZMP in m, ground frame). `trm_plan::Trajectory`
    /// reads it back (time and motor columns). A rollout holding a non-finite value (a diverged
    /// simulation) is refused: the reader would refuse the file.
    pub fn to_csv(&self, model: &RobotModel) -> Result<String, crate::WholeBodyError> {
        use std::fmt::Write as _;
        if let Some(i) = (0..self.times.len()).find(|&i| {
            let row = (self.q[i].iter().chain(&self.com[i]))
                .chain(self.com_desired[i].iter().chain(&self.zmp[i]));
            !self.times[i].is_finite() || row.into_iter().any(|v| !v.is_finite())
        }) {
            return Err(crate::WholeBodyError::Invalid {
                what: format!("the rollout at t = {}", self.times[i]),
                problem: "holds a non-finite value; not written as CSV".into(),
            });
        }
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
        Ok(text)
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

impl WholeBody {
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
            let torque = self.static_torques(&frame, locked);
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
        self.add_zmp(&mut out, n, dt);
        out.costs = costs(&out);
        if let (Some((_, target, _)), Some(h)) = (self.reach, out.hand.last()) {
            out.costs.reach = (Vector2::new(h[0], h[2]) - target).norm();
        }
        Ok(out)
    }

    /// The ZMP of the cart-table model at every sample, from the CoM's acceleration (central
    /// differences), with its support-polygon constraints; `fallen` when it leaves the real
    /// polygon.
    fn add_zmp(&self, out: &mut Rollout, n: usize, dt: f64) {
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
            let real = self.real_polygon(self.spec.phases[out.phase[i]].support);
            if zmp[0] < real[0] || zmp[0] > real[1] || zmp[1] < real[2] || zmp[1] > real[3] {
                out.fallen = true;
            }
            out.zmp.push(zmp);
        }
    }

    /// Static torques per motor: the motors hold the robot's weight, ∂(m g z_com)/∂q (legs
    /// resting on the seat, `locked`, carry nothing while it supports them).
    fn static_torques(&self, frame: &Frame, locked: &[bool]) -> Vec<f64> {
        let jn = &frame.com_jacobian;
        (0..self.active.len())
            .map(|k| {
                if locked[k] {
                    0.0
                } else {
                    self.mass * G * jn[(2, k)] / self.joints_per_motor[k]
                }
            })
            .collect()
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
