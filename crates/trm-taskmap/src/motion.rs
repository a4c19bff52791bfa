//! Attractor-based motion optimisation with goal sets (Gienger, Toussaint and Goerick 2008,
//! Sections III–V, after Toussaint, Gienger and Goerick 2007).
//!
//! A reaching motion is K attractor points x*₁…x*_K in a 5-D control task space: the hand's
//! position (root frame) and the polar angles of its grasp axis. An attractor system with a
//! smoothing variable r turns them into a task-space trajectory,
//!
//! ```text
//! r_t = r_{t−1} + λ (x*_{k(t)} − r_{t−1})
//! x_t = x_{t−1} + a (r_t − x_{t−1}) + b (x_{t−1} − x_{t−2})
//! ```
//!
//! (attractor k is active for an equal share of the first T − hold steps, the last one to the
//! end), and a whole-body resolved-rate controller (Liégeois) follows it:
//! q_t = clamp(q_{t−1} + J⁺ (x_t − φ(q_{t−1})) − α (I − J⁺J) ∇H(q_{t−1})), J⁺ damped.
//! The cost sums, over the motion, joint-limit proximity H(q_t), collision proximity
//! Σ ((d_safe − d)/d_safe)² over the body pairs (and body–world pairs) closer than d_safe whose
//! distance the motion can change, the squared joint steps, and, at the end, the hand's squared
//! velocity and the offset to the goal: an exact target, or the nearest grasp of a task map
//! (c_map, eq. 18), compared in the controlled terms (position and grasp axis).
//!
//! The gradient with respect to all attractor points is analytic and O(T) (eq. 1): a forward
//! pass stores each step's Jacobians and its exact derivative ∂q_t/∂q_{t−1} (the change of J⁺
//! and of the null-space term with q included, from the kinematic Hessian
//! [`ActiveSet::jacobian_derivatives`]); a backward pass propagates dC/dq_t to dC/dx_t through
//! J⁺ (so a cost on the hand pose reaches the 5-D control task as in eq. 20–21) and through the
//! attractor dynamics to the attractors. [`ReachProblem::numerical_gradient`] (central
//! differences) is the test oracle. The attractors are optimised with iRprop−.

use nalgebra::{DMatrix, DVector, Isometry3, Matrix3xX, Matrix6xX, Point3, Vector3, Vector5};
use trm_collision::{CollisionModel, NearPair, Shape, World};
use trm_kinematics::{ActiveSet, FrameId, PoseBuffer};
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

/// Weights of the cost terms.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CostWeights {
    /// Joint-limit proximity H, averaged over the motion.
    pub joint_limits: f64,
    /// Collision proximity Σ ((d_safe − d)/d_safe)², averaged over the motion.
    pub proximity: f64,
    /// Squared joint steps Σ ‖q_t − q_{t−1}‖².
    pub path: f64,
    /// Squared hand speed at the end, (m/s)².
    pub end_velocity: f64,
    /// End cost: offset to the target, or c_map.
    pub end: f64,
}

impl Default for CostWeights {
    fn default() -> Self {
        CostWeights {
            joint_limits: 10.0,
            proximity: 10.0,
            path: 1.0,
            end_velocity: 0.01,
            end: 100.0,
        }
    }
}

/// Motion settings.
#[derive(Debug, Clone, PartialEq)]
pub struct MotionOptions {
    /// Time steps T.
    pub steps: usize,
    /// Step length, s (for the end velocity).
    pub dt: f64,
    /// Attractor points K (the paper uses 12).
    pub attractors: usize,
    /// Steps at the end during which the last attractor holds (the rest are shared evenly).
    pub hold: usize,
    /// Attractor gain a.
    pub gain: f64,
    /// Velocity carry-over b.
    pub carry: f64,
    /// Smoothing rate λ of r.
    pub smoothing: f64,
    /// Null-space joint-limit avoidance step α.
    pub limit_gain: f64,
    /// Damping of the pseudo-inverse.
    pub damping: f64,
    /// Distance below which body pairs cost, m.
    pub safety_distance: f64,
    /// Cost weights.
    pub weights: CostWeights,
    /// Metric of the goal space (exact-target offsets use it too).
    pub metric: Metric,
}

