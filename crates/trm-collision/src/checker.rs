//! [`WorldChecker`]: the one place that decides how a robot's configurations and edges are
//! checked against a world.

use std::sync::Arc;

use trm_kinematics::{ActiveSet, LANES, PoseBatch, PoseBuffer};

use crate::batch::PlacedBatch;
use crate::certify::Certificate;
use crate::edge::{edge_steps, rake, span_steps};
use crate::error::Result;
use crate::fast::{FAST_LANES, FastChecker, FastModel, FastWorld};
use crate::model::CollisionModel;
use crate::placed::PlacedBodies;
use crate::prove::Prover;
use crate::world::World;

/// Collision checks of one robot's configurations and straight edges in one world, counted.
///
/// The checker decides, once, how: by the single-precision screen ([`FastChecker`],
/// [`FAST_LANES`] configurations at a time, exact answers) where the collision model compiles to
/// it — every valid model does — and otherwise by batched `f64` forward kinematics and the
/// exact model ([`CollisionModel::is_colliding`], [`LANES`] configurations at a time). Either
/// way the answers are the exact model's. Edges are checked *raked* ([`crate::edge::rake`]).
/// Caller-owned and allocation-free once made: make one per thread.
///
/// ```
/// use trm_collision::{CollisionModel, Shape, World, WorldChecker};
/// use trm_kinematics::nalgebra::Isometry3;
///
/// let robot = trm_models::icub_upper_body();
/// let home = robot.posture("home")?.to_vec();
/// let active = robot.active_set(&["torso_yaw", "r_shoulder_pitch", "r_elbow"], &home)?;
/// let collision = CollisionModel::new(&robot)?;
/// let mut world = World::new();
/// world.add("wall", Shape::Box { size: [0.05, 2.0, 2.0] }, Isometry3::translation(-0.6, 0.0, 0.0))?;
/// let mut checker = WorldChecker::new(&collision, &active, world)?;
/// let start = active.from_motors(&home);
/// assert!(checker.free(&start));
/// let mut bent = start.clone();
/// bent[1] -= 1.0;
/// // three points inside the edge, a quarter of a radian apart
/// assert!(checker.edge_free(&start, &bent, 0.25));
/// assert_eq!(checker.checks, 1 + 3);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Debug, Clone)]
pub struct WorldChecker {
    world: World,
    engine: Engine,
    /// The points of the edge being checked.
    samples: Vec<f64>,
    /// The robot and its active set (for the prover, made on first use).
    collision: CollisionModel,
    active: ActiveSet,
    /// Proofs in continuous motion, once asked for.
    prover: Option<Box<Prover>>,
    /// Whether an edge free at its points must also be proved free in continuous motion.
    proving: bool,
    /// Configurations checked so far (each point of an edge is one).
    pub checks: u64,
    /// Edges proved free, or refused, in continuous motion so far.
    pub certified: u64,
}

/// How a [`WorldChecker`] checks.
#[derive(Debug, Clone)]
enum Engine {
    /// The single-precision screen and the world compiled for it.
    Screen(Box<(FastChecker, FastWorld)>),
    /// Batched `f64` kinematics and the exact model.
    Exact(Box<Exact>),
}

/// Buffers of the `f64` checks.
#[derive(Debug, Clone)]
struct Exact {
    /// [`LANES`] configurations, one after the other.
    lanes: Vec<f64>,
    batch: PoseBatch,
    placed_batch: PlacedBatch,
    poses: PoseBuffer,
    placed: PlacedBodies,
}

impl WorldChecker {
    /// A checker of `collision`'s robot, moved by `active`'s coordinates, in `world`; an error
    /// for an active set of another robot.
    pub fn new(collision: &CollisionModel, active: &ActiveSet, world: World) -> Result<Self> {
        collision.check_active(active)?;
        let engine = match Self::screen_model(collision) {
            Some(_) => {
                let checker = FastChecker::new(collision, active.clone())?;
                let fast_world = checker.model().world(&world);
                Engine::Screen(Box::new((checker, fast_world)))
            }
            None => Engine::Exact(Box::new(Exact::new(collision, active))),
        };
        Ok(WorldChecker {
            world,
            engine,
            samples: Vec::new(),
            collision: collision.clone(),
            active: active.clone(),
            prover: None,
            proving: false,
            checks: 0,
            certified: 0,
        })
    }

    /// The single-precision screen's compilation of `collision` where the model compiles to it
    /// (every valid model does: `None` only for a body without enclosing spheres, which the
    /// exact model then checks). The one place that decides between the screen and the exact
    /// model, for this checker and for objectives that count collisions.
    pub fn screen_model(collision: &CollisionModel) -> Option<Arc<FastModel>> {
        FastModel::of(collision).ok()
    }

