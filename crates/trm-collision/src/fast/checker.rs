use super::model::{FastModel, Suspect};
use super::outcome::Tally;
use super::walk::FastScratch;
use super::world::FastWorld;
use super::{ALL_LANES, FAST_LANES, LaneMask};
use crate::error::CollisionError;
use crate::error::Result;
use crate::model::CollisionModel;
use crate::placed::PlacedBodies;
use crate::world::World;
use std::sync::Arc;
use trm_kinematics::ActiveSet;
use trm_kinematics::PoseBlock;
use trm_kinematics::PoseBuffer;

/// Exact collision checks, [`FAST_LANES`] configurations at a time: forward kinematics of a
/// block in `f32`, the [`FastModel`] screen, and for each lane it leaves uncertain the exact
/// `f64` check of the pairs that left it so. Its answers are the exact model's
/// ([`CollisionModel::is_colliding`]); only the work differs. Caller-owned: make one per thread.
#[derive(Debug, Clone)]
pub struct FastChecker {
    pub(super) fast: Arc<FastModel>,
    pub(super) collision: CollisionModel,
    /// The active set, its kinematics computing the bodies' links (the exact `f64` checks).
    pub(super) active: ActiveSet,
    /// The active set, its kinematics computing the poses the screen reads (blocks in `f32`).
    pub(super) screen: ActiveSet,
    /// `FAST_LANES × dim` inputs (unused lanes repeat the first configuration).
    pub(super) inputs: Vec<f64>,
    pub(super) block: PoseBlock,
    pub(super) scratch: FastScratch,
    pub(super) pose: PoseBuffer,
    pub(super) placed: PlacedBodies,
    /// Configurations the `f32` screen left uncertain so far (each then checked exactly).
    pub uncertain: u64,
}

impl FastChecker {
    /// A checker of `collision`'s robot moved by `active`'s coordinates; an error for an active
    /// set of another robot.
    pub fn new(collision: &CollisionModel, active: ActiveSet) -> Result<Self> {
        let fast = FastModel::of(collision)?;
        collision.check_active(&active)?;
        let robot = collision.robot();
        // forward kinematics of the links the checks read only (bodies' links and the culling
        // spheres' centres), not of frames and links without geometry
        let links = (collision.bodies().iter().map(|b| b.link))
            .chain(fast.origins.iter().map(|&o| o as usize));
        // the screen's kinematics: the poses its balls are placed from (a sphere model's
        // fixed links are placed from the links they are attached to)
        let frames =
            (fast.groups.iter().map(|g| g.frame)).chain(fast.origins.iter().map(|&o| o as usize));
        let screen = active.pruned_to(frames);
        let active = active.pruned_to(links);
        Ok(FastChecker {
            screen,
            scratch: fast.scratch(),
            inputs: vec![0.0; FAST_LANES * active.len()],
            block: robot.pose_block(),
            pose: robot.pose_buffer(),
            placed: collision.placed_bodies(),
            fast,
            collision: collision.clone(),
            active,
            uncertain: 0,
        })
    }

    /// The compiled model.
    pub fn model(&self) -> &FastModel {
        &self.fast
    }

    /// Coordinates per configuration.
    pub fn dim(&self) -> usize {
        self.active.len()
    }

    /// Whether every configuration of `qs` (1 to [`FAST_LANES`] of them, one after the other)
    /// is free of self-collisions and of `world` (`fast_world` is `world` compiled by
    /// [`FastModel::world`]): the exact model's answer. An error for a length that is not 1 to
    /// [`FAST_LANES`] whole configurations or a value that is not finite.
    pub fn all_free(&mut self, qs: &[f64], world: &World, fast_world: &FastWorld) -> Result<bool> {
        self.check_block(qs)?;
        Ok(self.all_free_unchecked(qs, world, fast_world))
    }

    /// The number of configurations in `qs` (1 to [`FAST_LANES`] whole configurations of
    /// finite values), or an error that says what is wrong.
    pub(super) fn check_block(&self, qs: &[f64]) -> Result<usize> {
        let d = self.active.len();
        let n = qs.len() / d.max(1);
        if d == 0 || n == 0 || n > FAST_LANES || qs.len() != n * d {
            return Err(CollisionError::InvalidValue {
                what: format!("{} configuration values", qs.len()),
                problem: format!(
                    "are not 1 to {FAST_LANES} whole configurations of {d} active motors"
                ),
            });
        }
        if let Some(i) = qs.iter().position(|v| !v.is_finite()) {
            return Err(CollisionError::InvalidValue {
                what: format!("value {} of configuration {}", i % d, i / d),
                problem: format!("is {}, not a finite number", qs[i]),
            });
        }
        Ok(n)
    }

