//! Collision checks of [`LANES`] configurations at once.
//!
//! [`CollisionModel::place_batch`] moves every body into the world frame for all lanes of a
//! [`PoseBatch`] in structure-of-arrays form (sphere and capsule ends as one value per lane), so
//! the broad phase — the culling spheres of the kinematic tree and each pair's bounding spheres —
//! tests all lanes in one vector instruction stream. Each lane carries a bit in a mask; a cull
//! skips its block only when every live lane is clear of it, and the exact narrow-phase test of
//! a pair runs only for the lanes its bounding spheres could not clear. The arithmetic repeats
//! the one-configuration path operation for operation, so counts and verdicts are identical to
//! [`CollisionModel::count_self`], [`CollisionModel::count_world`] and friends, lane by lane.

use nalgebra::{Isometry3, Point3, Quaternion, Translation3, UnitQuaternion, Vector3};
use trm_kinematics::{LANES, PoseBatch, PoseLanes};

use crate::cull::{Ball, Step};
use crate::model::CollisionModel;
use crate::placed::PlacedBodies;
use crate::query::CollisionCount;
use crate::shape::{
    Compiled, Geometry, Placed, PointLanes, intersects, segment_distance_squared_lanes,
};
use crate::world::World;

/// One bit per lane.
type Mask = u8;

/// Every lane of a batch.
const ALL: Mask = (1 << LANES) - 1;

/// Deepest nesting of culls followed lane by lane; deeper culls are passed through (still
/// exact: culls only skip work).
const MAX_DEPTH: usize = 64;

/// World-frame geometry of every body in [`LANES`] configurations (a reusable scratch buffer,
/// made by [`CollisionModel::placed_batch`] and filled by [`CollisionModel::place_batch`]).
#[derive(Debug, Clone)]
pub struct PlacedBatch {
    /// Bounding-sphere centres.
    centers: Vec<PointLanes>,
    /// Round shapes: segment ends.
    ends: Vec<[PointLanes; 2]>,
    /// General shapes: the shape's pose per lane.
    isos: Vec<[Isometry3<f64>; LANES]>,
    /// World origins of the links the culling spheres are centred on.
    origins: Vec<PointLanes>,
    /// The lanes in use (the first `n` of the batch).
    live: Mask,
}

impl PlacedBatch {
    /// Number of bodies.
    pub fn len(&self) -> usize {
        self.centers.len()
    }

    /// True for a robot without collision geometry.
    pub fn is_empty(&self) -> bool {
        self.centers.is_empty()
    }

    /// Number of configurations placed (the first lanes of the batch; queries answer 0 and
    /// false for the others).
    pub fn lanes(&self) -> usize {
        self.live.count_ones() as usize
    }

    /// Body `body` of lane `lane` in the one-configuration form the exact tests take.
    #[inline]
    fn placed(&self, compiled: &Compiled, body: usize, lane: usize) -> Placed {
        let center = point(&self.centers[body], lane);
        match compiled.geometry {
            Geometry::Round { .. } => {
                let [a, b] = &self.ends[body];
                Placed {
                    center,
                    bound: compiled.bound,
                    a: point(a, lane),
                    b: point(b, lane),
                    iso: Isometry3::identity(),
                }
            }
            Geometry::General { .. } => Placed {
                center,
                bound: compiled.bound,
                a: Point3::origin(),
                b: Point3::origin(),
                iso: self.isos[body][lane],
            },
        }
    }

    /// Centre and radius of a culling ball in every lane.
    #[inline(always)]
    fn sphere(&self, compiled: &[Compiled], ball: Ball) -> (&PointLanes, f64) {
        match ball {
            Ball::Body(i) => (&self.centers[i as usize], compiled[i as usize].bound),
            Ball::Origin { slot, radius } => (&self.origins[slot as usize], radius),
        }
    }
}

#[inline(always)]
fn point(p: &PointLanes, lane: usize) -> Point3<f64> {
    Point3::new(p[0][lane], p[1][lane], p[2][lane])
}

/// Lanes whose spheres `(a, ra)` and `(b, rb)` are apart, as the one-configuration test
/// computes it: ‖a − b‖² > (ra + rb)².
#[inline(always)]
fn apart(a: &PointLanes, b: &PointLanes, r: f64) -> Mask {
    let mut mask = 0;
    for l in 0..LANES {
        let (dx, dy, dz) = (a[0][l] - b[0][l], a[1][l] - b[1][l], a[2][l] - b[2][l]);
        mask |= u8::from(dx * dx + dy * dy + dz * dz > r * r) << l;
    }
    mask
}

