//! Motion optimisation with goal sets (Gienger et al., Sections III–V): a reaching motion is a
//! short sequence of attractor points in the goal space (hand pose relative to the object:
//! position and rotation vector); a whole-body resolved-rate controller (damped Jacobian
//! pseudo-inverse, joint-limit avoidance in the null space) tracks them; the cost integrates
//! joint-limit proximity, collisions and path length and adds, at the end, either the offset to
//! an exact target or the task-map cost c_map. The attractor points are optimised with iRprop−
//! on central-difference gradients.

use nalgebra::{DMatrix, DVector, Isometry3, Matrix6xX, Vector6};
use trm_collision::{CollisionModel, World};
use trm_kinematics::{ActiveSet, FrameId};
use trm_optim::{Rprop, RpropOptions, Start, StopOptions, by_name, minimize_fn};

use crate::map::{Metric, TaskMap, to_params, to_pose};

/// Where the motion must end.
#[derive(Debug, Clone)]
pub enum MotionGoal<'a> {
    /// One exact hand pose g (in the object frame).
    Target([f64; 6]),
    /// Anywhere on a task map.
    Map(&'a TaskMap),
}

/// Motion settings.
#[derive(Debug, Clone, PartialEq)]
pub struct MotionOptions {
    /// Controller steps.
    pub steps: usize,
    /// Step length, s.
    pub dt: f64,
    /// Tracking gain, 1/s.
    pub gain: f64,
    /// Null-space joint-limit avoidance gain.
    pub limit_gain: f64,
    /// Attractor points.
    pub attractors: usize,
    /// Weights: joint-limit proximity, collisions, path length, end cost.
    pub weights: [f64; 4],
    /// Metric of the goal space (exact-target offsets use it too).
    pub metric: Metric,
}

impl Default for MotionOptions {
    fn default() -> Self {
        MotionOptions {
            steps: 30,
            dt: 0.05,
            gain: 4.0,
            limit_gain: 0.5,
            attractors: 2,
            weights: [1.0, 1.0, 0.1, 100.0],
            metric: Metric::default(),
        }
    }
}

/// One simulated motion.
#[derive(Debug, Clone, PartialEq)]
pub struct Motion {
    /// Total cost.
    pub cost: f64,
    /// Joint-limit proximity (mean over the motion).
    pub limits: f64,
    /// Mean colliding pairs.
    pub collisions: f64,
    /// Joint-space path length.
    pub length: f64,
    /// End cost (offset to the target, or c_map).
    pub end: f64,
    /// Active values at every step.
    pub trajectory: Vec<Vec<f64>>,
    /// Final hand pose in the object frame.
    pub final_pose: [f64; 6],
}

/// A reaching problem: robot, hand frame, object pose, world, start and goal.
pub struct ReachProblem<'a> {
    /// Active motors.
    pub active: &'a ActiveSet,
    /// Collision model.
    pub collision: &'a CollisionModel,
    /// World (the object included, if it should be avoided by the arm).
    pub world: &'a World,
    /// The hand frame.
    pub hand: FrameId,
    /// The object's pose in the world.
    pub object: Isometry3<f64>,
    /// Start (active values).
    pub start: Vec<f64>,
    /// Goal.
    pub goal: MotionGoal<'a>,
    /// Settings.
    pub settings: MotionOptions,
}

fn joint_limit_proximity(q: &[f64], lower: &[f64], upper: &[f64], grad: Option<&mut [f64]>) -> f64 {
    let mut h = 0.0;
    let mut g = grad;
    for i in 0..q.len() {
        let (mid, range) = ((lower[i] + upper[i]) / 2.0, (upper[i] - lower[i]).max(1e-9));
        let u = (q[i] - mid) / range;
        h += u * u;
        if let Some(g) = g.as_deref_mut() {
            g[i] = 2.0 * u / range;
        }
    }
    h / q.len() as f64
}

