//! The weighted objective h = Σ aᵢ hᵢ, evaluated from one forward-kinematics pass per candidate,
//! optionally averaged over Gaussian noise on q (robust postures).

use std::sync::Arc;

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};
use trm_collision::fast::{FAST_LANES, FastChecker, FastWorld, Tally};
use trm_collision::{CollisionModel, PlacedBatch, PlacedBodies, World, WorldChecker};
use trm_kinematics::{ActiveSet, LANES, PoseBatch, PoseBuffer};

use crate::context::{BatchContext, Context};
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
    /// Some term reads placed bodies, not only collision counts.
    needs_placed: bool,
    /// The world compiled for the single-precision screen, when every collision term reads
    /// only counts ([`Cost::counts_collisions_only`]): batches count collisions with it.
    screen: Option<FastWorld>,
    /// Forward kinematics of only the frames the terms and the task function read (and their
    /// ancestors), for batches that place no bodies; `None` when some term may read any frame.
    pruned: Option<ActiveSet>,
    /// Forward kinematics of the links with collision bodies, for the pairs the screen leaves
    /// uncertain when `pruned` skips some of them.
    body_links: Option<ActiveSet>,
    /// This objective's robot and active set (kept by clones): a scratch's screen checker
    /// made for another is made again.
    key: u64,
    /// Some term or the task function reads one-candidate poses ([`BatchContext::lane`]).
    copies_poses: bool,
    /// Some term reading one-candidate contexts needs placed bodies.
    copies_placed: bool,
}

/// How close a posture comes to collision ([`Objective::clearance_in`]): signed distances in
/// metres (negative: penetration) with what they are between.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Clearance {
    /// The closest pair of the robot's own checked bodies: (distance, body, body).
    pub own: Option<(f64, usize, usize)>,
    /// The closest body to a world object: (distance, body, object).
    pub world: Option<(f64, usize, usize)>,
}

impl Clearance {
    /// The smaller of the two distances (+∞ when there is nothing to measure).
    pub fn distance(&self) -> f64 {
        let own = self.own.map_or(f64::INFINITY, |p| p.0);
        let world = self.world.map_or(f64::INFINITY, |p| p.0);
        own.min(world)
    }
}

/// Above this fraction of lanes left uncertain (each then checked exactly), counting with the
/// screen is slower than placing every body in `f64` (measured on Table III: SIR at 34 %
/// uncertain 23 % faster with the screen, xNES at 50 % 11 % slower, CMA-ES at 83 % 12 % slower).
const SCREEN_UNCERTAIN: f64 = 0.4;

/// Evaluation calls without the screen after it rose above [`SCREEN_UNCERTAIN`], before it is
/// tried again.
const SCREEN_REST: u32 = 64;

/// Keys of objectives (their robot and active set), for the screen checkers kept in scratches.
static NEXT_KEY: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);

