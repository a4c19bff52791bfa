//! AVX instructions the compiler does not choose by itself.

use super::kdop::KDOP;
use super::lanes::{F, Flags};
use super::model::{Ball, FastModel, GroupPair};
use super::outcome::Contact;
use super::walk::FastScratch;
use super::world::{FastWorld, Object};
use super::{FAST_LANES, LaneMask};
use trm_kinematics::PoseLanes32;

use std::arch::x86_64::{
    __m256, __m256i, _CMP_GT_OQ, _CMP_LT_OQ, _CMP_NGT_UQ, _mm256_add_ps, _mm256_and_ps,
    _mm256_and_si256, _mm256_castps_si256, _mm256_castsi256_ps, _mm256_cmp_ps, _mm256_fmadd_ps,
    _mm256_fmsub_ps, _mm256_fnmadd_ps, _mm256_load_ps, _mm256_loadu_ps, _mm256_max_ps,
    _mm256_min_ps, _mm256_movemask_ps, _mm256_mul_ps, _mm256_or_ps, _mm256_set1_epi32,
    _mm256_set1_ps, _mm256_setzero_ps, _mm256_slli_epi32, _mm256_sqrt_ps, _mm256_store_ps,
    _mm256_sub_ps, _mm256_testz_ps,
};

const _: () = assert!(FAST_LANES == 8, "one 8-lane AVX register per block");

/// [`F::any_within`]: one compare, one test.
///
/// # Safety
/// The CPU must have AVX.
#[target_feature(enable = "avx")]
#[inline]
pub(super) unsafe fn any_within(v: F, limit: f32) -> bool {
    // SAFETY: eight `f32` lanes, the size and layout of one 256-bit register
    let v: __m256 = unsafe { std::mem::transmute::<[f32; FAST_LANES], __m256>(v.0) };
    // not greater, unordered included (NaN is never clear)
    let flags = _mm256_cmp_ps::<_CMP_NGT_UQ>(v, _mm256_set1_ps(limit));
    _mm256_testz_ps(flags, flags) == 0
}

/// Eight `f32` lanes as one register.
#[target_feature(enable = "avx")]
#[inline]
pub(super) fn load(v: &F) -> __m256 {
    // SAFETY: `F` is eight `f32` aligned to 32 bytes
    unsafe { _mm256_load_ps(v.0.as_ptr()) }
}

/// `c` relative to `origin`, in the frame whose axes are the rows of `axes`.
#[target_feature(enable = "avx2,fma")]
#[inline]
pub(super) fn local(c: &[F; 3], origin: [f32; 3], axes: &[[f32; 3]; 3]) -> [__m256; 3] {
    let p = [
        _mm256_sub_ps(load(&c[0]), _mm256_set1_ps(origin[0])),
        _mm256_sub_ps(load(&c[1]), _mm256_set1_ps(origin[1])),
        _mm256_sub_ps(load(&c[2]), _mm256_set1_ps(origin[2])),
    ];
    let along = |a: [f32; 3]| {
        let xy = _mm256_fmadd_ps(
            p[1],
            _mm256_set1_ps(a[1]),
            _mm256_mul_ps(p[0], _mm256_set1_ps(a[0])),
        );
        _mm256_fmadd_ps(p[2], _mm256_set1_ps(a[2]), xy)
    };
    [along(axes[0]), along(axes[1]), along(axes[2])]
}

/// `v − limit` where positive, else 0 (NaN: 0, as `f32::max` gives).
#[target_feature(enable = "avx")]
#[inline]
pub(super) fn beyond(v: __m256, limit: f32) -> __m256 {
    _mm256_max_ps(_mm256_sub_ps(v, _mm256_set1_ps(limit)), _mm256_setzero_ps())
}

/// `|v|`.
#[target_feature(enable = "avx")]
#[inline]
pub(super) fn abs(v: __m256) -> __m256 {
    _mm256_and_ps(v, _mm256_castsi256_ps(_mm256_set1_epi32(i32::MAX)))
}

/// [`Object::distance2`] written out: the compiler vectorises it badly where lane masks
/// follow (measured: 0.40 → 0.37 ms median on the MBM Panda with mesh hulls). Each kind of
/// object is its own small function, so that the callers that match on the kind (the walk's
/// tests of a link's bounding sphere, [`near`]) take its few instructions inline rather than
/// a call of the whole match.
#[target_feature(enable = "avx2,fma")]
#[inline]
pub(super) fn distance2(object: &Object, c: &[F; 3]) -> __m256 {
    object_distance2!(object, c)
}

