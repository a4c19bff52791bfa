//! Queries on placed bodies: colliding-pair counts, early-exit checks, pair lists, distances.

use crate::cull::Step;
use crate::model::CollisionModel;
use crate::placed::PlacedBodies;
use nalgebra::{Point3, Vector3};

use crate::shape::{Closest, bounds_apart, intersects, proximity, signed_distance, sphere_apart};
use crate::world::World;

/// Colliding pairs of one configuration.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct CollisionCount {
    /// Colliding link pairs of the robot with itself.
    pub self_pairs: usize,
    /// Colliding (link, world object) pairs.
    pub world_pairs: usize,
}

impl CollisionCount {
    /// Both counts together.
    pub fn total(&self) -> usize {
        self.self_pairs + self.world_pairs
    }
}

/// What a body touched.
#[derive(Debug, Clone, PartialEq)]
pub enum Other {
    /// Another body of the robot.
    Body(String),
    /// A world object.
    Object(String),
}

/// A colliding pair, for debugging and reports: names for people, indices for programs.
#[derive(Debug, Clone, PartialEq)]
pub struct CollidingPair {
    /// The robot body's name.
    pub body: String,
    /// What it collides with, by name.
    pub other: Other,
    /// Index of the robot body in [`CollisionModel::bodies`] (its link:
    /// `bodies()[body_index].link`).
    pub body_index: usize,
    /// Index of what it collides with: a body index for [`Other::Body`], an index into
    /// [`World::objects`] for [`Other::Object`].
    pub other_index: usize,
    /// Signed distance (≤ 0: minus the penetration depth).
    pub distance: f64,
}

/// A robot body close to another body or a world object: the signed distance and the closest
/// points (world frame), from [`CollisionModel::near_pairs`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NearPair {
    /// Index of the robot body in [`CollisionModel::bodies`].
    pub body: usize,
    /// The other body's index ([`NearPair::is_object`] false) or the world object's index.
    pub other: usize,
    /// True when `other` indexes [`World::objects`].
    pub is_object: bool,
    /// Signed distance (negative when they overlap).
    pub distance: f64,
    /// Closest point on the robot body.
    pub point: Point3<f64>,
    /// Closest point on the other.
    pub other_point: Point3<f64>,
    /// Unit normal from the body towards the other: moving the other along it by δ raises the
    /// distance by δ.
    pub normal: Vector3<f64>,
}

/// The closest pair of bodies.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PairDistance {
    /// First body index.
    pub a: usize,
    /// Second body index.
    pub b: usize,
    /// Signed distance (negative when they overlap).
    pub distance: f64,
}

impl CollisionModel {
    /// Calls `hit(k)` for every checked body pair `k` that collides, in the order of the
    /// culling steps; when `hit` returns true, the rest of that link pair is skipped. Returns
    /// early when `hit` asks to stop (`None`).
    #[inline]
    fn walk_self(&self, placed: &PlacedBodies, mut hit: impl FnMut(usize) -> Option<bool>) {
        let (pairs, compiled, p) = (self.pairs(), self.compiled(), &placed.placed);
        let steps = &self.culling().self_steps;
        let mut i = 0;
        while i < steps.len() {
            match steps[i] {
                Step::Cull { a, b, end } => {
                    if placed.apart(a, b) {
                        i = end as usize;
                        continue;
                    }
                }
                Step::Test { start, end } => {
                    for (k, pair) in pairs
                        .iter()
                        .enumerate()
                        .take(end as usize)
                        .skip(start as usize)
                    {
                        let (a, b) = (pair.a as usize, pair.b as usize);
                        if !bounds_apart(&p[a], &p[b])
                            && intersects(&compiled[a], &p[a], &compiled[b], &p[b])
                        {
                            match hit(k) {
                                None => return,
                                Some(true) => break,
                                Some(false) => {}
                            }
                        }
                    }
                }
            }
            i += 1;
        }
    }

    /// As [`CollisionModel::walk_self`], over (link, object) pairs: `hit(body, object)`.
    #[inline]
    fn walk_world(
        &self,
        placed: &PlacedBodies,
        world: &World,
        mut hit: impl FnMut(usize, usize) -> Option<bool>,
    ) {
        let (compiled, p) = (self.compiled(), &placed.placed);
        let steps = &self.culling().world_steps;
        for (o, object) in world.objects().iter().enumerate() {
            let mut s = 0;
            while s < steps.len() {
                match steps[s] {
                    Step::Cull { a, end, .. } => {
                        let (c, r) = placed.sphere(a);
                        if sphere_apart(c, r, &object.compiled, &object.placed) {
                            s = end as usize;
                            continue;
                        }
                    }
                    Step::Test { start, end } => {
                        for i in start as usize..end as usize {
                            if !bounds_apart(&p[i], &object.placed)
                                && intersects(&compiled[i], &p[i], &object.compiled, &object.placed)
                            {
                                match hit(i, o) {
                                    None => return,
                                    Some(true) => break,
                                    Some(false) => {}
                                }
                            }
                        }
                    }
                }
                s += 1;
            }
        }
    }

