use super::LaneMask;
#[cfg(target_arch = "x86_64")]
use super::avx;
use super::cloud::solids_against_cloud;
use super::kdop::kdop_clear;
use super::lanes::{
    F, PORTABLE, aligned_box_distance2, compiled_per_isa, distance2, inverse_transform, pose_point,
    rotation, splat, transform,
};
use super::model::{CullStep, FastModel, GroupPair, Suspect, WorldStep};
use super::outcome::{Contact, Outcome};
use super::solid::{Placed, Solid, box_box, rotate, round_box, round_round};
use super::table::Angles;
use super::world::{FastWorld, Object};
use crate::batch::Nest;
use trm_kinematics::PoseLanes32;

/// Caller-owned scratch of [`FastModel::check`] (made by [`FastModel::scratch`]): world
/// centres of every sphere and bounding sphere in every lane. Checks do not allocate.
#[derive(Debug, Clone)]
pub struct FastScratch {
    pub(super) balls: Vec<[F; 3]>,
    pub(super) inner: Vec<[F; 3]>,
    /// Every solid ([`FastModel::solids`]) placed: a box's centre and axes, a capsule's ends.
    pub(super) solids: Vec<Placed>,
    /// Per link group: whether its solids are placed for the current block.
    pub(super) solid_placed: Vec<bool>,
    pub(super) bounds: Vec<[F; 3]>,
    /// Per link group: its frame (rotation rows, translation) in every lane, made by [`frame`]
    /// when first needed in a block (`framed`).
    pub(super) frames: Vec<([F; 9], [F; 3])>,
    /// Per link group: whether its frame's rotation is made for the current block.
    pub(super) framed: Vec<bool>,
    /// The tabled joints' angles read for the current block.
    pub(super) angles: Angles,
    /// Per link group: whether its balls are placed for the current block.
    pub(super) placed: Vec<bool>,
    /// What left lanes uncertain in the last check, and in which lanes.
    pub(super) suspects: Vec<(Suspect, LaneMask)>,
    /// The pair the last check that stopped at a collision stopped at: tested first by the
    /// next check (consecutive blocks, such as the points of a planner's edges, mostly collide
    /// where the last one did).
    pub(super) last_hit: Option<Suspect>,
}

/// Most culls open at once in a walk; deeper ones test but do not narrow the lanes.
pub(super) const MAX_NESTING: usize = 16;

/// [`FastModel::check`] and [`FastModel::count`], compiled for several instruction sets with the
/// best one chosen at run time.
#[allow(unsafe_code)] // multiversion's run-time CPU-feature dispatch
#[multiversion::multiversion(targets("x86_64+avx2+fma", "x86_64+avx", "aarch64+neon"))]
pub(super) fn screen<O: Outcome + Default>(
    model: &FastModel,
    poses: &[PoseLanes32],
    live: LaneMask,
    world: &FastWorld,
    scratch: &mut FastScratch,
) -> O {
    // the AVX code paths take AVX2 and FMA: the plain-AVX clone goes without them
    const AVX: bool = multiversion::target::selected_target!().supports_feature_str("avx2")
        && multiversion::target::selected_target!().supports_feature_str("fma");
    let mut outcome = O::default();
    walk::<AVX, _>(model, poses, live, world, scratch, &mut outcome);
    outcome
}