/// The match of [`distance2`], written where it is used: a function holding it is too large
/// for the compiler to take inline, and [`near`] is on the walk's hottest path.
macro_rules! object_distance2 {
    ($object:expr, $c:expr) => {
        match *$object {
            Object::Round { a, b, .. } => round_distance2($c, a, b),
            Object::Box { center, axes, half } => box_distance2($c, center, &axes, half),
            Object::Cylinder {
                center,
                axes,
                radius,
                half,
            } => cylinder_distance2($c, center, &axes, radius, half),
            Object::Cloud { center, half, .. } => aligned_box_distance2($c, center, half),
            Object::Bounded { center, .. } => point_distance2($c, center),
        }
    };
}
use object_distance2;

/// `|v|²` in every lane.
#[target_feature(enable = "avx2,fma")]
#[inline]
fn norm2(v: [__m256; 3]) -> __m256 {
    _mm256_fmadd_ps(
        v[2],
        v[2],
        _mm256_fmadd_ps(v[1], v[1], _mm256_mul_ps(v[0], v[0])),
    )
}

/// Squared distance from `c` to the segment `a`–`b` (a point when they are equal).
#[target_feature(enable = "avx2,fma")]
#[inline]
fn round_distance2(c: &[F; 3], a: [f32; 3], b: [f32; 3]) -> __m256 {
    let ab = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
    let len2 = ab[0] * ab[0] + ab[1] * ab[1] + ab[2] * ab[2];
    let inv = if len2 > 0.0 { 1.0 / len2 } else { 0.0 };
    let p = [
        _mm256_sub_ps(load(&c[0]), _mm256_set1_ps(a[0])),
        _mm256_sub_ps(load(&c[1]), _mm256_set1_ps(a[1])),
        _mm256_sub_ps(load(&c[2]), _mm256_set1_ps(a[2])),
    ];
    let ab = [
        _mm256_set1_ps(ab[0]),
        _mm256_set1_ps(ab[1]),
        _mm256_set1_ps(ab[2]),
    ];
    let along = _mm256_fmadd_ps(
        p[2],
        ab[2],
        _mm256_fmadd_ps(p[1], ab[1], _mm256_mul_ps(p[0], ab[0])),
    );
    let t = _mm256_mul_ps(along, _mm256_set1_ps(inv));
    let t = _mm256_max_ps(_mm256_min_ps(t, _mm256_set1_ps(1.0)), _mm256_setzero_ps());
    norm2([
        _mm256_fnmadd_ps(t, ab[0], p[0]),
        _mm256_fnmadd_ps(t, ab[1], p[1]),
        _mm256_fnmadd_ps(t, ab[2], p[2]),
    ])
}

/// Squared distance from `c` to a box (centre, rows of the world → box rotation, half sizes).
#[target_feature(enable = "avx2,fma")]
#[inline]
fn box_distance2(c: &[F; 3], center: [f32; 3], axes: &[[f32; 3]; 3], half: [f32; 3]) -> __m256 {
    let p = local(c, center, axes);
    norm2([
        beyond(abs(p[0]), half[0]),
        beyond(abs(p[1]), half[1]),
        beyond(abs(p[2]), half[2]),
    ])
}

/// Squared distance from `c` to a cylinder along its z axis.
#[target_feature(enable = "avx2,fma")]
#[inline]
fn cylinder_distance2(
    c: &[F; 3],
    center: [f32; 3],
    axes: &[[f32; 3]; 3],
    radius: f32,
    half: f32,
) -> __m256 {
    let [x, y, z] = local(c, center, axes);
    let radial = _mm256_sqrt_ps(_mm256_fmadd_ps(y, y, _mm256_mul_ps(x, x)));
    let radial = beyond(radial, radius);
    let axial = beyond(abs(z), half);
    _mm256_fmadd_ps(axial, axial, _mm256_mul_ps(radial, radial))
}

/// Squared distance from `c` to a box along the world's axes (centre, half sizes).
#[target_feature(enable = "avx2,fma")]
#[inline]
fn aligned_box_distance2(c: &[F; 3], center: [f32; 3], half: [f32; 3]) -> __m256 {
    let out = |k: usize| {
        let d = _mm256_sub_ps(load(&c[k]), _mm256_set1_ps(center[k]));
        beyond(abs(d), half[k])
    };
    norm2([out(0), out(1), out(2)])
}