    /// [`FastChecker::all_free`] without its checks, for callers that made `qs` themselves:
    /// false for NaN; `qs` must hold 1 to [`FAST_LANES`] whole configurations (checked in debug
    /// builds; otherwise a wrong length gives a wrong answer or a panic, never unsafety).
    pub fn all_free_unchecked(
        &mut self,
        qs: &[f64],
        world: &World,
        fast_world: &FastWorld,
    ) -> bool {
        let d = self.active.len();
        let n = qs.len() / d.max(1);
        debug_assert!(
            d > 0 && n > 0 && n <= FAST_LANES && qs.len() == n * d,
            "1 to {FAST_LANES} whole configurations"
        );
        if any_nan(qs) {
            return false;
        }
        let live = self.forward_block(qs, n);
        let verdict = self
            .fast
            .check(self.block.lanes(), live, fast_world, &mut self.scratch);
        if verdict.colliding != 0 {
            return false;
        }
        // each uncertain lane: its suspects alone, exactly
        let FastChecker {
            fast,
            collision,
            active,
            scratch,
            pose,
            placed,
            uncertain,
            ..
        } = self;
        for l in (0..n).filter(|l| verdict.uncertain & (1 << l) != 0) {
            *uncertain += 1;
            active.forward_unchecked(&qs[l * d..(l + 1) * d], pose);
            for &(suspect, lanes) in &scratch.suspects {
                if lanes & (1 << l) != 0
                    && suspect_collides(fast, collision, pose, placed, world, suspect)
                {
                    return false;
                }
            }
        }
        true
    }

    /// The exact model's counts ([`CollisionModel::count_self`], [`CollisionModel::count_world`])
    /// of each configuration of `qs` (1 to [`FAST_LANES`] of them, one after the other) into
    /// `self_pairs` and `world_pairs`, as [`FastChecker::count_unchecked`] gives them. An error
    /// for a length that is not 1 to [`FAST_LANES`] whole configurations, a value that is not
    /// finite, or outputs shorter than the configurations.
    pub fn count(
        &mut self,
        qs: &[f64],
        world: &World,
        fast_world: &FastWorld,
        self_pairs: &mut [usize],
        world_pairs: &mut [usize],
    ) -> Result<()> {
        let n = self.check_block(qs)?;
        if self_pairs.len() < n || world_pairs.len() < n {
            return Err(CollisionError::InvalidValue {
                what: format!(
                    "outputs of {} and {} values",
                    self_pairs.len(),
                    world_pairs.len()
                ),
                problem: format!("hold fewer than the {n} configurations' counts"),
            });
        }
        self.count_unchecked(qs, world, fast_world, self_pairs, world_pairs);
        Ok(())
    }

    /// The exact model's counts ([`CollisionModel::count_self`], [`CollisionModel::count_world`])
    /// of each configuration of `qs` (1 to [`FAST_LANES`] of them, as
    /// [`FastChecker::all_free_unchecked`] takes them) into `self_pairs` and `world_pairs`: the
    /// pairs the screen finds certainly colliding ([`FastChecker::screen_counts_unchecked`]),
    /// and each pair it leaves uncertain checked exactly ([`FastChecker::exact_counts`], with
    /// the configuration's `f64` forward kinematics). `qs` must hold 1 to [`FAST_LANES`] whole
    /// configurations and the outputs one value per configuration (checked in debug builds).
    pub fn count_unchecked(
        &mut self,
        qs: &[f64],
        world: &World,
        fast_world: &FastWorld,
        self_pairs: &mut [usize],
        world_pairs: &mut [usize],
    ) {
        let d = self.active.len();
        debug_assert!(self_pairs.len() * d >= qs.len() && world_pairs.len() * d >= qs.len());
        let tally = self.screen_counts_unchecked(qs, fast_world);
        for (l, q) in qs.chunks_exact(d).enumerate() {
            if tally.uncertain & (1 << l) != 0 || q.iter().any(|v| !v.is_finite()) {
                self.active.forward_unchecked(q, &mut self.pose);
            }
            [self_pairs[l], world_pairs[l]] = self.counts_in(&tally, l, q, None, world);
        }
    }