    /// Number of colliding link pairs of the robot with itself (checked pairs only).
    pub fn count_self(&self, placed: &PlacedBodies) -> usize {
        let mut n = 0;
        self.walk_self(placed, |_| {
            n += 1;
            Some(true)
        });
        n
    }

    /// Whether any checked link pair collides; stops at the first.
    pub fn any_self_collision(&self, placed: &PlacedBodies) -> bool {
        let mut any = false;
        self.walk_self(placed, |_| {
            any = true;
            None
        });
        any
    }

    /// Number of colliding (link, world object) pairs.
    pub fn count_world(&self, placed: &PlacedBodies, world: &World) -> usize {
        let mut n = 0;
        self.walk_world(placed, world, |_, _| {
            n += 1;
            Some(true)
        });
        n
    }

    /// Whether any link touches any world object; stops at the first.
    pub fn any_world_collision(&self, placed: &PlacedBodies, world: &World) -> bool {
        let mut any = false;
        self.walk_world(placed, world, |_, _| {
            any = true;
            None
        });
        any
    }

    /// Self and world counts.
    pub fn count(&self, placed: &PlacedBodies, world: &World) -> CollisionCount {
        CollisionCount {
            self_pairs: self.count_self(placed),
            world_pairs: self.count_world(placed, world),
        }
    }

    /// Whether the configuration collides with itself or the world (world first: it is
    /// usually the cheaper and likelier test).
    pub fn is_colliding(&self, placed: &PlacedBodies, world: &World) -> bool {
        self.any_world_collision(placed, world) || self.any_self_collision(placed)
    }

    /// The points of a cloud that no body at `placed` comes within `radius` of: a depth
    /// camera's cloud without the robot's own points (VAMP's `filter_self_from_pointcloud`),
    /// in their order. Pad `radius` beyond the cloud's own for a camera that sees the robot
    /// a little off where its model says.
    pub fn points_off_robot(
        &self,
        placed: &PlacedBodies,
        points: &[[f64; 3]],
        radius: f64,
    ) -> Vec<[f64; 3]> {
        let Some(ball) = crate::Shape::Sphere {
            radius: radius.max(f64::MIN_POSITIVE),
        }
        .compile(&nalgebra::Isometry3::identity()) else {
            return points.to_vec();
        };
        let (compiled, bodies) = (self.compiled(), &placed.placed);
        let mut at = crate::shape::Placed::default();
        points
            .iter()
            .filter(|p| {
                ball.place(&nalgebra::Isometry3::translation(p[0], p[1], p[2]), &mut at);
                !(compiled.iter().zip(bodies))
                    .any(|(c, b)| !bounds_apart(&at, b) && intersects(&ball, &at, c, b))
            })
            .copied()
            .collect()
    }

    /// Every colliding body pair (self pairs first, then world), with signed distances.
    pub fn colliding_pairs(&self, placed: &PlacedBodies, world: &World) -> Vec<CollidingPair> {
        let (bodies, compiled, p) = (self.bodies(), self.compiled(), &placed.placed);
        let mut out = Vec::new();
        let pairs = self.pairs();
        let mut hits = Vec::new();
        self.walk_self(placed, |k| {
            hits.push(k);
            Some(false)
        });
        // in the order of the checked pairs, not of the culling steps
        hits.sort_unstable();
        for k in hits {
            let (a, b) = (pairs[k].a as usize, pairs[k].b as usize);
            out.push(CollidingPair {
                body: bodies[a].name.clone(),
                other: Other::Body(bodies[b].name.clone()),
                body_index: a,
                other_index: b,
                distance: signed_distance(&compiled[a], &p[a], &compiled[b], &p[b]),
            });
        }
        self.walk_world(placed, world, |i, o| {
            let object = &world.objects()[o];
            out.push(CollidingPair {
                body: bodies[i].name.clone(),
                other: Other::Object(object.name().to_string()),
                body_index: i,
                other_index: o,
                distance: signed_distance(&compiled[i], &p[i], &object.compiled, &object.placed),
            });
            Some(false)
        });
        out
    }