/// Squared distance from `c` to a point.
#[target_feature(enable = "avx2,fma")]
#[inline]
fn point_distance2(c: &[F; 3], p: [f32; 3]) -> __m256 {
    norm2([
        _mm256_sub_ps(load(&c[0]), _mm256_set1_ps(p[0])),
        _mm256_sub_ps(load(&c[1]), _mm256_set1_ps(p[1])),
        _mm256_sub_ps(load(&c[2]), _mm256_set1_ps(p[2])),
    ])
}

/// [`Object::near`]: the lanes whose squared distance is within `reach2` (NaN included).
#[target_feature(enable = "avx2,fma")]
#[inline]
pub(super) fn near(object: &Object, c: &[F; 3], reach2: f32) -> LaneMask {
    let flags = _mm256_cmp_ps::<_CMP_NGT_UQ>(object_distance2!(object, c), _mm256_set1_ps(reach2));
    _mm256_movemask_ps(flags) as LaneMask
}

/// [`Object::test`] with the object's reach `r` (radii summed), flags in `contact`.
#[target_feature(enable = "avx2,fma")]
#[inline]
pub(super) fn test(object: &Object, contact: &mut Contact, c: &[F; 3], r: f32, m: f32) {
    let d2 = distance2(object, c);
    let one = _mm256_set1_epi32(1);
    let flags = |cmp: __m256| {
        let v = _mm256_and_si256(_mm256_castps_si256(cmp), one);
        // SAFETY: eight `u32` lanes, the size and layout of one 256-bit register
        Flags(unsafe { std::mem::transmute::<__m256i, [u32; FAST_LANES]>(v) })
    };
    let outer = r + m;
    let close = flags(_mm256_cmp_ps::<_CMP_NGT_UQ>(
        d2,
        _mm256_set1_ps(outer * outer),
    ));
    contact.close = contact.close | close;
    if !matches!(object, Object::Bounded { .. }) {
        let inner = (r - m).max(0.0);
        let hit = flags(_mm256_cmp_ps::<_CMP_LT_OQ>(
            d2,
            _mm256_set1_ps(inner * inner),
        ));
        contact.hit = contact.hit | hit;
    }
}

/// [`test`] for every sphere at `centres` (radii in `balls`) against `object`, not a point
/// cloud: the lanes certainly colliding and those within the margin `m` of contact (or NaN).
/// The object's kind is matched and its constants broadcast once, the flags kept in registers
/// (the same arithmetic as [`distance2`], sphere by sphere).
#[target_feature(enable = "avx2,fma")]
#[inline]
pub(super) fn balls_against(
    object: &Object,
    centres: &[[F; 3]],
    balls: &[Ball],
    m: f32,
) -> (LaneMask, LaneMask) {
    debug_assert!(!matches!(object, Object::Cloud { .. }));
    let (mut hit, mut close) = (_mm256_setzero_ps(), _mm256_setzero_ps());
    let bounded = matches!(object, Object::Bounded { .. });
    let mut add = |d2: __m256, reach: f32| {
        let outer = reach + m;
        close = _mm256_or_ps(
            close,
            _mm256_cmp_ps::<_CMP_NGT_UQ>(d2, _mm256_set1_ps(outer * outer)),
        );
        if !bounded {
            let inner = (reach - m).max(0.0);
            hit = _mm256_or_ps(
                hit,
                _mm256_cmp_ps::<_CMP_LT_OQ>(d2, _mm256_set1_ps(inner * inner)),
            );
        }
    };
    let norm2 = |v: [__m256; 3]| {
        _mm256_fmadd_ps(
            v[2],
            v[2],
            _mm256_fmadd_ps(v[1], v[1], _mm256_mul_ps(v[0], v[0])),
        )
    };
    let splat3 = |v: [f32; 3]| {
        [
            _mm256_set1_ps(v[0]),
            _mm256_set1_ps(v[1]),
            _mm256_set1_ps(v[2]),
        ]
    };
    let spheres = centres.iter().zip(balls);
    match *object {
        Object::Round { a, b, radius } => {
            let ab = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
            let len2 = ab[0] * ab[0] + ab[1] * ab[1] + ab[2] * ab[2];
            let inv = _mm256_set1_ps(if len2 > 0.0 { 1.0 / len2 } else { 0.0 });
            let (a, ab) = (splat3(a), splat3(ab));
            for (c, ball) in spheres {
                let p = [
                    _mm256_sub_ps(load(&c[0]), a[0]),
                    _mm256_sub_ps(load(&c[1]), a[1]),
                    _mm256_sub_ps(load(&c[2]), a[2]),
                ];
                let along = _mm256_fmadd_ps(
                    p[2],
                    ab[2],
                    _mm256_fmadd_ps(p[1], ab[1], _mm256_mul_ps(p[0], ab[0])),
                );
                let t = _mm256_mul_ps(along, inv);
                let t = _mm256_max_ps(_mm256_min_ps(t, _mm256_set1_ps(1.0)), _mm256_setzero_ps());
                let d2 = norm2([
                    _mm256_fnmadd_ps(t, ab[0], p[0]),
                    _mm256_fnmadd_ps(t, ab[1], p[1]),
                    _mm256_fnmadd_ps(t, ab[2], p[2]),
                ]);
                add(d2, ball.radius + radius);
            }
        }
        Object::Box { center, axes, half } => {
            let (o, x, y, z) = (
                splat3(center),
                splat3(axes[0]),
                splat3(axes[1]),
                splat3(axes[2]),
            );
            for (c, ball) in spheres {
                let p = [
                    _mm256_sub_ps(load(&c[0]), o[0]),
                    _mm256_sub_ps(load(&c[1]), o[1]),
                    _mm256_sub_ps(load(&c[2]), o[2]),
                ];
                let along = |a: &[__m256; 3]| {
                    _mm256_fmadd_ps(
                        p[2],
                        a[2],
                        _mm256_fmadd_ps(p[1], a[1], _mm256_mul_ps(p[0], a[0])),
                    )
                };
                let d2 = norm2([
                    beyond(abs(along(&x)), half[0]),
                    beyond(abs(along(&y)), half[1]),
                    beyond(abs(along(&z)), half[2]),
                ]);
                add(d2, ball.radius);
            }
        }
        _ => {
            // cylinders and bounded objects: the per-sphere distance
            let extra = object.reach(0.0);
            for (c, ball) in spheres {
                add(distance2(object, c), ball.radius + extra);
            }
        }
    }
    (
        _mm256_movemask_ps(hit) as LaneMask,
        _mm256_movemask_ps(close) as LaneMask,
    )
}