/// The lanes of a mask, lowest first.
#[inline(always)]
fn lanes_of(mask: Mask) -> impl Iterator<Item = usize> {
    (0..LANES).filter(move |l| mask & (1 << l) != 0)
}

/// What a visitor says about a colliding pair in one lane: go on, skip the rest of this link
/// pair (or link) in this lane, or stop this lane altogether.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Next {
    SkipRest,
    StopLane,
}

/// Applies a visitor's answer for lane `l`: `SkipRest` drops the lane from the block's
/// `pending` lanes, `StopLane` from the walk's `live` and current `mask` lanes too.
#[inline(always)]
fn follow(answer: Option<Next>, l: usize, pending: &mut Mask, live: &mut Mask, mask: &mut Mask) {
    let other = !(1 << l);
    match answer {
        None => {}
        Some(Next::SkipRest) => *pending &= other,
        Some(Next::StopLane) => {
            *pending &= other;
            *live &= other;
            *mask &= other;
        }
    }
}

/// Culls followed lane by lane: the lanes still live inside each open cull, and where it ends;
/// at most `N` open at once (deeper ones test but do not narrow the lanes). The `f64` walks and
/// the single-precision screen's walks ([`crate::fast`]) share it.
pub(crate) struct Nest<const N: usize> {
    open: [(u32, Mask); N],
    depth: usize,
}

impl<const N: usize> Nest<N> {
    pub(crate) fn new() -> Self {
        Nest {
            open: [(0, 0); N],
            depth: 0,
        }
    }

    /// Closes every cull that ends at or before step `i`; returns the lanes live after them.
    #[inline(always)]
    pub(crate) fn close(&mut self, i: usize, mut mask: Mask, live: Mask) -> Mask {
        while self.depth > 0 && self.open[self.depth - 1].0 as usize <= i {
            self.depth -= 1;
            mask = self.open[self.depth].1;
        }
        mask & live
    }

    /// Where the innermost open cull ends (the end of the steps when none is open).
    #[inline(always)]
    fn next_end(&self, steps: usize) -> usize {
        if self.depth > 0 {
            self.open[self.depth - 1].0 as usize
        } else {
            steps
        }
    }

    /// Opens a cull ending at `end`; `outer` are the lanes live before it. Beyond `N` open
    /// culls it is not narrowed (returns `outer`).
    #[inline(always)]
    pub(crate) fn open(&mut self, end: u32, outer: Mask, inner: Mask) -> Mask {
        if self.depth == N {
            return outer;
        }
        self.open[self.depth] = (end, outer);
        self.depth += 1;
        inner
    }
}

impl CollisionModel {
    /// A scratch buffer for [`CollisionModel::place_batch`].
    pub fn placed_batch(&self) -> PlacedBatch {
        let n = self.bodies().len();
        let zero = [[0.0; LANES]; 3];
        PlacedBatch {
            centers: vec![zero; n],
            ends: vec![[zero; 2]; n],
            isos: vec![[Isometry3::identity(); LANES]; n],
            origins: vec![zero; self.culling().origin_links.len()],
            live: 0,
        }
    }

    /// Moves every body to the world pose of its link in the first `lanes` (≤ [`LANES`])
    /// configurations of `poses` (no allocation); the queries then answer for those lanes and
    /// give 0 or false for the rest. Lane `l` holds exactly what [`CollisionModel::place`] makes
    /// of [`PoseBatch::lane_into`]'s poses of lane `l`.
    ///
    /// # Panics
    /// If the buffers do not belong to this model (wrong lengths) or `lanes` > [`LANES`].
    pub fn place_batch(&self, poses: &PoseBatch, lanes: usize, out: &mut PlacedBatch) {
        assert_eq!(
            out.len(),
            self.bodies().len(),
            "placed batch of another model"
        );
        assert!(lanes <= LANES, "at most {LANES} lanes");
        out.live = ALL >> (LANES - lanes);
        place_lanes(self, poses, out);
        let links = poses.lanes();
        for (o, &link) in out.origins.iter_mut().zip(&self.culling().origin_links) {
            let p = &links[link as usize];
            *o = [p[4], p[5], p[6]];
        }
    }

