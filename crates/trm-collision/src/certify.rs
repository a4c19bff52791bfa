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

use nalgebra::{Isometry3, Point3, Vector3};
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

/// A pair, or a group of pairs, still open over a piece of the motion: lower bounds on its
/// distance at the piece's two ends (exact distances for a pair of bodies).
#[derive(Debug, Clone, Copy)]
struct Open {
    /// The group: a pair of links, or a link and a world object.
    group: u32,
    /// One pair of the group (a body pair's index for a pair of links, a body for a link and
    /// an object), or [`GROUP`] for the whole group bounded by its enclosing spheres.
    unit: u32,
    d0: f64,
    d1: f64,
}

/// [`Open::unit`] of a whole group.
const GROUP: u32 = u32::MAX;

/// A piece of the motion: its ends (fractions, and the configurations placed there) and what
/// its ends leave open.
#[derive(Debug, Clone)]
struct Piece {
    u0: f64,
    u1: f64,
    s0: usize,
    s1: usize,
    open: Vec<Open>,
}

/// A configuration placed: its link poses, the centre of each link's enclosing sphere, and
/// the bodies, each placed when a pair first needs it.
#[derive(Debug, Clone)]
struct Snapshot {
    links: Vec<Isometry3<f64>>,
    centers: Vec<Point3<f64>>,
    placed: PlacedBodies,
    /// Per body: whether `placed` holds it at this configuration.
    ready: Vec<bool>,
}

/// A link with bodies: a sphere in its frame that encloses them all.
#[derive(Debug, Clone)]
struct Ball {
    link: usize,
    center: Point3<f64>,
    radius: f64,
    /// Its bodies.
    bodies: Vec<u32>,
}

