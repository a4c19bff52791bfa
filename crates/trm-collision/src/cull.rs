//! The order in which body pairs are tested: a sphere hierarchy over the kinematic tree.
//!
//! Every link's subtree (the link and everything below it) gets a sphere centred on the link's
//! origin that encloses every body of the subtree in *any* configuration: its radius adds, down
//! each chain, the length of every joint origin (plus the travel of prismatic joints) and the
//! extent of each body's bounding sphere. Such a sphere moves with its link only, so it costs
//! nothing to place, and two subtrees whose spheres are apart cannot touch. The self-collision
//! test is compiled once into a flat list of [`Step`]s: the body pairs of each checked link pair
//! in one block, nested under the sphere tests of the subtrees that contain them, so one test can
//! clear a hand against the other hand (289 body pairs on the iCub). The world test walks the
//! links depth first, clearing a whole subtree against an object at once.

use nalgebra::Point3;
use trm_kinematics::{JointKind, Tree};

use crate::placed::{BodyPair, PlacedBodies};
use crate::shape::Compiled;

/// A sphere that encloses some bodies.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Ball {
    /// The bounding sphere of one placed body.
    Body(u32),
    /// A sphere of this radius around the origin of the link in origin slot `slot`.
    Origin { slot: u32, radius: f64 },
}

/// One step of a compiled test.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Step {
    /// When the two spheres are apart, continue at step `end` (everything before it lies inside
    /// both spheres).
    Cull { a: Ball, b: Ball, end: u32 },
    /// Self tests: the body pairs `start..end` (one link pair). World tests: the bodies
    /// `start..end` (one link).
    Test { start: u32, end: u32 },
}

/// The compiled tests: self-collision steps, world steps (a [`Ball`] in a `Cull` is tested
/// against the object's sphere; its `b` is unused), and the links whose origins the steps use.
#[derive(Debug, Clone, Default)]
pub(crate) struct Culling {
    pub self_steps: Vec<Step>,
    pub world_steps: Vec<Step>,
    /// Link index of every origin slot.
    pub origin_links: Vec<u32>,
}

/// Part of the robot during compilation: one link's own bodies, or a link's whole subtree.
#[derive(Debug, Clone, Copy)]
enum Node {
    Link(usize),
    Subtree(usize),
}

struct Builder {
    children: Vec<Vec<usize>>,
    /// Depth-first entry and exit numbers: link `m` is in the subtree of `l` iff
    /// `enter[l] <= enter[m] < exit[l]`.
    enter: Vec<usize>,
    exit: Vec<usize>,
    /// Per link: its bodies `start..end`.
    bodies: Vec<(usize, usize)>,
    /// Per link: radius around its origin enclosing its own bodies / its subtree's bodies.
    own_radius: Vec<f64>,
    subtree_radius: Vec<f64>,
    /// Per link: bodies in its subtree.
    subtree_bodies: Vec<usize>,
    /// Checked link pairs: `(link a, link b, first pair, end of pairs)`.
    blocks: Vec<(usize, usize, u32, u32)>,
    slots: Vec<Option<u32>>,
    origin_links: Vec<u32>,
}