    /// Copies lane `lane` of `batch` into a one-configuration buffer (for code written for
    /// [`PlacedBodies`]). No allocation.
    ///
    /// # Panics
    /// If either buffer belongs to another model.
    pub fn lane_into(&self, batch: &PlacedBatch, lane: usize, out: &mut PlacedBodies) {
        assert_eq!(batch.len(), out.placed.len(), "buffers of another model");
        for (i, (c, p)) in self
            .compiled()
            .iter()
            .zip(out.placed.iter_mut())
            .enumerate()
        {
            *p = batch.placed(c, i, lane);
        }
        for (o, b) in out.origins.iter_mut().zip(&batch.origins) {
            *o = point(b, lane);
        }
    }

    /// Calls `hit(pair, lane)` for every checked body pair that collides in a live lane of
    /// `live`, as [`CollisionModel::count_self`]'s walk does lane by lane.
    fn walk_self_batch(
        &self,
        placed: &PlacedBatch,
        live: Mask,
        mut hit: impl FnMut(usize, usize) -> Option<Next>,
    ) {
        walk_self(self, placed, live, &mut hit);
    }

    /// As [`CollisionModel::walk_self_batch`], over (body, object) pairs: `hit(body, object,
    /// lane)`.
    fn walk_world_batch(
        &self,
        placed: &PlacedBatch,
        world: &World,
        live: Mask,
        mut hit: impl FnMut(usize, usize, usize) -> Option<Next>,
    ) {
        walk_world(self, placed, world, live, &mut hit);
    }

    /// [`CollisionModel::count_self`] of every lane.
    pub fn count_self_batch(&self, placed: &PlacedBatch) -> [usize; LANES] {
        let mut n = [0; LANES];
        self.walk_self_batch(placed, placed.live, |_, l| {
            n[l] += 1;
            Some(Next::SkipRest)
        });
        n
    }

    /// [`CollisionModel::count_world`] of every lane.
    pub fn count_world_batch(&self, placed: &PlacedBatch, world: &World) -> [usize; LANES] {
        let mut n = [0; LANES];
        self.walk_world_batch(placed, world, placed.live, |_, _, l| {
            n[l] += 1;
            Some(Next::SkipRest)
        });
        n
    }

    /// [`CollisionModel::count`] of every lane.
    pub fn count_batch(&self, placed: &PlacedBatch, world: &World) -> [CollisionCount; LANES] {
        let (own, objects) = (
            self.count_self_batch(placed),
            self.count_world_batch(placed, world),
        );
        std::array::from_fn(|l| CollisionCount {
            self_pairs: own[l],
            world_pairs: objects[l],
        })
    }

    /// [`CollisionModel::any_self_collision`] of every lane (each lane stops at its first).
    pub fn any_self_collision_batch(&self, placed: &PlacedBatch) -> [bool; LANES] {
        let mut any = [false; LANES];
        self.walk_self_batch(placed, placed.live, |_, l| {
            any[l] = true;
            Some(Next::StopLane)
        });
        any
    }

    /// [`CollisionModel::any_world_collision`] of every lane.
    pub fn any_world_collision_batch(&self, placed: &PlacedBatch, world: &World) -> [bool; LANES] {
        let mut any = [false; LANES];
        self.walk_world_batch(placed, world, placed.live, |_, _, l| {
            any[l] = true;
            Some(Next::StopLane)
        });
        any
    }

    /// [`CollisionModel::is_colliding`] of every lane: the world first, then self-collisions
    /// in the lanes still free.
    pub fn is_colliding_batch(&self, placed: &PlacedBatch, world: &World) -> [bool; LANES] {
        let mut any = self.any_world_collision_batch(placed, world);
        let free = (0..LANES).filter(|&l| !any[l]).fold(0, |m, l| m | (1 << l)) & placed.live;
        self.walk_self_batch(placed, free, |_, l| {
            any[l] = true;
            Some(Next::StopLane)
        });
        any
    }
}

