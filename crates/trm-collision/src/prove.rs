//! Fast proofs of straight motions: the [`Certifier`]'s verdict for most of a motion at the
//! cost of a discrete check.
//!
//! A configuration where the robot grown by a margin `m` ([`CollisionModel::padded`]) is free
//! keeps every checked pair at least `m` apart (two of its bodies `2m`). Between two such
//! configurations no point moves farther than the lever-arm bound of the step ([`Levers`]), so
//! when that bound is below `2m` the pair cannot close the gap anywhere between (it would have to
//! come from `m` away at both ends): the step is proved. [`Prover`] checks a motion's
//! configurations, that close together, with the fast checker ([`WorldChecker`]) of the robot
//! padded by a coarse margin, then the stretches it could not prove with a finer one, and
//! gives the [`Certifier`] (exact distances and bisection) only the stretches that come within
//! the finest margin of contact.

use trm_kinematics::ActiveSet;

use crate::certify::{Certificate, Certifier};
use crate::checker::WorldChecker;
use crate::error::Result;
use crate::levers::Levers;
use crate::model::CollisionModel;
use crate::world::World;

/// The margins of [`Prover::new`], m, coarse to fine.
pub const MARGINS: [f64; 3] = [0.032, 0.008, 0.002];

/// Link pairs that this many active coordinates or fewer move relative to each other (a
/// wrist's links) are left to the certifier: they may stay closer than any margin for good,
/// and, barely moving apart, are proved in a few steps.
pub const NEAR_COORDINATES: usize = 2;

/// A step's bound must stay this share below twice the margin (for rounding).
const ROUNDING: f64 = 1e-9;

/// One margin: the robot padded by it, checked in the prover's world.
#[derive(Debug, Clone)]
struct Level {
    margin: f64,
    checker: WorldChecker,
}

/// Proves straight motions of one robot free in one world, fast (see the [module](self)):
/// what it proves, the [`Certifier`] proves too, and what it cannot, the certifier decides.
/// Caller-owned: buffers grow to the largest motion checked and are reused.
///
/// ```
/// use trm_collision::{CollisionModel, Shape, World};
/// use trm_collision::prove::Prover;
/// use trm_kinematics::nalgebra::Isometry3;
///
/// let robot = trm_models::icub_upper_body();
/// let home = robot.posture("home")?.to_vec();
/// let active = robot.active_set(&["r_shoulder_pitch", "r_elbow"], &home)?;
/// let collision = CollisionModel::new(&robot)?;
/// let mut world = World::new();
/// world.add("post", Shape::Cylinder { radius: 0.02, length: 2.0 }, Isometry3::translation(0.0, -0.5, 0.0))?;
/// let mut prover = Prover::new(&collision, &active, world)?;
/// let start = active.from_motors(&home);
/// let mut raised = start.clone();
/// raised[0] -= 0.5;
/// assert!(prover.segment(&start, &raised)?.is_free());
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Debug, Clone)]
pub struct Prover {
    /// The certifier of the link pairs the padded robots do not check, in no world.
    near: Certifier,
    none: World,
    /// The certifier of everything, for the stretches the padded robots cannot prove.
    certifier: Certifier,
    levers: Levers,
    levels: Vec<Level>,
    world: World,
    /// The configurations of a block, one after the other (reused).
    samples: Vec<f64>,
    /// The ends of a stretch handed to the certifier (reused).
    ends: [Vec<f64>; 2],
    /// The current motion's change, and the farthest a point moves over it.
    delta: Vec<f64>,
    reach: f64,
    /// Configurations checked on the padded robots so far.
    pub checks: u64,
    /// Stretches handed to the certifier so far.
    pub exact: u64,
}

impl Prover {
    /// A prover of `collision`'s robot moved by `active`'s coordinates in `world`, with
    /// [`MARGINS`]; an error for an active set of another robot.
    pub fn new(collision: &CollisionModel, active: &ActiveSet, world: World) -> Result<Self> {
        let levers = Levers::new(collision, active)?;
        // the link pairs that at most NEAR_COORDINATES coordinates move relative to each other
        let mut relative = vec![0.0; active.len()];
        let near: Vec<[usize; 2]> = (collision.checked_link_pairs().into_iter())
            .filter(|&[a, b]| {
                levers.relative_into(a, b, &mut relative);
                relative.iter().filter(|&&l| l > 0.0).count() <= NEAR_COORDINATES
            })
            .collect();
        let levels = MARGINS
            .iter()
            .map(|&margin| {
                let padded = collision.padded(margin, &near)?;
                Ok(Level {
                    margin,
                    checker: WorldChecker::new(&padded, active, world.clone())?,
                })
            })
            .collect::<Result<_>>()?;
        Ok(Prover {
            near: Certifier::new(&collision.only_pairs(&near)?, active)?,
            none: World::new(),
            certifier: Certifier::new(collision, active)?,
            levers,
            levels,
            world,
            samples: Vec::new(),
            ends: [Vec::new(), Vec::new()],
            delta: Vec::new(),
            reach: 0.0,
            checks: 0,
            exact: 0,
        })
    }