    /// The world checked against.
    pub fn world(&self) -> &World {
        &self.world
    }

    /// Replaces the world: the screen compiles again only the objects that were added, moved or
    /// reshaped ([`crate::fast::FastModel::world_after`]).
    pub fn set_world(&mut self, world: World) {
        if let Engine::Screen(screen) = &mut self.engine {
            let (checker, fast_world) = &mut **screen;
            *fast_world = checker.model().world_after(&world, &self.world, fast_world);
        }
        if let Some(prover) = &mut self.prover {
            prover.set_world(world.clone());
        }
        self.world = world;
    }

    /// Certified edges: with `on`, every edge check but [`WorldChecker::edge_midpoints_free`]
    /// also proves the edge free in continuous motion once its points are free
    /// ([`WorldChecker::prove`]), and refuses an edge it cannot prove; otherwise edges are
    /// checked at their points only. An error when the prover cannot be made.
    pub fn set_proving(&mut self, on: bool) -> Result<()> {
        if on {
            self.prover()?;
        }
        self.proving = on;
        Ok(())
    }

    /// Whether edges are proved free in continuous motion ([`WorldChecker::set_proving`]).
    pub fn is_proving(&self) -> bool {
        self.proving
    }

    /// What can be proved about the straight motion `a` → `b` in the world, in continuous
    /// motion ([`Prover`]: the robot padded, checked on this checker's engine, and exact
    /// distances near contact). An error for configurations the [`crate::Certifier`] refuses,
    /// or when the prover cannot be made.
    pub fn prove(&mut self, a: &[f64], b: &[f64]) -> Result<Certificate> {
        self.prover()?.segment(a, b)
    }

    /// The prover, made on first use for this robot and world.
    pub fn prover(&mut self) -> Result<&mut Prover> {
        if self.prover.is_none() {
            let prover = Prover::new(&self.collision, &self.active, self.world.clone())?;
            self.prover = Some(Box::new(prover));
        }
        Ok(self.prover.as_deref_mut().expect("made above"))
    }

    /// Whether the single-precision screen checks this robot.
    pub fn is_screened(&self) -> bool {
        matches!(self.engine, Engine::Screen(_))
    }

    /// The screen's checker, when it checks this robot (for its statistics).
    pub fn screen(&self) -> Option<&FastChecker> {
        match &self.engine {
            Engine::Screen(screen) => Some(&screen.0),
            Engine::Exact(_) => None,
        }
    }

    /// Configurations checked at once: [`FAST_LANES`] on the screen, else [`LANES`].
    pub fn width(&self) -> usize {
        if self.is_screened() {
            FAST_LANES
        } else {
            LANES
        }
    }

    /// Coordinates per configuration.
    pub fn dim(&self) -> usize {
        match &self.engine {
            Engine::Screen(screen) => screen.0.dim(),
            Engine::Exact(_) => self.active.len(),
        }
    }

    /// Whether `q` is free of self-collisions and of the world. A value that is not finite
    /// counts as colliding.
    ///
    /// # Panics
    /// If `q` does not hold [`WorldChecker::dim`] values.
    pub fn free(&mut self, q: &[f64]) -> bool {
        assert_eq!(q.len(), self.dim(), "one value per active motor");
        self.checks += 1;
        self.block_free(q)
    }

    /// Whether every configuration of `qs` (whole configurations, one after the other) is free,
    /// checked [`WorldChecker::width`] at a time, stopping at the first collision.
    ///
    /// # Panics
    /// If `qs` does not hold whole configurations.
    pub fn all_free(&mut self, qs: &[f64]) -> bool {
        let (d, width) = (self.dim(), self.width());
        assert!(d > 0 && qs.len().is_multiple_of(d), "whole configurations");
        self.checks += (qs.len() / d) as u64;
        qs.chunks(width * d).all(|block| self.block_free(block))
    }

    /// Whether the straight edge a → b is free at points no more than `resolution` apart in
    /// Euclidean distance ([`edge_steps`]), the end points not checked again.
    pub fn edge_free(&mut self, a: &[f64], b: &[f64], resolution: f64) -> bool {
        let steps = edge_steps(a, b, resolution);
        // interior points 1..steps (0 and steps are the checked ends)
        self.rake(a, b, steps - 1, |i| (i + 1) as f64 / steps as f64) && self.proved(a, b)
    }

    /// Whether the straight edge a → b is free at every `resolution` and at `b` (`a` is not
    /// checked): [`WorldChecker::edge_free`] with the end in the first block, so that a new
    /// node costs no block of its own.
    pub fn edge_and_end_free(&mut self, a: &[f64], b: &[f64], resolution: f64) -> bool {
        let steps = edge_steps(a, b, resolution);
        // from b back towards a: b first, where an extension usually fails
        self.rake(a, b, steps, |i| (steps - i) as f64 / steps as f64) && self.proved(a, b)
    }