    /// The screen's counts of the configurations of `qs` (as [`FastChecker::count_unchecked`]
    /// takes them): the pairs certainly colliding in each lane, and the lanes with pairs left
    /// uncertain, which stay in the checker for [`FastChecker::exact_counts`] until the next
    /// screen.
    pub fn screen_counts_unchecked(&mut self, qs: &[f64], fast_world: &FastWorld) -> Tally {
        let d = self.active.len();
        let n = qs.len() / d.max(1);
        debug_assert!(
            d > 0 && n > 0 && n <= FAST_LANES && qs.len() == n * d,
            "1 to {FAST_LANES} whole configurations"
        );
        let live = self.forward_block(qs, n);
        self.fast
            .count(self.block.lanes(), live, fast_world, &mut self.scratch)
    }

    /// The exact counts [link pairs, (link, object) pairs] of lane `l` of the last screen
    /// (`tally`, its configuration `q`): the screen's, plus each pair it left uncertain in that
    /// lane checked exactly in the link poses `pose` (read only then). A configuration with a
    /// value that is not finite is counted by the `f64` model alone.
    pub fn exact_counts(
        &mut self,
        tally: &Tally,
        l: usize,
        q: &[f64],
        pose: &PoseBuffer,
        world: &World,
    ) -> [usize; 2] {
        self.counts_in(tally, l, q, Some(pose), world)
    }

    /// [`FastChecker::exact_counts`] in `pose`, or in the checker's own pose buffer.
    pub(super) fn counts_in(
        &mut self,
        tally: &Tally,
        l: usize,
        q: &[f64],
        pose: Option<&PoseBuffer>,
        world: &World,
    ) -> [usize; 2] {
        let FastChecker {
            fast,
            collision,
            placed,
            scratch,
            uncertain,
            pose: own,
            ..
        } = self;
        let pose = pose.unwrap_or(own);
        if q.iter().any(|v| !v.is_finite()) {
            collision.place(pose, placed);
            return [
                collision.count_self(placed),
                collision.count_world(placed, world),
            ];
        }
        let mut counts = [tally.self_pairs[l] as usize, tally.world_pairs[l] as usize];
        if tally.uncertain & (1 << l) != 0 {
            *uncertain += 1;
            for &(suspect, lanes) in &scratch.suspects {
                if lanes & (1 << l) != 0
                    && suspect_collides(fast, collision, pose, placed, world, suspect)
                {
                    counts[matches!(suspect, Suspect::Object { .. }) as usize] += 1;
                }
            }
        }
        counts
    }

    /// Forward kinematics (`f32`) of the `n` configurations of `qs` into the block, a partial
    /// block padded with its first configuration; the lanes in use.
    pub(super) fn forward_block(&mut self, qs: &[f64], n: usize) -> LaneMask {
        let d = self.active.len();
        // a full block straight from the caller; a partial one padded with its first lane
        let inputs = if n == FAST_LANES {
            qs
        } else {
            self.inputs[..n * d].copy_from_slice(qs);
            for l in n..FAST_LANES {
                self.inputs.copy_within(..d, l * d);
            }
            &self.inputs
        };
        self.screen.forward_block_unchecked(inputs, &mut self.block);
        if n == FAST_LANES {
            ALL_LANES
        } else {
            (1 << n) - 1
        }
    }
}

/// Whether `suspect` collides exactly (`f64`) in the configuration whose link poses are `pose`.
pub(super) fn suspect_collides(
    fast: &FastModel,
    collision: &CollisionModel,
    pose: &PoseBuffer,
    placed: &mut PlacedBodies,
    world: &World,
    suspect: Suspect,
) -> bool {
    match suspect {
        Suspect::Pair(k) => fast.group_pairs[k as usize].bodies.iter().any(|&(a, b)| {
            let (a, b) = (a as usize, b as usize);
            collision.place_body(pose, a, placed);
            collision.place_body(pose, b, placed);
            collision.bodies_touch(placed, a, b)
        }),
        Suspect::Object { object, group } => fast.groups[group as usize].bodies.iter().any(|&b| {
            collision.place_body(pose, b as usize, placed);
            collision.body_touches_object(placed, b as usize, world, object as usize)
        }),
    }
}

/// Whether a value is NaN: every value looked at (a vector loop, 4 wide with AVX), not the
/// first NaN searched for.
#[allow(unsafe_code)] // multiversion's run-time CPU-feature dispatch
#[multiversion::multiversion(targets("x86_64+avx2", "x86_64+avx", "aarch64+neon"))]
fn any_nan(qs: &[f64]) -> bool {
    qs.iter().fold(false, |nan, v| nan | v.is_nan())
}
