//! Certified motion checks: a straight motion between two configurations proved free in
//! continuous motion, not at samples.
//!
//! Between configurations `q₀` and `q₁` no point of a link moves farther than its lever arms
//! allow ([`Levers`]): a step `Δq` changes the distance between two bodies by at most
//! `r = Σᵢ |Δqᵢ| λᵢ`, λ their relative lever arms (the joints their chains share move both
//! rigidly and do not count), and a body's distance to a world object by its own. So a pair
//! whose exact distances `d₀`, `d₁` at the two ends satisfy `d₀ + d₁ > r` keeps apart along the
//! whole motion (the free-space bubbles of Quinlan, 1994, and the adaptive dynamic check of
//! Schwarzer, Saha and Latombe, T-RO 2005). Pairs that the bound does not clear are bisected,
//! each on its own, until it does or the pair's bound over the piece falls below a *floor*.
//!
//! Every motion that keeps at least `floor` clearance for every checked pair is proved free; a
//! motion that is not proved either collides at a configuration the check visited
//! ([`Certificate::Collides`]) or comes closer than `floor` to contact at one
//! ([`Certificate::Unproved`]). The check is `f64`, exact distances (the collision model's own
//! bodies) and its own code path: it shares no sampling with the planners it verifies.

use trm_kinematics::{ActiveSet, PoseBuffer};

use crate::error::{CollisionError, Result};
use crate::levers::Levers;
use crate::model::CollisionModel;
use crate::placed::PlacedBodies;
use crate::shape::signed_distance;
use crate::world::World;

/// The floor of [`Certifier::new`]: 1 µm.
pub const DEFAULT_FLOOR: f64 = 1e-6;

/// How far outside its limits a configuration's value may lie (MoveIt's requests round
/// limits; the lever arms of prismatic joints allow for it).
pub const TRAVEL_SLACK: f64 = 1e-4;

/// Slack for rounding in the distances (m): a pair is cleared when `d₀ + d₁ > r + SLACK`.
const SLACK: f64 = 1e-9;

/// Two things whose distance a certificate is about.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Contact {
    /// Two bodies of the robot ([`CollisionModel::bodies`] indices).
    Bodies(usize, usize),
    /// A body of the robot and a world object ([`World::objects`] index).
    Object(usize, usize),
}

/// What [`Certifier::segment`] proved about a straight motion.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Certificate {
    /// Free in continuous motion: every checked pair keeps a positive distance all along.
    Free,
    /// The configuration at fraction `at` of the motion (0 its start, 1 its end) collides:
    /// `pair` overlaps.
    Collides {
        /// Fraction of the motion.
        at: f64,
        /// The overlapping pair.
        pair: Contact,
    },
    /// Not proved: at fraction `at` the configuration is free but `pair` is closer than the
    /// floor (by `clearance`, m), and the bound cannot clear its neighbourhood.
    Unproved {
        /// Fraction of the motion.
        at: f64,
        /// The pair.
        pair: Contact,
        /// Its distance there, m.
        clearance: f64,
    },
}

impl Certificate {
    /// Whether the motion is proved free.
    pub fn is_free(&self) -> bool {
        matches!(self, Certificate::Free)
    }
}

/// What [`Certifier::path`] proved about a path: the first segment not proved free, if any.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PathCertificate {
    /// The first segment (`waypoints[segment]` to `waypoints[segment + 1]`) not proved free
    /// and its certificate; `None` when every segment is proved free.
    pub failure: Option<(usize, Certificate)>,
}

impl PathCertificate {
    /// Whether the whole path is proved free.
    pub fn is_free(&self) -> bool {
        self.failure.is_none()
    }
}

/// A pair still open over a piece of the motion: its distances at the piece's two ends.
#[derive(Debug, Clone, Copy)]
struct Open {
    unit: u32,
    d0: f64,
    d1: f64,
}

/// A piece of the motion and the pairs its ends leave open.
#[derive(Debug, Clone)]
struct Piece {
    u0: f64,
    u1: f64,
    open: Vec<Open>,
}