    /// Whether the points halfway between those [`WorldChecker::edge_free`] checks at
    /// `resolution` are free: after `edge_free(a, b, resolution)`, the edge is then free at every
    /// `resolution / 2`, for half the checks of `edge_free(a, b, resolution / 2)`.
    pub fn edge_midpoints_free(&mut self, a: &[f64], b: &[f64], resolution: f64) -> bool {
        let steps = edge_steps(a, b, resolution);
        self.rake(a, b, steps, |i| (2 * i + 1) as f64 / (2 * steps) as f64)
    }

    /// Whether the straight segment a → b is free, both ends included, at points no more than
    /// `resolution` apart in Euclidean distance ([`edge_steps`]).
    pub fn segment_free(&mut self, a: &[f64], b: &[f64], resolution: f64) -> bool {
        let steps = edge_steps(a, b, resolution);
        self.rake(a, b, steps + 1, |s| s as f64 / steps as f64) && self.proved(a, b)
    }

    /// Whether the straight segment a → b is free, both ends included, at points along which no
    /// coordinate moves more than `resolution` ([`span_steps`]: a roadmap's edges).
    pub fn span_free(&mut self, a: &[f64], b: &[f64], resolution: f64) -> bool {
        let steps = span_steps(a, b, resolution);
        self.rake(a, b, steps + 1, |s| s as f64 / steps as f64) && self.proved(a, b)
    }

    /// Whether the edge a → b is proved free, when edges are proved
    /// ([`WorldChecker::set_proving`]).
    fn proved(&mut self, a: &[f64], b: &[f64]) -> bool {
        match (&mut self.prover, self.proving) {
            (Some(prover), true) => {
                self.certified += 1;
                prover.segment_unchecked(a, b).is_free()
            }
            _ => true,
        }
    }

    /// Whether the `n` points a + at(i)·(b − a), i < n, are free, visited raked.
    fn rake(&mut self, a: &[f64], b: &[f64], n: usize, at: impl Fn(usize) -> f64) -> bool {
        if n == 0 {
            return true;
        }
        let (d, width) = (a.len(), self.width());
        let mut samples = std::mem::take(&mut self.samples);
        let free = rake(d, a, b, n, at, width, &mut samples, self, |qs, me| {
            me.checks += (qs.len() / d) as u64;
            me.block_free(qs)
        });
        self.samples = samples;
        free
    }

    /// Which of the 1 to [`WorldChecker::width`] configurations of `qs` are free: bit `l` for
    /// configuration `l` (a value that is not finite collides). Checks every configuration to
    /// the end, where [`WorldChecker::all_free`] stops at the first collision; not counted.
    pub(crate) fn free_lanes(&mut self, qs: &[f64]) -> u8 {
        let n = qs.len() / self.dim();
        let all = u8::MAX >> (8 - n);
        match &mut self.engine {
            Engine::Screen(screen) => {
                let (checker, fast_world) = &mut **screen;
                let ([mut links, mut objects], mut free) = ([[0; FAST_LANES]; 2], 0);
                checker.count_unchecked(qs, &self.world, fast_world, &mut links, &mut objects);
                for l in 0..n {
                    if links[l] + objects[l] == 0 {
                        free |= 1 << l;
                    }
                }
                free
            }
            Engine::Exact(exact) => {
                all & !exact.colliding(&self.collision, &self.active, qs, &self.world)
            }
        }
    }

    /// Whether every configuration of `qs` (1 to [`WorldChecker::width`] of them) is free.
    fn block_free(&mut self, qs: &[f64]) -> bool {
        match &mut self.engine {
            Engine::Screen(screen) => {
                let (checker, fast_world) = &mut **screen;
                checker.all_free_unchecked(qs, &self.world, fast_world)
            }
            Engine::Exact(exact) => exact.all_free(&self.collision, &self.active, qs, &self.world),
        }
    }
}

impl Exact {
    /// Buffers for `collision`'s robot moved by `active`.
    fn new(collision: &CollisionModel, active: &ActiveSet) -> Self {
        let robot = collision.robot();
        Exact {
            lanes: vec![0.0; LANES * active.len()],
            batch: robot.pose_batch(),
            placed_batch: collision.placed_batch(),
            poses: robot.pose_buffer(),
            placed: collision.placed_bodies(),
        }
    }

    /// Whether the 1 to [`LANES`] configurations of `qs` are free.
    fn all_free(
        &mut self,
        collision: &CollisionModel,
        active: &ActiveSet,
        qs: &[f64],
        world: &World,
    ) -> bool {
        let several = qs.len() > active.len();
        !(several && qs.iter().any(|v| v.is_nan()))
            && self.colliding(collision, active, qs, world) == 0
    }