/// The three coordinates of a point in every lane.
#[target_feature(enable = "avx")]
#[inline]
pub(super) fn load3(c: &[F; 3]) -> [__m256; 3] {
    [load(&c[0]), load(&c[1]), load(&c[2])]
}

/// Squared distance between two points in every lane.
#[target_feature(enable = "avx2,fma")]
#[inline]
pub(super) fn distance2_between(a: &[__m256; 3], b: &[__m256; 3]) -> __m256 {
    let d = [
        _mm256_sub_ps(a[0], b[0]),
        _mm256_sub_ps(a[1], b[1]),
        _mm256_sub_ps(a[2], b[2]),
    ];
    _mm256_fmadd_ps(
        d[2],
        d[2],
        _mm256_fmadd_ps(d[1], d[1], _mm256_mul_ps(d[0], d[0])),
    )
}

/// [`super::pair_contacts`] written out.
#[target_feature(enable = "avx2,fma")]
#[inline]
pub(super) fn pair_contacts(
    model: &FastModel,
    gp: &GroupPair,
    scratch: &FastScratch,
    world: &FastWorld,
) -> (LaneMask, LaneMask) {
    let m = world.margin;
    let (balls, bounds) = (&scratch.balls, &scratch.bounds);
    // what the unchecked reads below rest on: the model's pairs and runs index its balls and
    // its pairs (as compiled), and the scratch and the world are this model's
    assert!(
        balls.len() == model.balls.len() && world.limits.len() == model.pairs.len(),
        "a scratch or a world of another model"
    );
    let bound_b = load3(&bounds[gp.b]);
    let (mut hit, mut close) = (_mm256_setzero_ps(), _mm256_setzero_ps());
    for run in &gp.runs {
        // SAFETY: a run's ball is one of the model's balls (asserted above)
        #[allow(unsafe_code)]
        let ball = load3(unsafe { balls.get_unchecked(run.ball as usize) });
        let reach = run.reach + m;
        let near = _mm256_cmp_ps::<_CMP_NGT_UQ>(
            distance2_between(&ball, &bound_b),
            _mm256_set1_ps(reach * reach),
        );
        if _mm256_testz_ps(near, near) != 0 {
            continue;
        }
        let range = run.start as usize..run.end as usize;
        // SAFETY: a run's pairs are a range of the model's pairs, and the world holds their
        // limits (asserted above)
        #[allow(unsafe_code)]
        let pairs = unsafe {
            (model.pairs.get_unchecked(range.clone()).iter()).zip(world.limits.get_unchecked(range))
        };
        for (&(_, b, _), &[inner2, outer2]) in pairs {
            // SAFETY: a pair's balls are the model's (asserted above)
            #[allow(unsafe_code)]
            let other = unsafe { balls.get_unchecked(b as usize) };
            let d2 = distance2_between(&ball, &load3(other));
            let h = _mm256_cmp_ps::<_CMP_LT_OQ>(d2, _mm256_set1_ps(inner2));
            let c = _mm256_cmp_ps::<_CMP_NGT_UQ>(d2, _mm256_set1_ps(outer2));
            hit = _mm256_or_ps(hit, h);
            close = _mm256_or_ps(close, c);
        }
    }
    (
        _mm256_movemask_ps(hit) as LaneMask,
        _mm256_movemask_ps(close) as LaneMask,
    )
}