impl Default for MotionOptions {
    fn default() -> Self {
        MotionOptions {
            steps: 60,
            dt: 0.05,
            attractors: 12,
            hold: 12,
            gain: 0.2,
            carry: 0.3,
            smoothing: 0.5,
            limit_gain: 0.05,
            damping: 0.01,
            safety_distance: 0.04,
            weights: CostWeights::default(),
            metric: Metric::default(),
        }
    }
}

/// One simulated motion.
#[derive(Debug, Clone, PartialEq)]
pub struct Motion {
    /// Total cost.
    pub cost: f64,
    /// Joint-limit proximity H (mean over the motion; the paper's "integral joint-limit cost").
    pub limits: f64,
    /// Collision proximity (mean over the motion).
    pub proximity: f64,
    /// Smallest signed distance of any pair closer than d_safe (d_safe when none came closer).
    pub min_distance: f64,
    /// Steps at which some pair overlapped.
    pub collisions: usize,
    /// Joint-space path length, rad.
    pub length: f64,
    /// Hand speed at the end, m/s.
    pub end_speed: f64,
    /// End cost (offset to the target, or c_map).
    pub end: f64,
    /// Active values at every step (T + 1 rows).
    pub trajectory: Vec<Vec<f64>>,
    /// The attractor system's task-space path x_0…x_T (5-D).
    pub task_path: Vec<[f64; 5]>,
    /// Final hand pose in the object frame.
    pub final_pose: [f64; 6],
}

impl Motion {
    /// A motion standing at `q` (task point `x`), no cost yet; `clearance` is the closest
    /// approach counted from.
    fn at(q: Vec<f64>, x: [f64; 5], clearance: f64) -> Self {
        Motion {
            cost: 0.0,
            limits: 0.0,
            proximity: 0.0,
            min_distance: clearance,
            collisions: 0,
            length: 0.0,
            end_speed: 0.0,
            end: 0.0,
            trajectory: vec![q],
            task_path: vec![x],
            final_pose: [0.0; 6],
        }
    }
}

/// A reaching problem: robot, hand frame and grasp axis, object pose, world, start and goal.
pub struct ReachProblem<'a> {
    /// Active motors.
    pub active: &'a ActiveSet,
    /// Collision model.
    pub collision: &'a CollisionModel,
    /// Obstacles (the table, the basket's body); body pairs and body–object pairs closer than
    /// the safety distance cost.
    pub world: &'a World,
    /// The hand frame.
    pub hand: FrameId,
    /// The grasp axis in the hand frame (unit): its polar angles are the control task's last two
    /// coordinates; see [`grasp_axis`].
    pub grasp_axis: Vector3<f64>,
    /// The object's pose in the world.
    pub object: Isometry3<f64>,
    /// Start (active values).
    pub start: Vec<f64>,
    /// Goal.
    pub goal: MotionGoal<'a>,
    /// Settings.
    pub settings: MotionOptions,
}

/// The hand-frame grasp axis of a task map: at every map grasp, the axis of the object part
/// nearest the hand (a capsule's or cylinder's axis, a box's longest edge) seen from the hand,
/// averaged with consistent signs. `object` holds the parts in the object's frame. `None` when
/// the map is empty or no part has an axis.
pub fn grasp_axis(map: &TaskMap, object: &World) -> Option<Vector3<f64>> {
    let parts: Vec<(Point3<f64>, Vector3<f64>)> = object
        .objects()
        .iter()
        .filter_map(|o| {
            let local = match o.shape() {
                Shape::Capsule { .. } | Shape::Cylinder { .. } => Vector3::z(),
                Shape::Box { size } => {
                    let i = (0..3).max_by(|&a, &b| size[a].total_cmp(&size[b]))?;
                    Vector3::ith(i, 1.0)
                }
                _ => return None,
            };
            Some((
                Point3::from(o.pose().translation.vector),
                o.pose().rotation * local,
            ))
        })
        .collect();
    let mut sum = Vector3::zeros();
    for p in &map.points {
        let pose = to_pose(&p.g);
        let at = Point3::from(pose.translation.vector);
        let (_, axis) = parts
            .iter()
            .min_by(|a, b| (a.0 - at).norm().total_cmp(&(b.0 - at).norm()))?;
        let in_hand = pose.rotation.inverse() * axis;
        sum += if sum.dot(&in_hand) < 0.0 {
            -in_hand
        } else {
            in_hand
        };
    }
    sum.try_normalize(1e-12)
}

