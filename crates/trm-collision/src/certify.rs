//! Certified motion checks: a straight motion between two configurations proved free in
//! continuous motion, not at samples.
//!
//! Between configurations `q₀` and `q₁` no point of a link moves farther than its lever arms
//! allow: a step that changes joint `j`'s value by `Δvⱼ` moves a point by at most
//! `r = Σⱼ |Δvⱼ| ρⱼ`, `ρⱼ` the largest distance of the link's points from joint `j`'s axis
//! during the step (1 for a prismatic joint). `ρⱼ` is bounded per piece of the motion from its
//! two ends: at most the mean of the distances of the link's enclosing sphere from the axis
//! there plus half of how far the joints between the axis and the link can move the sphere
//! during the piece, and never more than the static bound of [`Levers`]. Two bodies' distance
//! changes by at most the sum of their links' `r` over the joints their chains do not share
//! (those move both rigidly), a body's distance to a world object by its own `r`. So a pair
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

use nalgebra::{Point3, Vector3};
use trm_kinematics::{ActiveSet, JointKind, PoseBuffer};

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

/// A piece of the motion: its ends (fractions, and the configurations placed there), what
/// its ends leave open, and how far the links' points can move over it.
#[derive(Debug, Clone)]
struct Piece {
    u0: f64,
    u1: f64,
    s0: usize,
    s1: usize,
    open: Vec<Open>,
    /// Per [`Term`] (see [`Certifier::reached`]): the farthest a point of the term's ball
    /// moves over the piece through that joint and the ones below it on the ball's chain; NaN
    /// until a pair needs the ball.
    reach: Vec<f64>,
}

/// A movable joint on a ball's chain to the root.
#[derive(Debug, Clone, Copy)]
struct Term {
    /// The joint's child link: its frame holds the joint's axis at its origin.
    child: usize,
    /// The joint's index among the joint values.
    value: usize,
    /// The axis in the child's frame; `None` for a prismatic joint.
    axis: Option<Vector3<f64>>,
    /// The ball's points' largest displacement per unit of the joint's value, over every
    /// configuration ([`Levers`]).
    lever: f64,
}

/// A configuration placed: its link poses, the centre of each link's enclosing sphere, and
/// the bodies, each placed when a pair first needs it.
#[derive(Debug, Clone)]
struct Snapshot {
    links: PoseBuffer,
    centers: Vec<Point3<f64>>,
    placed: PlacedBodies,
    /// Per body: whether `placed` holds it at this configuration.
    ready: Vec<bool>,
    /// Per [`Term`]: the largest distance of its ball's points from the joint's axis, once
    /// `armed` holds for the ball.
    arms: Vec<f64>,
    armed: Vec<bool>,
}

/// A link with bodies: a sphere in its frame that encloses them all.
#[derive(Debug, Clone)]
struct Ball {
    link: usize,
    center: Point3<f64>,
    radius: f64,
    /// Its bodies.
    bodies: Vec<u32>,
    /// Its chain's joints in [`Certifier::terms`], from its link up to the root.
    terms: std::ops::Range<usize>,
}

