//! The weighted objective h = Σ aᵢ hᵢ, evaluated from one forward-kinematics pass per candidate,
//! optionally averaged over Gaussian noise on q (robust postures).

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};
use trm_collision::{CollisionModel, PlacedBodies, World};
use trm_kinematics::{ActiveSet, PoseBuffer};

use crate::context::Context;
use crate::costs::Cost;
use crate::error::{Result, TaskError};
use crate::tasks::TaskFunction;

/// A weighted term.
#[derive(Debug)]
struct Term {
    weight: f64,
    cost: Box<dyn Cost>,
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
/// an optional task function. `Sync`: share it between threads, give each a [`Scratch`].
#[derive(Debug)]
pub struct Objective {
    active: ActiveSet,
    collision: CollisionModel,
    world: World,
    terms: Vec<Term>,
    task: Option<Box<dyn TaskFunction>>,
    /// Noise offsets of the robust objective (common random numbers, drawn once).
    noise: Vec<Vec<f64>>,
    needs_collision: bool,
}

/// Per-thread buffers for evaluating an [`Objective`].
#[derive(Debug, Clone)]
pub struct Scratch {
    poses: PoseBuffer,
    placed: PlacedBodies,
    noisy: Vec<f64>,
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
        self.terms.push(Term { weight, cost });
        Ok(())
    }

    /// Sets the task function.
    pub fn set_task(&mut self, task: Box<dyn TaskFunction>) {
        self.task = Some(task);
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
        }
    }

    /// Forward kinematics (and collision placement when needed) of `q` into `scratch`.
    fn pose(&self, q: &[f64], scratch: &mut Scratch, place: bool) {
        self.active.forward_unchecked(q, &mut scratch.poses);
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
        let ctx = self.context(q, scratch);
        self.terms
            .iter()
            .filter(|t| t.weight != 0.0)
            .map(|t| t.weight * t.cost.eval(&ctx))
            .sum()
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