/// Proves straight motions of one robot free in one world (see the [module](self)).
/// Caller-owned: buffers grow to the largest motion checked and are reused.
///
/// ```
/// use trm_collision::{Certificate, Certifier, CollisionModel, Shape, World};
/// use trm_kinematics::nalgebra::Isometry3;
///
/// let robot = trm_models::icub_upper_body();
/// let home = robot.posture("home")?.to_vec();
/// let active = robot.active_set(&["r_shoulder_pitch", "r_elbow"], &home)?;
/// let collision = CollisionModel::new(&robot)?;
/// let mut certifier = Certifier::new(&collision, &active)?;
/// let start = active.from_motors(&home);
/// let mut raised = start.clone();
/// raised[0] -= 0.5;
/// assert!(certifier.segment(&World::new(), &start, &raised)?.is_free());
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Debug, Clone)]
pub struct Certifier {
    collision: CollisionModel,
    active: ActiveSet,
    floor: f64,
    /// Per checked body pair: the relative lever arms of its two links, per active coordinate.
    pair_levers: Vec<Vec<f64>>,
    /// Per body: its link's lever arms, per active coordinate.
    body_levers: Vec<Vec<f64>>,
    /// Per unit of the current motion (checked body pairs, then body × object): its bound `r`
    /// over the whole motion.
    rates: Vec<f64>,
    /// Per unit: the bounding-sphere lower bounds at the motion's two ends.
    ends: [Vec<f64>; 2],
    poses: PoseBuffer,
    placed: PlacedBodies,
    q: Vec<f64>,
    /// Pieces to prove, and spare lists of open pairs.
    stack: Vec<Piece>,
    spare: Vec<Vec<Open>>,
    /// Configurations placed and exact distances computed so far.
    pub configurations: u64,
    /// Exact distances computed so far.
    pub distances: u64,
}

impl Certifier {
    /// A certifier of `collision`'s robot moved by `active`'s coordinates, with
    /// [`DEFAULT_FLOOR`]; an error for an active set of another robot.
    pub fn new(collision: &CollisionModel, active: &ActiveSet) -> Result<Self> {
        let levers = Levers::new(collision, active)?;
        let n = active.len();
        let link = |b: usize| collision.bodies()[b].link;
        let pair_levers = collision
            .pairs()
            .iter()
            .map(|p| {
                let mut out = vec![0.0; n];
                levers.relative_into(link(p.a as usize), link(p.b as usize), &mut out);
                out
            })
            .collect();
        let body_levers = (0..collision.bodies().len())
            .map(|b| {
                let mut out = vec![0.0; n];
                levers.link_into(link(b), &mut out);
                out
            })
            .collect();
        let robot = collision.robot();
        Ok(Certifier {
            collision: collision.clone(),
            active: active.clone(),
            floor: DEFAULT_FLOOR,
            pair_levers,
            body_levers,
            rates: Vec::new(),
            ends: [Vec::new(), Vec::new()],
            poses: robot.pose_buffer(),
            placed: collision.placed_bodies(),
            q: vec![0.0; n],
            stack: Vec::new(),
            spare: Vec::new(),
            configurations: 0,
            distances: 0,
        })
    }

    /// The same certifier with another floor (m; finite and positive, else an error).
    pub fn with_floor(mut self, floor: f64) -> Result<Self> {
        if !(floor.is_finite() && floor > 0.0) {
            return Err(CollisionError::InvalidValue {
                what: "the certified check's floor".into(),
                problem: format!("{floor} is not a positive distance (m); 1e-6 is the default"),
            });
        }
        self.floor = floor;
        Ok(self)
    }

    /// The floor, m.
    pub fn floor(&self) -> f64 {
        self.floor
    }

    /// The collision model it checks.
    pub fn collision(&self) -> &CollisionModel {
        &self.collision
    }

    /// What can be proved about the straight motion `a` → `b` (active coordinates) in `world`.
    /// An error when a configuration does not hold one finite value per active coordinate
    /// within the motors' limits (up to [`TRAVEL_SLACK`]).
    pub fn segment(&mut self, world: &World, a: &[f64], b: &[f64]) -> Result<Certificate> {
        self.check_configuration(a)?;
        self.check_configuration(b)?;
        Ok(self.segment_unchecked(world, a, b))
    }

    /// What can be proved about the path through `waypoints` in `world`: each segment in
    /// turn, up to the first not proved free. An error as for [`Certifier::segment`].
    pub fn path(&mut self, world: &World, waypoints: &[Vec<f64>]) -> Result<PathCertificate> {
        for q in waypoints {
            self.check_configuration(q)?;
        }
        if let [only] = waypoints {
            let certificate = self.segment_unchecked(world, only, only);
            return Ok(PathCertificate {
                failure: (!certificate.is_free()).then_some((0, certificate)),
            });
        }
        for (i, w) in waypoints.windows(2).enumerate() {
            let certificate = self.segment_unchecked(world, &w[0], &w[1]);
            if !certificate.is_free() {
                return Ok(PathCertificate {
                    failure: Some((i, certificate)),
                });
            }
        }
        Ok(PathCertificate { failure: None })
    }