/// Checked body pairs of one pair of links.
#[derive(Debug, Clone)]
struct LinkPair {
    balls: [usize; 2],
    /// Indices into the model's checked body pairs.
    pairs: Vec<u32>,
    /// Per ball: how many of its chain's joints are not on the other's (the rest move both
    /// rigidly).
    own: [usize; 2],
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
    /// The balls' chains, ball after ball.
    terms: Vec<Term>,
    /// The joint values at the current motion's two ends (reused).
    values: [Vec<f64>; 2],
    /// Per term: how much its joint's value changes over the current motion.
    motion: Vec<f64>,
    /// Placed configurations (reused): those of the current motion's pieces still to prove,
    /// and spares.
    snapshots: Vec<Snapshot>,
    /// Snapshots free for the next configuration placed.
    free: Vec<usize>,
    q: Vec<f64>,
    /// Pieces to prove, and spare lists of open pairs and reaches.
    stack: Vec<Piece>,
    spare: Vec<Vec<Open>>,
    spare_reach: Vec<Vec<f64>>,
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
                    terms: 0..0,
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
        let tree = robot.tree();
        let mut terms = Vec::new();
        for ball in &mut balls {
            let start = terms.len();
            terms.extend(levers.chain(ball.link).iter().map(|&(j, value, lever)| {
                let joint = &tree.joints[j];
                Term {
                    child: joint.child,
                    value,
                    axis: (joint.kind != JointKind::Prismatic).then_some(joint.axis.into_inner()),
                    lever,
                }
            }));
            ball.terms = start..terms.len();
        }
        let ball = |body: u32| ball_of_link[collision.bodies()[body as usize].link].unwrap();
        let mut link_pairs: Vec<LinkPair> = Vec::new();
        let mut index = std::collections::HashMap::new();
        for (k, pair) in collision.pairs().iter().enumerate() {
            let balls_of = [ball(pair.a), ball(pair.b)];
            let at = *index.entry(balls_of).or_insert_with(|| {
                // the chains share the joints above the links' common ancestor: a common tail
                let [ca, cb] = balls_of.map(|b| levers.chain(balls[b].link));
                let shared = ca
                    .iter()
                    .rev()
                    .zip(cb.iter().rev())
                    .take_while(|(x, y)| x.0 == y.0)
                    .count();
                link_pairs.push(LinkPair {
                    balls: balls_of,
                    pairs: Vec::new(),
                    own: [ca.len() - shared, cb.len() - shared],
                });
                link_pairs.len() - 1
            });
            link_pairs[at].pairs.push(k as u32);
        }
        let joints = robot.num_joints();
        Ok(Certifier {
            collision: collision.clone(),
            active: active.clone(),
            floor: DEFAULT_FLOOR,
            balls,
            link_pairs,
            terms,
            values: [vec![0.0; joints], vec![0.0; joints]],
            motion: Vec::new(),
            snapshots: Vec::new(),
            free: Vec::new(),
            q: vec![0.0; n],
            stack: Vec::new(),
            spare: Vec::new(),
            spare_reach: Vec::new(),
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
        check_configuration(&self.collision, &self.active, q)
    }

    /// [`Certifier::segment`] without checking the configurations.
    pub fn segment_unchecked(&mut self, world: &World, a: &[f64], b: &[f64]) -> Certificate {
        let (s0, s1) = self.begin(a, b);
        let mut open = self.spare.pop().unwrap_or_default();
        open.clear();
        // the groups: link pairs, then ball-major ball × object
        let groups = self.link_pairs.len() + self.balls.len() * world.objects().len();
        let reach = self.reach();
        for group in 0..groups {
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
            reach,
        });
        let verdict = self.prove(world, a, b);
        while let Some(piece) = self.stack.pop() {
            self.recycle(piece);
        }
        verdict
    }

    /// Starts the motion `a` → `b`: its joints' changes, and its two ends placed (their
    /// snapshots).
    fn begin(&mut self, a: &[f64], b: &[f64]) -> (usize, usize) {
        // the joints' values are affine in the active coordinates: each changes evenly
        let [va, vb] = &mut self.values;
        self.active.joint_values_unchecked(a, va);
        self.active.joint_values_unchecked(b, vb);
        self.motion.clear();
        self.motion
            .extend(self.terms.iter().map(|t| (vb[t.value] - va[t.value]).abs()));
        self.free.clear();
        self.free.extend((0..self.snapshots.len()).rev());
        (self.place(a), self.place(b))
    }

    /// Keeps a piece's lists for later pieces.
    fn recycle(&mut self, piece: Piece) {
        self.spare.push(piece.open);
        self.spare_reach.push(piece.reach);
    }

    /// A piece's reach list, not yet computed for any ball.
    fn reach(&mut self) -> Vec<f64> {
        let mut out = self.spare_reach.pop().unwrap_or_default();
        out.clear();
        out.resize(self.terms.len(), f64::NAN);
        out
    }