/// [`super::kdop_clear`] written out, for [`super::KDOP`]'s directions: the axes, then
/// the face diagonals as sums and differences of two coordinates.
#[target_feature(enable = "avx2,fma")]
pub(super) fn kdop_clear(
    model: &FastModel,
    a: usize,
    kdop: &[[f32; 2]; KDOP.len()],
    frame: &([F; 9], [F; 3]),
    scratch: &FastScratch,
    m: f32,
) -> LaneMask {
    let mut rot = [_mm256_setzero_ps(); 9];
    for k in 0..9 {
        rot[k] = load(&frame.0[k]);
    }
    let t = load3(&frame.1);
    let mut clear = _mm256_castsi256_ps(_mm256_set1_epi32(-1));
    for i in model.groups[a].balls.clone() {
        let c = load3(&scratch.balls[i]);
        let d = [
            _mm256_sub_ps(c[0], t[0]),
            _mm256_sub_ps(c[1], t[1]),
            _mm256_sub_ps(c[2], t[2]),
        ];
        // rotᵀ d: the centre in the link's frame
        let local = |j: usize| {
            _mm256_fmadd_ps(
                rot[6 + j],
                d[2],
                _mm256_fmadd_ps(rot[3 + j], d[1], _mm256_mul_ps(rot[j], d[0])),
            )
        };
        let (x, y, z) = (local(0), local(1), local(2));
        let s = [
            x,
            y,
            z,
            _mm256_add_ps(x, y),
            _mm256_sub_ps(x, y),
            _mm256_add_ps(x, z),
            _mm256_sub_ps(x, z),
            _mm256_add_ps(y, z),
            _mm256_sub_ps(y, z),
        ];
        let r = model.balls[i].radius + m;
        let mut beyond = _mm256_setzero_ps();
        for (k, &[lo, hi]) in kdop.iter().enumerate() {
            // the diagonals are √2 long
            let reach = if k < 3 {
                r
            } else {
                r * std::f32::consts::SQRT_2
            };
            let above = _mm256_cmp_ps::<_CMP_GT_OQ>(s[k], _mm256_set1_ps(hi + reach));
            let below = _mm256_cmp_ps::<_CMP_LT_OQ>(s[k], _mm256_set1_ps(lo - reach));
            beyond = _mm256_or_ps(beyond, _mm256_or_ps(above, below));
        }
        clear = _mm256_and_ps(clear, beyond);
        if _mm256_testz_ps(clear, clear) != 0 {
            return 0;
        }
    }
    _mm256_movemask_ps(clear) as LaneMask
}

/// Eight `f32` lanes as one register (unaligned).
#[target_feature(enable = "avx")]
#[inline]
pub(super) fn load_lanes(v: &[f32; FAST_LANES]) -> __m256 {
    // SAFETY: eight `f32`
    unsafe { _mm256_loadu_ps(v.as_ptr()) }
}

/// One register into an `F`.
#[target_feature(enable = "avx")]
#[inline]
pub(super) fn store(v: __m256) -> F {
    let mut out = F::default();
    // SAFETY: `F` is eight `f32` aligned to 32 bytes
    unsafe { _mm256_store_ps(out.0.as_mut_ptr(), v) };
    out
}