/// The self-collision walk of [`CollisionModel::walk_self_batch`], compiled for several
/// instruction sets (the lane tests are one vector instruction each), the best chosen at run
/// time.
#[allow(unsafe_code)] // multiversion's run-time CPU-feature dispatch
#[multiversion::multiversion(targets("x86_64+avx2+fma", "x86_64+avx", "aarch64+neon"))]
fn walk_self(
    model: &CollisionModel,
    placed: &PlacedBatch,
    mut live: Mask,
    hit: &mut dyn FnMut(usize, usize) -> Option<Next>,
) {
    let (pairs, compiled) = (model.pairs(), model.compiled());
    let steps = &model.culling().self_steps;
    let mut nest = Nest::<MAX_DEPTH>::new();
    let mut mask = live;
    let mut i = 0;
    while i < steps.len() && live != 0 {
        mask = nest.close(i, mask, live);
        if mask == 0 {
            i = nest.next_end(steps.len());
            continue;
        }
        match steps[i] {
            Step::Cull { a, b, end } => {
                let ((ca, ra), (cb, rb)) = (placed.sphere(compiled, a), placed.sphere(compiled, b));
                let inner = mask & !apart(ca, cb, ra + rb);
                if inner == 0 {
                    i = end as usize;
                    continue;
                }
                mask = nest.open(end, mask, inner);
            }
            Step::Test { start, end } => {
                let mut pending = mask;
                let block = &pairs[start as usize..end as usize];
                for (k, pair) in (start as usize..).zip(block) {
                    let (a, b) = (pair.a as usize, pair.b as usize);
                    let near = pending
                        & !apart(
                            &placed.centers[a],
                            &placed.centers[b],
                            compiled[a].bound + compiled[b].bound,
                        );
                    if near == 0 {
                        continue;
                    }
                    let touching = match (&compiled[a].geometry, &compiled[b].geometry) {
                        // two capsules or spheres near in several lanes: one vector test
                        (
                            Geometry::Round { radius: ra, .. },
                            Geometry::Round { radius: rb, .. },
                        ) => {
                            let r = ra + rb;
                            let d2 =
                                segment_distance_squared_lanes(&placed.ends[a], &placed.ends[b]);
                            near & (0..LANES).fold(0, |m, l| m | (u8::from(d2[l] <= r * r) << l))
                        }
                        _ => lanes_of(near).fold(0, |m, l| {
                            let (pa, pb) = (
                                placed.placed(&compiled[a], a, l),
                                placed.placed(&compiled[b], b, l),
                            );
                            m | (u8::from(intersects(&compiled[a], &pa, &compiled[b], &pb)) << l)
                        }),
                    };
                    for l in lanes_of(touching) {
                        follow(hit(k, l), l, &mut pending, &mut live, &mut mask);
                    }
                    if pending == 0 {
                        break;
                    }
                }
            }
        }
        i += 1;
    }
}

/// A world object as the world walk tests spheres against it in every lane at once: its
/// bounding sphere and, for a box, its pose (the inverse rotation as nalgebra applies it) and
/// half extents.
#[derive(Clone, Copy)]
pub(crate) struct Obstacle {
    center: [f64; 3],
    bound: f64,
    /// Boxes: the conjugate quaternion (w, x, y, z), the translation and the half extents.
    slabs: Option<([f64; 4], [f64; 3], [f64; 3])>,
}

impl Obstacle {
    fn new(object: &crate::world::WorldObject) -> Self {
        let (c, p) = (&object.compiled, &object.placed);
        let slabs = match &c.geometry {
            Geometry::General {
                half_extents: Some(h),
                ..
            } => {
                let q = p.iso.rotation.conjugate();
                let t = p.iso.translation.vector;
                Some(([q.w, q.i, q.j, q.k], [t.x, t.y, t.z], [h.x, h.y, h.z]))
            }
            _ => None,
        };
        Obstacle {
            center: [p.center.x, p.center.y, p.center.z],
            bound: p.bound,
            slabs,
        }
    }

    /// One sphere around every object of `objects` when they lie close together — 2 to
    /// [`CLUSTERED`] objects whose enclosing sphere is at most three times as wide as one of
    /// their bounding spheres' summed volume (a fixture, a ring of parts; Table III's posture 2:
    /// its batched runs 7 % faster) — for the world walk to descend the robot's culling tree
    /// once for them all; `None` otherwise.
    pub(crate) fn cluster(objects: &[crate::world::WorldObject]) -> Option<Obstacle> {
        if !(2..=CLUSTERED).contains(&objects.len()) {
            return None;
        }
        let around = Obstacle::around(objects);
        let volume: f64 = objects.iter().map(|o| o.placed.bound.powi(3)).sum();
        (around.bound.is_finite() && around.bound.powi(3) <= 27.0 * volume).then_some(around)
    }

