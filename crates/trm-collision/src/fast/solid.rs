//! Robot bodies tested as themselves in `f32` lanes: boxes against boxes by their separating
//! axes, capsules and spheres by the distance between their segments, a capsule against a box
//! by the distance from its segment, each with a lower bound that is sound whether or not the
//! closest points were found exactly.
//!
//! **The contract is the spheres' one** ([`super`]): a pair whose computed separation exceeds
//! its tolerance is certainly clear, one that overlaps by more than it certainly collides, and
//! the rest is uncertain and checked exactly. A pair's tolerance is the world's margin scaled
//! by `1 + ` the two bodies' extents in metres ([`SolidPair::scale`]): the margin bounds how far
//! single precision moves any point of a link, and the extents bound the lever arm over which a
//! rounded axis or a rounded projection acts.
//!
//! - **Box–box**: the 15 axes of the separating-axis theorem (Gottschalk, Lin and Manocha,
//!   SIGGRAPH 1996): the boxes' 6 face normals and the 9 cross products of their edges. The
//!   largest gap over the axes is computed; cross axes are not normalised (|L| ≤ 1, so a gap
//!   above the tolerance still separates by more than it). The theorem is complete for convex
//!   polytopes: when all 15 overlap by more than the tolerance, the boxes intersect. Nearly
//!   parallel edges make a cross axis vanish; its gap is then near 0, never certain either way.
//! - **Capsule–capsule**: the closest points of two segments (Ericson, *Real-Time Collision
//!   Detection*, 5.1.9), their distance an upper bound. Nearly parallel segments make the
//!   closest points ill-conditioned; the distance `f` of the points found is then corrected into
//!   a lower bound by convexity: `f* ≥ f − Σ (the gradient's components that point into the
//!   parameter square) / f`, zero at a true optimum.
//! - **Capsule–box**: the segment point closest to the box's centre, the box point closest to
//!   it, the segment point closest to that (two projections); the distance from there to the box
//!   is an upper bound, and the same convexity step turns it into a lower bound. A sphere
//!   against a box is the exact point–box distance.

use super::lanes::{F, Flags, compiled_per_isa, to_f32};
use crate::model::Body;
use crate::shape::Shape;

/// A body in its link's frame, as the screen tests it.
#[derive(Debug, Clone, Copy)]
pub(super) enum Solid {
    /// A box: centre, its x, y and z axes, half sizes.
    Box {
        center: [f32; 3],
        axes: [[f32; 3]; 3],
        half: [f32; 3],
    },
    /// A capsule from `a` to `b` (a sphere when they are the same point).
    Round {
        a: [f32; 3],
        b: [f32; 3],
        radius: f32,
    },
}

/// Lane vectors each placed solid takes in [`super::FastScratch::solids`]: a box's centre and
/// axes, a capsule's two ends.
pub(super) const SLOTS: usize = 4;

impl Solid {
    /// The body as a solid, when it is a box, a capsule or a sphere.
    pub(super) fn of(body: &Body) -> Option<Solid> {
        let pose = &body.local;
        let t = pose.translation.vector;
        match body.shape {
            Shape::Box { size } => {
                let m = pose.rotation.to_rotation_matrix();
                let m = m.matrix();
                Some(Solid::Box {
                    center: to_f32(t),
                    axes: std::array::from_fn(|k| to_f32(m.column(k).into_owned())),
                    half: size.map(|s| (0.5 * s) as f32),
                })
            }
            Shape::Capsule { radius, length } => {
                let half = pose.rotation * nalgebra::Vector3::new(0.0, 0.0, 0.5 * length);
                Some(Solid::Round {
                    a: to_f32(t - half),
                    b: to_f32(t + half),
                    radius: radius as f32,
                })
            }
            Shape::Sphere { radius } => Some(Solid::Round {
                a: to_f32(t),
                b: to_f32(t),
                radius: radius as f32,
            }),
            Shape::Cylinder { .. }
            | Shape::Convex { .. }
            | Shape::Points { .. }
            | Shape::Mesh { .. } => None,
        }
    }

