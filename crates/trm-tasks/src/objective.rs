//! The weighted objective h = Σ aᵢ hᵢ, evaluated from one forward-kinematics pass per candidate,
//! optionally averaged over Gaussian noise on q (robust postures).

use std::sync::Arc;

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};
use trm_collision::{CollisionModel, PlacedBodies, World};
use trm_kinematics::{ActiveSet, LANES, PoseBatch, PoseBuffer};

use crate::context::Context;
use crate::costs::{Cost, TaskTarget};
use crate::error::{Result, TaskError};
use crate::tasks::TaskFunction;

/// A weighted term (costs are shared between clones of an objective: they hold no state).
#[derive(Debug, Clone)]
struct Term {
    weight: f64,
    cost: Arc<dyn Cost>,
}

/// One term's share of a cost.
#[derive(Debug, Clone, PartialEq)]
pub struct TermValue {
    /// The term's label.
    pub label: String,
    /// Its weight aᵢ.
    pub weight: f64,
    /// Its value hᵢ (unweighted).
    pub value: f64,
}

/// The objective of NGIK: robot (active motors), collision geometry, world, weighted costs and
/// an optional task function. `Sync`: share it between threads, give each a [`Scratch`]. Clones
/// share the costs.
#[derive(Debug, Clone)]
pub struct Objective {
    active: ActiveSet,
    collision: CollisionModel,
    world: World,
    terms: Vec<Term>,
    task: Option<Arc<dyn TaskFunction>>,
    /// Noise offsets of the robust objective (common random numbers, drawn once).
    noise: Vec<Vec<f64>>,
    needs_collision: bool,
}

/// Per-thread buffers for evaluating an [`Objective`], one candidate or a batch at a time.
#[derive(Debug, Clone)]
pub struct Scratch {
    poses: PoseBuffer,
    placed: PlacedBodies,
    noisy: Vec<f64>,
    /// Batched evaluation: the poses of [`LANES`] candidates, their values one after the
    /// other, and every candidate's noisy copies.
    batch: PoseBatch,
    lanes: Vec<f64>,
    noisy_batch: Vec<f64>,
    noisy_owner: Vec<usize>,
}

impl Objective {
    /// An objective without terms over `active`'s variables.
    pub fn new(active: ActiveSet, collision: CollisionModel, world: World) -> Self {
        Objective {
            active,
            collision,
            world,
            terms: Vec::new(),
            task: None,
            noise: Vec::new(),
            needs_collision: false,
        }
    }

    /// The same objective in another world (builder form of [`Objective::set_world`]).
    pub fn with_world(mut self, world: World) -> Self {
        self.world = world;
        self
    }

    /// Replaces the world the collision and world-dependent costs see.
    pub fn set_world(&mut self, world: World) {
        self.world = world;
    }

    /// Adds a term `weight · cost` (weight finite and ≥ 0).
    pub fn add(&mut self, weight: f64, cost: Box<dyn Cost>) -> Result<()> {
        if !(weight.is_finite() && weight >= 0.0) {
            return Err(TaskError::Invalid {
                what: format!("weight of `{}`", cost.label()),
                problem: format!("{weight} is not a finite number ≥ 0"),
            });
        }
        self.needs_collision |= cost.needs_collision();
        self.terms.push(Term {
            weight,
            cost: Arc::from(cost),
        });
        Ok(())
    }

    /// Sets the task function.
    pub fn set_task(&mut self, task: Box<dyn TaskFunction>) {
        self.task = Some(Arc::from(task));
    }

    /// A copy of this objective with one more term, `weight` · ‖g(q) − `target`‖ (g = the task
    /// function): the same costs, pulled to an exact task-space point (for finishing a planned
    /// path at its goal rather than at the nearest map node).
    pub fn with_task_target(&self, target: &[f64], weight: f64) -> Result<Objective> {
        let Some(task) = &self.task else {
            return Err(TaskError::Invalid {
                what: "task target".into(),
                problem: "the objective has no task function".into(),
            });
        };
        let cost = TaskTarget::new(task.clone(), target)?;
        let mut out = self.clone();
        out.add(weight, Box::new(cost))?;
        Ok(out)
    }