    fn check_configuration(&self, q: &[f64]) -> Result<()> {
        if q.len() != self.active.len() {
            return Err(CollisionError::InvalidValue {
                what: "a configuration to certify".into(),
                problem: format!(
                    "{} values for {} active coordinates",
                    q.len(),
                    self.active.len()
                ),
            });
        }
        if let Some(i) = q.iter().position(|v| !v.is_finite()) {
            return Err(CollisionError::InvalidValue {
                what: "a configuration to certify".into(),
                problem: format!("value {i} is {}", q[i]),
            });
        }
        // the lever arms of prismatic joints rest on their travel: a motion outside the limits
        // is not what they bound
        let motors = self.collision.robot().motors();
        for (&m, &v) in self.active.motor_indices().iter().zip(q) {
            let limits = &motors[m].limits;
            if v < limits.lower - TRAVEL_SLACK || v > limits.upper + TRAVEL_SLACK {
                return Err(CollisionError::InvalidValue {
                    what: "a configuration to certify".into(),
                    problem: format!(
                        "{} = {v} is outside its limits [{}, {}]: clamp it into them",
                        motors[m].name, limits.lower, limits.upper
                    ),
                });
            }
        }
        Ok(())
    }

    /// [`Certifier::segment`] without checking the configurations.
    pub fn segment_unchecked(&mut self, world: &World, a: &[f64], b: &[f64]) -> Certificate {
        let pairs = self.collision.pairs().len();
        let bodies = self.collision.bodies().len();
        let objects = world.objects().len();
        let units = pairs + bodies * objects;
        // each unit's bound over the whole motion
        self.rates.clear();
        let step = |lever: &[f64]| -> f64 {
            lever
                .iter()
                .zip(a.iter().zip(b))
                .map(|(l, (x, y))| l * (y - x).abs())
                .sum()
        };
        self.rates.extend(self.pair_levers.iter().map(|l| step(l)));
        for lever in &self.body_levers {
            let r = step(lever);
            self.rates.extend(std::iter::repeat_n(r, objects));
        }
        // world units are laid out body-major: unit = pairs + body * objects + object
        let mut ends = std::mem::take(&mut self.ends);
        for (end, q) in [a, b].into_iter().enumerate() {
            self.place(q);
            ends[end].clear();
            ends[end].extend((0..units).map(|unit| self.lower_bound(world, unit)));
        }
        let mut open = self.spare.pop().unwrap_or_default();
        open.clear();
        for (unit, ((&l0, &l1), &rate)) in ends[0].iter().zip(&ends[1]).zip(&self.rates).enumerate()
        {
            if l0 + l1 > rate + SLACK && l0 > 0.0 && l1 > 0.0 {
                continue;
            }
            open.push(Open {
                unit: unit as u32,
                d0: f64::NAN,
                d1: f64::NAN,
            });
        }
        self.ends = ends;
        // exact distances of the open units at both ends
        for (end, q) in [a, b].into_iter().enumerate() {
            if open.is_empty() {
                break;
            }
            self.place(q);
            for o in open.iter_mut() {
                let d = self.distance(world, o.unit as usize);
                if d <= 0.0 {
                    let certificate = Certificate::Collides {
                        at: end as f64,
                        pair: self.contact(o.unit as usize, objects),
                    };
                    self.spare.push(open);
                    return certificate;
                }
                if end == 0 {
                    o.d0 = d;
                } else {
                    o.d1 = d;
                }
            }
        }
        self.stack.clear();
        self.stack.push(Piece {
            u0: 0.0,
            u1: 1.0,
            open,
        });
        let verdict = self.prove(world, a, b, objects);
        while let Some(piece) = self.stack.pop() {
            self.spare.push(piece.open);
        }
        verdict
    }