    /// Largest distance of a point of the solid from its first placed slot (a box's centre, a
    /// capsule's first end), rounded up.
    pub(super) fn reach(&self) -> f32 {
        let r = match *self {
            Solid::Box { .. } => self.extent(),
            Solid::Round { a, b, radius } => {
                let d = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
                (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt() + radius
            }
        };
        r * (1.0 + 1e-6) + 1e-7
    }

    /// Largest distance of a point of the solid from its centre.
    pub(super) fn extent(&self) -> f32 {
        match *self {
            Solid::Box { half, .. } => {
                (half[0] * half[0] + half[1] * half[1] + half[2] * half[2]).sqrt()
            }
            Solid::Round { a, b, radius } => {
                let d = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
                0.5 * (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt() + radius
            }
        }
    }
}

/// Two solids (indices into [`super::FastModel::solids`]) whose bodies are a checked pair, the
/// round one first where one is round (the walk takes either order).
#[derive(Debug, Clone, Copy)]
pub(super) struct SolidPair {
    pub(super) a: u32,
    pub(super) b: u32,
    /// The tolerance per unit of margin: 1 + the two solids' extents in metres.
    pub(super) scale: f32,
    /// The sum of the radii of the spheres about the solids' first slots (a box's centre, a
    /// capsule's first end) that enclose them.
    pub(super) reach: f32,
}

impl SolidPair {
    /// The pair of solids `a` and `b`, the round one first.
    pub(super) fn new(solids: &[Solid], a: usize, b: usize) -> SolidPair {
        let (a, b) = match (&solids[a], &solids[b]) {
            (Solid::Box { .. }, Solid::Round { .. }) => (b, a),
            _ => (a, b),
        };
        SolidPair {
            a: a as u32,
            b: b as u32,
            scale: 1.0 + solids[a].extent() + solids[b].extent(),
            reach: solids[a].reach() + solids[b].reach(),
        }
    }
}

/// A solid placed in every lane: a box's centre and axes, or a capsule's ends.
pub(super) type Placed = [[F; 3]; SLOTS];

/// `rot · p` in every lane (a direction: no translation).
#[inline(always)]
pub(super) fn rotate(rot: &[F; 9], p: [f32; 3]) -> [F; 3] {
    let (x, y, z) = (F::splat(p[0]), F::splat(p[1]), F::splat(p[2]));
    [
        rot[0] * x + rot[1] * y + rot[2] * z,
        rot[3] * x + rot[4] * y + rot[5] * z,
        rot[6] * x + rot[7] * y + rot[8] * z,
    ]
}

#[inline(always)]
fn dot(a: &[F; 3], b: &[F; 3]) -> F {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

#[inline(always)]
fn sub(a: &[F; 3], b: &[F; 3]) -> [F; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

#[inline(always)]
fn abs(x: F) -> F {
    x.map(f32::abs)
}

#[inline(always)]
fn clamp01(x: F) -> F {
    x.map(|v| v.clamp(0.0, 1.0))
}

/// Per lane: `yes` where `cond` holds, else `no`.
#[inline(always)]
fn select(cond: Flags, yes: F, no: F) -> F {
    let mut out = no.0;
    for l in 0..out.len() {
        if cond.0[l] != 0 {
            out[l] = yes.0[l];
        }
    }
    F(out)
}

/// The larger of each lane's values (not NaN-preserving: callers add NaN back).
#[inline(always)]
fn max(a: F, b: F) -> F {
    let mut out = a.0;
    for l in 0..out.len() {
        out[l] = if b.0[l] > a.0[l] { b.0[l] } else { a.0[l] };
    }
    F(out)
}

/// How far the distance's first-order bound may fall short of the distance of the points found,
/// times that distance: the gradient components (`g_s`, `g_t`: the derivatives of half the
/// squared distance in the segment parameters) that point into the parameter range from the
/// parameters found. Zero at a true optimum.
#[inline(always)]
fn shortfall(s: F, g_s: F) -> F {
    let zero = F::splat(0.0);
    let up = select(s.below(1.0), zero - g_s, zero);
    let down = select(s.above(0.0), g_s, zero);
    max(max(up, down), zero)
}

/// Certain collision and uncertain lanes of a pair whose distance `f` is known within
/// `[f − short / f, f]` (`d2` = f²), against the sum of radii `r`, with tolerance `tol`.
#[inline(always)]
fn verdict(d2: F, short: F, r: f32, tol: f32) -> (Flags, Flags) {
    let inner = (r - tol).max(0.0);
    let hit = d2.below(inner * inner);
    // clear when f − short / f > R = r + tol; f² − 2 short > R² implies it (then f > R, and
    // f² − short − R f > (f − R)² / 2 ≥ 0), without a square root
    let reach = r + tol;
    let clear = (d2 - short - short).above(reach * reach);
    (hit, not(clear))
}

#[inline(always)]
fn not(flags: Flags) -> Flags {
    let mut out = flags.0;
    for v in &mut out {
        *v ^= 1;
    }
    Flags(out)
}

/// A capsule (or sphere): its two ends and radius in its link's frame.
pub(super) type Round = ([f32; 3], [f32; 3], f32);

compiled_per_isa! {
    /// Two capsules (or spheres) in every lane (placed, and as in their links): certainly
    /// colliding lanes and lanes within the tolerance of contact (or NaN).
    round_round => round_round_in(p: &Placed, a: Round, q: &Placed, b: Round, tol: f32)
        -> (Flags, Flags)
}

#[inline(always)]
fn round_round_in<const AVX: bool>(
    p: &Placed,
    (pa, pb, pr): Round,
    q: &Placed,
    (qa, qb, qr): Round,
    tol: f32,
) -> (Flags, Flags) {
    let len2 = |a: [f32; 3], b: [f32; 3]| {
        let d = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
        d[0] * d[0] + d[1] * d[1] + d[2] * d[2]
    };
    let (la, lb) = (len2(pa, pb), len2(qa, qb));
    let (d1, d2) = (sub(&p[1], &p[0]), sub(&q[1], &q[0]));
    let r = sub(&p[0], &q[0]);
    let zero = F::splat(0.0);
    let (c, f) = (dot(&d1, &r), dot(&d2, &r));
    // the closest points' parameters s (on p) and t (on q); a sphere's is 0
    let (s, t) = if la == 0.0 && lb == 0.0 {
        (zero, zero)
    } else if la == 0.0 {
        (zero, clamp01(f * F::splat(1.0 / lb)))
    } else if lb == 0.0 {
        (clamp01(zero - c * F::splat(1.0 / la)), zero)
    } else {
        let b = dot(&d1, &d2);
        let denom = F::splat(la * lb) - b * b;
        let parallel = denom.below(1e-6 * la * lb);
        let s0 = select(parallel, zero, clamp01((b * f - c * F::splat(lb)) / denom));
        let t0 = (b * s0 + f) * F::splat(1.0 / lb);
        let inv_a = F::splat(1.0 / la);
        let s = select(
            t0.below(0.0),
            clamp01(zero - c * inv_a),
            select(t0.above(1.0), clamp01((b - c) * inv_a), s0),
        );
        (s, clamp01(t0))
    };
    let w = [
        r[0] + d1[0] * s - d2[0] * t,
        r[1] + d1[1] * s - d2[1] * t,
        r[2] + d1[2] * s - d2[2] * t,
    ];
    let short = if la == 0.0 || lb == 0.0 {
        // a point against a segment: the projection is exact
        zero
    } else {
        shortfall(s, dot(&w, &d1)) + shortfall(t, zero - dot(&w, &d2))
    };
    verdict(dot(&w, &w), short, pr + qr, tol)
}

/// A box placed in every lane (centre, axes) with half sizes `half`, and the point in every
/// lane: the point in the box's frame.
#[inline(always)]
fn in_box(c: &[F; 3], b: &Placed) -> [F; 3] {
    let d = sub(c, &b[0]);
    [dot(&d, &b[1]), dot(&d, &b[2]), dot(&d, &b[3])]
}

compiled_per_isa! {
    /// A capsule (or sphere) against a box of half sizes `half`, in every lane: certainly
    /// colliding lanes and lanes within the tolerance of contact (or NaN). With `settle`
    /// false, once some lane certainly collides the lanes still undecided are left *close*
    /// (for a walk that stops at the first collision).
    round_box => round_box_in(
        p: &Placed,
        round: Round,
        b: &Placed,
        half: [f32; 3],
        tol: f32,
        settle: bool,
    ) -> (Flags, Flags)
}

#[inline(always)]
fn round_box_in<const AVX: bool>(
    p: &Placed,
    (pa, pb, r): Round,
    b: &Placed,
    half: [f32; 3],
    tol: f32,
    settle: bool,
) -> (Flags, Flags) {
    let zero = F::splat(0.0);
    let h = [F::splat(half[0]), F::splat(half[1]), F::splat(half[2])];
    let d = [pb[0] - pa[0], pb[1] - pa[1], pb[2] - pa[2]];
    let la = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
    // the segment in the box's frame: its start and direction
    let start = in_box(&p[0], b);
    if la == 0.0 {
        let out = beyond(&start, &h);
        return verdict(dot(&out, &out), zero, r, tol);
    }
    let dir = sub(&p[1], &p[0]);
    let dir = [dot(&dir, &b[1]), dot(&dir, &b[2]), dot(&dir, &b[3])];
    // the separating axes of the segment and the box first (the box's normals, the segment's
    // direction across the box's edges): they are cheap, and clear most pairs a walk meets;
    // where the segment runs along a face they also clear the lanes whose projections below
    // converge slowly
    let apart = segment_box_gap(&start, &dir, &h, r, la).above(tol);
    if apart.0.iter().all(|&v| v != 0) {
        return (Flags::default(), Flags::default());
    }
    let inv = F::splat(1.0 / la);
    // the segment point nearest the centre, then alternately the box point nearest the
    // segment point and the segment point nearest that box point
    let mut s = clamp01((zero - dot(&start, &dir)) * inv);
    for _ in 0..PROJECTIONS {
        let p = along(&start, &dir, s);
        let q = [
            clamp_abs(p[0], h[0]),
            clamp_abs(p[1], h[1]),
            clamp_abs(p[2], h[2]),
        ];
        s = clamp01(dot(&sub(&q, &start), &dir) * inv);
    }
    let (hit, close) = segment_box_verdict(&start, &dir, s, &h, r, tol);
    let close = and_not(close, apart);
    if and_not(close, hit).0.iter().all(|&v| v == 0) || !settle && hit.0.iter().any(|&v| v != 0) {
        return (hit, close);
    }
    // lanes still undecided (a segment's end near a box's edge or corner, where projections
    // converge slowly): the segment parameter where the derivative of the distance changes
    // sign, by bisection (the derivative is monotone: the distance is convex along the segment)
    let half = F::splat(0.5);
    let (mut lo, mut hi) = (zero, F::splat(1.0));
    for _ in 0..BISECTIONS {
        let mid = (lo + hi) * half;
        let out = beyond(&along(&start, &dir, mid), &h);
        let rising = dot(&out, &dir).above(0.0);
        hi = select(rising, mid, hi);
        lo = select(rising, lo, mid);
    }
    let (hit2, close2) = segment_box_verdict(&start, &dir, (lo + hi) * half, &h, r, tol);
    (or(hit, hit2), and(close, close2))
}

/// The largest gap, less the radius `r`, between a segment (`start`, `dir` in a box's frame;
/// `la` its squared length) and the box of half sizes `h` along their separating axes: the
/// box's normals and the segment's direction across each of the box's edges (cross axes
/// normalised by an upper bound of their length, so the gap is a lower bound).
#[inline(always)]
fn segment_box_gap(start: &[F; 3], dir: &[F; 3], h: &[F; 3], r: f32, la: f32) -> F {
    let half = F::splat(0.5);
    let e = [dir[0] * half, dir[1] * half, dir[2] * half];
    let mid = along(start, &e, F::splat(1.0));
    let rr = F::splat(r);
    let mut gap = abs(mid[0]) - h[0] - abs(e[0]) - rr;
    gap = max(gap, abs(mid[1]) - h[1] - abs(e[1]) - rr);
    gap = max(gap, abs(mid[2]) - h[2] - abs(e[2]) - rr);
    // across edge k: L = e × axis k, |L| ≤ |e|; the gap over |e| bounds the normalised one
    let inv_e = F::splat(1.0 / (0.5 * la.sqrt()));
    for k in 0..3 {
        let (k1, k2) = ((k + 1) % 3, (k + 2) % 3);
        let across =
            abs(mid[k1] * e[k2] - mid[k2] * e[k1]) - h[k1] * abs(e[k2]) - h[k2] * abs(e[k1]);
        gap = max(gap, across * inv_e - rr);
    }
    gap
}

/// The verdict of a capsule's segment (`start`, `dir` in a box's frame) against the box of half
/// sizes `h`, from the segment point at parameter `s`: its distance to the box, and the
/// convexity bound below it.
#[inline(always)]
fn segment_box_verdict(
    start: &[F; 3],
    dir: &[F; 3],
    s: F,
    h: &[F; 3],
    r: f32,
    tol: f32,
) -> (Flags, Flags) {
    // the offset from the box's nearest point: half the squared distance's gradient
    let out = beyond(&along(start, dir, s), h);
    let short = shortfall(s, dot(&out, dir));
    verdict(dot(&out, &out), short, r, tol)
}

/// Bisection steps of a capsule's segment against a box where projections left lanes undecided.
const BISECTIONS: usize = 16;

/// The lanes in `a` or `b`.
#[inline(always)]
fn or(a: Flags, b: Flags) -> Flags {
    a | b
}

/// The lanes in both `a` and `b`.
#[inline(always)]
fn and(a: Flags, b: Flags) -> Flags {
    let mut out = a.0;
    for l in 0..out.len() {
        out[l] &= b.0[l];
    }
    Flags(out)
}

/// The lanes of `a` not in `b`.
#[inline(always)]
fn and_not(a: Flags, b: Flags) -> Flags {
    let mut out = a.0;
    for l in 0..out.len() {
        out[l] &= !b.0[l];
    }
    Flags(out)
}

/// Alternating projections between a capsule's segment and a box before the distance is bounded.
const PROJECTIONS: usize = 3;

/// `start + s dir` in every lane.
#[inline(always)]
fn along(start: &[F; 3], dir: &[F; 3], s: F) -> [F; 3] {
    [
        start[0] + dir[0] * s,
        start[1] + dir[1] * s,
        start[2] + dir[2] * s,
    ]
}

/// The offset of a point (in a box's frame) from the box point nearest it (zero inside).
#[inline(always)]
fn beyond(p: &[F; 3], h: &[F; 3]) -> [F; 3] {
    [
        p[0] - clamp_abs(p[0], h[0]),
        p[1] - clamp_abs(p[1], h[1]),
        p[2] - clamp_abs(p[2], h[2]),
    ]
}

/// `x` clamped to `[−h, h]` in every lane (NaN stays NaN). Comparisons, not `f32::clamp`,
/// whose check of its bounds is a branch per lane that keeps the loop from vectorising.
#[inline(always)]
fn clamp_abs(x: F, h: F) -> F {
    let mut out = x.0;
    for l in 0..out.len() {
        let (v, h) = (out[l], h.0[l]);
        out[l] = if v < -h {
            -h
        } else if v > h {
            h
        } else {
            v
        };
    }
    F(out)
}

compiled_per_isa! {
    /// Two boxes (placed, and their half sizes) in every lane: certainly colliding lanes and
    /// lanes within the tolerance of contact (or NaN), by the separating-axis theorem.
    box_box => box_box_in(a: &Placed, ha: [f32; 3], b: &Placed, hb: [f32; 3], tol: f32)
        -> (Flags, Flags)
}

#[inline(always)]
fn box_box_in<const AVX: bool>(
    a: &Placed,
    ha: [f32; 3],
    b: &Placed,
    hb: [f32; 3],
    tol: f32,
) -> (Flags, Flags) {
    let d = sub(&b[0], &a[0]);
    // the centre of b in a's frame, and the rotation from b's axes to a's
    let t = [dot(&d, &a[1]), dot(&d, &a[2]), dot(&d, &a[3])];
    // first the sphere about b against a itself: most pairs a walk meets are apart by more
    // than b's extent (a NaN axis of b reaches the distance through `nan_b`)
    let reach = (hb[0] * hb[0] + hb[1] * hb[1] + hb[2] * hb[2]).sqrt() * (1.0 + 1e-6) + 1e-7 + tol;
    let nan_b = (b[1][0] + b[2][1] + b[3][2]) * F::splat(0.0);
    let out = beyond(&t, &[F::splat(ha[0]), F::splat(ha[1]), F::splat(ha[2])]);
    if !(dot(&out, &out) + nan_b).any_within::<AVX>(reach * reach) {
        return (Flags::default(), Flags::default());
    }
    let r: [[F; 3]; 3] = [
        [dot(&a[1], &b[1]), dot(&a[1], &b[2]), dot(&a[1], &b[3])],
        [dot(&a[2], &b[1]), dot(&a[2], &b[2]), dot(&a[2], &b[3])],
        [dot(&a[3], &b[1]), dot(&a[3], &b[2]), dot(&a[3], &b[3])],
    ];
    // no array `map` here: its closures may stay calls compiled without the vector
    // instructions this function is compiled for
    let mut ar = r;
    for row in &mut ar {
        for v in row.iter_mut() {
            *v = abs(*v);
        }
    }
    let ha = [F::splat(ha[0]), F::splat(ha[1]), F::splat(ha[2])];
    let hb = [F::splat(hb[0]), F::splat(hb[1]), F::splat(hb[2])];
    let mut gap = F::splat(f32::NEG_INFINITY);
    for i in 0..3 {
        let g = abs(t[i]) - ha[i] - (hb[0] * ar[i][0] + hb[1] * ar[i][1] + hb[2] * ar[i][2]);
        gap = max(gap, g);
    }
    for j in 0..3 {
        let tb = t[0] * r[0][j] + t[1] * r[1][j] + t[2] * r[2][j];
        let g = abs(tb) - hb[j] - (ha[0] * ar[0][j] + ha[1] * ar[1][j] + ha[2] * ar[2][j]);
        gap = max(gap, g);
    }
    // a NaN centre or axis reaches every lane's gap through this
    let nan = (t[0] + t[1] + t[2] + r[0][0] + r[1][1] + r[2][2]) * F::splat(0.0);
    // most pairs near enough to be tested are apart along a face normal
    if !(gap + nan).any_within::<AVX>(tol) {
        return (Flags::default(), Flags::default());
    }
    for i in 0..3 {
        let (i1, i2) = ((i + 1) % 3, (i + 2) % 3);
        for j in 0..3 {
            let (j1, j2) = ((j + 1) % 3, (j + 2) % 3);
            let along = t[i2] * r[i1][j] - t[i1] * r[i2][j];
            let ra = ha[i1] * ar[i2][j] + ha[i2] * ar[i1][j];
            let rb = hb[j1] * ar[i][j2] + hb[j2] * ar[i][j1];
            gap = max(gap, abs(along) - ra - rb);
        }
    }
    let gap = gap + nan;
    let (hit, close) = (gap.below(-tol), gap.within(tol));
    if and_not(close, hit).0.iter().all(|&v| v == 0) {
        return (hit, close);
    }
    // overlapping lanes the axes cannot call (a cross axis vanishes where edges are parallel):
    // a point of one box inside the other by more than the tolerance is a certain collision.
    // Alternately the point of b nearest a point of a, the point of a nearest that, from a's
    // centre
    let mut p = a[0];
    let mut inside = Flags::default();
    for _ in 0..OVERLAP_PROJECTIONS {
        let q = nearest_in_box(&p, b, &hb);
        inside = inside | within_box(&q, a, &ha, tol);
        p = nearest_in_box(&q, a, &ha);
        inside = inside | within_box(&p, b, &hb, tol);
    }
    (or(hit, and(close, inside)), close)
}

/// Projections from a box's centre looking for a point inside both boxes.
const OVERLAP_PROJECTIONS: usize = 5;

/// The point of the box `b` (placed: centre and axes; half sizes `h`) nearest `p`, in every lane.
#[inline(always)]
fn nearest_in_box(p: &[F; 3], b: &Placed, h: &[F; 3]) -> [F; 3] {
    let local = in_box(p, b);
    let c = [
        clamp_abs(local[0], h[0]),
        clamp_abs(local[1], h[1]),
        clamp_abs(local[2], h[2]),
    ];
    [
        b[0][0] + b[1][0] * c[0] + b[2][0] * c[1] + b[3][0] * c[2],
        b[0][1] + b[1][1] * c[0] + b[2][1] * c[1] + b[3][1] * c[2],
        b[0][2] + b[1][2] * c[0] + b[2][2] * c[1] + b[3][2] * c[2],
    ]
}

/// The lanes in which `p` lies inside the box `b` by more than `tol` along each of its axes.
#[inline(always)]
fn within_box(p: &[F; 3], b: &Placed, h: &[F; 3], tol: f32) -> Flags {
    let local = in_box(p, b);
    let t = F::splat(tol);
    let depth = |k: usize| h[k] - abs(local[k]) - t;
    let inside = max(
        max(zero_minus(depth(0)), zero_minus(depth(1))),
        zero_minus(depth(2)),
    );
    inside.below(0.0)
}

/// `−x` in every lane.
#[inline(always)]
fn zero_minus(x: F) -> F {
    F::splat(0.0) - x
}