    /// Makes the objective the mean over `samples` copies of q perturbed by N(0, σ²) noise
    /// (drawn once from `seed`: every candidate sees the same offsets, so the objective stays
    /// deterministic). `samples = 0` turns it off.
    pub fn set_noise(&mut self, samples: usize, sigma: f64, seed: u64) -> Result<()> {
        let normal = Normal::new(0.0, sigma).map_err(|_| TaskError::Invalid {
            what: "noise sigma".into(),
            problem: format!("{sigma} is not a finite number ≥ 0"),
        })?;
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        self.noise = (0..samples)
            .map(|_| (0..self.dim()).map(|_| normal.sample(&mut rng)).collect())
            .collect();
        Ok(())
    }

    /// Number of variables (active motors).
    pub fn dim(&self) -> usize {
        self.active.len()
    }

    /// The active motors.
    pub fn active(&self) -> &ActiveSet {
        &self.active
    }

    /// The collision model.
    pub fn collision(&self) -> &CollisionModel {
        &self.collision
    }

    /// The world.
    pub fn world(&self) -> &World {
        &self.world
    }

    /// The task function, if any.
    pub fn task(&self) -> Option<&dyn TaskFunction> {
        self.task.as_deref()
    }

    /// Number of terms.
    pub fn num_terms(&self) -> usize {
        self.terms.len()
    }

    /// Buffers for one thread.
    pub fn scratch(&self) -> Scratch {
        Scratch {
            poses: self.active.model().pose_buffer(),
            placed: self.collision.placed_bodies(),
            noisy: vec![0.0; self.dim()],
            batch: self.active.model().pose_batch(),
            lanes: vec![0.0; LANES * self.dim()],
            noisy_batch: Vec::new(),
            noisy_owner: Vec::new(),
        }
    }

    /// Whether `scratch` has this objective's sizes (poses, bodies, variables), so that a
    /// scratch kept from an earlier call can serve it: evaluations overwrite everything else.
    pub fn scratch_fits(&self, scratch: &Scratch) -> bool {
        let model = self.active.model();
        let (joints, frames) = (model.num_joints(), model.num_frames());
        scratch.poses.fits(joints, frames)
            && scratch.batch.fits(joints, frames)
            && scratch.placed.len() == self.collision.bodies().len()
            && scratch.noisy.len() == self.dim()
            && scratch.lanes.len() == LANES * self.dim()
    }

    /// Forward kinematics (and collision placement when needed) of `q` into `scratch`, through
    /// the batched kinematics like every other evaluation of the objective (in all lanes, so
    /// the values are those of any batch holding `q`): a single check and a population's
    /// evaluation never disagree, not even at exact contact. NaN in `q` gives NaN poses.
    fn pose(&self, q: &[f64], scratch: &mut Scratch, place: bool) {
        let d = self.dim();
        for lane in 0..LANES {
            scratch.lanes[lane * d..(lane + 1) * d].copy_from_slice(q);
        }
        self.active
            .forward_batch_unchecked(&scratch.lanes, &mut scratch.batch);
        scratch.batch.lane_into(0, &mut scratch.poses);
        if place {
            self.collision.place(&scratch.poses, &mut scratch.placed);
        }
    }