impl Culling {
    /// Compiles the tests for bodies sorted by link, with their compiled shapes and the checked
    /// body pairs (grouped by link pair).
    pub(crate) fn new(
        tree: &Tree,
        body_links: &[usize],
        compiled: &[Compiled],
        pairs: &[BodyPair],
    ) -> Culling {
        let n = tree.links.len();
        let mut children = vec![Vec::new(); n];
        for joint in &tree.joints {
            children[joint.parent].push(joint.child);
        }
        let mut bodies = vec![(0, 0); n];
        let mut own_radius = vec![0.0_f64; n];
        for (i, (&link, c)) in body_links.iter().zip(compiled).enumerate() {
            if bodies[link].1 == 0 {
                bodies[link].0 = i;
            }
            bodies[link].1 = i + 1;
            own_radius[link] = own_radius[link].max(c.center.coords.norm() + c.bound);
        }
        // Joints are listed parents first (`joints[i].child == i + 1`), so one backward pass
        // sees every child before its parent.
        let mut subtree_radius = own_radius.clone();
        let mut subtree_bodies: Vec<usize> = bodies.iter().map(|(s, e)| e - s).collect();
        for joint in tree.joints.iter().rev() {
            let (c, p) = (joint.child, joint.parent);
            let travel = match joint.kind {
                JointKind::Prismatic => joint.limits.lower.abs().max(joint.limits.upper.abs()),
                _ => 0.0,
            };
            if subtree_bodies[c] > 0 {
                let reach = joint.local_origin.translation.vector.norm() + travel;
                subtree_radius[p] = subtree_radius[p].max(reach + subtree_radius[c]);
                subtree_bodies[p] += subtree_bodies[c];
            }
        }
        let (mut enter, mut exit) = (vec![0; n], vec![0; n]);
        let mut clock = 0;
        let mut stack = vec![(0usize, false)];
        while let Some((l, done)) = stack.pop() {
            if done {
                exit[l] = clock;
                continue;
            }
            enter[l] = clock;
            clock += 1;
            stack.push((l, true));
            stack.extend(children[l].iter().rev().map(|&c| (c, false)));
        }
        let mut blocks = Vec::new();
        let mut k = 0;
        while k < pairs.len() {
            let end = pairs[k].next as usize;
            let (a, b) = (
                body_links[pairs[k].a as usize],
                body_links[pairs[k].b as usize],
            );
            blocks.push((a, b, k as u32, end as u32));
            k = end;
        }
        let mut builder = Builder {
            children,
            enter,
            exit,
            bodies,
            own_radius,
            subtree_radius,
            subtree_bodies,
            blocks,
            slots: vec![None; n],
            origin_links: Vec::new(),
        };
        let all: Vec<usize> = (0..builder.blocks.len()).collect();
        let mut self_steps = Vec::new();
        if n > 0 {
            builder.within(0, &all, &mut self_steps);
        }
        let mut world_steps = Vec::new();
        if n > 0 {
            builder.world(0, f64::INFINITY, &mut world_steps);
        }
        Culling {
            self_steps,
            world_steps,
            origin_links: builder.origin_links,
        }
    }
}

impl Builder {
    fn contains(&self, node: Node, link: usize) -> bool {
        match node {
            Node::Link(l) => l == link,
            Node::Subtree(l) => {
                self.enter[l] <= self.enter[link] && self.enter[link] < self.exit[l]
            }
        }
    }

    fn slot(&mut self, link: usize) -> u32 {
        *self.slots[link].get_or_insert_with(|| {
            self.origin_links.push(link as u32);
            (self.origin_links.len() - 1) as u32
        })
    }

    /// The tightest sphere of a node: the body's own when it has one body.
    fn ball(&mut self, node: Node) -> Ball {
        let (link, count, radius) = match node {
            Node::Link(l) => (l, self.bodies[l].1 - self.bodies[l].0, self.own_radius[l]),
            Node::Subtree(l) => (l, self.subtree_bodies[l], self.subtree_radius[l]),
        };
        let (start, end) = self.bodies[link];
        if count == 1 && end - start == 1 {
            Ball::Body(start as u32)
        } else {
            Ball::Origin {
                slot: self.slot(link),
                radius,
            }
        }
    }

    fn radius(&self, node: Node) -> f64 {
        match node {
            Node::Link(l) => self.own_radius[l],
            Node::Subtree(l) => self.subtree_radius[l],
        }
    }

    /// The parts of a subtree: its root link's bodies and its children's subtrees.
    fn parts(&self, l: usize) -> Vec<Node> {
        let mut parts = vec![Node::Link(l)];
        parts.extend(
            self.children[l]
                .iter()
                .filter(|&&c| self.subtree_bodies[c] > 0)
                .map(|&c| Node::Subtree(c)),
        );
        parts
    }

    /// Steps for every checked link pair of `candidates` inside the subtree of `l`.
    fn within(&mut self, l: usize, candidates: &[usize], out: &mut Vec<Step>) {
        let parts = self.parts(l);
        for (i, &x) in parts.iter().enumerate() {
            if let Node::Subtree(c) = x {
                let inside: Vec<usize> = candidates
                    .iter()
                    .copied()
                    .filter(|&b| {
                        let (la, lb) = (self.blocks[b].0, self.blocks[b].1);
                        self.contains(x, la) && self.contains(x, lb)
                    })
                    .collect();
                self.within(c, &inside, out);
            }
            for &y in &parts[i + 1..] {
                self.between(x, y, candidates, f64::INFINITY, out);
            }
        }
    }