    /// How far ball `ball`'s points can move through the first `own` joints of its chain over
    /// `piece` (its two snapshots and its length as a fraction of the motion), computed into
    /// `reach` for the whole chain on first use: the sum over the chain of each joint's change
    /// times its arm. A joint's arm over the piece is at most its arm at either end plus how
    /// far the joints below it move the ball meanwhile: at most the mean of the two plus half
    /// of that (and at most its static lever).
    #[inline]
    fn reached(
        &mut self,
        reach: &mut [f64],
        piece: (usize, usize, f64),
        ball: usize,
        own: usize,
    ) -> f64 {
        if own == 0 {
            return 0.0;
        }
        let terms = self.balls[ball].terms.clone();
        if reach[terms.start].is_nan() {
            let (s0, s1, length) = piece;
            self.arm(s0, ball);
            self.arm(s1, ball);
            let (r0, r1) = (&self.snapshots[s0].arms, &self.snapshots[s1].arms);
            let (mut below, mut sum) = (0.0, 0.0);
            for t in terms.clone() {
                let term = &self.terms[t];
                let step = self.motion[t] * length;
                let arm = match term.axis {
                    Some(_) => term.lever.min(0.5 * (r0[t] + r1[t] + below)),
                    None => term.lever,
                };
                sum += step * arm;
                below += step * term.lever;
                reach[t] = sum;
            }
        }
        reach[terms.start + own - 1]
    }

    /// How far the pairs of group `group` can approach over `piece` (see
    /// [`Certifier::reached`]).
    #[inline]
    fn bound(
        &mut self,
        world: &World,
        reach: &mut [f64],
        piece: (usize, usize, f64),
        group: u32,
    ) -> f64 {
        let g = group as usize;
        if g < self.link_pairs.len() {
            let p = &self.link_pairs[g];
            let ([a, b], [own_a, own_b]) = (p.balls, p.own);
            self.reached(reach, piece, a, own_a) + self.reached(reach, piece, b, own_b)
        } else {
            let (ball, _) = self.ball_object(world, g);
            let own = self.balls[ball].terms.len();
            self.reached(reach, piece, ball, own)
        }
    }

    /// Computes ball `ball`'s arms at snapshot `s` unless they are there: per joint of its
    /// chain, the distance of its centre from the joint's axis plus its radius.
    #[inline]
    fn arm(&mut self, s: usize, ball: usize) {
        let snap = &mut self.snapshots[s];
        if snap.armed[ball] {
            return;
        }
        snap.armed[ball] = true;
        let (b, c) = (&self.balls[ball], snap.centers[ball]);
        for t in b.terms.clone() {
            let term = &self.terms[t];
            if let Some(axis) = term.axis {
                let frame = &snap.links.poses()[term.child];
                let offset = c.coords - frame.translation.vector;
                snap.arms[t] = (frame.rotation * axis).cross(&offset).norm() + b.radius;
            }
        }
    }