/// Three registers into a point in every lane.
#[target_feature(enable = "avx")]
#[inline]
pub(super) fn store3(v: [__m256; 3]) -> [F; 3] {
    [store(v[0]), store(v[1]), store(v[2])]
}

/// `rot · p + t` in every lane ([`super::transform`]).
#[target_feature(enable = "avx2,fma")]
#[inline]
pub(super) fn transform(rot: &[__m256; 9], t: &[__m256; 3], p: [f32; 3]) -> [__m256; 3] {
    let (x, y, z) = (
        _mm256_set1_ps(p[0]),
        _mm256_set1_ps(p[1]),
        _mm256_set1_ps(p[2]),
    );
    let row = |k: usize| {
        let xy = _mm256_fmadd_ps(rot[3 * k + 1], y, _mm256_fmadd_ps(rot[3 * k], x, t[k]));
        _mm256_fmadd_ps(rot[3 * k + 2], z, xy)
    };
    [row(0), row(1), row(2)]
}

/// [`super::place`] written out: each link's bounding sphere's centre (rotated by its
/// quaternion).
#[target_feature(enable = "avx2,fma")]
#[inline]
pub(super) fn place(model: &FastModel, poses: &[PoseLanes32], scratch: &mut FastScratch) {
    let two = _mm256_set1_ps(2.0);
    for (g, group) in model.groups.iter().enumerate() {
        let p = &poses[group.frame];
        // no array `map` here: its closures would be compiled without AVX
        let (w, x, y, z) = (
            load_lanes(&p[0]),
            load_lanes(&p[1]),
            load_lanes(&p[2]),
            load_lanes(&p[3]),
        );
        let t = [load_lanes(&p[4]), load_lanes(&p[5]), load_lanes(&p[6])];
        // the centre c moved: t + c + w·u + q×u, u = 2 q×c
        let c = group.bound.center;
        let c = [
            _mm256_set1_ps(c[0]),
            _mm256_set1_ps(c[1]),
            _mm256_set1_ps(c[2]),
        ];
        let cross =
            |a: __m256, b: __m256, d: __m256, e: __m256| _mm256_fmsub_ps(a, b, _mm256_mul_ps(d, e));
        let u = [
            _mm256_mul_ps(two, cross(y, c[2], z, c[1])),
            _mm256_mul_ps(two, cross(z, c[0], x, c[2])),
            _mm256_mul_ps(two, cross(x, c[1], y, c[0])),
        ];
        let moved = |t: __m256, c: __m256, u: __m256, q: __m256| {
            _mm256_add_ps(_mm256_add_ps(t, c), _mm256_fmadd_ps(w, u, q))
        };
        scratch.bounds[g] = store3([
            moved(t[0], c[0], u[0], cross(y, u[2], z, u[1])),
            moved(t[1], c[1], u[1], cross(z, u[0], x, u[2])),
            moved(t[2], c[2], u[2], cross(x, u[1], y, u[0])),
        ]);
    }
}

/// [`super::place_balls`] written out.
#[target_feature(enable = "avx2,fma")]
#[inline]
pub(super) fn place_balls(model: &FastModel, g: usize, scratch: &mut FastScratch) {
    let (rot, t) = &scratch.frames[g];
    let mut m = [_mm256_setzero_ps(); 9];
    for k in 0..9 {
        m[k] = load(&rot[k]);
    }
    let (rot, t) = (m, load3(t));
    let group = &model.groups[g];
    // (one check for the group's balls: the loop reads and writes without one per ball)
    let (placed, balls) = (
        &mut scratch.balls[group.balls.clone()],
        &model.balls[group.balls.clone()],
    );
    for (out, ball) in placed.iter_mut().zip(balls) {
        *out = store3(transform(&rot, &t, ball.center));
    }
    for i in group.inner.clone() {
        scratch.inner[i] = store3(transform(&rot, &t, model.inner[i].center));
    }
    scratch.placed[g] = true;
}

/// [`Flags::mask`]: the flags (0 or 1) moved to the sign bits, then gathered.
///
/// # Safety
/// The CPU must have AVX2.
#[target_feature(enable = "avx2")]
#[inline]
pub(super) unsafe fn mask(flags: Flags) -> LaneMask {
    // SAFETY: eight `u32` lanes, the size and layout of one 256-bit register
    let v: __m256i = unsafe { std::mem::transmute::<[u32; FAST_LANES], __m256i>(flags.0) };
    _mm256_movemask_ps(_mm256_castsi256_ps(_mm256_slli_epi32::<31>(v))) as LaneMask
}