    /// Steps for every checked link pair of `candidates` with one link in `x`, one in `y`,
    /// inside a cull whose radii add up to `enclosing`.
    fn between(
        &mut self,
        x: Node,
        y: Node,
        candidates: &[usize],
        enclosing: f64,
        out: &mut Vec<Step>,
    ) {
        let mine: Vec<usize> = candidates
            .iter()
            .copied()
            .filter(|&b| {
                let (la, lb) = (self.blocks[b].0, self.blocks[b].1);
                (self.contains(x, la) && self.contains(y, lb))
                    || (self.contains(x, lb) && self.contains(y, la))
            })
            .collect();
        match mine.as_slice() {
            [] => return,
            &[b] => {
                let (_, _, start, end) = self.blocks[b];
                out.push(Step::Test { start, end });
                return;
            }
            _ => {}
        }
        let radius = self.radius(x) + self.radius(y);
        let cull = worth_a_cull(radius, enclosing).then(|| {
            let (a, b) = (self.ball(x), self.ball(y));
            out.push(Step::Cull { a, b, end: 0 });
            out.len() - 1
        });
        let enclosing = if cull.is_some() { radius } else { enclosing };
        // Split the larger subtree (a link's own bodies are a block of their own).
        let (split, other) = match (x, y) {
            (Node::Subtree(_), Node::Subtree(_)) if self.radius(x) >= self.radius(y) => (x, y),
            (Node::Subtree(_), Node::Subtree(_)) => (y, x),
            (Node::Subtree(_), _) => (x, y),
            _ => (y, x),
        };
        let Node::Subtree(l) = split else {
            unreachable!("two single links hold one link pair")
        };
        for part in self.parts(l) {
            self.between(part, other, &mine, enclosing, out);
        }
        close(out, cull);
    }

    /// World steps for the subtree of `l`, depth first, inside a cull of radius `enclosing`.
    fn world(&mut self, l: usize, enclosing: f64, out: &mut Vec<Step>) {
        if self.subtree_bodies[l] == 0 {
            return;
        }
        let (start, end) = self.bodies[l];
        let radius = self.subtree_radius[l];
        let worth = self.subtree_bodies[l] > end - start && worth_a_cull(radius, enclosing);
        let cull = worth.then(|| {
            let a = self.ball(Node::Subtree(l));
            out.push(Step::Cull { a, b: a, end: 0 });
            out.len() - 1
        });
        let enclosing = if cull.is_some() { radius } else { enclosing };
        if end > start {
            out.push(Step::Test {
                start: start as u32,
                end: end as u32,
            });
        }
        for c in self.children[l].clone() {
            self.world(c, enclosing, out);
        }
        close(out, cull);
    }
}

/// A cull inside another pays when its spheres are clearly smaller (a link of a chain is
/// enclosed by nearly the same sphere as its parent: testing both rarely clears more).
fn worth_a_cull(radius: f64, enclosing: f64) -> bool {
    radius <= 0.8 * enclosing
}

/// Points the cull pushed at `at`, if any, past the steps pushed since.
fn close(out: &mut [Step], at: Option<usize>) {
    let end = out.len() as u32;
    if let Some(Step::Cull { end: e, .. }) = at.and_then(|at| out.get_mut(at)) {
        *e = end;
    }
}

impl PlacedBodies {
    /// World centre and radius of a ball.
    #[inline(always)]
    pub(crate) fn sphere(&self, ball: Ball) -> (&Point3<f64>, f64) {
        match ball {
            Ball::Body(i) => {
                let p = &self.placed[i as usize];
                (&p.center, p.bound)
            }
            Ball::Origin { slot, radius } => (&self.origins[slot as usize], radius),
        }
    }

    /// Whether two balls are apart.
    #[inline(always)]
    pub(crate) fn apart(&self, a: Ball, b: Ball) -> bool {
        let ((ca, ra), (cb, rb)) = (self.sphere(a), self.sphere(b));
        let r = ra + rb;
        (ca - cb).norm_squared() > r * r
    }
}