    /// A sphere around the objects' bounding spheres, centred on the box around them.
    fn around(objects: &[crate::world::WorldObject]) -> Obstacle {
        let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
        for o in objects {
            let (c, r) = (o.placed.center, o.placed.bound);
            for k in 0..3 {
                lo[k] = lo[k].min(c[k] - r);
                hi[k] = hi[k].max(c[k] + r);
            }
        }
        let center: [f64; 3] = std::array::from_fn(|k| 0.5 * (lo[k] + hi[k]));
        let mut bound = 0.0f64;
        for o in objects {
            let c = o.placed.center;
            let d =
                ((c.x - center[0]).powi(2) + (c.y - center[1]).powi(2) + (c.z - center[2]).powi(2))
                    .sqrt();
            bound = bound.max(d + o.placed.bound);
        }
        Obstacle {
            center,
            bound,
            slabs: None,
        }
    }

    /// Of the lanes `of`, those where the sphere `(c, r)` cannot touch the object: outside its
    /// bounding sphere or, for a box, outside one of its slabs — `sphere_apart` of the
    /// one-configuration walk, operation for operation.
    #[inline(always)]
    #[allow(clippy::needless_range_loop)] // lane-indexed loops, written as the vectoriser reads them
    fn sphere_apart(&self, c: &PointLanes, r: f64, of: Mask) -> Mask {
        let rr = r + self.bound;
        let mut far = 0;
        for l in 0..LANES {
            let (dx, dy, dz) = (
                c[0][l] - self.center[0],
                c[1][l] - self.center[1],
                c[2][l] - self.center[2],
            );
            far |= u8::from(dx * dx + dy * dy + dz * dz > rr * rr) << l;
        }
        let Some((q, t, half)) = &self.slabs else {
            return far & of;
        };
        if far & of == of {
            return of;
        }
        // the centre in the box frame, q⁻¹ (c − t) as UnitQuaternion * Vector3 computes it
        // (for an axis-aligned box that is c − t exactly)
        let mut local = [[0.0; LANES]; 3];
        for (k, axis) in local.iter_mut().enumerate() {
            for l in 0..LANES {
                axis[l] = c[k][l] - t[k];
            }
        }
        if q[1..] != [0.0; 3] {
            for l in 0..LANES {
                let r = rotate(*q, [local[0][l], local[1][l], local[2][l]]);
                for k in 0..3 {
                    local[k][l] = r[k];
                }
            }
        }
        let mut outside = 0;
        for (axis, h) in local.iter().zip(half) {
            for (l, v) in axis.iter().enumerate() {
                outside |= u8::from(v.abs() > h + r) << l;
            }
        }
        (far | outside) & of
    }
}

/// The world walk of [`CollisionModel::walk_world_batch`]: for each object, the lanes followed
/// together through the culling steps as in the self walk; a cull sphere or a body's bounding
/// sphere is tested against the object (its bounding sphere, a box's slabs) in every lane at
/// once, and the exact test runs only in the lanes those could not clear. Compiled for several
/// instruction sets, the best chosen at run time.
#[allow(unsafe_code)] // multiversion's run-time CPU-feature dispatch
#[multiversion::multiversion(targets("x86_64+avx2+fma", "x86_64+avx", "aarch64+neon"))]
fn walk_world(
    model: &CollisionModel,
    placed: &PlacedBatch,
    world: &World,
    mut live: Mask,
    hit: &mut dyn FnMut(usize, usize, usize) -> Option<Next>,
) {
    let compiled = model.compiled();
    let steps = &model.culling().world_steps;
    let objects = world.objects();
    if let Some(cluster) = Obstacle::cluster(objects) {
        walk_cluster(model, placed, objects, &cluster, live, hit);
        return;
    }
    for (o, object) in objects.iter().enumerate() {
        let (oc, op) = (&object.compiled, &object.placed);
        let obstacle = Obstacle::new(object);
        let mut nest = Nest::<MAX_DEPTH>::new();
        let mut mask = live;
        let mut s = 0;
        while s < steps.len() && live != 0 {
            mask = nest.close(s, mask, live);
            if mask == 0 {
                s = nest.next_end(steps.len());
                continue;
            }
            match steps[s] {
                Step::Cull { a, end, .. } => {
                    let (c, r) = placed.sphere(compiled, a);
                    let inner = mask & !obstacle.sphere_apart(c, r, mask);
                    if inner == 0 {
                        s = end as usize;
                        continue;
                    }
                    mask = nest.open(end, mask, inner);
                }
                Step::Test { start, end } => {
                    let mut pending = mask;
                    let bodies = &compiled[start as usize..end as usize];
                    for (i, body) in (start as usize..).zip(bodies) {
                        let near = pending
                            & !obstacle.sphere_apart(&placed.centers[i], body.bound, pending);
                        for l in lanes_of(near) {
                            let p = placed.placed(body, i, l);
                            if !intersects(body, &p, oc, op) {
                                continue;
                            }
                            follow(hit(i, o, l), l, &mut pending, &mut live, &mut mask);
                        }
                        if pending == 0 {
                            break;
                        }
                    }
                }
            }
            s += 1;
        }
    }
}

