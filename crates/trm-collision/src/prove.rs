//! Fast proofs of straight motions: the [`Certifier`]'s verdict for most of a motion at the
//! cost of a discrete check.
//!
//! A configuration where the robot grown by a margin `m` ([`CollisionModel::padded`]) is free
//! keeps every checked pair at least `m` apart from the world and `2m` from the robot's other
//! bodies. Between two such configurations a body moves no farther than the lever-arm bound of
//! the step ([`Levers`]), and two bodies close in on each other by at most their relative
//! bound, so when those stay below `2m` and `4m` the pair cannot close the gap anywhere between
//! (it would have to come from `m`, or `2m`, away at both ends): the step is proved. [`Prover`]
//! checks a motion's configurations, that close together, with the fast checker
//! ([`WorldChecker`]) of the robot padded by a coarse margin, then the stretches it could not
//! prove with finer ones (only the steps into and out of a configuration that the margin
//! fails: the configurations of a block are judged one by one), and gives the [`Certifier`]
//! (exact distances and bisection) only the stretches that come within the finest margin of
//! contact. The margins shrink fourfold from level to level, down to a fraction of a
//! millimetre: a path pulled tight along an obstacle by shortcutting runs a few tenths of a
//! millimetre from it for centimetres, which padded checks prove for less than exact
//! distances do.
//!
//! Link pairs that one or two coordinates alone move relative to each other (a wrist's links)
//! may stay closer than any margin for good, yet barely move relative to each other: they are
//! proved apart from the rest, in no world, at steps bounded by their relative motion alone.

use trm_kinematics::ActiveSet;

use crate::certify::{Certificate, Certifier, check_configuration};
use crate::checker::WorldChecker;
use crate::error::Result;
use crate::levers::Levers;
use crate::model::CollisionModel;
use crate::world::World;

/// The margins the robot is padded by against the world and its distant link pairs, m, coarse
/// to fine.
pub const MARGINS: [f64; 5] = [0.032, 0.008, 0.002, 0.0005, 0.000125];

/// The margins for the link pairs [`NEAR_COORDINATES`] or fewer coordinates move relative to
/// each other, m, coarse to fine.
pub const NEAR_MARGINS: [f64; 2] = [0.004, 0.001];

/// Link pairs that this many active coordinates or fewer move relative to each other are
/// proved on their own ([module](self)).
pub const NEAR_COORDINATES: usize = 2;

/// A step's bound must stay this share below its limit (for rounding).
const ROUNDING: f64 = 1e-9;

/// One margin: the pairs' model padded by it, and its checker in the family's world (made
/// when a stretch first needs it; the coarsest at once).
#[derive(Debug, Clone)]
struct Level {
    margin: f64,
    padded: CollisionModel,
    checker: Option<WorldChecker>,
    /// The configurations of a block, one after the other.
    samples: Vec<f64>,
}

/// Pairs proved together: the padded models that check them, how far they can close in, and
/// the certifier of what the finest margin leaves.
#[derive(Debug, Clone)]
struct Family {
    levels: Vec<Level>,
    /// The model the certifier is made of, and the certifier once needed.
    model: CollisionModel,
    certifier: Option<Certifier>,
    /// How far the pairs close in per unit of each active coordinate: one row per link for
    /// the world and distant pairs (which close in by at most twice a link's motion), one per
    /// link pair for near pairs (their relative motion). `limit` × margin bounds a step.
    rows: Vec<Vec<f64>>,
    limit: f64,
    /// The current motion's bound, over the whole motion.
    reach: f64,
}

impl Family {
    /// A family checking the pairs of `model`, padded by `margins` as `padded` pads it, in
    /// `world`.
    fn new(
        model: CollisionModel,
        padded: impl Fn(f64) -> Result<CollisionModel>,
        active: &ActiveSet,
        margins: &[f64],
        world: &World,
        (rows, limit): (Vec<Vec<f64>>, f64),
    ) -> Result<Self> {
        let mut levels = (margins.iter())
            .map(|&margin| {
                let padded = padded(margin)?;
                Ok(Level {
                    margin,
                    padded,
                    checker: None,
                    samples: Vec::new(),
                })
            })
            .collect::<Result<Vec<_>>>()?;
        if let Some(coarsest) = levels.first_mut() {
            coarsest.checker = Some(WorldChecker::new(&coarsest.padded, active, world.clone())?);
        }
        Ok(Family {
            levels,
            model,
            certifier: None,
            rows,
            limit,
            reach: 0.0,
        })
    }