/// Per-thread buffers for evaluating an [`Objective`], one candidate or a batch at a time.
#[derive(Debug, Clone)]
pub struct Scratch {
    poses: PoseBuffer,
    placed: PlacedBodies,
    /// Batched evaluation: the poses and placed bodies of [`LANES`] candidates, their values
    /// one after the other, one-candidate copies for unbatched terms, task values per lane,
    /// and every candidate's noisy copies.
    batch: PoseBatch,
    placed_batch: PlacedBatch,
    lanes: Vec<f64>,
    lane_poses: Vec<PoseBuffer>,
    lane_placed: Vec<PlacedBodies>,
    /// The screen's checker (made for the objective of that key) and its last block: the
    /// candidates' indices, their values one after the other, their counts; the counts of
    /// the current batch.
    screen: Option<(u64, FastChecker)>,
    screen_inputs: Vec<f64>,
    screened: Vec<usize>,
    tally: Tally,
    /// The fraction of lanes the screen left uncertain, a moving average over its blocks, and
    /// how many evaluations go without the screen after it rose above [`SCREEN_UNCERTAIN`].
    screen_uncertain: f64,
    screen_rest: u32,
    body_batch: PoseBatch,
    batch_counts: [[usize; 2]; LANES],
    task_lanes: Vec<f64>,
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
            needs_placed: false,
            screen: None,
            pruned: None,
            body_links: None,
            key: NEXT_KEY.fetch_add(1, std::sync::atomic::Ordering::Relaxed),
            copies_poses: false,
            copies_placed: false,
        }
    }

    /// Compiles the world for the screen when the collision terms only count (again after the
    /// world or the terms changed).
    fn compile_screen(&mut self) {
        self.screen = (self.needs_collision && !self.needs_placed)
            .then(|| WorldChecker::screen_model(&self.collision))
            .flatten()
            .map(|fast| fast.world(&self.world));
    }

    /// The kinematics of the frames the terms and the task function read, when every one of
    /// them says which (again after the terms or the task changed).
    fn prune_kinematics(&mut self) {
        let mut frames = Vec::new();
        let declared = self.terms.iter().all(|t| match t.cost.frames_read() {
            Some(f) => {
                frames.extend(f);
                true
            }
            None => false,
        }) && self.task.as_ref().is_none_or(|t| match t.frames_read() {
            Some(f) => {
                frames.extend(f);
                true
            }
            None => false,
        });
        self.pruned = declared.then(|| self.active.pruned_to(frames.iter().map(|f| f.index())));
        self.body_links = self.pruned.as_ref().map(|_| {
            self.active
                .pruned_to(self.collision.bodies().iter().map(|b| b.link))
        });
    }

    /// The same objective in another world (builder form of [`Objective::set_world`]).
    pub fn with_world(mut self, world: World) -> Self {
        self.set_world(world);
        self
    }

    /// Replaces the world the collision and world-dependent costs see.
    pub fn set_world(&mut self, world: World) {
        self.world = world;
        self.compile_screen();
    }

    /// Replaces the collision model by another of the same robot and bodies — the same model
    /// with another allowed-collision matrix (a planning scene's, say) or holding other objects
    /// ([`CollisionModel::with_attached`]) — keeping its compiled screen when it has one.
    /// Scratches made before are made again when next used. An error for a model of another
    /// robot or other bodies of its own.
    pub fn set_collision(&mut self, collision: CollisionModel) -> Result<()> {
        collision.check_active(&self.active)?;
        let own = |c: &CollisionModel| {
            let held: usize = c.attached().iter().map(|o| o.shapes.len()).sum();
            c.bodies().len() - held
        };
        if own(&collision) != own(&self.collision) {
            return Err(TaskError::Invalid {
                what: "collision model".into(),
                problem: format!(
                    "{} bodies of its own where the objective's model has {}",
                    own(&collision),
                    own(&self.collision)
                ),
            });
        }
        self.collision = collision;
        self.key = NEXT_KEY.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        self.compile_screen();
        Ok(())
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
        // (a term read one candidate at a time gets its placed bodies copied out of the batch)
        self.needs_placed |=
            cost.needs_collision() && !(cost.counts_collisions_only() && cost.batched());
        self.copies_poses |= !cost.batched();
        self.copies_placed |= !cost.batched() && cost.needs_collision();
        self.terms.push(Term {
            weight,
            cost: Arc::from(cost),
        });
        self.compile_screen();
        self.prune_kinematics();
        Ok(())
    }

    /// Sets the task function.
    pub fn set_task(&mut self, task: Box<dyn TaskFunction>) {
        self.copies_poses |= !task.batched();
        self.task = Some(Arc::from(task));
        self.prune_kinematics();
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
        let model = self.active.model();
        Scratch {
            poses: model.pose_buffer(),
            placed: self.collision.placed_bodies(),
            batch: model.pose_batch(),
            placed_batch: self.collision.placed_batch(),
            lanes: vec![0.0; LANES * self.dim()],
            lane_poses: vec![model.pose_buffer(); LANES],
            lane_placed: vec![self.collision.placed_bodies(); LANES],
            screen: None,
            screen_inputs: Vec::new(),
            screened: Vec::new(),
            tally: Tally::default(),
            screen_uncertain: 0.0,
            screen_rest: 0,
            body_batch: model.pose_batch(),
            batch_counts: [[0; 2]; LANES],
            task_lanes: Vec::new(),
            noisy_batch: Vec::new(),
            noisy_owner: Vec::new(),
        }
    }

    /// Whether `scratch` has this objective's sizes (poses, bodies, variables), so that a
    /// scratch kept from an earlier call can serve it: evaluations overwrite everything else.
    pub fn scratch_fits(&self, scratch: &Scratch) -> bool {
        let model = self.active.model();
        let (joints, frames) = (model.num_joints(), model.num_frames());
        let bodies = self.collision.bodies().len();
        scratch.poses.fits(joints, frames)
            && scratch.batch.fits(joints, frames)
            && scratch.lane_poses.iter().all(|p| p.fits(joints, frames))
            && scratch.placed.len() == bodies
            && scratch.placed_batch.len() == bodies
            && scratch.lane_placed.iter().all(|p| p.len() == bodies)
            && scratch.body_batch.fits(joints, frames)
            && scratch.lanes.len() == LANES * self.dim()
    }

    /// Forward kinematics (and collision placement when asked) of `q` into `scratch`'s
    /// one-configuration buffers, through the batched kinematics like every other evaluation
    /// (in all lanes, so the values are those of any batch holding `q`). NaN in `q` gives NaN
    /// poses.
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

    fn is_valid(&self, q: &[f64]) -> bool {
        q.len() == self.dim() && !q.iter().any(|v| v.is_nan())
    }

    /// Loads the next valid candidates `q(k)`, from `*k` on, into the lanes (at most
    /// [`LANES`]; invalid ones — wrong length, NaN — are skipped), runs batched forward
    /// kinematics and, when `place`, places the bodies of the batch. Their indices go to `ks`,
    /// their values to `qs`; returns how many (0 when none is left). A partial batch is padded
    /// with its first candidate, whose results are not used: a candidate's values never depend
    /// on the others in its batch.
    fn load<'q>(
        &self,
        n: usize,
        q: &impl Fn(usize) -> &'q [f64],
        k: &mut usize,
        scratch: &mut Scratch,
        place: bool,
        (ks, qs): (&mut [usize; LANES], &mut [&'q [f64]; LANES]),
    ) -> usize {
        let d = self.dim();
        let mut used = 0;
        while used < LANES && *k < n {
            let candidate = q(*k);
            if self.is_valid(candidate) {
                ks[used] = *k;
                qs[used] = candidate;
                scratch.lanes[used * d..(used + 1) * d].copy_from_slice(candidate);
                used += 1;
            }
            *k += 1;
        }
        if used == 0 {
            return 0;
        }
        for l in used..LANES {
            scratch.lanes.copy_within(0..d, l * d);
        }
        // without bodies to place, only the frames the terms read
        let fk = match &self.pruned {
            Some(pruned) if !place => pruned,
            _ => &self.active,
        };
        fk.forward_batch_unchecked(&scratch.lanes, &mut scratch.batch);
        if place {
            self.collision
                .place_batch(&scratch.batch, used, &mut scratch.placed_batch);
        }
        used
    }

    /// Evaluates the `n` candidates `q(k)` [`LANES`] at a time and calls `f(ks, ctx)` for each
    /// batch (the candidates' indices and their [`BatchContext`]), in order, until `f` returns
    /// false. Makes one-candidate copies of poses and bodies only when an unbatched term or
    /// task function reads them.
    fn batches<'q>(
        &self,
        n: usize,
        q: impl Fn(usize) -> &'q [f64],
        scratch: &mut Scratch,
        mut f: impl FnMut(&[usize], &BatchContext) -> bool,
    ) {
        // the screen, unless it recently left too many lanes to the exact check (populations
        // at grazing contact): then placed bodies for a while, the same counts either way
        let screening = self.screen.is_some() && !self.needs_placed && scratch.screen_rest == 0;
        scratch.screen_rest = scratch.screen_rest.saturating_sub(1);
        let place = self.needs_placed || (self.needs_collision && !screening);
        let (mut ks, mut qs) = ([0; LANES], [&[][..]; LANES]);
        let mut k = 0;
        scratch.screened.clear();
        loop {
            let used = self.load(n, &q, &mut k, scratch, place, (&mut ks, &mut qs));
            if used == 0 {
                return;
            }
            let counted = match &self.screen {
                Some(world) if !place => {
                    self.count_batch(world, &ks[..used], n, &q, scratch);
                    true
                }
                _ => false,
            };
            if self.copies_poses {
                for l in 0..used {
                    scratch.batch.lane_into(l, &mut scratch.lane_poses[l]);
                }
            }
            if place && self.copies_placed {
                for l in 0..used {
                    self.collision
                        .lane_into(&scratch.placed_batch, l, &mut scratch.lane_placed[l]);
                }
            }
            let ctx = BatchContext {
                robot: self.active.model(),
                q: &qs[..used],
                poses: &scratch.batch,
                collision: &self.collision,
                placed: &scratch.placed_batch,
                world: &self.world,
                lane_poses: &scratch.lane_poses,
                lane_placed: &scratch.lane_placed,
                counts: counted.then_some(&scratch.batch_counts[..used]),
            };
            if !f(&ks[..used], &ctx) {
                return;
            }
        }
    }

    /// The collision counts of the batch's candidates `ks` into `scratch.batch_counts`, from the
    /// screen's blocks of [`FAST_LANES`] valid candidates (the batch's and the next ones), each
    /// screened once.
    fn count_batch<'q>(
        &self,
        world: &FastWorld,
        ks: &[usize],
        n: usize,
        q: &impl Fn(usize) -> &'q [f64],
        scratch: &mut Scratch,
    ) {
        let d = self.dim();
        let mut bodies_posed = false;
        for (l, &k) in ks.iter().enumerate() {
            let at = match scratch.screened.iter().position(|&j| j == k) {
                Some(at) => at,
                None => {
                    // a new block: this candidate and the valid ones after it
                    scratch.screened.clear();
                    scratch.screen_inputs.clear();
                    for j in k..n {
                        if scratch.screened.len() == FAST_LANES {
                            break;
                        }
                        if self.is_valid(q(j)) {
                            scratch.screened.push(j);
                            scratch.screen_inputs.extend_from_slice(q(j));
                        }
                    }
                    if scratch
                        .screen
                        .as_ref()
                        .is_none_or(|(key, _)| *key != self.key)
                    {
                        scratch.screen = FastChecker::new(&self.collision, self.active.clone())
                            .ok()
                            .map(|checker| (self.key, checker));
                    }
                    if let Some((_, checker)) = &mut scratch.screen {
                        scratch.tally =
                            checker.screen_counts_unchecked(&scratch.screen_inputs, world);
                        let uncertain = scratch.tally.uncertain.count_ones() as f64
                            / scratch.screened.len() as f64;
                        scratch.screen_uncertain += (uncertain - scratch.screen_uncertain) / 8.0;
                        if scratch.screen_uncertain > SCREEN_UNCERTAIN {
                            scratch.screen_rest = SCREEN_REST;
                            scratch.screen_uncertain = SCREEN_UNCERTAIN / 2.0;
                        }
                    }
                    0
                }
            };
            // the pairs the screen left uncertain, exactly in the batch's own poses (those of
            // the f64 path without the screen, to the last bit): its links with bodies computed
            // once for the batch when the batch's kinematics skipped some
            let q = &scratch.screen_inputs[at * d..(at + 1) * d];
            if scratch.tally.uncertain & (1 << at) != 0 || q.iter().any(|v| !v.is_finite()) {
                match &self.body_links {
                    Some(fk) => {
                        if !bodies_posed {
                            fk.forward_batch_unchecked(&scratch.lanes, &mut scratch.body_batch);
                            bodies_posed = true;
                        }
                        scratch.body_batch.lane_into(l, &mut scratch.poses);
                    }
                    None => scratch.batch.lane_into(l, &mut scratch.poses),
                }
            }
            scratch.batch_counts[l] = match &mut scratch.screen {
                Some((_, checker)) => {
                    checker.exact_counts(&scratch.tally, at, q, &scratch.poses, &self.world)
                }
                // (not reached: the model compiled for the screen)
                None => {
                    self.collision.place(&scratch.poses, &mut scratch.placed);
                    [
                        self.collision.count_self(&scratch.placed),
                        self.collision.count_world(&scratch.placed, &self.world),
                    ]
                }
            };
        }
    }

    /// Σ aᵢ hᵢ of every lane of a batch, summed term by term in order.
    fn weighted_batch(&self, ctx: &BatchContext, values: &mut [f64; LANES]) -> [f64; LANES] {
        let mut total = [-0.0; LANES];
        for t in self.terms.iter().filter(|t| t.weight != 0.0) {
            t.cost.eval_batch(ctx, values);
            for (s, v) in total.iter_mut().zip(&values[..ctx.len()]) {
                *s += t.weight * v;
            }
        }
        total
    }

    /// Whether every configuration of `qs` (`n × dim` values, one configuration after the
    /// other) is free of self-collisions and of collisions with `world`: batched as
    /// [`Objective::eval_batch`], stopping at the first collision. A configuration of NaN
    /// counts as colliding.
    ///
    /// # Panics
    /// If `qs.len()` is not a multiple of [`Objective::dim`].
    pub fn all_collision_free_in(&self, qs: &[f64], world: &World, scratch: &mut Scratch) -> bool {
        self.all_placed_batch(qs, scratch, |placed| {
            self.collision.is_colliding_batch(placed, world)
        })
    }

    /// Whether no configuration of `qs` (as in [`Objective::all_collision_free_in`]) touches an
    /// object of `world`; self-collisions are not checked (for postures known to be free of
    /// them, against objects that changed).
    ///
    /// # Panics
    /// If `qs.len()` is not a multiple of [`Objective::dim`].
    pub fn all_clear_of(&self, qs: &[f64], world: &World, scratch: &mut Scratch) -> bool {
        self.all_placed_batch(qs, scratch, |placed| {
            self.collision.any_world_collision_batch(placed, world)
        })
    }

    /// Whether `hits` finds no collision in any batch of the configurations of `qs` (`n ×
    /// dim` values), placed [`LANES`] at a time; false at once for NaN.
    fn all_placed_batch(
        &self,
        qs: &[f64],
        scratch: &mut Scratch,
        hits: impl Fn(&PlacedBatch) -> [bool; LANES],
    ) -> bool {
        self.each_placed_batch(qs, scratch, |used, s| {
            !hits(&s.placed_batch)[..used].iter().any(|&h| h)
        })
    }

    /// Calls `f(used, scratch)` with each batch of the configurations of `qs` (`n × dim`
    /// values) placed in `scratch.placed_batch` (its first `used` lanes), in order, until `f`
    /// returns false; returns whether it held for all. NaN anywhere makes it false without a
    /// call.
    fn each_placed_batch(
        &self,
        qs: &[f64],
        scratch: &mut Scratch,
        mut f: impl FnMut(usize, &mut Scratch) -> bool,
    ) -> bool {
        let d = self.dim();
        assert!(d > 0 && qs.len().is_multiple_of(d), "whole configurations");
        if qs.iter().any(|v| v.is_nan()) {
            return false;
        }
        let n = qs.len() / d;
        let q = |k: usize| &qs[k * d..(k + 1) * d];
        let (mut ks, mut qv) = ([0; LANES], [&[][..]; LANES]);
        let mut k = 0;
        loop {
            let used = self.load(n, &q, &mut k, scratch, true, (&mut ks, &mut qv));
            if used == 0 {
                return true;
            }
            if !f(used, scratch) {
                return false;
            }
        }
    }

    /// Calls `f` with the robot's bodies placed at each configuration of `qs` (`n × dim`
    /// values), in order, with forward kinematics and placement [`LANES`] configurations at a
    /// time, until `f` returns false; returns whether it held for all. A configuration holding
    /// NaN makes it false without a call.
    ///
    /// # Panics
    /// If `qs.len()` is not a multiple of [`Objective::dim`].
    pub fn all_placed(
        &self,
        qs: &[f64],
        scratch: &mut Scratch,
        mut free: impl FnMut(&PlacedBodies) -> bool,
    ) -> bool {
        self.each_placed_batch(qs, scratch, |used, s| {
            (0..used).all(|l| {
                self.collision.lane_into(&s.placed_batch, l, &mut s.placed);
                free(&s.placed)
            })
        })
    }

    /// [`Objective::eval`] of many candidates: `out[k]` = h(`qs[k]`), [`LANES`] candidates at a
    /// time through batched kinematics, batched collision placement and counts and each term's
    /// `eval_batch` (every noise sample of a candidate is one more lane). `eval` is a batch of
    /// one, so the two agree bit for bit, and each value depends on its own candidate only:
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
        let m = task.as_ref().map_or(0, |(t, _)| t.dim());
        let mut lanes_out = std::mem::take(&mut scratch.task_lanes);
        lanes_out.resize(LANES * m, 0.0);
        let mut values = [0.0; LANES];
        self.batches(
            qs.len(),
            |k| qs[k].as_ref(),
            scratch,
            |ks, ctx| {
                if nominal {
                    let h = self.weighted_batch(ctx, &mut values);
                    for (&k, h) in ks.iter().zip(h) {
                        out[k] = h;
                    }
                }
                if let Some((task, tasks)) = &mut task {
                    task.eval_batch(ctx, &mut lanes_out);
                    for (l, &k) in ks.iter().enumerate() {
                        tasks[k * m..(k + 1) * m].copy_from_slice(&lanes_out[l * m..(l + 1) * m]);
                    }
                }
                true
            },
        );
        scratch.task_lanes = lanes_out;
    }

    /// The robust h: the mean over every valid candidate's noisy copies, all evaluated in
    /// batches.
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
        let mut values = [0.0; LANES];
        self.batches(
            owner.len(),
            |j| &noisy[j * d..(j + 1) * d],
            scratch,
            |js, ctx| {
                let h = self.weighted_batch(ctx, &mut values);
                for (&j, h) in js.iter().zip(h) {
                    out[owner[j]] += h;
                }
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
    /// wrong length or with NaN values. One candidate through each term's `eval` (cheaper than
    /// a batch of one); equal to [`Objective::eval_batch`] bit for bit, as each term's
    /// `eval_batch` equals its `eval`.
    pub fn eval(&self, q: &[f64], scratch: &mut Scratch) -> f64 {
        if !self.is_valid(q) {
            return f64::NAN;
        }
        if !self.noise.is_empty() {
            let mut out = [0.0];
            self.eval_batch(&[q], scratch, &mut out);
            return out[0];
        }
        self.pose(q, scratch, self.needs_collision);
        let ctx = self.context(q, scratch);
        self.terms
            .iter()
            .filter(|t| t.weight != 0.0)
            .map(|t| t.weight * t.cost.eval(&ctx))
            .sum()
    }

    /// h(q) as [`Objective::eval`], and the task vector g(q) at the nominal q written to `task`
    /// (length of the task function's dimension), from the same forward-kinematics pass when there
    /// is no noise. Without a task function `task` is left untouched.
    pub fn eval_with_task(&self, q: &[f64], scratch: &mut Scratch, task: &mut [f64]) -> f64 {
        let mut out = [0.0];
        if self.is_valid(q) {
            self.eval_with_task_batch(&[q], scratch, &mut out, task);
            return out[0];
        }
        let cost = self.eval(q, scratch);
        if let (Some(t), true) = (&self.task, q.len() == self.dim()) {
            self.pose(q, scratch, false);
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

    /// A checker of this objective's robot and active motors in `world`
    /// ([`WorldChecker`]: configurations and edges, on the screen where the model compiles to
    /// it): what planners check with.
    pub fn world_checker(&self, world: &World) -> trm_collision::Result<WorldChecker> {
        WorldChecker::new(&self.collision, &self.active, world.clone())
    }

    /// How close active values `q` come to collision in `world`: the closest checked pair of
    /// the robot's own bodies and the closest body to a world object (exact signed distances).
    pub fn clearance_in(&self, q: &[f64], world: &World, scratch: &mut Scratch) -> Clearance {
        self.pose(q, scratch, true);
        let model = self.collision();
        let placed = &scratch.placed;
        let own = model
            .min_self_distance(placed)
            .map(|p| (p.distance, p.a, p.b));
        let to_world = (0..model.bodies().len())
            .flat_map(|b| (0..world.len()).map(move |o| (b, o)))
            .map(|(b, o)| (model.object_distance(placed, b, world, o), b, o))
            .min_by(|x, y| x.0.total_cmp(&y.0));
        Clearance {
            own,
            world: to_world,
        }
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