    /// Bisects the pieces on the stack until every open pair is cleared.
    fn prove(&mut self, world: &World, a: &[f64], b: &[f64], objects: usize) -> Certificate {
        while let Some(mut piece) = self.stack.pop() {
            let length = piece.u1 - piece.u0;
            piece
                .open
                .retain(|o| o.d0 + o.d1 <= self.rates[o.unit as usize] * length + SLACK);
            if piece.open.is_empty() {
                self.spare.push(piece.open);
                continue;
            }
            if let Some(o) = piece
                .open
                .iter()
                .find(|o| self.rates[o.unit as usize] * length < self.floor)
            {
                let (at, clearance) = if o.d0 <= o.d1 {
                    (piece.u0, o.d0)
                } else {
                    (piece.u1, o.d1)
                };
                let pair = self.contact(o.unit as usize, objects);
                self.spare.push(piece.open);
                return Certificate::Unproved {
                    at,
                    pair,
                    clearance,
                };
            }
            let mid = 0.5 * (piece.u0 + piece.u1);
            for ((q, x), y) in self.q.iter_mut().zip(a).zip(b) {
                *q = x + mid * (y - x);
            }
            let q = std::mem::take(&mut self.q);
            self.place(&q);
            self.q = q;
            let half = 0.5 * length;
            let mut left = self.spare.pop().unwrap_or_default();
            left.clear();
            let mut right = self.spare.pop().unwrap_or_default();
            right.clear();
            for o in &piece.open {
                let unit = o.unit as usize;
                let need = self.rates[unit] * half + SLACK;
                // the bounding spheres first: exact only where they cannot clear both halves
                let mut d = self.lower_bound(world, unit);
                if !(d > 0.0 && o.d0 + d > need && d + o.d1 > need) {
                    d = self.distance(world, unit);
                }
                if d <= 0.0 {
                    self.spare.extend([piece.open, left, right]);
                    return Certificate::Collides {
                        at: mid,
                        pair: self.contact(unit, objects),
                    };
                }
                left.push(Open {
                    unit: o.unit,
                    d0: o.d0,
                    d1: d,
                });
                right.push(Open {
                    unit: o.unit,
                    d0: d,
                    d1: o.d1,
                });
            }
            self.spare.push(piece.open);
            self.stack.push(Piece {
                u0: mid,
                u1: piece.u1,
                open: right,
            });
            self.stack.push(Piece {
                u0: piece.u0,
                u1: mid,
                open: left,
            });
        }
        Certificate::Free
    }

    /// Places the bodies at active configuration `q`.
    fn place(&mut self, q: &[f64]) {
        self.active.forward_unchecked(q, &mut self.poses);
        self.collision.place(&self.poses, &mut self.placed);
        self.configurations += 1;
    }

    /// A lower bound on unit `unit`'s distance, from bounding spheres.
    fn lower_bound(&self, world: &World, unit: usize) -> f64 {
        let p = &self.placed.placed;
        let pairs = self.collision.pairs();
        if unit < pairs.len() {
            let (a, b) = (&p[pairs[unit].a as usize], &p[pairs[unit].b as usize]);
            (a.center - b.center).norm() - a.bound - b.bound
        } else {
            let (body, object) = self.world_unit(world, unit);
            let (a, o) = (&p[body], &world.objects()[object].placed);
            (a.center - o.center).norm() - a.bound - o.bound
        }
    }

    /// Unit `unit`'s exact signed distance.
    fn distance(&mut self, world: &World, unit: usize) -> f64 {
        self.distances += 1;
        let (c, p) = (self.collision.compiled(), &self.placed.placed);
        let pairs = self.collision.pairs();
        if unit < pairs.len() {
            let (a, b) = (pairs[unit].a as usize, pairs[unit].b as usize);
            signed_distance(&c[a], &p[a], &c[b], &p[b])
        } else {
            let (body, object) = self.world_unit(world, unit);
            let o = &world.objects()[object];
            signed_distance(&c[body], &p[body], &o.compiled, &o.placed)
        }
    }

    /// The (body, object) of a world unit.
    fn world_unit(&self, world: &World, unit: usize) -> (usize, usize) {
        let k = unit - self.collision.pairs().len();
        let objects = world.objects().len();
        (k / objects, k % objects)
    }

    /// The pair a unit is about.
    fn contact(&self, unit: usize, objects: usize) -> Contact {
        let pairs = self.collision.pairs();
        if unit < pairs.len() {
            Contact::Bodies(pairs[unit].a as usize, pairs[unit].b as usize)
        } else {
            let k = unit - pairs.len();
            Contact::Object(k / objects, k % objects)
        }
    }
}