    /// Every checked body pair and every (body, world object) pair whose signed distance is
    /// below `margin`, with closest points and normals (for smooth proximity costs and their
    /// gradients); `out` is cleared first. Pairs are listed in the model's pair order, then
    /// bodies × objects.
    pub fn near_pairs(
        &self,
        placed: &PlacedBodies,
        world: &World,
        margin: f64,
        out: &mut Vec<NearPair>,
    ) {
        out.clear();
        let (c, p) = (self.compiled(), &placed.placed);
        let mut push = |body, other, is_object, near: Option<Closest>| {
            if let Some(c) = near {
                out.push(NearPair {
                    body,
                    other,
                    is_object,
                    distance: c.distance,
                    point: c.point1,
                    other_point: c.point2,
                    normal: c.normal,
                });
            }
        };
        for pair in self.pairs() {
            let (a, b) = (pair.a as usize, pair.b as usize);
            push(a, b, false, proximity(&c[a], &p[a], &c[b], &p[b], margin));
        }
        for (i, (ci, pi)) in c.iter().zip(p).enumerate() {
            for (o, object) in world.objects().iter().enumerate() {
                push(
                    i,
                    o,
                    true,
                    proximity(ci, pi, &object.compiled, &object.placed, margin),
                );
            }
        }
    }

    /// Whether placed bodies `a` and `b` touch (whether or not their pair is checked).
    pub(crate) fn bodies_touch(&self, placed: &PlacedBodies, a: usize, b: usize) -> bool {
        let (c, p) = (self.compiled(), &placed.placed);
        !bounds_apart(&p[a], &p[b]) && intersects(&c[a], &p[a], &c[b], &p[b])
    }

    /// Whether placed body `body` touches world object `object`.
    pub(crate) fn body_touches_object(
        &self,
        placed: &PlacedBodies,
        body: usize,
        world: &World,
        object: usize,
    ) -> bool {
        let (c, p) = (&self.compiled()[body], &placed.placed[body]);
        let o = &world.objects()[object];
        !bounds_apart(p, &o.placed) && intersects(c, p, &o.compiled, &o.placed)
    }

    /// [`CollisionModel::body_distance`], faster for convex hulls, when whether the bodies
    /// touch is known (`touching`, as [`CollisionModel::bodies_touch`] says).
    pub(crate) fn body_distance_knowing(
        &self,
        placed: &PlacedBodies,
        a: usize,
        b: usize,
        touching: bool,
    ) -> f64 {
        let (c, p) = (self.compiled(), &placed.placed);
        crate::shape::hull_signed_distance(&c[a], &p[a], &c[b], &p[b], touching)
    }

    /// Signed distance between bodies `a` and `b` (whether or not their pair is checked).
    ///
    /// # Panics
    /// If an index is out of range.
    pub fn body_distance(&self, placed: &PlacedBodies, a: usize, b: usize) -> f64 {
        let (c, p) = (self.compiled(), &placed.placed);
        signed_distance(&c[a], &p[a], &c[b], &p[b])
    }

    /// Signed distance between body `body` and world object `object`.
    ///
    /// # Panics
    /// If an index is out of range.
    pub fn object_distance(
        &self,
        placed: &PlacedBodies,
        body: usize,
        world: &World,
        object: usize,
    ) -> f64 {
        let o = &world.objects()[object];
        signed_distance(
            &self.compiled()[body],
            &placed.placed[body],
            &o.compiled,
            &o.placed,
        )
    }

    /// The closest checked body pair (bounding spheres prune pairs that cannot beat the best so
    /// far); `None` when no pair is checked.
    pub fn min_self_distance(&self, placed: &PlacedBodies) -> Option<PairDistance> {
        let (c, p) = (self.compiled(), &placed.placed);
        let mut best: Option<PairDistance> = None;
        for pair in self.pairs() {
            let (a, b) = (pair.a as usize, pair.b as usize);
            let lower = (p[a].center - p[b].center).norm() - p[a].bound - p[b].bound;
            if best.is_some_and(|best| lower >= best.distance) {
                continue;
            }
            let distance = signed_distance(&c[a], &p[a], &c[b], &p[b]);
            if best.is_none_or(|best| distance < best.distance) {
                best = Some(PairDistance { a, b, distance });
            }
        }
        best
    }
}

impl CollisionModel {
    /// `[a, b]` body indices of one colliding body pair per colliding checked link pair.
    pub(crate) fn colliding_pair_indices(&self, placed: &PlacedBodies) -> Vec<[usize; 2]> {
        let pairs = self.pairs();
        let mut out = Vec::new();
        self.walk_self(placed, |k| {
            out.push(k);
            Some(true)
        });
        out.sort_unstable();
        out.iter()
            .map(|&k| [pairs[k].a as usize, pairs[k].b as usize])
            .collect()
    }
}