    fn context<'a>(&'a self, q: &'a [f64], scratch: &'a Scratch) -> Context<'a> {
        Context {
            robot: self.active.model(),
            q,
            poses: &scratch.poses,
            collision: &self.collision,
            placed: &scratch.placed,
            world: &self.world,
        }
    }

    fn weighted(&self, q: &[f64], scratch: &mut Scratch) -> f64 {
        self.pose(q, scratch, self.needs_collision);
        self.weighted_posed(q, scratch)
    }

    /// Σ aᵢ hᵢ at `q`, posed in `scratch` already.
    fn weighted_posed(&self, q: &[f64], scratch: &Scratch) -> f64 {
        let ctx = self.context(q, scratch);
        self.terms
            .iter()
            .filter(|t| t.weight != 0.0)
            .map(|t| t.weight * t.cost.eval(&ctx))
            .sum()
    }

    fn is_valid(&self, q: &[f64]) -> bool {
        q.len() == self.dim() && !q.iter().any(|v| v.is_nan())
    }

    /// Poses the `n` candidates `q(k)` with batched forward kinematics, [`LANES`] at a time (a
    /// partial batch is padded), and calls `f(k, q, scratch)` with candidate `k` posed (and its
    /// bodies placed when `place`) in `scratch`, in order of `k`, until `f` returns false.
    /// Invalid candidates (wrong length, NaN) are skipped. A candidate's poses do not depend on
    /// the others in its batch.
    fn pose_each<'q>(
        &self,
        n: usize,
        q: impl Fn(usize) -> &'q [f64],
        scratch: &mut Scratch,
        place: bool,
        mut f: impl FnMut(usize, &'q [f64], &mut Scratch) -> bool,
    ) {
        let d = self.dim();
        let mut lanes = [0usize; LANES];
        let mut k = 0;
        while k < n {
            let mut used = 0;
            while used < LANES && k < n {
                if self.is_valid(q(k)) {
                    lanes[used] = k;
                    scratch.lanes[used * d..(used + 1) * d].copy_from_slice(q(k));
                    used += 1;
                }
                k += 1;
            }
            if used == 0 {
                break;
            }
            for l in used..LANES {
                scratch.lanes.copy_within(0..d, l * d);
            }
            self.active
                .forward_batch_unchecked(&scratch.lanes, &mut scratch.batch);
            for (l, &k) in lanes[..used].iter().enumerate() {
                scratch.batch.lane_into(l, &mut scratch.poses);
                if place {
                    self.collision.place(&scratch.poses, &mut scratch.placed);
                }
                if !f(k, q(k), scratch) {
                    return;
                }
            }
        }
    }

    /// Whether every configuration of `qs` (`n × dim` values, one configuration after the
    /// other) is free of self-collisions and of collisions with `world`: batched as
    /// [`Objective::eval_batch`], stopping at the first collision. A configuration of NaN
    /// counts as colliding.
    ///
    /// # Panics
    /// If `qs.len()` is not a multiple of [`Objective::dim`].
    pub fn all_collision_free_in(&self, qs: &[f64], world: &World, scratch: &mut Scratch) -> bool {
        self.all_placed(qs, scratch, |placed| {
            !self.collision.is_colliding(placed, world)
        })
    }

    /// Whether no configuration of `qs` (as in [`Objective::all_collision_free_in`]) touches an
    /// object of `world`; self-collisions are not checked (for postures known to be free of
    /// them, against objects that changed).
    ///
    /// # Panics
    /// If `qs.len()` is not a multiple of [`Objective::dim`].
    pub fn all_clear_of(&self, qs: &[f64], world: &World, scratch: &mut Scratch) -> bool {
        self.all_placed(qs, scratch, |placed| {
            !self.collision.any_world_collision(placed, world)
        })
    }

    /// Calls `f` with the robot's bodies placed at each configuration of `qs` (`n × dim`
    /// values), in order, with forward kinematics [`LANES`] configurations at a time, until `f`
    /// returns false; returns whether it held for all. A configuration holding NaN makes it
    /// false without a call.
    ///
    /// # Panics
    /// If `qs.len()` is not a multiple of [`Objective::dim`].
    pub fn all_placed(
        &self,
        qs: &[f64],
        scratch: &mut Scratch,
        mut free: impl FnMut(&PlacedBodies) -> bool,
    ) -> bool {
        let d = self.dim();
        assert!(d > 0 && qs.len() % d == 0, "whole configurations");
        let n = qs.len() / d;
        if qs.iter().any(|v| v.is_nan()) {
            return false;
        }
        let mut all = true;
        self.pose_each(
            n,
            |k| &qs[k * d..(k + 1) * d],
            scratch,
            true,
            |_, _, s| {
                all = free(&s.placed);
                all
            },
        );
        all
    }

    /// [`Objective::eval`] of many candidates: `out[k]` = h(`qs[k]`), with forward kinematics
    /// for [`LANES`] candidates at a time (and every noise sample of a candidate as one more
    /// lane). Equal to `eval`, bit for bit: each value depends on its own candidate only, so
    /// splitting `qs` differently (over threads, say) gives the same values. Allocation-free
    /// once `scratch` has grown to the largest batch with noise.
    ///
    /// # Panics
    /// If `out` and `qs` differ in length.
    pub fn eval_batch<Q: AsRef<[f64]>>(&self, qs: &[Q], scratch: &mut Scratch, out: &mut [f64]) {
        self.eval_batch_with(qs, scratch, out, None);
    }

    /// [`Objective::eval_with_task`] of many candidates: `out[k]` = h(`qs[k]`) and
    /// `tasks[k·m..(k+1)·m]` = g(`qs[k]`) (m = the task dimension; left untouched without a
    /// task function and for invalid candidates). Batched as [`Objective::eval_batch`].
    ///
    /// # Panics
    /// If `out` and `qs` differ in length or `tasks` is shorter than `qs.len()` × m.
    pub fn eval_with_task_batch<Q: AsRef<[f64]>>(
        &self,
        qs: &[Q],
        scratch: &mut Scratch,
        out: &mut [f64],
        tasks: &mut [f64],
    ) {
        let task = self.task.as_deref().map(|task| {
            assert!(
                tasks.len() >= qs.len() * task.dim(),
                "one task vector per candidate"
            );
            (task, tasks)
        });
        self.eval_batch_with(qs, scratch, out, task);
    }

    /// h of every candidate into `out` and, with a task function, g into its buffer.
    fn eval_batch_with<Q: AsRef<[f64]>>(
        &self,
        qs: &[Q],
        scratch: &mut Scratch,
        out: &mut [f64],
        mut task: Option<(&dyn TaskFunction, &mut [f64])>,
    ) {
        assert_eq!(qs.len(), out.len(), "one output per candidate");
        let nominal = self.noise.is_empty();
        if nominal {
            out.fill(f64::NAN);
        } else {
            self.eval_noisy_batch(qs, scratch, out);
            if task.is_none() {
                return;
            }
        }
        let place = nominal && self.needs_collision;
        self.pose_each(
            qs.len(),
            |k| qs[k].as_ref(),
            scratch,
            place,
            |k, q, s| {
                if nominal {
                    out[k] = self.weighted_posed(q, s);
                }
                if let Some((task, tasks)) = &mut task {
                    let m = task.dim();
                    task.eval(&self.context(q, s), &mut tasks[k * m..(k + 1) * m]);
                }
                true
            },
        );
    }

    /// The robust h: the mean over every valid candidate's noisy copies, all posed in batches.
    fn eval_noisy_batch<Q: AsRef<[f64]>>(&self, qs: &[Q], scratch: &mut Scratch, out: &mut [f64]) {
        out.fill(f64::NAN);
        let d = self.dim();
        let mut noisy = std::mem::take(&mut scratch.noisy_batch);
        let mut owner = std::mem::take(&mut scratch.noisy_owner);
        noisy.clear();
        owner.clear();
        for (k, q) in qs.iter().enumerate() {
            let q = q.as_ref();
            if !self.is_valid(q) {
                continue;
            }
            out[k] = 0.0;
            for offsets in &self.noise {
                noisy.extend(q.iter().zip(offsets).map(|(q, e)| q + e));
                owner.push(k);
            }
        }
        let place = self.needs_collision;
        self.pose_each(
            owner.len(),
            |j| &noisy[j * d..(j + 1) * d],
            scratch,
            place,
            |j, q, s| {
                out[owner[j]] += self.weighted_posed(q, s);
                true
            },
        );
        let samples = self.noise.len() as f64;
        for (o, q) in out.iter_mut().zip(qs) {
            if self.is_valid(q.as_ref()) {
                *o /= samples;
            }
        }
        scratch.noisy_batch = noisy;
        scratch.noisy_owner = owner;
    }

    /// h(q) = Σ aᵢ hᵢ (the mean over the noise samples when noise is set). NaN for a q of the
    /// wrong length or with NaN values.
    pub fn eval(&self, q: &[f64], scratch: &mut Scratch) -> f64 {
        if q.len() != self.dim() || q.iter().any(|v| v.is_nan()) {
            return f64::NAN;
        }
        if self.noise.is_empty() {
            return self.weighted(q, scratch);
        }
        let mut total = 0.0;
        let mut noisy = std::mem::take(&mut scratch.noisy);
        for offsets in &self.noise {
            for ((n, q), e) in noisy.iter_mut().zip(q).zip(offsets) {
                *n = q + e;
            }
            total += self.weighted(&noisy, scratch);
        }
        scratch.noisy = noisy;
        total / self.noise.len() as f64
    }

    /// h(q) as [`Objective::eval`], and the task vector g(q) at the nominal q written to `task`
    /// (length of the task function's dimension), from the same forward-kinematics pass when there
    /// is no noise. Without a task function `task` is left untouched.
    pub fn eval_with_task(&self, q: &[f64], scratch: &mut Scratch, task: &mut [f64]) -> f64 {
        let cost =
            if self.noise.is_empty() && q.len() == self.dim() && !q.iter().any(|v| v.is_nan()) {
                self.weighted(q, scratch)
            } else {
                let c = self.eval(q, scratch);
                if q.len() == self.dim() {
                    self.pose(q, scratch, false);
                }
                c
            };
        if let (Some(t), true) = (&self.task, q.len() == self.dim()) {
            t.eval(&self.context(q, scratch), task);
        }
        cost
    }

    /// Every term's value at `q` (without noise) and the weighted total.
    pub fn breakdown(&self, q: &[f64], scratch: &mut Scratch) -> (f64, Vec<TermValue>) {
        self.pose(q, scratch, true);
        let ctx = self.context(q, scratch);
        let values: Vec<TermValue> = self
            .terms
            .iter()
            .map(|t| TermValue {
                label: t.cost.label(),
                weight: t.weight,
                value: t.cost.eval(&ctx),
            })
            .collect();
        let total = values.iter().map(|v| v.weight * v.value).sum();
        (total, values)
    }

    /// Whether `q` is free of self- and world collisions.
    pub fn is_collision_free(&self, q: &[f64], scratch: &mut Scratch) -> bool {
        self.is_collision_free_in(q, &self.world, scratch)
    }

    /// Whether `q` is free of self-collisions and of collisions with `world` (another world
    /// than the objective's: the planner's current one, say).
    pub fn is_collision_free_in(&self, q: &[f64], world: &World, scratch: &mut Scratch) -> bool {
        self.pose(q, scratch, true);
        !self.collision.is_colliding(&scratch.placed, world)
    }

    /// The task vector g(q) (empty without a task function).
    pub fn task_value(&self, q: &[f64], scratch: &mut Scratch) -> Vec<f64> {
        let Some(task) = &self.task else {
            return Vec::new();
        };
        self.pose(q, scratch, false);
        let mut out = vec![0.0; task.dim()];
        task.eval(&self.context(q, scratch), &mut out);
        out
    }

    /// Poses of every frame at `q` (for output files).
    pub fn poses(&self, q: &[f64], scratch: &mut Scratch) -> PoseBuffer {
        self.pose(q, scratch, false);
        scratch.poses.clone()
    }
}