/// Most objects the world walk takes as one ([`Obstacle::cluster`]).
const CLUSTERED: usize = 16;
/// Objects per group inside a cluster (each group's sphere tested before its objects).
const GROUPED: usize = 4;

/// The world walk for objects close together: the culling steps followed once, against the
/// sphere around them all (`cluster`), and at each link's bodies each group of four objects'
/// sphere, then its objects in turn, as their own walks would test them — the same pairs
/// reported (link by link rather than object by object), so the same counts and verdicts.
#[inline(always)]
fn walk_cluster(
    model: &CollisionModel,
    placed: &PlacedBatch,
    objects: &[crate::world::WorldObject],
    cluster: &Obstacle,
    mut live: Mask,
    hit: &mut dyn FnMut(usize, usize, usize) -> Option<Next>,
) {
    let compiled = model.compiled();
    let steps = &model.culling().world_steps;
    let mut obstacles = [*cluster; CLUSTERED];
    for (slot, object) in obstacles.iter_mut().zip(objects) {
        *slot = Obstacle::new(object);
    }
    let obstacles = &obstacles[..objects.len()];
    // consecutive objects in fours, each four with a sphere around it (a ring listed in order
    // falls into arcs), tested before its objects
    let mut groups = [*cluster; CLUSTERED / GROUPED];
    for (group, four) in groups.iter_mut().zip(objects.chunks(GROUPED)) {
        *group = Obstacle::around(four);
    }
    let mut nest = Nest::<MAX_DEPTH>::new();
    let mut mask = live;
    let mut s = 0;
    while s < steps.len() && live != 0 {
        mask = nest.close(s, mask, live);
        if mask == 0 {
            s = nest.next_end(steps.len());
            continue;
        }
        match steps[s] {
            Step::Cull { a, end, .. } => {
                let (c, r) = placed.sphere(compiled, a);
                let inner = mask & !cluster.sphere_apart(c, r, mask);
                if inner == 0 {
                    s = end as usize;
                    continue;
                }
                mask = nest.open(end, mask, inner);
            }
            Step::Test { start, end } => {
                // each object's lanes still pending in this link (a hit skips the rest of the
                // link for that object alone)
                let mut pending = [mask; CLUSTERED];
                let bodies = &compiled[start as usize..end as usize];
                for (i, body) in (start as usize..).zip(bodies) {
                    let center = &placed.centers[i];
                    let waiting = pending[..objects.len()].iter().fold(0, |m, p| m | p) & mask;
                    if waiting == 0 {
                        break;
                    }
                    let close = waiting & !cluster.sphere_apart(center, body.bound, waiting);
                    if close == 0 {
                        continue;
                    }
                    for (g, group) in groups.iter().enumerate() {
                        let members = g * GROUPED..((g + 1) * GROUPED).min(objects.len());
                        if members.is_empty() {
                            break;
                        }
                        let waiting = pending[members.clone()].iter().fold(0, |m, p| m | p);
                        let lanes = waiting & close & mask;
                        if lanes == 0 || group.sphere_apart(center, body.bound, lanes) == lanes {
                            continue;
                        }
                        for o in members {
                            let (object, obstacle) = (&objects[o], &obstacles[o]);
                            let lanes = pending[o] & close & mask;
                            if lanes == 0 {
                                continue;
                            }
                            let near = lanes & !obstacle.sphere_apart(center, body.bound, lanes);
                            for l in lanes_of(near) {
                                let p = placed.placed(body, i, l);
                                if !intersects(body, &p, &object.compiled, &object.placed) {
                                    continue;
                                }
                                follow(hit(i, o, l), l, &mut pending[o], &mut live, &mut mask);
                            }
                        }
                    }
                }
            }
        }
        s += 1;
    }
}