    /// The world it proves motions in.
    pub fn world(&self) -> &World {
        &self.world
    }

    /// Replaces the world (the padded robots' checks compile again only what changed).
    pub fn set_world(&mut self, world: World) {
        for level in &mut self.levels {
            level.checker.set_world(world.clone());
        }
        self.world = world;
    }

    /// The certifier it hands the stretches near contact to.
    pub fn certifier(&self) -> &Certifier {
        &self.certifier
    }

    /// What can be proved about the straight motion `a` → `b` (active coordinates): free, or
    /// the [`Certifier`]'s verdict on the stretch it could not prove (its fraction `at` of the
    /// whole motion). An error as for [`Certifier::segment`].
    pub fn segment(&mut self, a: &[f64], b: &[f64]) -> Result<Certificate> {
        self.certifier.check_configuration(a)?;
        self.certifier.check_configuration(b)?;
        Ok(self.segment_unchecked(a, b))
    }

    /// [`Prover::segment`] without checking the configurations.
    pub fn segment_unchecked(&mut self, a: &[f64], b: &[f64]) -> Certificate {
        self.delta.clear();
        self.delta.extend(b.iter().zip(a).map(|(y, x)| y - x));
        self.reach = self.levers.displacement(&self.delta);
        match self.near.segment_unchecked(&self.none, a, b) {
            Certificate::Free => self.cover(0, a, 0.0, 1.0),
            not => not,
        }
    }

    /// Proves the stretch `u0`..`u1` of the motion from `a` with level `level`'s margin, the
    /// stretches it leaves with the next level, and the rest with the certifier.
    fn cover(&mut self, level: usize, a: &[f64], u0: f64, u1: f64) -> Certificate {
        let Some(Level { margin, .. }) = self.levels.get(level) else {
            return self.exactly(a, u0, u1);
        };
        // points close enough that a step's bound stays below twice the margin
        let bound = self.reach * (u1 - u0);
        let steps = (bound / (2.0 * margin * (1.0 - ROUNDING))).ceil().max(1.0) as usize;
        let at = |i: usize| match i == steps {
            true => u1,
            false => u0 + (u1 - u0) * i as f64 / steps as f64,
        };
        let width = self.levels[level].checker.width();
        let mut samples = std::mem::take(&mut self.samples);
        // the points of the stretch not yet proved: from .0 to .1
        let mut open: Option<(usize, usize)> = None;
        let mut first = 0;
        let mut verdict = Certificate::Free;
        while first <= steps {
            let n = width.min(steps + 1 - first);
            samples.clear();
            for i in first..first + n {
                let u = at(i);
                samples.extend(a.iter().zip(&self.delta).map(|(x, d)| x + u * d));
            }
            self.checks += n as u64;
            let free = self.levels[level].checker.all_free(&samples);
            if !free {
                // the steps into, within and out of the block
                let (lo, hi) = (first.saturating_sub(1), (first + n).min(steps));
                open = Some(match open {
                    Some((start, _)) => (start, hi),
                    None => (lo, hi),
                });
            }
            first += n;
            if let Some((lo, hi)) = open
                && (free || first > steps)
            {
                open = None;
                verdict = self.cover(level + 1, a, at(lo), at(hi));
                if !verdict.is_free() {
                    break;
                }
            }
        }
        self.samples = samples;
        verdict
    }

    /// The certifier's verdict on the stretch `u0`..`u1` of the motion from `a`.
    fn exactly(&mut self, a: &[f64], u0: f64, u1: f64) -> Certificate {
        self.exact += 1;
        let [start, end] = &mut self.ends;
        for (out, u) in [(&mut *start, u0), (&mut *end, u1)] {
            out.clear();
            out.extend(a.iter().zip(&self.delta).map(|(x, d)| x + u * d));
        }
        let within = |at: f64| u0 + at * (u1 - u0);
        match self.certifier.segment_unchecked(&self.world, start, end) {
            Certificate::Free => Certificate::Free,
            Certificate::Collides { at, pair } => Certificate::Collides {
                at: within(at),
                pair,
            },
            Certificate::Unproved {
                at,
                pair,
                clearance,
            } => Certificate::Unproved {
                at: within(at),
                pair,
                clearance,
            },
        }
    }
}