/// Checked body pairs of one pair of links.
#[derive(Debug, Clone)]
struct LinkPair {
    balls: [usize; 2],
    /// Indices into the model's checked body pairs.
    pairs: Vec<u32>,
    /// Relative lever arms of the two links, per active coordinate.
    levers: Vec<f64>,
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
    balls: Vec<Ball>,
    /// Per link pair with checked body pairs.
    link_pairs: Vec<LinkPair>,
    /// Per ball: its link's lever arms, per active coordinate (for world objects).
    ball_levers: Vec<Vec<f64>>,
    /// Per group of the current motion (link pairs, then ball × object): its bound over the
    /// whole motion.
    rates: Vec<f64>,
    /// The current motion's configurations placed so far (reused).
    snapshots: Vec<Snapshot>,
    placed_count: usize,
    poses: PoseBuffer,
    q: Vec<f64>,
    /// Pieces to prove, and spare lists of open pairs.
    stack: Vec<Piece>,
    spare: Vec<Vec<Open>>,
    /// Configurations placed so far.
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
        let robot = collision.robot();
        // one enclosing sphere per link with bodies, around its bodies' enclosing spheres
        let mut ball_of_link = vec![None; robot.tree().links.len()];
        let mut balls: Vec<Ball> = Vec::new();
        for (b, body) in collision.bodies().iter().enumerate() {
            let k = *ball_of_link[body.link].get_or_insert_with(|| {
                balls.push(Ball {
                    link: body.link,
                    center: Point3::origin(),
                    radius: 0.0,
                    bodies: Vec::new(),
                });
                balls.len() - 1
            });
            balls[k].bodies.push(b as u32);
        }
        for ball in &mut balls {
            let spheres: Vec<_> = ball
                .bodies
                .iter()
                .flat_map(|&b| collision.enclosing_spheres(b as usize))
                .collect();
            let center = spheres
                .iter()
                .fold(Vector3::zeros(), |sum, s| sum + s.center.coords)
                / spheres.len().max(1) as f64;
            ball.center = Point3::from(center);
            ball.radius = spheres
                .iter()
                .map(|s| (s.center.coords - center).norm() + s.radius)
                .fold(0.0, f64::max);
        }
        let ball = |body: u32| ball_of_link[collision.bodies()[body as usize].link].unwrap();
        let mut link_pairs: Vec<LinkPair> = Vec::new();
        let mut index = std::collections::HashMap::new();
        for (k, pair) in collision.pairs().iter().enumerate() {
            let balls_of = [ball(pair.a), ball(pair.b)];
            let at = *index.entry(balls_of).or_insert_with(|| {
                let mut out = vec![0.0; n];
                levers.relative_into(balls[balls_of[0]].link, balls[balls_of[1]].link, &mut out);
                link_pairs.push(LinkPair {
                    balls: balls_of,
                    pairs: Vec::new(),
                    levers: out,
                });
                link_pairs.len() - 1
            });
            link_pairs[at].pairs.push(k as u32);
        }
        let ball_levers = balls
            .iter()
            .map(|b| {
                let mut out = vec![0.0; n];
                levers.link_into(b.link, &mut out);
                out
            })
            .collect();
        Ok(Certifier {
            collision: collision.clone(),
            active: active.clone(),
            floor: DEFAULT_FLOOR,
            balls,
            link_pairs,
            ball_levers,
            rates: Vec::new(),
            snapshots: Vec::new(),
            placed_count: 0,
            poses: robot.pose_buffer(),
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
        let objects = world.objects().len();
        let step = |lever: &[f64]| -> f64 {
            lever
                .iter()
                .zip(a.iter().zip(b))
                .map(|(l, (x, y))| l * (y - x).abs())
                .sum()
        };
        // each group's bound over the whole motion: link pairs, then ball-major ball × object
        self.rates.clear();
        self.rates
            .extend(self.link_pairs.iter().map(|p| step(&p.levers)));
        for lever in &self.ball_levers {
            let r = step(lever);
            self.rates.extend(std::iter::repeat_n(r, objects));
        }
        self.placed_count = 0;
        let s0 = self.place(a);
        let s1 = self.place(b);
        let mut open = self.spare.pop().unwrap_or_default();
        open.clear();
        for group in 0..self.rates.len() {
            open.push(Open {
                group: group as u32,
                unit: GROUP,
                d0: self.group_bound(world, s0, group),
                d1: self.group_bound(world, s1, group),
            });
        }
        self.stack.clear();
        self.stack.push(Piece {
            u0: 0.0,
            u1: 1.0,
            s0,
            s1,
            open,
        });
        let verdict = self.prove(world, a, b);
        while let Some(piece) = self.stack.pop() {
            self.spare.push(piece.open);
        }
        verdict
    }

    /// Bisects the pieces on the stack until every open group and pair is cleared.
    fn prove(&mut self, world: &World, a: &[f64], b: &[f64]) -> Certificate {
        while let Some(mut piece) = self.stack.pop() {
            if let Err(certificate) = self.settle(world, &mut piece) {
                self.spare.push(piece.open);
                return certificate;
            }
            if piece.open.is_empty() {
                self.spare.push(piece.open);
                continue;
            }
            let mid = 0.5 * (piece.u0 + piece.u1);
            for ((q, x), y) in self.q.iter_mut().zip(a).zip(b) {
                *q = x + mid * (y - x);
            }
            let q = std::mem::take(&mut self.q);
            let sm = self.place(&q);
            self.q = q;
            let half = 0.5 * (piece.u1 - piece.u0);
            let mut left = self.spare.pop().unwrap_or_default();
            left.clear();
            let mut right = self.spare.pop().unwrap_or_default();
            right.clear();
            for o in &piece.open {
                let d = if o.unit == GROUP {
                    self.group_bound(world, sm, o.group as usize)
                } else {
                    // the bounding spheres first: exact only where they cannot clear both halves
                    let need = self.rates[o.group as usize] * half + SLACK;
                    let lower = self.unit_bound(world, sm, o.group, o.unit);
                    if lower > 0.0 && o.d0 + lower > need && lower + o.d1 > need {
                        lower
                    } else {
                        let d = self.unit_distance(world, sm, o.group, o.unit);
                        if d <= 0.0 {
                            let pair = self.contact(world, o.group, o.unit);
                            self.spare.extend([piece.open, left, right]);
                            return Certificate::Collides { at: mid, pair };
                        }
                        d
                    }
                };
                left.push(Open { d1: d, ..*o });
                right.push(Open { d0: d, ..*o });
            }
            self.spare.push(piece.open);
            self.stack.push(Piece {
                u0: mid,
                u1: piece.u1,
                s0: sm,
                s1: piece.s1,
                open: right,
            });
            self.stack.push(Piece {
                u0: piece.u0,
                u1: mid,
                s0: piece.s0,
                s1: sm,
                open: left,
            });
        }
        Certificate::Free
    }

    /// Drops what `piece`'s ends clear; opens into its pairs a group whose enclosing spheres
    /// cannot clear it (touching at an end, or down to the floor), with their exact distances
    /// at both ends. An error for a pair that collides at an end or cannot be cleared above the
    /// floor.
    fn settle(&mut self, world: &World, piece: &mut Piece) -> std::result::Result<(), Certificate> {
        let length = piece.u1 - piece.u0;
        let mut k = 0;
        while k < piece.open.len() {
            let o = piece.open[k];
            let bound = self.rates[o.group as usize] * length;
            if o.d0 + o.d1 > bound + SLACK {
                piece.open.swap_remove(k);
                continue;
            }
            if o.unit != GROUP {
                if bound < self.floor {
                    let (at, clearance) = if o.d0 <= o.d1 {
                        (piece.u0, o.d0)
                    } else {
                        (piece.u1, o.d1)
                    };
                    return Err(Certificate::Unproved {
                        at,
                        pair: self.contact(world, o.group, o.unit),
                        clearance,
                    });
                }
                k += 1;
                continue;
            }
            if o.d0 > 0.0 && o.d1 > 0.0 && bound >= self.floor {
                k += 1;
                continue;
            }
            // the group's spheres touch at an end: its pairs, each on its own
            piece.open.swap_remove(k);
            for unit in self.units(world, o.group) {
                let lower = [piece.s0, piece.s1].map(|s| self.unit_bound(world, s, o.group, unit));
                if lower[0] + lower[1] > bound + SLACK {
                    continue;
                }
                let mut exact = [0.0; 2];
                for (end, s) in [piece.s0, piece.s1].into_iter().enumerate() {
                    exact[end] = self.unit_distance(world, s, o.group, unit);
                    if exact[end] <= 0.0 {
                        return Err(Certificate::Collides {
                            at: [piece.u0, piece.u1][end],
                            pair: self.contact(world, o.group, unit),
                        });
                    }
                }
                piece.open.push(Open {
                    group: o.group,
                    unit,
                    d0: exact[0],
                    d1: exact[1],
                });
            }
        }
        Ok(())
    }

    /// The pairs of group `group`: body pair indices of a link pair, bodies of a ball.
    fn units(&self, world: &World, group: u32) -> std::ops::Range<u32> {
        // ranges into `link_pairs[g].pairs` / `balls[b].bodies`, by position
        let g = group as usize;
        let len = if g < self.link_pairs.len() {
            self.link_pairs[g].pairs.len()
        } else {
            let (ball, _) = self.ball_object(world, g);
            self.balls[ball].bodies.len()
        };
        0..len as u32
    }

    /// Places the bodies at active configuration `q`: the index of its snapshot.
    fn place(&mut self, q: &[f64]) -> usize {
        self.active.forward_unchecked(q, &mut self.poses);
        if self.placed_count == self.snapshots.len() {
            self.snapshots.push(Snapshot {
                links: Vec::new(),
                centers: vec![Point3::origin(); self.balls.len()],
                placed: self.collision.placed_bodies(),
                ready: vec![false; self.collision.bodies().len()],
            });
        }
        let snapshot = &mut self.snapshots[self.placed_count];
        let poses = self.poses.poses();
        snapshot.links.clear();
        snapshot.links.extend_from_slice(poses);
        snapshot.ready.fill(false);
        for (c, ball) in snapshot.centers.iter_mut().zip(&self.balls) {
            *c = poses[ball.link] * ball.center;
        }
        self.configurations += 1;
        self.placed_count += 1;
        self.placed_count - 1
    }

    /// A lower bound on the distance of every pair of group `group` at snapshot `s`, from the
    /// links' enclosing spheres (and the object's bounding sphere).
    fn group_bound(&self, world: &World, s: usize, group: usize) -> f64 {
        let snap = &self.snapshots[s];
        if group < self.link_pairs.len() {
            let [a, b] = self.link_pairs[group].balls;
            (snap.centers[a] - snap.centers[b]).norm() - self.balls[a].radius - self.balls[b].radius
        } else {
            let (ball, object) = self.ball_object(world, group);
            let o = &world.objects()[object].placed;
            (snap.centers[ball] - o.center).norm() - self.balls[ball].radius - o.bound
        }
    }

    /// The two things pair `unit` of group `group` is about: (body, Ok(body)) or
    /// (body, Err(object)).
    fn unit_of(
        &self,
        world: &World,
        group: u32,
        unit: u32,
    ) -> (usize, std::result::Result<usize, usize>) {
        let g = group as usize;
        if g < self.link_pairs.len() {
            let pair = &self.collision.pairs()[self.link_pairs[g].pairs[unit as usize] as usize];
            (pair.a as usize, Ok(pair.b as usize))
        } else {
            let (ball, object) = self.ball_object(world, g);
            (self.balls[ball].bodies[unit as usize] as usize, Err(object))
        }
    }

    /// Places body `body` at snapshot `s` unless it is there.
    fn ready(&mut self, s: usize, body: usize) {
        let snap = &mut self.snapshots[s];
        if !snap.ready[body] {
            let link = self.collision.bodies()[body].link;
            self.collision.compiled()[body].place(&snap.links[link], &mut snap.placed.placed[body]);
            snap.ready[body] = true;
        }
    }

    /// Places pair `unit`'s bodies at snapshot `s`: the pair.
    fn ready_unit(
        &mut self,
        world: &World,
        s: usize,
        group: u32,
        unit: u32,
    ) -> (usize, std::result::Result<usize, usize>) {
        let (a, other) = self.unit_of(world, group, unit);
        self.ready(s, a);
        if let Ok(b) = other {
            self.ready(s, b);
        }
        (a, other)
    }

    /// A lower bound on pair `unit`'s distance at snapshot `s`, from bounding spheres.
    fn unit_bound(&mut self, world: &World, s: usize, group: u32, unit: u32) -> f64 {
        let (a, other) = self.ready_unit(world, s, group, unit);
        let p = &self.snapshots[s].placed.placed;
        let o = match other {
            Ok(b) => &p[b],
            Err(object) => &world.objects()[object].placed,
        };
        (p[a].center - o.center).norm() - p[a].bound - o.bound
    }

    /// Pair `unit`'s exact signed distance at snapshot `s`.
    fn unit_distance(&mut self, world: &World, s: usize, group: u32, unit: u32) -> f64 {
        self.distances += 1;
        let pair = self.ready_unit(world, s, group, unit);
        let (c, p) = (self.collision.compiled(), &self.snapshots[s].placed.placed);
        match pair {
            (a, Ok(b)) => signed_distance(&c[a], &p[a], &c[b], &p[b]),
            (a, Err(object)) => {
                let o = &world.objects()[object];
                signed_distance(&c[a], &p[a], &o.compiled, &o.placed)
            }
        }
    }

    /// The (ball, object) of a world group.
    fn ball_object(&self, world: &World, group: usize) -> (usize, usize) {
        let k = group - self.link_pairs.len();
        let objects = world.objects().len();
        (k / objects, k % objects)
    }

    /// The pair a unit is about.
    fn contact(&self, world: &World, group: u32, unit: u32) -> Contact {
        match self.unit_of(world, group, unit) {
            (a, Ok(b)) => Contact::Bodies(a, b),
            (a, Err(object)) => Contact::Object(a, object),
        }
    }
}