    /// The farthest the pairs close in along `delta`.
    fn reach_of(&self, delta: &[f64]) -> f64 {
        (self.rows.iter())
            .map(|row| row.iter().zip(delta).map(|(l, d)| l * d.abs()).sum::<f64>())
            .fold(0.0, f64::max)
    }
}

/// Buffers of the motion being proved.
#[derive(Debug, Clone, Default)]
struct Motion {
    /// Its start and change.
    start: Vec<f64>,
    delta: Vec<f64>,
    /// The ends of a stretch handed to a certifier.
    ends: [Vec<f64>; 2],
}

impl Motion {
    /// Writes the configuration at fraction `u` of the motion into `out`, after what it holds.
    fn at(&self, u: f64, out: &mut Vec<f64>) {
        out.extend(self.start.iter().zip(&self.delta).map(|(x, d)| x + u * d));
    }
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
    /// The world and the distant link pairs; then the near link pairs, in no world.
    families: [Family; 2],
    world: World,
    none: World,
    collision: CollisionModel,
    active: ActiveSet,
    motion: Motion,
    /// Configurations checked on the padded robots so far.
    pub checks: u64,
    /// Stretches handed to a certifier so far.
    pub exact: u64,
}

impl Prover {
    /// A prover of `collision`'s robot moved by `active`'s coordinates in `world`, with
    /// [`MARGINS`] and [`NEAR_MARGINS`]; an error for an active set of another robot.
    pub fn new(collision: &CollisionModel, active: &ActiveSet, world: World) -> Result<Self> {
        let levers = Levers::new(collision, active)?;
        let n = active.len();
        let (mut near, mut near_rows) = (Vec::new(), Vec::new());
        for [a, b] in collision.checked_link_pairs() {
            let mut relative = vec![0.0; n];
            levers.relative_into(a, b, &mut relative);
            if relative.iter().filter(|&&l| l > 0.0).count() <= NEAR_COORDINATES {
                near.push([a, b]);
                near_rows.push(relative);
            }
        }
        let far_rows = levers.links().iter().map(|(_, l)| l.clone()).collect();
        let none = World::new();
        // a link moves at most its row: the world's gap m and two bodies' 2m stay closed to a
        // step below 2m; two near bodies' relative motion is their row, against their 4m
        let far = Family::new(
            collision.clone(),
            |margin| collision.padded(margin, &near),
            active,
            &MARGINS,
            &world,
            (far_rows, 2.0),
        )?;
        let only_near = collision.only_pairs(&near)?;
        let near = Family::new(
            only_near.clone(),
            |margin| only_near.padded(margin, &[]),
            active,
            &NEAR_MARGINS,
            &none,
            (near_rows, 4.0),
        )?;
        Ok(Prover {
            families: [far, near],
            world,
            none,
            collision: collision.clone(),
            active: active.clone(),
            motion: Motion::default(),
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
        for level in &mut self.families[0].levels {
            if let Some(checker) = &mut level.checker {
                checker.set_world(world.clone());
            }
        }
        self.world = world;
    }

    /// What can be proved about the straight motion `a` → `b` (active coordinates): free, or
    /// the [`Certifier`]'s verdict on a stretch it could not prove (its fraction `at` of the
    /// whole motion). An error as for [`Certifier::segment`].
    pub fn segment(&mut self, a: &[f64], b: &[f64]) -> Result<Certificate> {
        check_configuration(&self.collision, &self.active, a)?;
        check_configuration(&self.collision, &self.active, b)?;
        Ok(self.segment_unchecked(a, b))
    }

    /// [`Prover::segment`] without checking the configurations.
    pub fn segment_unchecked(&mut self, a: &[f64], b: &[f64]) -> Certificate {
        let motion = &mut self.motion;
        motion.start.clear();
        motion.start.extend_from_slice(a);
        motion.delta.clear();
        motion.delta.extend(b.iter().zip(a).map(|(y, x)| y - x));
        // the near pairs first: they cost least, and a wrist that folds onto itself fails there
        for f in [1, 0] {
            let family = &mut self.families[f];
            family.reach = family.reach_of(&self.motion.delta);
            let verdict = self.cover(f, 0, 0.0, 1.0);
            if !verdict.is_free() {
                return verdict;
            }
        }
        Certificate::Free
    }

    /// Proves family `f`'s pairs over the stretch `u0`..`u1` of the motion with its level
    /// `level`'s margin, each run of steps that leaves (a step whose end fails the margin)
    /// with the next level, and the rest with its certifier.
    fn cover(&mut self, f: usize, level: usize, u0: f64, u1: f64) -> Certificate {
        let family = &self.families[f];
        let Some(&Level { margin, .. }) = family.levels.get(level) else {
            return self.exactly(f, u0, u1);
        };
        // points close enough that a step's bound stays below the limit
        let bound = family.reach * (u1 - u0);
        let steps = (bound / (family.limit * margin * (1.0 - ROUNDING)))
            .ceil()
            .max(1.0) as usize;
        let at = |i: usize| match i == steps {
            true => u1,
            false => u0 + (u1 - u0) * i as f64 / steps as f64,
        };
        let world = if f == 0 { &self.world } else { &self.none };
        let Level {
            padded, checker, ..
        } = &mut self.families[f].levels[level];
        let checker = match checker {
            Some(checker) => checker,
            none => none.insert(
                WorldChecker::new(padded, &self.active, world.clone())
                    .expect("the prover's robot moved by its active set"),
            ),
        };
        let width = checker.width();
        let mut samples = std::mem::take(&mut self.families[f].levels[level].samples);
        // the first point of the run of steps not yet proved, and whether the point before
        // the one at hand is free
        let (mut open, mut last_free) = (None, true);
        let (mut first, mut verdict) = (0, Certificate::Free);
        'blocks: while first <= steps {
            let n = width.min(steps + 1 - first);
            samples.clear();
            for i in first..first + n {
                self.motion.at(at(i), &mut samples);
            }
            self.checks += n as u64;
            let checker = self.families[f].levels[level].checker.as_mut();
            let free = checker.expect("made above").free_lanes(&samples);
            for (i, l) in (first..first + n).zip(0..) {
                let here = free & (1 << l) != 0;
                // the step into point i: proved when both its ends are free
                match (open, i > 0 && !(last_free && here)) {
                    (None, true) => open = Some(i - 1),
                    (Some(lo), false) if i > 0 => {
                        open = None;
                        verdict = self.cover(f, level + 1, at(lo), at(i - 1));
                        if !verdict.is_free() {
                            break 'blocks;
                        }
                    }
                    _ => {}
                }
                last_free = here;
            }
            first += n;
        }
        if let Some(lo) = open
            && verdict.is_free()
        {
            verdict = self.cover(f, level + 1, at(lo), at(steps));
        }
        self.families[f].levels[level].samples = samples;
        verdict
    }

    /// Family `f`'s certifier's verdict on the stretch `u0`..`u1` of the motion.
    fn exactly(&mut self, f: usize, u0: f64, u1: f64) -> Certificate {
        self.exact += 1;
        let family = &mut self.families[f];
        let certifier = match &mut family.certifier {
            Some(c) => c,
            none => none.insert(
                Certifier::new(&family.model, &self.active)
                    .expect("the prover's model moved by its active set"),
            ),
        };
        let mut ends = std::mem::take(&mut self.motion.ends);
        for (end, u) in ends.iter_mut().zip([u0, u1]) {
            end.clear();
            self.motion.at(u, end);
        }
        let world = if f == 0 { &self.world } else { &self.none };
        let within = |at: f64| u0 + at * (u1 - u0);
        let verdict = certifier.segment_unchecked(world, &ends[0], &ends[1]);
        self.motion.ends = ends;
        match verdict {
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