impl ReachProblem<'_> {
    /// The hand pose in the object frame as goal parameters.
    fn hand_params(&self, poses: &trm_kinematics::PoseBuffer) -> [f64; 6] {
        to_params(&(self.object.inverse() * poses.pose(self.hand)))
    }

    /// Simulates the controller through `attractors` (K × 6 values, goal-space points visited
    /// in order after the start pose).
    pub fn simulate(&self, attractors: &[f64]) -> Motion {
        let s = &self.settings;
        let model = self.active.model();
        let (lower, upper) = self.active.bounds();
        let n = self.active.len();
        let mut poses = model.pose_buffer();
        let mut placed = self.collision.placed_bodies();
        let mut q = self.start.clone();
        let mut jac = Matrix6xX::zeros(n);
        let mut limit_grad = vec![0.0; n];
        let (mut limits, mut collisions, mut length) = (0.0, 0.0, 0.0);
        let mut trajectory = vec![q.clone()];
        self.active.forward_unchecked(&q, &mut poses);
        let start_pose = self.hand_params(&poses);
        let points: Vec<[f64; 6]> = std::iter::once(start_pose)
            .chain(attractors.chunks(6).map(|c| std::array::from_fn(|i| c[i])))
            .collect();
        let segments = (points.len() - 1).max(1) as f64;
        for t in 1..=s.steps {
            // the attractor path, piecewise linear over the motion
            let u = (t as f64 / s.steps as f64 * segments).min(segments - 1e-12);
            let (k, f) = (u.floor() as usize, u.fract());
            let k = k.min(points.len() - 2);
            let target: [f64; 6] =
                std::array::from_fn(|i| points[k][i] + f * (points[k + 1][i] - points[k][i]));
            // task-space error in the world: position and rotation vector
            let want = self.object * to_pose(&target);
            let have = poses.pose(self.hand);
            let dp = want.translation.vector - have.translation.vector;
            let dr = (want.rotation * have.rotation.inverse()).scaled_axis();
            let err = Vector6::new(dp.x, dp.y, dp.z, dr.x, dr.y, dr.z) * s.gain;
            self.active.jacobian(&poses, self.hand, &mut jac);
            let jd = DMatrix::from_iterator(6, n, jac.iter().copied());
            if jd.iter().any(|v| !v.is_finite()) {
                break;
            }
            limits += joint_limit_proximity(&q, &lower, &upper, Some(&mut limit_grad));
            let xi = DVector::from_iterator(n, limit_grad.iter().map(|g| -s.limit_gain * g));
            // resolved rate: q̇ = J⁺ e + (I − J⁺ J) ξ, damped least squares (λ = 0.01)
            let task = [(jd, DVector::from_column_slice(err.as_slice()))];
            let dq = trm_kinematics::ik::prioritised_velocities(&task, &xi, 0.01);
            let previous = q.clone();
            for i in 0..n {
                q[i] = (q[i] + s.dt * dq[i]).clamp(lower[i], upper[i]);
            }
            length += previous
                .iter()
                .zip(&q)
                .map(|(a, b)| (a - b).powi(2))
                .sum::<f64>()
                .sqrt();
            self.active.forward_unchecked(&q, &mut poses);
            self.collision.place(&poses, &mut placed);
            collisions += self.collision.count(&placed, self.world).total() as f64;
            trajectory.push(q.clone());
        }
        let steps = s.steps.max(1) as f64;
        let (limits, collisions) = (limits / steps, collisions / steps);
        let final_pose = self.hand_params(&poses);
        let end = match &self.goal {
            MotionGoal::Target(g) => {
                let d = s.metric.distance(&final_pose, g);
                d * d
            }
            MotionGoal::Map(map) => map.cost(&final_pose).0,
        };
        let w = s.weights;
        Motion {
            cost: w[0] * limits + w[1] * collisions + w[2] * length + w[3] * end,
            limits,
            collisions,
            length,
            end,
            trajectory,
            final_pose,
        }
    }

    /// The attractors a straight reach would use: evenly spaced from the start pose to the goal
    /// (the exact target, or the map point nearest to the start).
    pub fn initial_attractors(&self) -> Vec<f64> {
        let mut poses = self.active.model().pose_buffer();
        self.active.forward_unchecked(&self.start, &mut poses);
        let from = self.hand_params(&poses);
        let to = match &self.goal {
            MotionGoal::Target(g) => *g,
            MotionGoal::Map(map) => map.nearest(&from).map_or(from, |(i, _)| map.points[i].g),
        };
        let k = self.settings.attractors.max(1);
        (1..=k)
            .flat_map(|j| {
                let u = j as f64 / k as f64;
                (0..6).map(move |i| from[i] + u * (to[i] - from[i]))
            })
            .collect()
    }

    /// Optimises the attractors with iRprop− on central-difference gradients (step `h`), for
    /// `iterations`; returns the best motion and the cost trace `(total, joint-limit proximity)`.
    pub fn optimize(&self, iterations: usize, h: f64) -> (Motion, Vec<(f64, f64)>) {
        let x0 = self.initial_attractors();
        let mut rprop = Rprop::new(
            &x0,
            &RpropOptions {
                initial_step: 0.01,
                max_step: 0.1,
                ..Default::default()
            },
        )
        .expect("valid defaults");
        let mut best = self.simulate(&x0);
        let mut trace = vec![(best.cost, best.limits)];
        let mut gradient = vec![0.0; x0.len()];
        for _ in 0..iterations {
            let x = rprop.x().to_vec();
            for i in 0..x.len() {
                let (mut xp, mut xm) = (x.clone(), x.clone());
                xp[i] += h;
                xm[i] -= h;
                gradient[i] = (self.simulate(&xp).cost - self.simulate(&xm).cost) / (2.0 * h);
            }
            rprop.step(&gradient);
            let m = self.simulate(rprop.x());
            if m.cost < best.cost {
                best = m;
            }
            trace.push((best.cost, best.limits));
        }
        (best, trace)
    }

    /// Optimises the attractors with a sampling optimiser of `trm-optim` instead (`algo`, e.g.
    /// `xnes` or `cmaes`; initial step `sigma` in goal-space units), for `evaluations`.
    pub fn optimize_sampling(
        &self,
        algo: &str,
        sigma: f64,
        evaluations: u64,
        seed: u64,
    ) -> trm_optim::Result<Motion> {
        use rand::SeedableRng;
        let start = Start::new(self.initial_attractors(), sigma).with_stop(StopOptions {
            max_evaluations: Some(evaluations),
            ..Default::default()
        });
        let mut optimizer = by_name(algo, &start, None)?;
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
        let report = minimize_fn(optimizer.as_mut(), &mut rng, |x| self.simulate(x).cost);
        let initial = self.simulate(&self.initial_attractors());
        let best = self.simulate(&report.best_x);
        Ok(if best.cost <= initial.cost {
            best
        } else {
            initial
        })
    }
}