    /// Bisects the pieces on the stack until every open group and pair is cleared.
    fn prove(&mut self, world: &World, a: &[f64], b: &[f64]) -> Certificate {
        while let Some(mut piece) = self.stack.pop() {
            if let Err(certificate) = self.settle(world, &mut piece) {
                self.recycle(piece);
                return certificate;
            }
            if piece.open.is_empty() {
                // the pieces left of this one are proved: its start is no other piece's end
                self.free.push(piece.s0);
                self.recycle(piece);
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
            let (mut left_reach, mut right_reach) = (self.reach(), self.reach());
            let halves = [(piece.s0, sm, half), (sm, piece.s1, half)];
            let mut left = self.spare.pop().unwrap_or_default();
            left.clear();
            let mut right = self.spare.pop().unwrap_or_default();
            right.clear();
            for o in &piece.open {
                let d = if o.unit == GROUP {
                    self.group_bound(world, sm, o.group as usize)
                } else {
                    // the bounding spheres first: exact only where they cannot clear both halves
                    let need = [
                        self.bound(world, &mut left_reach, halves[0], o.group) + SLACK,
                        self.bound(world, &mut right_reach, halves[1], o.group) + SLACK,
                    ];
                    let lower = self.unit_bound(world, sm, o.group, o.unit);
                    if lower > 0.0 && o.d0 + lower > need[0] && lower + o.d1 > need[1] {
                        lower
                    } else {
                        let d = self.unit_distance(world, sm, o.group, o.unit);
                        if d <= 0.0 {
                            let pair = self.contact(world, o.group, o.unit);
                            self.spare.extend([left, right]);
                            self.spare_reach.extend([left_reach, right_reach]);
                            self.recycle(piece);
                            return Certificate::Collides { at: mid, pair };
                        }
                        d
                    }
                };
                left.push(Open { d1: d, ..*o });
                right.push(Open { d0: d, ..*o });
            }
            let (u0, u1, s0, s1) = (piece.u0, piece.u1, piece.s0, piece.s1);
            self.recycle(piece);
            self.stack.push(Piece {
                u0: mid,
                u1,
                s0: sm,
                s1,
                open: right,
                reach: right_reach,
            });
            self.stack.push(Piece {
                u0,
                u1: mid,
                s0,
                s1: sm,
                open: left,
                reach: left_reach,
            });
        }
        Certificate::Free
    }

    /// Drops what `piece`'s ends clear; opens into its pairs a group whose enclosing spheres
    /// cannot clear it (touching at an end, or down to the floor), with their exact distances
    /// at both ends. An error for a pair that collides at an end or cannot be cleared above the
    /// floor.
    fn settle(&mut self, world: &World, piece: &mut Piece) -> std::result::Result<(), Certificate> {
        let extent = (piece.s0, piece.s1, piece.u1 - piece.u0);
        let mut k = 0;
        while k < piece.open.len() {
            let o = piece.open[k];
            let bound = self.bound(world, &mut piece.reach, extent, o.group);
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

    /// Places the bodies at active configuration `q` in a free snapshot: its index.
    fn place(&mut self, q: &[f64]) -> usize {
        let s = match self.free.pop() {
            Some(s) => s,
            None => {
                self.snapshots.push(Snapshot {
                    links: self.collision.robot().pose_buffer(),
                    centers: vec![Point3::origin(); self.balls.len()],
                    placed: self.collision.placed_bodies(),
                    ready: vec![false; self.collision.bodies().len()],
                    arms: vec![0.0; self.terms.len()],
                    armed: vec![false; self.balls.len()],
                });
                self.snapshots.len() - 1
            }
        };
        let snapshot = &mut self.snapshots[s];
        self.active.forward_unchecked(q, &mut snapshot.links);
        let poses = snapshot.links.poses();
        snapshot.ready.fill(false);
        snapshot.armed.fill(false);
        for (c, ball) in snapshot.centers.iter_mut().zip(&self.balls) {
            *c = poses[ball.link] * ball.center;
        }
        self.configurations += 1;
        s
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
    #[inline]
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
    #[inline]
    fn ready(&mut self, s: usize, body: usize) {
        let snap = &mut self.snapshots[s];
        if !snap.ready[body] {
            let link = self.collision.bodies()[body].link;
            self.collision.compiled()[body]
                .place(&snap.links.poses()[link], &mut snap.placed.placed[body]);
            snap.ready[body] = true;
        }
    }

    /// Places pair `unit`'s bodies at snapshot `s`: the pair.
    #[inline]
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
    #[inline]
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

/// Whether `q` holds one finite value per coordinate of `active`, within the motors' limits of
/// `collision`'s robot (up to [`TRAVEL_SLACK`]): an error that says what is wrong otherwise.
pub(crate) fn check_configuration(
    collision: &CollisionModel,
    active: &ActiveSet,
    q: &[f64],
) -> Result<()> {
    if q.len() != active.len() {
        return Err(CollisionError::InvalidValue {
            what: "a configuration to certify".into(),
            problem: format!("{} values for {} active coordinates", q.len(), active.len()),
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
    let motors = collision.robot().motors();
    for (&m, &v) in active.motor_indices().iter().zip(q) {
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

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{RngExt, SeedableRng};
    use rand_chacha::ChaCha8Rng;
    use trm_kinematics::RobotModel;
    use trm_kinematics::nalgebra::Isometry3;

    /// Checks [`Certifier::reached`] on a piece (`u0`..`u1`) of each motion: the path points
    /// on the spheres enclosing a ball's bodies travel, in the frame of the link above the
    /// joints counted, never exceeds it. Returns the largest share of the bound travelled,
    /// and the sums of the bounds and of the static levers' bounds.
    fn travels(
        collision: &CollisionModel,
        motions: &[(Vec<f64>, Vec<f64>, f64, f64)],
        rng: &mut ChaCha8Rng,
    ) -> (f64, f64, f64) {
        const STEPS: usize = 200;
        let (robot, active) = (collision.robot(), collision.robot().all_active());
        let tree = robot.tree();
        let mut c = Certifier::new(collision, &active).unwrap();
        let mut poses = robot.pose_buffer();
        let (mut tightest, mut ours, mut fixed) = (0.0f64, 0.0, 0.0);
        for (a, b, u0, u1) in motions {
            let at =
                |u: f64| -> Vec<f64> { a.iter().zip(b).map(|(x, y)| x + u * (y - x)).collect() };
            c.begin(a, b);
            let (s0, s1) = (c.place(&at(*u0)), c.place(&at(*u1)));
            // every link's pose along the piece
            let trace: Vec<Vec<Isometry3<f64>>> = (0..=STEPS)
                .map(|s| {
                    active
                        .forward(&at(u0 + (u1 - u0) * s as f64 / STEPS as f64), &mut poses)
                        .unwrap();
                    poses.poses().to_vec()
                })
                .collect();
            let mut reach = c.reach();
            for k in 0..c.balls.len() {
                let ball = c.balls[k].clone();
                for own in 1..=ball.terms.len() {
                    let bound = c.reached(&mut reach, (s0, s1, u1 - u0), k, own);
                    let t = ball.terms.start + own - 1;
                    fixed += (ball.terms.start..=t)
                        .map(|t| c.motion[t] * (u1 - u0) * c.terms[t].lever)
                        .sum::<f64>();
                    ours += bound;
                    // the frame the counted joints move the ball in
                    let joint = tree.links[c.terms[t].child].parent_joint.unwrap();
                    let frame = tree.joints[joint].parent;
                    for _ in 0..4 {
                        // a point on a sphere enclosing one of the ball's bodies
                        let body = ball.bodies[rng.random_range(0..ball.bodies.len())] as usize;
                        let spheres = collision.enclosing_spheres(body);
                        let sphere = &spheres[rng.random_range(0..spheres.len())];
                        let dir = Vector3::new(
                            rng.random_range(-1.0..1.0),
                            rng.random_range(-1.0..1.0),
                            rng.random_range(-1.0..1.0),
                        );
                        let p = sphere.center + dir.normalize() * sphere.radius;
                        let seen: Vec<Point3<f64>> = trace
                            .iter()
                            .map(|links| links[frame].inverse() * (links[ball.link] * p))
                            .collect();
                        let travelled: f64 = seen.windows(2).map(|w| (w[1] - w[0]).norm()).sum();
                        assert!(travelled <= bound + 1e-12, "{travelled} > {bound}");
                        tightest = tightest.max(travelled / bound.max(1e-12));
                    }
                }
            }
            c.spare_reach.push(reach);
        }
        (tightest, ours, fixed)
    }

    /// On trm's Panda and the iCub upper body (coupled motors), random pieces of random
    /// motions: sound, met closely somewhere, and well below the static levers on the whole.
    #[test]
    fn a_pieces_reach_bounds_how_far_every_point_travels() {
        for file in ["panda/panda.ron", "icub_upper_body.ron"] {
            let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
                .join("../../models")
                .join(file);
            let collision = CollisionModel::new(&RobotModel::load(path).unwrap()).unwrap();
            let active = collision.robot().all_active();
            let (lower, upper) = active.bounds();
            let mut rng = ChaCha8Rng::seed_from_u64(7);
            let motions: Vec<_> = (0..20)
                .map(|_| {
                    let a = active.random(&mut rng);
                    let b = (0..a.len())
                        .map(|i| (a[i] + rng.random_range(-0.6..0.6)).clamp(lower[i], upper[i]))
                        .collect();
                    (a, b, rng.random_range(0.0..0.5), rng.random_range(0.5..1.0))
                })
                .collect();
            let (tightest, ours, fixed) = travels(&collision, &motions, &mut rng);
            assert!(tightest > 0.3, "{file}: at most {tightest} of the bound");
            assert!(ours < 0.8 * fixed, "{file}: {ours} against static {fixed}");
        }
    }

    /// A planar arm whose elbow swings its hand out and back while the shoulder turns: the
    /// hand is farther from the shoulder's axis mid-piece than at either end, and only the
    /// elbow's share of the bound (half of how far it moves the hand) keeps the bound sound.
    #[test]
    fn a_joint_below_widening_the_arm_mid_piece_is_counted() {
        let collision = crate::levers::tests::arm();
        let motions = [
            (vec![0.0, -2.0], vec![2.0, 2.0], 0.0, 1.0),
            (vec![0.0, -1.5], vec![1.0, 1.5], 0.0, 1.0),
        ];
        let (tightest, ..) = travels(&collision, &motions, &mut ChaCha8Rng::seed_from_u64(3));
        assert!(tightest > 0.7, "at most {tightest} of the bound");
    }
}