/// The screen's walk: the world's objects against the links, then the link pairs, each group
/// of spheres' contacts handed to `outcome`; ends early when the outcome says so.
#[inline(always)]
pub(super) fn walk<const AVX: bool, O: Outcome>(
    model: &FastModel,
    poses: &[PoseLanes32],
    live: LaneMask,
    world: &FastWorld,
    scratch: &mut FastScratch,
    verdict: &mut O,
) {
    place::<AVX>(model, poses, scratch);
    scratch.suspects.clear();
    if O::STOPS_AT_FIRST && last_hit_again::<AVX, O>(model, poses, live, world, scratch, verdict) {
        return;
    }
    let m = world.margin;
    // the world first: in a planner's queries most collisions are with the world, and the
    // objects nearest the robot first. A model of few links: link by link, the links last in
    // the tree first (the hand and the forearm sweep the most space: most collisions are
    // theirs), each link's bounding sphere against each object, then its spheres. A model of
    // many links: each object against the culling spheres of the kinematic tree's subtrees
    // first
    if model.world_steps.is_empty() {
        for g in (0..model.groups.len()).rev() {
            let within = farthest(&scratch.bounds[g]) + model.groups[g].bound.radius + m;
            let reach = model.groups[g].bound.radius + m;
            // the objects nearer the origin than the link's bounding sphere reaches (they are
            // sorted: their count is where the first beyond is, found without a branch), 64 at
            // a time: first which of them the sphere comes near in some lane (no branch per
            // object: whether one passes is hard to predict), then those
            let upto: usize = world
                .from_origin
                .iter()
                .map(|&d| usize::from(!(d > within)))
                .sum();
            for start in (0..upto).step_by(64) {
                let end = (start + 64).min(upto);
                let mut near = 0u64;
                for k in start..end {
                    let passes = enclosing_near::<AVX>(world, k, &scratch.bounds[g], reach, live);
                    near |= u64::from(passes) << (k - start);
                }
                while near != 0 {
                    let k = start + near.trailing_zeros() as usize;
                    near &= near - 1;
                    let (o, object) = (world.original[k] as usize, &world.objects[k]);
                    if object_link::<AVX, _>(
                        model, poses, o, object, g, live, world, scratch, verdict,
                    ) {
                        return;
                    }
                }
            }
        }
    } else if !model.culls {
        // the same order, a frame's groups behind the sphere enclosing them
        let steps = &model.world_steps;
        let mut i = 0;
        while i < steps.len() {
            let (links, ball) = match steps[i] {
                WorldStep::Cull { ball, radius, end } => {
                    (i + 1..end as usize, Some((ball, radius)))
                }
                WorldStep::Link(_) => (i..i + 1, None),
            };
            // the sphere enclosing the step's links: the cull's, or the link's bounding sphere
            let (centre, reach) = match (ball, steps[i]) {
                (Some((ball, radius)), _) => (ball as usize, radius + m),
                (None, WorldStep::Link(g)) => {
                    (g as usize, model.groups[g as usize].bound.radius + m)
                }
                // (a cull step has its ball)
                (None, WorldStep::Cull { .. }) => (0, f32::INFINITY),
            };
            let within = farthest(&scratch.bounds[centre]) + reach;
            for (k, (&o, object)) in world.original.iter().zip(&world.objects).enumerate() {
                if world.from_origin[k] > within {
                    break;
                }
                if !enclosing_near::<AVX>(world, k, &scratch.bounds[centre], reach, live) {
                    continue;
                }
                let o = o as usize;
                let near = match ball {
                    Some((ball, radius)) => {
                        live & object.near::<AVX>(&scratch.bounds[ball as usize], radius + m)
                    }
                    None => live,
                };
                if near == 0 {
                    continue;
                }
                for step in &steps[links.clone()] {
                    let WorldStep::Link(g) = *step else {
                        continue;
                    };
                    let g = g as usize;
                    if object_link::<AVX, _>(
                        model, poses, o, object, g, near, world, scratch, verdict,
                    ) {
                        return;
                    }
                }
            }
            i = links.end;
        }
    } else {
        for (&o, object) in world.original.iter().zip(&world.objects) {
            let o = o as usize;
            let steps = &model.world_steps;
            let mut nest = Nest::<MAX_NESTING>::new();
            let (mut mask, mut i) = (live, 0);
            while i < steps.len() {
                mask = nest.close(i, mask, live);
                match steps[i] {
                    WorldStep::Cull { ball, radius, end } => {
                        let c = &scratch.bounds[ball as usize];
                        let near = mask & object.near::<AVX>(c, radius + m);
                        if near == 0 {
                            i = end as usize;
                            continue;
                        }
                        mask = nest.open(end, mask, near);
                    }
                    WorldStep::Link(g) => {
                        let g = g as usize;
                        if object_link::<AVX, _>(
                            model, poses, o, object, g, mask, world, scratch, verdict,
                        ) {
                            return;
                        }
                    }
                }
                i += 1;
            }
        }
    }
    verdict.enter_self();
    // self: the culling spheres of the kinematic tree (one test clears a hand against the
    // other hand), then each link pair's bounding spheres and spheres
    if !model.culls {
        // 64 link pairs at a time: first which of them come near in some lane by their
        // bounding spheres (no branch per pair: whether one does is hard to predict), then
        // those
        let pairs = &model.group_pairs;
        for start in (0..pairs.len()).step_by(64) {
            let end = (start + 64).min(pairs.len());
            let mut lanes = [0 as LaneMask; 64];
            let mut near = 0u64;
            for k in start..end {
                let mask = bounds_near::<AVX>(&pairs[k], live, scratch, m);
                lanes[k - start] = mask;
                near |= u64::from(mask != 0) << (k - start);
            }
            while near != 0 {
                let j = near.trailing_zeros() as usize;
                near &= near - 1;
                let k = start + j;
                if near_link_pair::<AVX, _>(
                    model, poses, &pairs[k], k, lanes[j], world, scratch, verdict,
                ) {
                    return;
                }
            }
        }
        clear_suspects::<AVX, _>(model, poses, world, scratch, verdict);
        return;
    }
    let steps = &model.steps;
    let mut nest = Nest::<MAX_NESTING>::new();
    let (mut mask, mut i) = (live, 0);
    while i < steps.len() {
        mask = nest.close(i, mask, live);
        match steps[i] {
            CullStep::Cull { a, b, reach, end } => {
                let (ca, cb) = (&scratch.bounds[a as usize], &scratch.bounds[b as usize]);
                let reach = reach + m;
                let near = mask & distance2(ca, cb).within(reach * reach).mask::<AVX>();
                if near == 0 {
                    i = end as usize;
                    continue;
                }
                mask = nest.open(end, mask, near);
            }
            CullStep::Pair { k, a, b, reach } => {
                let (ca, cb) = (&scratch.bounds[a as usize], &scratch.bounds[b as usize]);
                let reach = reach + m;
                let near = mask & distance2(ca, cb).within(reach * reach).mask::<AVX>();
                if near != 0 {
                    let gp = &model.group_pairs[k as usize];
                    if near_link_pair::<AVX, _>(
                        model, poses, gp, k as usize, near, world, scratch, verdict,
                    ) {
                        return;
                    }
                }
            }
        }
        i += 1;
    }
    clear_suspects::<AVX, _>(model, poses, world, scratch, verdict);
}