#[cfg(test)]
mod tests {
    use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};
    use proptest::prelude::*;
    use trm_kinematics::{ActiveSet, LANES, PoseBuffer, RobotModel};

    use super::Step;
    use crate::shape::{bounds_apart, intersects};
    use crate::{CollisionCount, CollisionModel, PlacedBodies, Shape, World};

    /// Today's answer without culling: every checked body pair, one hit per link pair.
    fn exhaustive(model: &CollisionModel, placed: &PlacedBodies, world: &World) -> CollisionCount {
        let (c, p) = (model.compiled(), &placed.placed);
        let pairs = model.pairs();
        let (mut self_pairs, mut k) = (0, 0);
        while k < pairs.len() {
            let (a, b) = (pairs[k].a as usize, pairs[k].b as usize);
            if !bounds_apart(&p[a], &p[b]) && intersects(&c[a], &p[a], &c[b], &p[b]) {
                self_pairs += 1;
                k = pairs[k].next as usize;
            } else {
                k += 1;
            }
        }
        let bodies = model.bodies();
        let mut world_pairs = 0;
        for o in world.objects() {
            let mut linked = std::collections::BTreeSet::new();
            for i in 0..p.len() {
                if intersects(&c[i], &p[i], &o.compiled, &o.placed) {
                    linked.insert(bodies[i].link);
                }
            }
            world_pairs += linked.len();
        }
        CollisionCount {
            self_pairs,
            world_pairs,
        }
    }

    struct Fixture {
        robot: RobotModel,
        active: ActiveSet,
        model: CollisionModel,
    }

    fn icub() -> &'static Fixture {
        static F: std::sync::OnceLock<Fixture> = std::sync::OnceLock::new();
        F.get_or_init(|| {
            let robot = trm_models::icub_upper_body();
            let active = robot.all_active();
            let model = CollisionModel::new(&robot).unwrap();
            Fixture {
                robot,
                active,
                model,
            }
        })
    }

    fn configuration(f: &Fixture, unit: &[f64]) -> Vec<f64> {
        let (lo, hi) = f.active.bounds();
        lo.iter()
            .zip(&hi)
            .zip(unit)
            .map(|((l, h), u)| l + (h - l) * u)
            .collect()
    }

    fn check(f: &Fixture, q: &[f64], world: &World, poses: &mut PoseBuffer) {
        let mut placed = f.model.placed_bodies();
        f.active.forward(q, poses).unwrap();
        f.model.place(poses, &mut placed);
        let want = exhaustive(&f.model, &placed, world);
        assert_eq!(f.model.count(&placed, world), want, "at {q:?}");
        assert_eq!(f.model.any_self_collision(&placed), want.self_pairs > 0);
        assert_eq!(
            f.model.any_world_collision(&placed, world),
            want.world_pairs > 0
        );
        assert_eq!(
            f.model.colliding_pair_indices(&placed).len(),
            want.self_pairs
        );
    }

    /// Up to [`LANES`] configurations through batched kinematics and [`CollisionModel::place_batch`]:
    /// every batched count and verdict equals the one-configuration path on the same lane's
    /// poses and the exhaustive answer, and the lane's placed bodies are those `place` makes.
    fn check_batch(f: &Fixture, qs: &[Vec<f64>], world: &World) {
        let d = f.active.len();
        let mut flat = Vec::new();
        for l in 0..LANES {
            flat.extend_from_slice(&qs[l.min(qs.len() - 1)]);
        }
        assert_eq!(flat.len(), LANES * d);
        let mut batch = f.robot.pose_batch();
        f.active.forward_batch(&flat, &mut batch).unwrap();
        let mut placed_batch = f.model.placed_batch();
        f.model.place_batch(&batch, qs.len(), &mut placed_batch);
        assert_eq!(placed_batch.lanes(), qs.len());
        let counts = f.model.count_batch(&placed_batch, world);
        let own = f.model.any_self_collision_batch(&placed_batch);
        let objects = f.model.any_world_collision_batch(&placed_batch, world);
        let either = f.model.is_colliding_batch(&placed_batch, world);
        let (mut poses, mut placed, mut copied) = (
            f.robot.pose_buffer(),
            f.model.placed_bodies(),
            f.model.placed_bodies(),
        );
        for l in qs.len()..LANES {
            assert_eq!(counts[l], CollisionCount::default(), "unused lane {l}");
            assert!(!own[l] && !objects[l] && !either[l], "unused lane {l}");
        }
        for l in 0..qs.len() {
            batch.lane_into(l, &mut poses);
            f.model.place(&poses, &mut placed);
            f.model.lane_into(&placed_batch, l, &mut copied);
            for (a, b) in placed.placed.iter().zip(&copied.placed) {
                let fields = |p: &crate::shape::Placed| (p.center, p.bound, p.a, p.b, p.iso);
                assert_eq!(fields(a), fields(b), "lane {l}: bit for bit");
            }
            assert_eq!(placed.origins, copied.origins);
            let want = exhaustive(&f.model, &placed, world);
            assert_eq!(f.model.count(&placed, world), want);
            assert_eq!(
                counts[l],
                want,
                "lane {l} at {:?}",
                &flat[l * d..(l + 1) * d]
            );
            assert_eq!(own[l], want.self_pairs > 0, "lane {l}");
            assert_eq!(objects[l], want.world_pairs > 0, "lane {l}");
            assert_eq!(either[l], want.total() > 0, "lane {l}");
            assert_eq!(f.model.count(&copied, world), want, "lane {l} copied back");
        }
    }

    #[test]
    fn every_checked_pair_and_every_body_is_tested_exactly_once() {
        for model in [
            icub().model.clone(),
            CollisionModel::new(&trm_models::icub_sagittal()).unwrap(),
        ] {
            let culling = model.culling();
            let mut seen = vec![0; model.pairs().len()];
            for step in &culling.self_steps {
                if let Step::Test { start, end } = *step {
                    seen[start as usize..end as usize]
                        .iter_mut()
                        .for_each(|s| *s += 1);
                }
            }
            assert!(seen.iter().all(|&s| s == 1), "{seen:?}");
            let mut seen = vec![0; model.bodies().len()];
            for step in &culling.world_steps {
                if let Step::Test { start, end } = *step {
                    seen[start as usize..end as usize]
                        .iter_mut()
                        .for_each(|s| *s += 1);
                }
            }
            assert!(seen.iter().all(|&s| s == 1), "{seen:?}");
            let culls = culling
                .self_steps
                .iter()
                .filter(|s| matches!(s, Step::Cull { .. }));
            assert!(culls.count() > 10, "no hierarchy was built");
        }
    }

    /// Configurations on the boundary of self-contact (bisection between a colliding and a
    /// free configuration to 1e-12 of the segment) and random ones.
    #[test]
    fn near_contact_and_random_configurations_give_the_exhaustive_answer() {
        let f = icub();
        let mut poses = f.robot.pose_buffer();
        let mut placed = f.model.placed_bodies();
        let empty = World::new();
        let mut colliding = |q: &[f64]| {
            f.active.forward(q, &mut poses).unwrap();
            f.model.place(&poses, &mut placed);
            exhaustive(&f.model, &placed, &empty).self_pairs > 0
        };
        let mut state = 7u64;
        let mut unit = || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let mut boundaries = Vec::new();
        while boundaries.len() < 200 {
            let u: Vec<f64> = (0..f.active.len()).map(|_| unit()).collect();
            let v: Vec<f64> = (0..f.active.len()).map(|_| unit()).collect();
            let (qa, qb) = (configuration(f, &u), configuration(f, &v));
            if colliding(&qa) == colliding(&qb) {
                continue;
            }
            let (mut lo, mut hi) = (0.0, 1.0);
            let at =
                |t: f64| -> Vec<f64> { qa.iter().zip(&qb).map(|(a, b)| a + (b - a) * t).collect() };
            let first = colliding(&qa);
            for _ in 0..40 {
                let mid = 0.5 * (lo + hi);
                if colliding(&at(mid)) == first {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            boundaries.push(at(lo));
            boundaries.push(at(hi));
        }
        // and plain random ones, many: contacts between the two hands are rare
        for _ in 0..20_000 {
            let u: Vec<f64> = (0..f.active.len()).map(|_| unit()).collect();
            boundaries.push(configuration(f, &u));
        }
        let mut poses = f.robot.pose_buffer();
        for q in &boundaries {
            check(f, q, &empty, &mut poses);
        }
        // batched: contact and free lanes side by side, and a table across the body
        let mut table = World::new();
        table
            .add(
                "table",
                Shape::Box {
                    size: [0.5, 0.8, 0.04],
                },
                Isometry3::translation(-0.4, 0.0, -0.14),
            )
            .unwrap();
        for lanes in boundaries.chunks(LANES) {
            check_batch(f, lanes, &empty);
            check_batch(f, lanes, &table);
        }
    }

    fn object() -> impl Strategy<Value = (Shape, Isometry3<f64>)> {
        let shape = prop_oneof![
            (0.01..0.3f64).prop_map(|radius| Shape::Sphere { radius }),
            (0.01..0.1f64, 0.01..0.5f64)
                .prop_map(|(radius, length)| Shape::Capsule { radius, length }),
            (0.01..0.6f64, 0.01..0.6f64, 0.01..0.6f64)
                .prop_map(|(x, y, z)| Shape::Box { size: [x, y, z] }),
            (0.01..0.2f64, 0.01..0.4f64)
                .prop_map(|(radius, length)| Shape::Cylinder { radius, length }),
        ];
        let pose = (
            -0.6..0.6f64,
            -0.6..0.6f64,
            -0.4..0.9f64,
            -3.0..3.0f64,
            -1.5..1.5f64,
            -3.0..3.0f64,
        )
            .prop_map(|(x, y, z, r, p, w)| {
                Isometry3::from_parts(
                    Translation3::new(x, y, z),
                    UnitQuaternion::from_euler_angles(r, p, w),
                )
            });
        (shape, pose)
    }

    /// Worlds of small objects close together, which the batched world walk takes as one
    /// cluster (a ring, a fixture), placed where the arms reach: every count and verdict is the
    /// exhaustive one.
    #[test]
    fn clustered_objects_give_the_exhaustive_answer() {
        use rand::{RngExt, SeedableRng};
        let f = icub();
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
        let (mut clustered, mut touching) = (0, 0);
        let (mut poses, mut placed) = (f.robot.pose_buffer(), f.model.placed_bodies());
        for _ in 0..150 {
            let lanes: Vec<Vec<f64>> = (0..LANES)
                .map(|_| {
                    let u: Vec<f64> = (0..f.active.len())
                        .map(|_| rng.random_range(0.0..1.0))
                        .collect();
                    configuration(f, &u)
                })
                .collect();
            // about a body of the first configuration, so that objects touch it
            f.active.forward(&lanes[0], &mut poses).unwrap();
            f.model.place(&poses, &mut placed);
            let body = rng.random_range(0..placed.placed.len());
            let centre = placed.placed[body].center.coords;
            let mut world = World::new();
            for i in 0..rng.random_range(2..9) {
                let shape = match i % 3 {
                    0 => Shape::Sphere {
                        radius: rng.random_range(0.02..0.05),
                    },
                    1 => Shape::Capsule {
                        radius: rng.random_range(0.01..0.03),
                        length: rng.random_range(0.02..0.08),
                    },
                    _ => Shape::Cylinder {
                        radius: rng.random_range(0.01..0.04),
                        length: rng.random_range(0.02..0.1),
                    },
                };
                let offset = Vector3::from_fn(|_, _| rng.random_range(-0.05..0.05));
                let pose = Isometry3::from_parts(
                    Translation3::from(centre + offset),
                    UnitQuaternion::from_euler_angles(
                        rng.random_range(-3.0..3.0),
                        rng.random_range(-1.5..1.5),
                        rng.random_range(-3.0..3.0),
                    ),
                );
                world.add(&format!("o{i}"), shape, pose).unwrap();
            }
            clustered += usize::from(crate::batch::Obstacle::cluster(world.objects()).is_some());
            touching += usize::from(f.model.count(&placed, &world).world_pairs > 0);
            check_batch(f, &lanes, &world);
        }
        assert!(clustered >= 100, "only {clustered} of 150 worlds clustered");
        assert!(touching >= 75, "only {touching} of 150 worlds touched");
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(256))]
        #[test]
        fn random_configurations_and_worlds_give_the_exhaustive_answer(
            unit in proptest::collection::vec(0.0..=1.0f64, 41),
            others in proptest::collection::vec(proptest::collection::vec(0.0..=1.0f64, 41), 0..LANES),
            objects in proptest::collection::vec(object(), 0..5),
            shift in -0.05..0.05f64,
        ) {
            let f = icub();
            let mut world = World::new();
            for (i, (shape, pose)) in objects.into_iter().enumerate() {
                let pose = Isometry3::from_parts(
                    Translation3::from(pose.translation.vector + Vector3::repeat(shift)),
                    pose.rotation,
                );
                world.add(&format!("o{i}"), shape, pose).unwrap();
            }
            let mut poses = f.robot.pose_buffer();
            check(f, &configuration(f, &unit), &world, &mut poses);
            let mut lanes = vec![configuration(f, &unit)];
            lanes.extend(others.iter().map(|u| configuration(f, u)));
            check_batch(f, &lanes, &world);
        }
    }
}