/// `q v` for the rotation `q = (w, x, y, z)`, as nalgebra's `UnitQuaternion * Vector3` computes
/// it (t = 2 q×v; v + w t + q×t).
#[inline(always)]
fn rotate([w, x, y, z]: [f64; 4], v: [f64; 3]) -> [f64; 3] {
    let t = [
        (y * v[2] - z * v[1]) * 2.0,
        (z * v[0] - x * v[2]) * 2.0,
        (x * v[1] - y * v[0]) * 2.0,
    ];
    let cross = [
        y * t[2] - z * t[1],
        z * t[0] - x * t[2],
        x * t[1] - y * t[0],
    ];
    [
        t[0] * w + cross[0] + v[0],
        t[1] * w + cross[1] + v[1],
        t[2] * w + cross[2] + v[2],
    ]
}

/// `p v`: the fixed point `v` moved by the pose of each lane (rotated, then translated).
#[inline(always)]
fn moved(p: &PoseLanes, v: &Vector3<f64>) -> PointLanes {
    let mut out = [[0.0; LANES]; 3];
    for l in 0..LANES {
        let r = rotate([p[0][l], p[1][l], p[2][l], p[3][l]], [v.x, v.y, v.z]);
        for k in 0..3 {
            out[k][l] = r[k] + p[4 + k][l];
        }
    }
    out
}

/// Every body in the world frame for all lanes, as [`Compiled::place`] computes it operation
/// for operation (so each lane equals it bit for bit): round bodies' segment ends and centres;
/// general bodies' pose (the parent's rotation times the body's, the parent's translation plus
/// the rotated offset, as nalgebra composes isometries) and bounding-sphere centre. Compiled for
/// several instruction sets, the best chosen at run time.
#[allow(unsafe_code)] // multiversion's run-time CPU-feature dispatch
#[multiversion::multiversion(targets("x86_64+avx2+fma", "x86_64+avx", "aarch64+neon"))]
fn place_lanes(model: &CollisionModel, poses: &PoseBatch, out: &mut PlacedBatch) {
    let links = poses.lanes();
    for (i, (body, c)) in model.bodies().iter().zip(model.compiled()).enumerate() {
        let p = &links[body.link];
        match &c.geometry {
            Geometry::Round { a, b, .. } => {
                let ends = [moved(p, &a.coords), moved(p, &b.coords)];
                let mut center = [[0.0; LANES]; 3];
                for k in 0..3 {
                    for l in 0..LANES {
                        center[k][l] = (ends[0][k][l] + ends[1][k][l]) * 0.5;
                    }
                }
                out.ends[i] = ends;
                out.centers[i] = center;
            }
            Geometry::General { local, .. } => {
                let translation = moved(p, &local.translation.vector);
                let r = local.rotation.quaternion();
                let (w2, i2, j2, k2) = (r.w, r.i, r.j, r.k);
                for l in 0..LANES {
                    let (w1, i1, j1, k1) = (p[0][l], p[1][l], p[2][l], p[3][l]);
                    let q = Quaternion::new(
                        w1 * w2 - i1 * i2 - j1 * j2 - k1 * k2,
                        w1 * i2 + i1 * w2 + j1 * k2 - k1 * j2,
                        w1 * j2 - i1 * k2 + j1 * w2 + k1 * i2,
                        w1 * k2 + i1 * j2 - j1 * i2 + k1 * w2,
                    );
                    out.isos[i][l] = Isometry3::from_parts(
                        Translation3::new(translation[0][l], translation[1][l], translation[2][l]),
                        UnitQuaternion::new_unchecked(q),
                    );
                }
                out.centers[i] = moved(p, &c.center.coords);
            }
        }
    }
}