/// Polar angles of a unit axis about the root's x axis: θ from x, ψ about x (0 along z).
fn polar(a: &Vector3<f64>) -> [f64; 2] {
    [a.x.clamp(-1.0, 1.0).acos(), a.y.atan2(a.z)]
}

/// The angle wrapped into (−π, π].
fn wrap(angle: f64) -> f64 {
    let w = angle.rem_euclid(std::f64::consts::TAU);
    if w > std::f64::consts::PI {
        w - std::f64::consts::TAU
    } else {
        w
    }
}

/// Per-step quantities the backward pass needs.
/// The end cost's derivatives at the final posture: the hand's end velocity (whose square is
/// penalised) and the end cost's gradient in the hand's position and orientation.
struct EndGradient {
    velocity: Vector3<f64>,
    position: Vector3<f64>,
    orientation: Vector3<f64>,
}

struct Step {
    /// Control-task Jacobian at q_{t−1} (5 × n).
    jacobian: DMatrix<f64>,
    /// Its damped pseudo-inverse (n × 5).
    pinv: DMatrix<f64>,
    /// 1 where q_t was not clamped to a limit.
    free: Vec<f64>,
    /// ∂q_t/∂q_{t−1} (n × n), exact: the change of J⁺ with q included.
    step: DMatrix<f64>,
    /// ∂C/∂q_t of the terms that depend on q_t alone.
    direct: DVector<f64>,
}

/// Takes `q` by `dq`, each value clamped to its limits; returns 1 per value left free (0 where
/// clamped) and the step's squared length.
fn clamped_step(q: &mut [f64], dq: &[f64], lower: &[f64], upper: &[f64]) -> (Vec<f64>, f64) {
    let mut free = vec![1.0; q.len()];
    let mut step_sq = 0.0;
    for i in 0..q.len() {
        let v = q[i] + dq[i];
        let c = v.clamp(lower[i], upper[i]);
        if c != v {
            free[i] = 0.0;
        }
        step_sq += (c - q[i]).powi(2);
        q[i] = c;
    }
    (free, step_sq)
}

/// Joint-limit proximity H(q) = (1/n) Σ ((q − mid)/range)², its gradient and its (diagonal)
/// Hessian.
fn joint_limits(q: &[f64], lower: &[f64], upper: &[f64]) -> (f64, DVector<f64>, DVector<f64>) {
    let n = q.len() as f64;
    let mut h = 0.0;
    let mut grad = DVector::zeros(q.len());
    let mut hess = DVector::zeros(q.len());
    for i in 0..q.len() {
        let (mid, range) = ((lower[i] + upper[i]) / 2.0, (upper[i] - lower[i]).max(1e-9));
        let u = (q[i] - mid) / range;
        h += u * u / n;
        grad[i] = 2.0 * u / range / n;
        hess[i] = 2.0 / (range * range) / n;
    }
    (h, grad, hess)
}