/// Whether a sphere at `c` of radius `reach` (in some lane of `live`) comes within object
/// `k`'s enclosing box ([`FastWorld::boxes`]): when not, it misses the object.
#[inline(always)]
pub(super) fn enclosing_near<const AVX: bool>(
    world: &FastWorld,
    k: usize,
    c: &[F; 3],
    reach: f32,
    live: LaneMask,
) -> bool {
    let (center, half) = world.boxes[k];
    live & aligned_box_distance2(c, center, half)
        .within(reach * reach)
        .mask::<AVX>()
        != 0
}

/// The largest distance from the world's origin of the point in any lane of `c`.
#[inline(always)]
fn farthest(c: &[F; 3]) -> f32 {
    let d2 = c[0] * c[0] + c[1] * c[1] + c[2] * c[2];
    d2.0.iter().fold(0.0f32, |a, &b| a.max(b)).sqrt()
}

/// Whether the pair the last stopped walk stopped at (when there is one, and its object is in
/// `world`) certainly collides in a lane of `live`: then `verdict` says so and the walk may
/// end. Otherwise `verdict` and the suspects are left as they were (the walk tests the pair
/// again in its turn).
#[inline(always)]
pub(super) fn last_hit_again<const AVX: bool, O: Outcome>(
    model: &FastModel,
    poses: &[PoseLanes32],
    live: LaneMask,
    world: &FastWorld,
    scratch: &mut FastScratch,
    verdict: &mut O,
) -> bool {
    let (before, marked) = (*verdict.uncertain(), scratch.suspects.len());
    let stopped = match scratch.last_hit {
        Some(Suspect::Object { object, group }) => world
            .compiled_of
            .get(object as usize)
            .and_then(|&k| world.objects.get(k as usize))
            .is_some_and(|object_shape| {
                object_link::<AVX, _>(
                    model,
                    poses,
                    object as usize,
                    object_shape,
                    group as usize,
                    live,
                    world,
                    scratch,
                    verdict,
                )
            }),
        Some(Suspect::Pair(k)) => {
            let gp = &model.group_pairs[k as usize];
            link_pair::<AVX>(model, poses, gp, k as usize, live, world, scratch, verdict)
        }
        None => false,
    };
    if !stopped {
        *verdict.uncertain() = before;
        scratch.suspects.truncate(marked);
    }
    stopped
}

/// `verdict` without the link-pair suspects' lanes in which either link's spheres all lie
/// beyond a slab of the other's k-DOP (when both are convex hulls), and with the point clouds'
/// scans the walk left for its end ([`scan_clouds`]): a second, tighter screen that only a
/// block left uncertain pays for, before its lanes are checked exactly.
#[inline(always)]
pub(super) fn clear_suspects<const AVX: bool, O: Outcome>(
    model: &FastModel,
    poses: &[PoseLanes32],
    world: &FastWorld,
    scratch: &mut FastScratch,
    verdict: &mut O,
) {
    if verdict.settled() || *verdict.uncertain() == 0 {
        return;
    }
    if O::STOPS_AT_FIRST && model.exact {
        scan_clouds::<AVX, O>(model, world, scratch, verdict);
        return;
    }
    if model.exact {
        return;
    }
    let m = world.margin;
    let mut suspects = std::mem::take(&mut scratch.suspects);
    let uncertain = verdict.uncertain();
    *uncertain = 0;
    for (suspect, lanes) in &mut suspects {
        if let Suspect::Pair(k) = *suspect {
            let gp = &model.group_pairs[k as usize];
            // the k-DOP screen reads both links' spheres: a link tested as one box has not had
            // them placed for this block
            place_balls::<AVX>(model, poses, gp.a, scratch);
            place_balls::<AVX>(model, poses, gp.b, scratch);
            *lanes &= !kdop_clear::<AVX>(model, gp.a, gp.b, scratch, m);
            if *lanes != 0 {
                *lanes &= !kdop_clear::<AVX>(model, gp.b, gp.a, scratch, m);
            }
        }
        *uncertain |= *lanes;
    }
    suspects.retain(|&(_, lanes)| lanes != 0);
    scratch.suspects = suspects;
}