    /// Which of the 1 to [`LANES`] configurations of `qs` collide, bit `l` for configuration
    /// `l` (NaN collides): one configuration placed alone (through the batched kinematics, as
    /// every `f64` evaluation), several in a batch.
    fn colliding(
        &mut self,
        collision: &CollisionModel,
        active: &ActiveSet,
        qs: &[f64],
        world: &World,
    ) -> u8 {
        let d = active.len();
        let n = qs.len() / d;
        if n == 1 {
            if qs.iter().any(|v| v.is_nan()) {
                return 1;
            }
            for lane in 0..LANES {
                self.lanes[lane * d..(lane + 1) * d].copy_from_slice(qs);
            }
            active.forward_batch_unchecked(&self.lanes, &mut self.batch);
            self.batch.lane_into(0, &mut self.poses);
            collision.place(&self.poses, &mut self.placed);
            return u8::from(collision.is_colliding(&self.placed, world));
        }
        if qs.iter().any(|v| v.is_nan()) {
            return (qs.chunks_exact(d).enumerate())
                .map(|(l, q)| self.colliding(collision, active, q, world) << l)
                .fold(0, |mask, lane| mask | lane);
        }
        // a partial batch padded with its first configuration, whose answer is not used
        self.lanes[..qs.len()].copy_from_slice(qs);
        for l in n..LANES {
            self.lanes.copy_within(0..d, l * d);
        }
        active.forward_batch_unchecked(&self.lanes, &mut self.batch);
        collision.place_batch(&self.batch, n, &mut self.placed_batch);
        (collision.is_colliding_batch(&self.placed_batch, world)[..n].iter())
            .enumerate()
            .fold(0, |mask, (l, &hit)| mask | u8::from(hit) << l)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A checker of one robot moved by another robot's motors is an error naming both.
    #[test]
    fn an_active_set_of_another_robot_is_refused() {
        let upper = trm_models::icub_upper_body();
        let sagittal = trm_models::icub_sagittal();
        let collision = CollisionModel::new(&upper).unwrap();
        let e = WorldChecker::new(&collision, &sagittal.all_active(), World::new())
            .unwrap_err()
            .to_string();
        assert!(
            e.contains(sagittal.name()) && e.contains(upper.name()),
            "{e}"
        );
        let mut checker = WorldChecker::new(&collision, &upper.all_active(), World::new()).unwrap();
        assert!(checker.is_screened());
        let home = upper.posture("home").unwrap().to_vec();
        assert!(checker.free(&upper.all_active().from_motors(&home)));
    }

    /// Each engine's per-configuration verdicts of a block are its verdicts one at a time,
    /// NaN colliding, whether the block's first configuration collides or not.
    #[test]
    fn free_lanes_are_the_verdicts_one_at_a_time() {
        use rand::{RngExt, SeedableRng};
        let robot = trm_models::icub_upper_body();
        let home = robot.posture("home").unwrap().to_vec();
        let names = [
            "torso_yaw",
            "r_shoulder_pitch",
            "r_shoulder_roll",
            "r_elbow",
        ];
        let active = robot.active_set(&names, &home).unwrap();
        let collision = CollisionModel::new(&robot).unwrap();
        let mut world = World::new();
        let pose = trm_kinematics::nalgebra::Isometry3::translation(0.0, -0.3, 0.1);
        world
            .add("ball", crate::Shape::Sphere { radius: 0.12 }, pose)
            .unwrap();
        let limits: Vec<_> = (active.motor_indices().iter())
            .map(|&i| robot.motors()[i].limits)
            .collect();
        let mut screened = WorldChecker::new(&collision, &active, world.clone()).unwrap();
        let mut exact = WorldChecker::new(&collision, &active, world).unwrap();
        exact.engine = Engine::Exact(Box::new(Exact::new(&collision, &active)));
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
        let (mut free, mut colliding) = (0, 0);
        for round in 0..200 {
            for checker in [&mut screened, &mut exact] {
                let n = 1 + round % checker.width();
                let mut qs = Vec::new();
                for _ in 0..n {
                    qs.extend(limits.iter().map(|l| rng.random_range(l.lower..=l.upper)));
                }
                if round % 7 == 3 {
                    qs[(n - 1) * names.len()] = f64::NAN;
                }
                let lanes = checker.free_lanes(&qs);
                for (l, q) in qs.chunks(names.len()).enumerate() {
                    let one = checker.free(q);
                    assert_eq!(lanes & (1 << l) != 0, one, "round {round}, lane {l}");
                    match one {
                        true => free += 1,
                        false => colliding += 1,
                    }
                }
                assert_eq!(u16::from(lanes) >> n, 0, "no lane past the block");
            }
        }
        assert!(
            free > 100 && colliding > 100,
            "{free} free, {colliding} colliding"
        );
    }
}