impl ReachProblem<'_> {
    /// The hand pose in the object frame as goal parameters.
    fn hand_params(&self, poses: &PoseBuffer) -> [f64; 6] {
        to_params(&(self.object.inverse() * poses.pose(self.hand)))
    }

    /// For every collision body, which active values move it: bodies moved by the same set are
    /// rigidly joined while the others hold still, so their distance cannot change and does not
    /// cost (nor do world objects near bodies nothing moves).
    fn movers(&self, poses: &PoseBuffer) -> Vec<Vec<bool>> {
        let mut jac = Matrix3xX::zeros(self.active.len());
        self.collision
            .bodies()
            .iter()
            .map(|b| {
                let origin = Point3::from(poses.poses()[b.link].translation.vector);
                let mut moved = vec![false; self.active.len()];
                // three points that are not on one line: one of them is off any joint axis
                for offset in [Vector3::zeros(), Vector3::x() * 0.1, Vector3::y() * 0.1] {
                    self.active
                        .point_jacobian(poses, b.link, &(origin + offset), &mut jac);
                    for (k, m) in moved.iter_mut().enumerate() {
                        *m |= jac.column(k).norm() > 1e-12;
                    }
                }
                moved
            })
            .collect()
    }

    /// The control task φ(q) of a hand pose: position and the grasp axis's polar angles.
    fn control(&self, hand: &Isometry3<f64>) -> [f64; 5] {
        let p = hand.translation.vector;
        let [theta, psi] = polar(&(hand.rotation * self.grasp_axis));
        [p.x, p.y, p.z, theta, psi]
    }

    /// The 5 × n control-task Jacobian from the hand's 6 × n geometric Jacobian.
    fn control_jacobian(&self, hand: &Isometry3<f64>, jac: &Matrix6xX<f64>) -> DMatrix<f64> {
        let n = jac.ncols();
        let a = hand.rotation * self.grasp_axis;
        let mut out = DMatrix::zeros(5, n);
        let sin_theta = (1.0 - a.x * a.x).max(1e-12).sqrt();
        let ring = (a.y * a.y + a.z * a.z).max(1e-12);
        for c in 0..n {
            let w = Vector3::new(jac[(3, c)], jac[(4, c)], jac[(5, c)]);
            let da = w.cross(&a);
            for r in 0..3 {
                out[(r, c)] = jac[(r, c)];
            }
            out[(3, c)] = -da.x / sin_theta;
            out[(4, c)] = (a.z * da.y - a.y * da.z) / ring;
        }
        out
    }

    /// ∂/∂q_k of the control-task Jacobian, from the hand's Jacobian and its derivative
    /// ∂J/∂q_k.
    fn control_jacobian_derivative(
        &self,
        hand: &Isometry3<f64>,
        jac: &Matrix6xX<f64>,
        djac: &Matrix6xX<f64>,
        k: usize,
    ) -> DMatrix<f64> {
        let n = jac.ncols();
        let omega = |m: &Matrix6xX<f64>, c: usize| Vector3::new(m[(3, c)], m[(4, c)], m[(5, c)]);
        let a = hand.rotation * self.grasp_axis;
        let da = omega(jac, k).cross(&a);
        let s = (1.0 - a.x * a.x).max(1e-12).sqrt();
        let ds = -a.x * da.x / s;
        let ring = (a.y * a.y + a.z * a.z).max(1e-12);
        let d_ring = 2.0 * (a.y * da.y + a.z * da.z);
        let mut out = DMatrix::zeros(5, n);
        for c in 0..n {
            let d = omega(jac, c).cross(&a);
            let dd = omega(djac, c).cross(&a) + omega(jac, c).cross(&da);
            for r in 0..3 {
                out[(r, c)] = djac[(r, c)];
            }
            out[(3, c)] = -dd.x / s + d.x * ds / (s * s);
            let num = a.z * d.y - a.y * d.z;
            let d_num = da.z * d.y + a.z * dd.y - da.y * d.z - a.y * dd.z;
            out[(4, c)] = d_num / ring - num * d_ring / (ring * ring);
        }
        out
    }

    /// The control task of a goal pose g (object frame).
    fn control_of_goal(&self, g: &[f64; 6]) -> [f64; 5] {
        self.control(&(self.object * to_pose(g)))
    }

    /// Where the initial attractors lead: the exact target, or (as the paper initialises its
    /// basket runs) the map's grasp nearest the object's centre.
    fn goal_pose(&self) -> [f64; 6] {
        match &self.goal {
            MotionGoal::Target(g) => *g,
            MotionGoal::Map(map) => map.center_grasp().unwrap_or([0.0; 6]),
        }
    }

    /// The paper's initialisation: K attractor points linearly interpolated from the start's
    /// control task to the goal's (the exact target, or the map's grasp nearest the object's
    /// centre).
    pub fn initial_attractors(&self) -> Vec<f64> {
        let mut poses = self.active.model().pose_buffer();
        self.active.forward_unchecked(&self.start, &mut poses);
        let from = self.control(poses.pose(self.hand));
        let mut to = self.control_of_goal(&self.goal_pose());
        to[4] = from[4] + wrap(to[4] - from[4]);
        let k = self.settings.attractors.max(1);
        (1..=k)
            .flat_map(|j| {
                let u = j as f64 / k as f64;
                (0..5).map(move |i| from[i] + u * (to[i] - from[i]))
            })
            .collect()
    }

    /// Index of the attractor active at step `t` (1-based).
    fn attractor_at(&self, t: usize) -> usize {
        let s = &self.settings;
        let k = s.attractors.max(1);
        let moving = s.steps.saturating_sub(s.hold).max(1);
        ((t - 1) * k / moving).min(k - 1)
    }

    /// Simulates the motion the attractors (K × 5 values) produce.
    pub fn simulate(&self, attractors: &[f64]) -> Motion {
        self.run(attractors, false).0
    }

    /// The motion and the analytic gradient of its cost with respect to the attractors.
    pub fn gradient(&self, attractors: &[f64]) -> (Motion, Vec<f64>) {
        let (m, g) = self.run(attractors, true);
        (m, g.unwrap_or_default())
    }

    /// Central-difference gradient (step `h`): the oracle the analytic gradient is tested
    /// against.
    pub fn numerical_gradient(&self, attractors: &[f64], h: f64) -> Vec<f64> {
        (0..attractors.len())
            .map(|i| {
                let (mut xp, mut xm) = (attractors.to_vec(), attractors.to_vec());
                xp[i] += h;
                xm[i] -= h;
                (self.simulate(&xp).cost - self.simulate(&xm).cost) / (2.0 * h)
            })
            .collect()
    }

    /// The end cost of a final hand pose (world) and its gradients with respect to the hand's
    /// position and to a small rotation ω of the hand (world frame), in the controlled task's
    /// terms: W-weighted squared offsets of the position and of the grasp axis (chordal, ≈ the
    /// angle) from the exact target, or from the nearest task-map grasp (c_map, eq. 18, with the
    /// map's metric). The roll about the grasp axis, which the 5-D controller leaves free, is
    /// not compared.
    fn end_cost(&self, hand: &Isometry3<f64>) -> (f64, Vector3<f64>, Vector3<f64>) {
        let (goals, metric): (Box<dyn Iterator<Item = &[f64; 6]>>, _) = match &self.goal {
            MotionGoal::Target(g) => (Box::new(std::iter::once(g)), self.settings.metric),
            MotionGoal::Map(map) => (Box::new(map.points.iter().map(|p| &p.g)), map.metric),
        };
        let a = hand.rotation * self.grasp_axis;
        let offsets = |g: &[f64; 6]| {
            let want = self.object * to_pose(g);
            (
                hand.translation.vector - want.translation.vector,
                a - want.rotation * self.grasp_axis,
            )
        };
        let cost = |(dp, da): &(Vector3<f64>, Vector3<f64>)| {
            metric.position * dp.norm_squared() + metric.orientation * da.norm_squared()
        };
        goals
            .map(offsets)
            .map(|o| (cost(&o), o))
            .min_by(|x, y| x.0.total_cmp(&y.0))
            .map_or(
                (f64::INFINITY, Vector3::zeros(), Vector3::zeros()),
                |(c, (dp, da))| {
                    (
                        c,
                        2.0 * metric.position * dp,
                        2.0 * metric.orientation * a.cross(&da),
                    )
                },
            )
    }

    /// Forward pass (and, with `backward`, the backward pass).
    fn run(&self, attractors: &[f64], backward: bool) -> (Motion, Option<Vec<f64>>) {
        let s = &self.settings;
        let w = &s.weights;
        let model = self.active.model();
        let (lower, upper) = self.active.bounds();
        let n = self.active.len();
        let steps = s.steps.max(1);
        let per_step = 1.0 / steps as f64;
        let mut poses = model.pose_buffer();
        let mut placed = self.collision.placed_bodies();
        let mut q = self.start.clone();
        let mut jac = Matrix6xX::zeros(n);
        let mut point_jac = Matrix3xX::zeros(n);
        let mut other_jac = Matrix3xX::zeros(n);
        let mut djac = Vec::new();
        let mut near: Vec<NearPair> = Vec::new();
        self.active.forward_unchecked(&q, &mut poses);
        let movers = self.movers(&poses);
        let x0 = Vector5::from(self.control(poses.pose(self.hand)));
        let points: Vec<Vector5<f64>> = attractors
            .chunks(5)
            .map(|c| Vector5::from_fn(|i, _| c.get(i).copied().unwrap_or(0.0)))
            .collect();
        let (mut r, mut x, mut x_prev) = (x0, x0, x0);
        let mut m = Motion::at(q.clone(), x0.into(), s.safety_distance);
        let mut path_cost = 0.0;
        let mut record: Vec<Step> = Vec::with_capacity(if backward { steps } else { 0 });
        let mut hand_before = poses.pose(self.hand).translation.vector;
        for t in 1..=steps {
            // attractor dynamics
            let target = points.get(self.attractor_at(t)).copied().unwrap_or(x0);
            r += s.smoothing * (target - r);
            let next = x + s.gain * (r - x) + s.carry * (x - x_prev);
            (x_prev, x) = (x, next);
            // resolved-rate step towards x_t from q_{t−1}
            let hand = *poses.pose(self.hand);
            self.active.jacobian(&poses, self.hand, &mut jac);
            let j = self.control_jacobian(&hand, &jac);
            let gram = &j * j.transpose() + DMatrix::identity(5, 5) * (s.damping * s.damping);
            let Some(gram_inv) = gram
                .try_inverse()
                .filter(|g| g.iter().all(|v| v.is_finite()))
            else {
                break;
            };
            let pinv = j.transpose() * &gram_inv;
            let mut e = x - Vector5::from(self.control(&hand));
            e[4] = wrap(e[4]);
            let e = DVector::from_column_slice(e.as_slice());
            let (_, limit_grad, limit_hess) = joint_limits(&q, &lower, &upper);
            let null_step = &limit_grad - &pinv * (&j * &limit_grad);
            let dq = &pinv * &e - s.limit_gain * null_step;
            // ∂/∂q_{t−1} of q_{t−1} + J⁺ e − α (I − J⁺J) ∇H, column by column
            let mut step_derivative = DMatrix::zeros(if backward { n } else { 0 }, n);
            if backward {
                let limits = (&limit_grad, &limit_hess);
                let solve = (&j, &pinv, &gram_inv, &e);
                step_derivative = self.step_derivative(&poses, &jac, &mut djac, solve, limits);
            }
            hand_before = hand.translation.vector;
            let (free, step_sq) = clamped_step(&mut q, dq.as_slice(), &lower, &upper);
            m.length += step_sq.sqrt();
            path_cost += step_sq;
            self.active.forward_unchecked(&q, &mut poses);
            self.collision.place(&poses, &mut placed);
            // costs of q_t
            let (h, h_grad, _) = joint_limits(&q, &lower, &upper);
            m.limits += h * per_step;
            let mut direct = h_grad * (w.joint_limits * per_step);
            self.collision
                .near_pairs(&placed, self.world, s.safety_distance, &mut near);
            let mut overlapping = false;
            for pair in near.iter().filter(|p| {
                if p.is_object {
                    movers[p.body].iter().any(|&m| m)
                } else {
                    movers[p.body] != movers[p.other]
                }
            }) {
                let gap = (s.safety_distance - pair.distance) / s.safety_distance;
                m.proximity += gap * gap * per_step;
                m.min_distance = m.min_distance.min(pair.distance);
                overlapping |= pair.distance < 0.0;
                if backward {
                    // dd/dq = nᵀ (J_other − J_body): the other moving along n opens the gap
                    let bodies = self.collision.bodies();
                    self.active.point_jacobian(
                        &poses,
                        bodies[pair.body].link,
                        &pair.point,
                        &mut point_jac,
                    );
                    let mut dd = -(point_jac.transpose() * pair.normal);
                    if !pair.is_object {
                        self.active.point_jacobian(
                            &poses,
                            bodies[pair.other].link,
                            &pair.other_point,
                            &mut other_jac,
                        );
                        dd += other_jac.transpose() * pair.normal;
                    }
                    let dc_dd = -2.0 * gap / s.safety_distance * w.proximity * per_step;
                    direct.axpy(dc_dd, &dd, 1.0);
                }
            }
            m.collisions += usize::from(overlapping);
            m.trajectory.push(q.clone());
            m.task_path.push(x.into());
            if backward {
                for (k, f) in free.iter().enumerate() {
                    if *f == 0.0 {
                        step_derivative.row_mut(k).fill(0.0);
                    }
                }
                record.push(Step {
                    jacobian: j,
                    pinv,
                    free,
                    step: step_derivative,
                    direct,
                });
            }
        }
        // end terms
        let hand = *poses.pose(self.hand);
        m.final_pose = self.hand_params(&poses);
        let (end, gp, go) = self.end_cost(&hand);
        m.end = end;
        let velocity = (hand.translation.vector - hand_before) / s.dt;
        m.end_speed = velocity.norm();
        m.cost = w.joint_limits * m.limits
            + w.proximity * m.proximity
            + w.path * path_cost
            + w.end_velocity * velocity.norm_squared()
            + w.end * end;
        if !backward || record.len() != steps {
            return (m, None);
        }
        let end = EndGradient {
            velocity,
            position: gp,
            orientation: go,
        };
        let grad = self.backward(&mut record, &poses, &end, &m.trajectory, attractors.len());
        (m, Some(grad))
    }

    /// ∂q_t/∂q_{t−1} of the resolved-rate step q_{t−1} + J⁺ e − α (I − J⁺J) ∇H, the change of
    /// J⁺ with q included (`solve`: J, J⁺, (JJᵀ + λ²I)⁻¹ and e; `limits`: ∇H and H's diagonal
    /// Hessian), at the poses of q_{t−1} with the hand Jacobian `jac`.
    fn step_derivative(
        &self,
        poses: &PoseBuffer,
        jac: &Matrix6xX<f64>,
        djac: &mut Vec<Matrix6xX<f64>>,
        solve: (&DMatrix<f64>, &DMatrix<f64>, &DMatrix<f64>, &DVector<f64>),
        limits: (&DVector<f64>, &DVector<f64>),
    ) -> DMatrix<f64> {
        let (s, n) = (&self.settings, self.active.len());
        let ((j, pinv, gram_inv, e), (limit_grad, limit_hess)) = (solve, limits);
        let hand = *poses.pose(self.hand);
        let mut derivative = DMatrix::zeros(n, n);
        self.active.jacobian_derivatives(poses, self.hand, djac);
        let (jg, pj_cols) = (j * limit_grad, pinv * j);
        for k in 0..n {
            let dj = self.control_jacobian_derivative(&hand, jac, &djac[k], k);
            let dp = dj.transpose() * gram_inv
                - pinv * (&dj * j.transpose() + j * dj.transpose()) * gram_inv;
            let dn_g = -(&dp * &jg + pinv * (&dj * limit_grad));
            let mut col = &dp * e - pj_cols.column(k);
            col -= s.limit_gain * dn_g;
            col -= (s.limit_gain * limit_hess[k]) * (-pj_cols.column(k));
            col[k] += 1.0 - s.limit_gain * limit_hess[k];
            derivative.set_column(k, &col);
        }
        derivative
    }

    /// The backward pass of [`ReachProblem::run`]: the cost's gradient with respect to the
    /// attractors (`attractors` values), from the forward pass's `record` of a full motion, its
    /// `trajectory`, the final `poses` and the end cost's derivatives `end`.
    fn backward(
        &self,
        record: &mut [Step],
        poses: &PoseBuffer,
        end: &EndGradient,
        trajectory: &[Vec<f64>],
        attractors: usize,
    ) -> Vec<f64> {
        // ∂/∂q_T of the end cost (eq. 20–21 continue through J⁺ in the backward pass)
        let (s, n, steps) = (&self.settings, self.active.len(), record.len());
        let w = &s.weights;
        let mut jac = Matrix6xX::zeros(n);
        self.active.jacobian(poses, self.hand, &mut jac);
        let v_grad = end.velocity * (2.0 * w.end_velocity / s.dt);
        let last = record.len() - 1;
        for c in 0..n {
            let jv = Vector3::new(jac[(0, c)], jac[(1, c)], jac[(2, c)]);
            let jw = Vector3::new(jac[(3, c)], jac[(4, c)], jac[(5, c)]);
            record[last].direct[c] +=
                w.end * (end.position.dot(&jv) + end.orientation.dot(&jw)) + v_grad.dot(&jv);
            // the hand velocity's other end, q_{T−1}: its Jacobian's position rows
            if last > 0 {
                let jp = &record[last].jacobian;
                record[last - 1].direct[c] -=
                    v_grad.x * jp[(0, c)] + v_grad.y * jp[(1, c)] + v_grad.z * jp[(2, c)];
            }
        }
        // backward pass: Q_t = dC/dq_t, X_t = dC/dx_t, R_t = dC/dr_t
        let (a, b, lambda) = (s.gain, s.carry, s.smoothing);
        let mut q_bar = DVector::<f64>::zeros(n);
        let mut x_bar = vec![Vector5::<f64>::zeros(); steps + 2];
        let mut grad = vec![0.0; attractors];
        let traj = trajectory;
        for t in (1..=steps).rev() {
            let step = &record[t - 1];
            // direct terms, the path term's two ends, and what q_{t+1} passes back
            let mut qt = step.direct.clone();
            for i in 0..n {
                qt[i] += 2.0 * w.path * (traj[t][i] - traj[t - 1][i]);
                if t < steps {
                    qt[i] -= 2.0 * w.path * (traj[t + 1][i] - traj[t][i]);
                }
            }
            if t < steps {
                qt += record[t].step.transpose() * &q_bar;
            }
            q_bar = qt;
            // ∂q_t/∂x_t = M J⁺
            let masked = q_bar.component_mul(&DVector::from_column_slice(&step.free));
            let direct_x = step.pinv.transpose() * masked;
            x_bar[t] = Vector5::from_column_slice(direct_x.as_slice())
                + (1.0 + b - a) * x_bar[t + 1]
                - b * x_bar.get(t + 2).copied().unwrap_or_default();
        }
        // r: R_t = a X_t + (1 − λ) R_{t+1}; dC/dx*_k = Σ_{k(t) = k} λ R_t
        let mut r_bar = Vector5::<f64>::zeros();
        for t in (1..=steps).rev() {
            r_bar = a * x_bar[t] + (1.0 - lambda) * r_bar;
            let k = self.attractor_at(t);
            if let Some(g) = grad.get_mut(5 * k..5 * k + 5) {
                for i in 0..5 {
                    g[i] += lambda * r_bar[i];
                }
            }
        }
        grad
    }

    /// Optimises the attractors with iRprop− on the analytic gradient for `iterations`; returns
    /// the best motion and the trace `(total cost, joint-limit cost)` of the best so far.
    pub fn optimize(&self, iterations: usize) -> (Motion, Vec<(f64, f64)>) {
        self.optimize_with(iterations, |x| self.gradient(x))
    }

    /// As [`ReachProblem::optimize`], on central-difference gradients (step `h`): slower, for
    /// comparison.
    pub fn optimize_numerically(&self, iterations: usize, h: f64) -> (Motion, Vec<(f64, f64)>) {
        self.optimize_with(iterations, |x| {
            (self.simulate(x), self.numerical_gradient(x, h))
        })
    }

    fn optimize_with(
        &self,
        iterations: usize,
        mut gradient: impl FnMut(&[f64]) -> (Motion, Vec<f64>),
    ) -> (Motion, Vec<(f64, f64)>) {
        let x0 = self.initial_attractors();
        let (mut best, mut g) = gradient(&x0);
        let mut trace = vec![(best.cost, best.limits)];
        let settings = RpropOptions {
            initial_step: 0.01,
            max_step: 0.1,
            ..Default::default()
        };
        // the settings are valid; only a non-finite start (from a non-finite `start`) fails:
        // nothing to optimise then
        let Ok(mut rprop) = Rprop::new(&x0, &settings) else {
            return (best, trace);
        };
        for _ in 0..iterations {
            rprop.step(&g);
            let (m, next) = gradient(rprop.x());
            g = next;
            if m.cost < best.cost {
                best = m;
            }
            trace.push((best.cost, best.limits));
        }
        (best, trace)
    }

    /// Optimises the attractors with a sampling optimiser of `trm-optim` instead (`algo`, e.g.
    /// `xnes` or `cmaes`; initial step `sigma` in task-space units), for `evaluations`.
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