/// The scans of the points of the clouds among the suspects (a walk that stops at the first
/// certain collision leaves them for its end, see [`object_balls`]): each suspect link's
/// spheres against the cloud's points in the suspect lanes; `verdict` and the suspects are
/// left with the lanes that stay within the margin, or say which lane collides.
fn scan_clouds<const AVX: bool, O: Outcome>(
    model: &FastModel,
    world: &FastWorld,
    scratch: &mut FastScratch,
    verdict: &mut O,
) {
    let mut suspects = std::mem::take(&mut scratch.suspects);
    let m = world.margin;
    let mut hit_at = None;
    for (k, (suspect, lanes)) in suspects.iter_mut().enumerate() {
        let Suspect::Object { object, group } = *suspect else {
            continue;
        };
        let object = &world.objects[world.compiled_of[object as usize] as usize];
        if !matches!(object, Object::Cloud { .. }) {
            continue;
        }
        let mut contact = Contact::default();
        for i in model.groups[group as usize].balls.clone() {
            let r = model.balls[i].radius;
            world.test::<AVX>(object, &mut contact, &scratch.balls[i], r, m, *lanes, true);
            if contact.hit.mask::<AVX>() != 0 {
                break;
            }
        }
        let (hit, close) = (contact.hit.mask::<AVX>(), contact.close.mask::<AVX>());
        if verdict.add(*lanes, hit, close).is_none() {
            hit_at = Some(k);
            break;
        }
        *lanes &= close;
    }
    if let Some(k) = hit_at {
        scratch.last_hit = Some(suspects[k].0);
    } else {
        let uncertain = verdict.uncertain();
        *uncertain = suspects.iter().fold(0, |all, &(_, lanes)| all | lanes);
        suspects.retain(|&(_, lanes)| lanes != 0);
    }
    scratch.suspects = suspects;
}

/// Checks world object `o` against link group `g` in the lanes of `live`: the link's bounding
/// sphere, then its spheres (and the spheres inside its bodies). True when a lane certainly
/// collides (then `verdict` says which); lanes left uncertain are added to `verdict` and the
/// suspects.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
pub(super) fn object_link<const AVX: bool, O: Outcome>(
    model: &FastModel,
    poses: &[PoseLanes32],
    o: usize,
    object: &Object,
    g: usize,
    live: LaneMask,
    world: &FastWorld,
    scratch: &mut FastScratch,
    verdict: &mut O,
) -> bool {
    let (m, group) = (world.margin, &model.groups[g]);
    let mut near = live & object.near::<AVX>(&scratch.bounds[g], group.bound.radius + m);
    if near == 0 {
        return false;
    }
    let cloud = match *object {
        Object::Cloud { index, radius, .. } => Some((&world.clouds[index as usize], radius)),
        _ => None,
    };
    if let Some((grid, radius)) = cloud {
        // the link's bounding sphere against the cells' clearances, past the cloud's box
        let reach = group.bound.radius + m + radius + grid.gap;
        near = grid.may_touch::<AVX>(&scratch.bounds[g], reach, near);
        if near == 0 {
            return false;
        }
    }
    let solids = match cloud {
        Some((cloud, radius)) => {
            solids_against_cloud(model, poses, cloud, radius, g, near, scratch, m)
        }
        None => object_solids::<AVX>(model, poses, object, g, scratch, m, !O::STOPS_AT_FIRST),
    };
    let (hit, close) = if let Some(contacts) = solids {
        contacts
    } else {
        object_balls::<AVX>(
            model,
            poses,
            world,
            object,
            g,
            near,
            scratch,
            O::STOPS_AT_FIRST,
        )
    };
    let suspect = Suspect::Object {
        object: o as u32,
        group: g as u32,
    };
    match verdict.add(near, hit, close) {
        None => {
            scratch.last_hit = Some(suspect);
            true
        }
        Some(0) => false,
        Some(lanes) => {
            scratch.suspects.push((suspect, lanes));
            false
        }
    }
}

compiled_per_isa! {
    /// The lanes in which a world object certainly collides with link group `g`'s solids, and
    /// those within their tolerance of contact: `None` unless the link is solids
    /// ([`super::model::Group::solids`]) and the object a sphere, a capsule or a box. With
    /// `settle` false, a capsule–box pair that certainly collides in some lane is not refined
    /// further (its undecided lanes stay close).
    object_solids => object_solids_in(
        model: &FastModel,
        poses: &[PoseLanes32],
        object: &Object,
        g: usize,
        scratch: &mut FastScratch,
        m: f32,
        settle: bool,
    ) -> Option<(LaneMask, LaneMask)>
}

#[inline(always)]
fn object_solids_in<const AVX: bool>(
    model: &FastModel,
    poses: &[PoseLanes32],
    object: &Object,
    g: usize,
    scratch: &mut FastScratch,
    m: f32,
    settle: bool,
) -> Option<(LaneMask, LaneMask)> {
    let range = model.groups[g].solids.clone()?;
    let (placed, extent) = match *object {
        Object::Round { a, b, radius } => {
            let d = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
            let half = 0.5 * (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
            ([splat(a), splat(b), splat(a), splat(a)], half + radius)
        }
        Object::Box { center, axes, half } => (
            [
                splat(center),
                splat(axes[0]),
                splat(axes[1]),
                splat(axes[2]),
            ],
            (half[0] * half[0] + half[1] * half[1] + half[2] * half[2]).sqrt(),
        ),
        Object::Cylinder { .. } | Object::Bounded { .. } | Object::Cloud { .. } => return None,
    };
    place_solids(model, poses, g, scratch);
    let mut contact = Contact::default();
    for k in range {
        let solid = model.solids[k];
        let tol = m * (1.0 + extent + model.solid_extents[k]);
        let p = &scratch.solids[k];
        let (hit, close) = match (solid, *object) {
            (
                Solid::Round { a, b, radius },
                Object::Round {
                    a: c,
                    b: d,
                    radius: r,
                },
            ) => round_round::<AVX>(p, (a, b, radius), &placed, (c, d, r), tol),
            (Solid::Round { a, b, radius }, Object::Box { half, .. }) => {
                round_box::<AVX>(p, (a, b, radius), &placed, half, tol, settle)
            }
            (Solid::Box { half, .. }, Object::Round { a, b, radius }) => {
                round_box::<AVX>(&placed, (a, b, radius), p, half, tol, settle)
            }
            (Solid::Box { half, .. }, Object::Box { half: other, .. }) => {
                box_box::<AVX>(p, half, &placed, other, tol)
            }
            _ => return None,
        };
        contact.hit = contact.hit | hit;
        contact.close = contact.close | close;
    }
    Some((contact.hit.mask::<AVX>(), contact.close.mask::<AVX>()))
}

/// The lanes in which a world object certainly collides with link group `g`'s spheres (the
/// spheres inside its bodies, when they enclose them), and those within the margin of contact
/// (with `stop_at_hit`, possibly only some of them once one lane certainly collides).
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn object_balls<const AVX: bool>(
    model: &FastModel,
    poses: &[PoseLanes32],
    world: &FastWorld,
    object: &Object,
    g: usize,
    near: LaneMask,
    scratch: &mut FastScratch,
    stop_at_hit: bool,
) -> (LaneMask, LaneMask) {
    let (m, group) = (world.margin, &model.groups[g]);
    place_balls::<AVX>(model, poses, g, scratch);
    #[cfg(target_arch = "x86_64")]
    if AVX && !matches!(object, Object::Cloud { .. }) {
        let against = |centres: &[[F; 3]], balls: &[super::model::Ball]| {
            // SAFETY: as in `F::any_within`
            #[allow(unsafe_code)]
            unsafe {
                avx::balls_against(object, centres, balls, m)
            }
        };
        let (hit, close) = against(
            &scratch.balls[group.balls.clone()],
            &model.balls[group.balls.clone()],
        );
        if model.exact || near & close == 0 {
            // enclosing spheres only say "maybe": far from them, nothing is certain either
            return (if model.exact { hit } else { 0 }, close);
        }
        // a sphere inside a body says "certainly"
        let inner = group.inner.clone();
        let (inside, _) = against(&scratch.inner[inner.clone()], &model.inner[inner]);
        return (inside, close);
    }
    // a point cloud costs per sphere and lane: where a certain collision ends the walk, the
    // first one ends the link's spheres too (a sphere model's spheres are its bodies), and
    // the scans of its points wait for the end of the walk ([`scan_clouds`]): most blocks
    // end before, at a collision that costs no scan
    let stop = stop_at_hit && model.exact && matches!(object, Object::Cloud { .. });
    if stop {
        let balls = group.balls.clone();
        return world.glance_balls::<AVX>(
            object,
            &scratch.balls[balls.clone()],
            &model.balls[balls],
            m,
            near,
        );
    }
    let mut contact = Contact::default();
    for i in group.balls.clone() {
        let r = model.balls[i].radius;
        world.test::<AVX>(object, &mut contact, &scratch.balls[i], r, m, near, false);
    }
    let (mut hit, close) = (contact.hit.mask::<AVX>(), contact.close.mask::<AVX>());
    if !model.exact {
        // enclosing spheres only say "maybe"; a sphere inside a body says "certainly"
        let mut inside = Contact::default();
        if near & close != 0 {
            for i in group.inner.clone() {
                let r = model.inner[i].radius;
                world.test::<AVX>(object, &mut inside, &scratch.inner[i], r, m, near, false);
            }
        }
        hit = inside.hit.mask::<AVX>();
    }
    (hit, close)
}

/// Checks link pair `gp` (index `k` in [`FastModel::group_pairs`]) in the lanes of `live`:
/// bounding spheres, then a box against the other link's spheres or the two links' spheres.
/// True when a lane certainly collides (then `verdict` says which); lanes left uncertain are
/// added to `verdict` and the suspects.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
pub(super) fn link_pair<const AVX: bool>(
    model: &FastModel,
    poses: &[PoseLanes32],
    gp: &GroupPair,
    k: usize,
    live: LaneMask,
    world: &FastWorld,
    scratch: &mut FastScratch,
    verdict: &mut impl Outcome,
) -> bool {
    let near = bounds_near::<AVX>(gp, live, scratch, world.margin);
    near != 0 && near_link_pair::<AVX, _>(model, poses, gp, k, near, world, scratch, verdict)
}

/// The lanes of `live` where the bounding spheres of `gp`'s links come within the margin `m`.
#[inline(always)]
fn bounds_near<const AVX: bool>(
    gp: &GroupPair,
    live: LaneMask,
    scratch: &FastScratch,
    m: f32,
) -> LaneMask {
    let reach = gp.reach + m;
    live & distance2(&scratch.bounds[gp.a], &scratch.bounds[gp.b])
        .within(reach * reach)
        .mask::<AVX>()
}

/// [`link_pair`] in the lanes of `near`, where the links' bounding spheres come near.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
pub(super) fn near_link_pair<const AVX: bool, O: Outcome>(
    model: &FastModel,
    poses: &[PoseLanes32],
    gp: &GroupPair,
    k: usize,
    near: LaneMask,
    world: &FastWorld,
    scratch: &mut FastScratch,
    verdict: &mut O,
) -> bool {
    let m = world.margin;
    // the pair's clearance table decides the lanes in its free and colliding cells
    let near = match gp.table {
        Some(t) => {
            let table = &model.tables[t as usize];
            let (free, hit) = table.lookup(&model.readers, &mut scratch.angles, poses, near);
            if hit != 0 && verdict.add(hit, hit, 0).is_none() {
                scratch.last_hit = Some(Suspect::Pair(k as u32));
                return true;
            }
            near & !(free | hit)
        }
        None => near,
    };
    if near == 0 {
        return false;
    }
    let (hit, close) = if !gp.solid_pairs.is_empty() {
        // the bodies themselves
        solid_contacts::<AVX>(model, poses, gp, scratch, m, !O::STOPS_AT_FIRST)
    } else if let Some((s, o)) = gp.solid {
        // the other link's spheres in the box link's frame, against the box itself
        place_balls::<AVX>(model, poses, o, scratch);
        frame(model, poses, scratch, s);
        let (box_, group, frame) = (&model.groups[s].solid, &model.groups[o], &scratch.frames[s]);
        let Some(box_) = box_ else { return false };
        let mut contact = Contact::default();
        for i in group.balls.clone() {
            let c = inverse_transform(frame, &scratch.balls[i]);
            box_.test::<AVX>(&mut contact, &c, model.balls[i].radius, m);
        }
        let close = contact.close.mask::<AVX>();
        let mut inside = Contact::default();
        if near & close != 0 {
            for i in group.inner.clone() {
                let c = inverse_transform(frame, &scratch.inner[i]);
                box_.test::<AVX>(&mut inside, &c, model.inner[i].radius, m);
            }
        }
        (inside.hit.mask::<AVX>(), close)
    } else {
        // each sphere of link a against link b's bounding sphere, then b's spheres
        place_balls::<AVX>(model, poses, gp.a, scratch);
        place_balls::<AVX>(model, poses, gp.b, scratch);
        let (mut hit, close) = pair_contacts::<AVX>(model, gp, scratch, world);
        if !model.exact {
            // enclosing spheres only say "maybe"; spheres inside the bodies say "certainly"
            let mut inside = Contact::default();
            if near & close != 0 {
                for &(i, j, r) in &gp.inner {
                    let (i, j) = (&scratch.inner[i as usize], &scratch.inner[j as usize]);
                    inside.add(distance2(i, j), r, m);
                }
            }
            hit = inside.hit.mask::<AVX>();
        }
        (hit, close)
    };
    match verdict.add(near, hit, close) {
        None => {
            scratch.last_hit = Some(Suspect::Pair(k as u32));
            true
        }
        Some(0) => false,
        Some(lanes) => {
            scratch.suspects.push((Suspect::Pair(k as u32), lanes));
            false
        }
    }
}

compiled_per_isa! {
    /// The lanes in which link pair `gp`'s solids ([`GroupPair::solid_pairs`]) certainly
    /// collide (placing them first), and those in which they come within their tolerance of
    /// contact (or NaN).
    /// With `settle` false, a capsule–box pair that certainly collides in some lane is not
    /// refined further (its undecided lanes stay close: for a walk that stops at the first
    /// collision).
    solid_contacts => solid_contacts_in(
        model: &FastModel,
        poses: &[PoseLanes32],
        gp: &GroupPair,
        scratch: &mut FastScratch,
        m: f32,
        settle: bool,
    ) -> (LaneMask, LaneMask)
}

#[inline(always)]
fn solid_contacts_in<const AVX: bool>(
    model: &FastModel,
    poses: &[PoseLanes32],
    gp: &GroupPair,
    scratch: &mut FastScratch,
    m: f32,
    settle: bool,
) -> (LaneMask, LaneMask) {
    place_solids(model, poses, gp.a, scratch);
    place_solids(model, poses, gp.b, scratch);
    let mut contact = Contact::default();
    let several = gp.solid_pairs.len() > 1;
    for pair in &gp.solid_pairs {
        let (a, b) = (pair.a as usize, pair.b as usize);
        let (pa, pb) = (&scratch.solids[a], &scratch.solids[b]);
        let tol = m * pair.scale;
        // the spheres around the two solids first, when the links hold several: most of
        // their pairs near enough for the links' bounding spheres are not near enough for
        // their own
        let reach = pair.reach + tol;
        if several && !distance2(&pa[0], &pb[0]).any_within::<AVX>(reach * reach) {
            continue;
        }
        let (hit, close) = match (model.solids[a], model.solids[b]) {
            (
                Solid::Round { a, b, radius },
                Solid::Round {
                    a: c,
                    b: d,
                    radius: r,
                },
            ) => round_round::<AVX>(pa, (a, b, radius), pb, (c, d, r), tol),
            (Solid::Round { a, b, radius }, Solid::Box { half, .. }) => {
                round_box::<AVX>(pa, (a, b, radius), pb, half, tol, settle)
            }
            (Solid::Box { half, .. }, Solid::Round { a, b, radius }) => {
                round_box::<AVX>(pb, (a, b, radius), pa, half, tol, settle)
            }
            (Solid::Box { half, .. }, Solid::Box { half: other, .. }) => {
                box_box::<AVX>(pa, half, pb, other, tol)
            }
        };
        contact.hit = contact.hit | hit;
        contact.close = contact.close | close;
    }
    (contact.hit.mask::<AVX>(), contact.close.mask::<AVX>())
}

/// The solids of group `g` in every lane, placed once per block.
#[inline(always)]
pub(super) fn place_solids(
    model: &FastModel,
    poses: &[PoseLanes32],
    g: usize,
    scratch: &mut FastScratch,
) {
    if scratch.solid_placed[g] {
        return;
    }
    let Some(range) = model.groups[g].solids.clone() else {
        return;
    };
    frame(model, poses, scratch, g);
    let (rot, t) = &scratch.frames[g];
    for k in range {
        let placed = &mut scratch.solids[k];
        match model.solids[k] {
            Solid::Box { center, axes, .. } => {
                placed[0] = transform(rot, t, center);
                placed[1] = rotate(rot, axes[0]);
                placed[2] = rotate(rot, axes[1]);
                placed[3] = rotate(rot, axes[2]);
            }
            Solid::Round { a, b, .. } => {
                placed[0] = transform(rot, t, a);
                placed[1] = transform(rot, t, b);
            }
        }
    }
    scratch.solid_placed[g] = true;
}

/// The lanes in which link pair `gp`'s spheres certainly collide, and those in which they come
/// within the margin `m` of contact (or NaN): each sphere of link a against link b's bounding
/// sphere, then b's spheres. Without a branch per pair: flags or-ed together, turned into lane
/// masks once.
#[inline(always)]
pub(super) fn pair_contacts<const AVX: bool>(
    model: &FastModel,
    gp: &GroupPair,
    scratch: &FastScratch,
    world: &FastWorld,
) -> (LaneMask, LaneMask) {
    #[cfg(target_arch = "x86_64")]
    if AVX {
        // SAFETY: as in `F::any_within`
        #[allow(unsafe_code)]
        return unsafe { avx::pair_contacts(model, gp, scratch, world) };
    }
    let m = world.margin;
    let (balls, bounds) = (&scratch.balls, &scratch.bounds);
    let mut contact = Contact::default();
    for run in &gp.runs {
        let ball = &balls[run.ball as usize];
        let reach = run.reach + m;
        if !distance2(ball, &bounds[gp.b]).any_within::<PORTABLE>(reach * reach) {
            continue;
        }
        let range = run.start as usize..run.end as usize;
        let pairs = model.pairs[range.clone()].iter().zip(&world.limits[range]);
        for (&(_, b, _), &limits) in pairs {
            contact.add_within(distance2(ball, &balls[b as usize]), limits);
        }
    }
    (
        contact.hit.mask::<PORTABLE>(),
        contact.close.mask::<PORTABLE>(),
    )
}

/// The bounding-sphere centre of every link group in every lane; frames, balls and
/// solids are made later, for the groups that come near something ([`frame`],
/// [`place_balls`], [`place_solids`]).
#[inline(always)]
pub(super) fn place<const AVX: bool>(
    model: &FastModel,
    poses: &[PoseLanes32],
    scratch: &mut FastScratch,
) {
    // the culling spheres' centres: their links' origins
    let groups = model.groups.len();
    scratch.solid_placed.fill(false);
    scratch.placed.fill(false);
    scratch.framed.fill(false);
    scratch.angles.clear();
    for (s, &frame) in model.origins.iter().enumerate() {
        let p = &poses[frame as usize];
        scratch.bounds[groups + s] = [F(p[4]), F(p[5]), F(p[6])];
    }
    // the spheres enclosing the groups of a frame
    let after = groups + model.origins.len();
    for (k, &(frame, center)) in model.frame_balls.iter().enumerate() {
        scratch.bounds[after + k] = pose_point(&poses[frame as usize], center);
    }
    #[cfg(target_arch = "x86_64")]
    if AVX {
        // SAFETY: as in `F::any_within`
        #[allow(unsafe_code)]
        return unsafe { avx::place(model, poses, scratch) };
    }
    for (g, group) in model.groups.iter().enumerate() {
        let p = &poses[group.frame];
        scratch.bounds[g] = pose_point(p, group.bound.center);
    }
}

/// Group `g`'s frame in every lane (rotation rows, translation), made from its pose once per
/// block.
#[inline(always)]
pub(super) fn frame<'s>(
    model: &FastModel,
    poses: &[PoseLanes32],
    scratch: &'s mut FastScratch,
    g: usize,
) -> &'s ([F; 9], [F; 3]) {
    if !scratch.framed[g] {
        let p = &poses[model.groups[g].frame];
        let rot = rotation(F(p[0]), F(p[1]), F(p[2]), F(p[3]));
        scratch.frames[g] = (rot, [F(p[4]), F(p[5]), F(p[6])]);
        scratch.framed[g] = true;
    }
    &scratch.frames[g]
}

/// The centres of group `g`'s balls in every lane, placed once per block.
#[inline(always)]
pub(super) fn place_balls<const AVX: bool>(
    model: &FastModel,
    poses: &[PoseLanes32],
    g: usize,
    scratch: &mut FastScratch,
) {
    if scratch.placed[g] {
        return;
    }
    frame(model, poses, scratch, g);
    #[cfg(target_arch = "x86_64")]
    if AVX {
        // SAFETY: as in `F::any_within`
        #[allow(unsafe_code)]
        return unsafe { avx::place_balls(model, g, scratch) };
    }
    let (rot, t) = &scratch.frames[g];
    for i in model.groups[g].balls.clone() {
        scratch.balls[i] = transform(rot, t, model.balls[i].center);
    }
    for i in model.groups[g].inner.clone() {
        scratch.inner[i] = transform(rot, t, model.inner[i].center);
    }
    scratch.placed[g] = true;
}
