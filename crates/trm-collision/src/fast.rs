//! Single-precision collision checks, [`FAST_LANES`] configurations at once: sphere models as
//! they are, other models (mesh hulls) through spheres that enclose their bodies.
//!
//! VAMP's way (Thomason, Kingston and Kavraki, ICRA 2024): the robot as spheres, and every
//! number of a block of eight configurations one `f32` lane, so that each arithmetic step is one
//! 8-wide vector instruction (AVX2, chosen at run time; two 4-wide ones with SSE or NEON).
//! Spheres are screened link by link: a link's bounding sphere first, its own spheres only when
//! some lane's bounding spheres come close.
//!
//! **Exact verdicts, not approximate ones.** Single precision moves a sphere's centre by far less
//! than the [`FastWorld::margin`]; a pair whose distance exceeds the sum of its radii by more than
//! the margin is *clear*, one that falls short of it by more than the margin is *colliding*, and
//! anything between is *uncertain*. A lane with an uncertain pair and no certain collision is
//! handed back ([`Verdict::uncertain`]) for the exact `f64` check, so a caller that checks those
//! lanes exactly answers as the `f64` path does, configuration by configuration (tested on
//! random configurations of the Panda against [`CollisionModel::is_colliding`]).
//! [`FastChecker`] checks them pair by pair: only the link pairs and (link, object) pairs that
//! left the lane uncertain, each body placed alone.
//!
//! Robot bodies that are spheres (a spherized URDF, or one written by
//! [`fit::urdf_with_spheres`](crate::fit::urdf_with_spheres)) are the model itself; other bodies
//! are *screened* through the spheres enclosing them ([`CollisionModel::enclosing_spheres`]: a
//! mesh's convex hull cut into cells, each enclosed exactly; a capsule's caps and pieces of its
//! cylinder), so that contact is only a reason to look exactly, and through spheres inside them
//! ([`Shape::inscribed_spheres`]), whose contact is a certain collision. A link that is one box
//! is tested as that box: the other link's spheres are taken into its frame. A block whose
//! lanes are left uncertain by two links of convex hulls gets a second, tighter screen before
//! the exact checks: each link's spheres against the other's 18-sided bounding polytope
//! (k-DOP). World objects of every shape are taken: spheres, capsules and boxes are checked
//! in single precision, cylinders and convex hulls through their bounding spheres (a lane near
//! one is uncertain).

// Lane loops index several arrays at once, the form the vectoriser turns into one instruction;
// `!(x > limit)` is the NaN-inclusive test on purpose.
#![allow(clippy::needless_range_loop, clippy::neg_cmp_op_on_partial_ord)]

use std::collections::BTreeMap;
use std::sync::Arc;

use nalgebra::{Point3, Vector3};
use trm_kinematics::{ActiveSet, BLOCK_LANES, JointKind, PoseBlock, PoseBuffer, PoseLanes32};

use crate::batch::Nest;
use crate::error::{CollisionError, Result};
use crate::model::{CollisionModel, PlacedBodies};
use crate::shape::Shape;
use crate::world::World;

/// Configurations per block ([`BLOCK_LANES`] of single-precision forward kinematics).
pub const FAST_LANES: usize = BLOCK_LANES;

/// One `f32` per configuration of a block, aligned for one 8-wide register. Its operations are
/// element-wise loops, which the compiler turns into single vector instructions.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
#[repr(C, align(32))]
struct F([f32; FAST_LANES]);

macro_rules! lane_wise {
    ($trait:ident, $method:ident, $op:tt) => {
        impl std::ops::$trait for F {
            type Output = F;
            #[inline(always)]
            fn $method(self, other: F) -> F {
                let mut out = [0.0; FAST_LANES];
                for l in 0..FAST_LANES {
                    out[l] = self.0[l] $op other.0[l];
                }
                F(out)
            }
        }
    };
}
lane_wise!(Add, add, +);
lane_wise!(Sub, sub, -);
lane_wise!(Mul, mul, *);

impl F {
    /// `x` in every lane.
    #[inline(always)]
    fn splat(x: f32) -> F {
        F([x; FAST_LANES])
    }

    /// `f` of every lane.
    #[inline(always)]
    fn map(self, f: impl Fn(f32) -> f32) -> F {
        let mut out = self.0;
        for v in &mut out {
            *v = f(*v);
        }
        F(out)
    }

    /// The lanes ≤ `limit` or NaN (NaN is never certainly clear).
    #[inline(always)]
    fn within(self, limit: f32) -> Flags {
        let mut flags = [0; FAST_LANES];
        for l in 0..FAST_LANES {
            flags[l] = u32::from(!(self.0[l] > limit));
        }
        Flags(flags)
    }

    /// Whether any lane is ≤ `limit` or NaN ([`F::within`] not all clear). `AVX`: compiled
    /// for AVX, where one instruction gathers the lanes' sign bits (the compiler does not find
    /// it by itself).
    #[inline(always)]
    fn any_within<const AVX: bool>(self, limit: f32) -> bool {
        #[cfg(target_arch = "x86_64")]
        if AVX {
            // SAFETY: `AVX` is true only in `check`'s clones compiled for AVX, which run only
            // where the CPU has it (multiversion's run-time dispatch)
            #[allow(unsafe_code)]
            return unsafe { avx::any_within(self, limit) };
        }
        let mut count = 0u32;
        for l in 0..FAST_LANES {
            count += u32::from(!(self.0[l] > limit));
        }
        count != 0
    }

    /// The lanes < `limit`.
    #[inline(always)]
    fn below(self, limit: f32) -> Flags {
        let mut flags = [0; FAST_LANES];
        for l in 0..FAST_LANES {
            flags[l] = u32::from(self.0[l] < limit);
        }
        Flags(flags)
    }

    /// The lanes > `limit`.
    #[inline(always)]
    fn above(self, limit: f32) -> Flags {
        let mut flags = [0; FAST_LANES];
        for l in 0..FAST_LANES {
            flags[l] = u32::from(self.0[l] > limit);
        }
        Flags(flags)
    }
}

/// [`Flags::mask`]'s lane-by-lane form: the world's tests keep it, as they vectorise worse
/// around the AVX one (measured: 0.40 → 0.60 ms median on the MBM Panda with mesh hulls).
const PORTABLE: bool = false;

/// AVX instructions the compiler does not choose by itself.
#[cfg(target_arch = "x86_64")]
#[allow(unsafe_code)]
mod avx {
    use super::{
        Contact, F, FAST_LANES, FastModel, FastScratch, FastWorld, Flags, GroupPair, LaneMask,
        Object, PoseLanes32,
    };
    use std::arch::x86_64::{
        __m256, __m256i, _CMP_GT_OQ, _CMP_LT_OQ, _CMP_NGT_UQ, _mm256_add_ps, _mm256_and_ps,
        _mm256_and_si256, _mm256_castps_si256, _mm256_castsi256_ps, _mm256_cmp_ps, _mm256_fmadd_ps,
        _mm256_fnmadd_ps, _mm256_load_ps, _mm256_loadu_ps, _mm256_max_ps, _mm256_min_ps,
        _mm256_movemask_ps, _mm256_mul_ps, _mm256_or_ps, _mm256_set1_epi32, _mm256_set1_ps,
        _mm256_setzero_ps, _mm256_slli_epi32, _mm256_sqrt_ps, _mm256_store_ps, _mm256_sub_ps,
        _mm256_testz_ps,
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
    fn load(v: &F) -> __m256 {
        // SAFETY: `F` is eight `f32` aligned to 32 bytes
        unsafe { _mm256_load_ps(v.0.as_ptr()) }
    }

    /// `c` relative to `origin`, in the frame whose axes are the rows of `axes`.
    #[target_feature(enable = "avx2,fma")]
    #[inline]
    fn local(c: &[F; 3], origin: [f32; 3], axes: &[[f32; 3]; 3]) -> [__m256; 3] {
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
    fn beyond(v: __m256, limit: f32) -> __m256 {
        _mm256_max_ps(_mm256_sub_ps(v, _mm256_set1_ps(limit)), _mm256_setzero_ps())
    }

    /// `|v|`.
    #[target_feature(enable = "avx")]
    #[inline]
    fn abs(v: __m256) -> __m256 {
        _mm256_and_ps(v, _mm256_castsi256_ps(_mm256_set1_epi32(i32::MAX)))
    }

    /// [`Object::distance2`] written out: the compiler vectorises it badly where lane masks
    /// follow (measured: 0.40 → 0.37 ms median on the MBM Panda with mesh hulls).
    #[target_feature(enable = "avx2,fma")]
    #[inline]
    pub(super) fn distance2(object: &Object, c: &[F; 3]) -> __m256 {
        let norm2 = |v: [__m256; 3]| {
            _mm256_fmadd_ps(
                v[2],
                v[2],
                _mm256_fmadd_ps(v[1], v[1], _mm256_mul_ps(v[0], v[0])),
            )
        };
        match *object {
            Object::Round { a, b, .. } => {
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
            Object::Box { center, axes, half } => {
                let p = local(c, center, &axes);
                norm2([
                    beyond(abs(p[0]), half[0]),
                    beyond(abs(p[1]), half[1]),
                    beyond(abs(p[2]), half[2]),
                ])
            }
            Object::Cylinder {
                center,
                axes,
                radius,
                half,
            } => {
                let [x, y, z] = local(c, center, &axes);
                let radial = _mm256_sqrt_ps(_mm256_fmadd_ps(y, y, _mm256_mul_ps(x, x)));
                let radial = beyond(radial, radius);
                let axial = beyond(abs(z), half);
                _mm256_fmadd_ps(axial, axial, _mm256_mul_ps(radial, radial))
            }
            Object::Bounded { center, .. } => norm2([
                _mm256_sub_ps(load(&c[0]), _mm256_set1_ps(center[0])),
                _mm256_sub_ps(load(&c[1]), _mm256_set1_ps(center[1])),
                _mm256_sub_ps(load(&c[2]), _mm256_set1_ps(center[2])),
            ]),
        }
    }

    /// [`Object::near`]: the lanes whose squared distance is within `reach2` (NaN included).
    #[target_feature(enable = "avx2,fma")]
    #[inline]
    pub(super) fn near(object: &Object, c: &[F; 3], reach2: f32) -> LaneMask {
        let flags = _mm256_cmp_ps::<_CMP_NGT_UQ>(distance2(object, c), _mm256_set1_ps(reach2));
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

    /// The three coordinates of a point in every lane.
    #[target_feature(enable = "avx")]
    #[inline]
    fn load3(c: &[F; 3]) -> [__m256; 3] {
        [load(&c[0]), load(&c[1]), load(&c[2])]
    }

    /// Squared distance between two points in every lane.
    #[target_feature(enable = "avx2,fma")]
    #[inline]
    fn distance2_between(a: &[__m256; 3], b: &[__m256; 3]) -> __m256 {
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
        let bound_b = load3(&bounds[gp.b]);
        let bound_radius = model.groups[gp.b].bound.radius;
        let (mut hit, mut close) = (_mm256_setzero_ps(), _mm256_setzero_ps());
        for (a, run) in &gp.runs {
            let ball = load3(&balls[*a as usize]);
            let reach = model.balls[*a as usize].radius + bound_radius + m;
            let near = _mm256_cmp_ps::<_CMP_NGT_UQ>(
                distance2_between(&ball, &bound_b),
                _mm256_set1_ps(reach * reach),
            );
            if _mm256_testz_ps(near, near) != 0 {
                continue;
            }
            let pairs = model.pairs[run.clone()]
                .iter()
                .zip(&world.limits[run.clone()]);
            for (&(_, b, _), &[inner2, outer2]) in pairs {
                let d2 = distance2_between(&ball, &load3(&balls[b as usize]));
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
        kdop: &[[f32; 2]; super::KDOP.len()],
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
    fn load_lanes(v: &[f32; FAST_LANES]) -> __m256 {
        // SAFETY: eight `f32`
        unsafe { _mm256_loadu_ps(v.as_ptr()) }
    }

    /// One register into an `F`.
    #[target_feature(enable = "avx")]
    #[inline]
    fn store(v: __m256) -> F {
        let mut out = F::default();
        // SAFETY: `F` is eight `f32` aligned to 32 bytes
        unsafe { _mm256_store_ps(out.0.as_mut_ptr(), v) };
        out
    }

    /// Three registers into a point in every lane.
    #[target_feature(enable = "avx")]
    #[inline]
    fn store3(v: [__m256; 3]) -> [F; 3] {
        [store(v[0]), store(v[1]), store(v[2])]
    }

    /// `rot · p + t` in every lane ([`super::transform`]).
    #[target_feature(enable = "avx2,fma")]
    #[inline]
    fn transform(rot: &[__m256; 9], t: &[__m256; 3], p: [f32; 3]) -> [__m256; 3] {
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

    /// [`super::place`] written out: each link's rotation matrix from its quaternion, and its
    /// bounding sphere's centre.
    #[target_feature(enable = "avx2,fma")]
    #[inline]
    pub(super) fn place(model: &FastModel, poses: &[PoseLanes32], scratch: &mut FastScratch) {
        let (one, two) = (_mm256_set1_ps(1.0), _mm256_set1_ps(2.0));
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
            let (xx, yy, zz) = (
                _mm256_mul_ps(x, x),
                _mm256_mul_ps(y, y),
                _mm256_mul_ps(z, z),
            );
            let (xy, xz, yz) = (
                _mm256_mul_ps(x, y),
                _mm256_mul_ps(x, z),
                _mm256_mul_ps(y, z),
            );
            let (wx, wy, wz) = (
                _mm256_mul_ps(w, x),
                _mm256_mul_ps(w, y),
                _mm256_mul_ps(w, z),
            );
            let diagonal = |a: __m256, b: __m256| _mm256_fnmadd_ps(two, _mm256_add_ps(a, b), one);
            let twice = |a: __m256| _mm256_mul_ps(two, a);
            let rot = [
                diagonal(yy, zz),
                twice(_mm256_sub_ps(xy, wz)),
                twice(_mm256_add_ps(xz, wy)),
                twice(_mm256_add_ps(xy, wz)),
                diagonal(xx, zz),
                twice(_mm256_sub_ps(yz, wx)),
                twice(_mm256_sub_ps(xz, wy)),
                twice(_mm256_add_ps(yz, wx)),
                diagonal(xx, yy),
            ];
            scratch.bounds[g] = store3(transform(&rot, &t, group.bound.center));
            let frame = &mut scratch.frames[g];
            for k in 0..9 {
                frame.0[k] = store(rot[k]);
            }
            frame.1 = store3(t);
            scratch.placed[g] = false;
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
        for i in group.balls.clone() {
            scratch.balls[i] = store3(transform(&rot, &t, model.balls[i].center));
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
}

/// One flag (0 or 1) per lane, or-ed together without branches and turned into a
/// [`LaneMask`] once per group of pairs.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
#[repr(C, align(32))]
struct Flags([u32; FAST_LANES]);

impl std::ops::BitOr for Flags {
    type Output = Flags;
    #[inline(always)]
    fn bitor(self, other: Flags) -> Flags {
        let mut out = [0; FAST_LANES];
        for l in 0..FAST_LANES {
            out[l] = self.0[l] | other.0[l];
        }
        Flags(out)
    }
}

impl Flags {
    /// The lanes flagged. `AVX`: compiled for AVX, where one instruction gathers them.
    #[inline(always)]
    fn mask<const AVX: bool>(self) -> LaneMask {
        #[cfg(target_arch = "x86_64")]
        if AVX {
            // SAFETY: as in `F::any_within`
            #[allow(unsafe_code)]
            return unsafe { avx::mask(self) };
        }
        let mut mask = 0;
        for l in 0..FAST_LANES {
            mask |= (self.0[l] as LaneMask) << l;
        }
        mask
    }
}

/// One bit per configuration of a block (bit `l`: configuration `l`).
pub type LaneMask = u8;

/// Every configuration of a block.
pub const ALL_LANES: LaneMask = u8::MAX;

/// Rounding budget of the margin, m per metre of the largest coordinate per joint of the
/// deepest chain (see [`FastWorld::margin`]).
const MARGIN_PER_METRE_JOINT: f64 = 1e-6;

/// A sphere in the frame of its link.
#[derive(Debug, Clone, Copy)]
struct Ball {
    center: [f32; 3],
    radius: f32,
}

/// A link's spheres and the sphere bounding them (in the link frame).
#[derive(Debug, Clone)]
struct Group {
    /// Index of the link pose in the pose batches.
    frame: usize,
    bound: Ball,
    /// The link's spheres: indices into [`FastModel::balls`].
    balls: std::ops::Range<usize>,
    /// Spheres inside the link's bodies, when its spheres enclose them (not a sphere model):
    /// indices into [`FastModel::inner`]. Touching one is a certain collision.
    inner: std::ops::Range<usize>,
    /// The link's bodies (indices into [`CollisionModel::bodies`]).
    bodies: Vec<u32>,
    /// The link's body in the link frame when it is one box: other links' spheres are tested
    /// against the box itself, not against the spheres enclosing it.
    solid: Option<Object>,
    /// When every body of the link is a convex hull: the polytope bounding them along the
    /// [`KDOP`] directions in the link frame, `[lowest, highest]` per direction. A sphere
    /// beyond one of its slabs is clear of the link's bodies.
    kdop: Option<[[f32; 2]; KDOP.len()]>,
}

/// The 9 directions of an 18-sided discrete orientation polytope (k-DOP): the axes and the
/// face diagonals of a cube, unnormalised (slab values scale with them). Measured against the
/// 26-sided one (adding the corner diagonals) and the 6-sided box: fewest lanes left to the
/// exact checks for the time spent on the MotionBenchMaker Panda's and Fetch's hulls.
const KDOP: [[f32; 3]; 9] = [
    [1.0, 0.0, 0.0],
    [0.0, 1.0, 0.0],
    [0.0, 0.0, 1.0],
    [1.0, 1.0, 0.0],
    [1.0, -1.0, 0.0],
    [1.0, 0.0, 1.0],
    [1.0, 0.0, -1.0],
    [0.0, 1.0, 1.0],
    [0.0, 1.0, -1.0],
];

/// Two balls (indices into [`FastModel::balls`]) and the sum of their radii.
type BallPair = (u32, u32, f32);

/// A link pair's ball pairs and checked body pairs, while compiling.
type LinkPairTests = (Vec<BallPair>, Vec<(u32, u32)>);

/// Two links whose spheres are tested against each other.
#[derive(Debug, Clone)]
struct GroupPair {
    a: usize,
    b: usize,
    /// Per ball of link `a`: the ball and its pairs with link `b`'s balls, a range of
    /// [`FastModel::pairs`].
    runs: Vec<(u32, std::ops::Range<usize>)>,
    /// The checked body pairs of the two links (indices into [`CollisionModel::bodies`]).
    bodies: Vec<(u32, u32)>,
    /// Pairs of spheres inside the two links' checked bodies (indices into
    /// [`FastModel::inner`]) and the sums of their radii: touching is a certain collision.
    inner: Vec<BallPair>,
    /// `(solid, other)` when one link is a box ([`Group::solid`]) checked against every body of
    /// the other: the other's spheres are tested against the box in its link's frame instead
    /// of the sphere pairs.
    solid: Option<(usize, usize)>,
}

/// Most culls open at once in a walk; deeper ones test but do not narrow the lanes.
const MAX_NESTING: usize = 16;

/// One step of the self-collision walk, in the order of [`crate::cull`]'s steps.
#[derive(Debug, Clone, Copy)]
enum CullStep {
    /// When spheres `a` and `b` (indices into [`FastScratch::bounds`]: link groups' bounding
    /// spheres, then culling spheres about link origins) whose radii sum to `reach` are apart
    /// in every lane, continue at step `end`.
    Cull {
        a: u32,
        b: u32,
        reach: f32,
        end: u32,
    },
    /// A link pair: an index into [`FastModel::group_pairs`].
    Pair(u32),
}

/// One step of a world object's walk, in the order of [`crate::cull`]'s world steps.
#[derive(Debug, Clone, Copy)]
enum WorldStep {
    /// When the object is farther than `radius` from the centre `ball` (an index into
    /// [`FastScratch::bounds`]) in every lane, continue at step `end`.
    Cull { ball: u32, radius: f32, end: u32 },
    /// A link group: an index into [`FastModel::groups`].
    Link(u32),
}

/// What left lanes of a block uncertain: checked exactly, only it, in those lanes.
#[derive(Debug, Clone, Copy)]
enum Suspect {
    /// A link pair: an index into [`FastModel::group_pairs`].
    Pair(u32),
    /// A world object and a link group.
    Object { object: u32, group: u32 },
}

/// A collision model compiled for single-precision checks of [`FAST_LANES`] configurations at
/// once (made by [`FastModel::new`]): its spheres, or the spheres enclosing its bodies.
#[derive(Debug, Clone)]
pub struct FastModel {
    balls: Vec<Ball>,
    /// Spheres inside the bodies ([`Shape::inscribed_spheres`]), grouped by link.
    inner: Vec<Ball>,
    /// For each ball, the index of the body it came from.
    bodies: Vec<usize>,
    groups: Vec<Group>,
    group_pairs: Vec<GroupPair>,
    /// Ball pairs and the sums of their radii.
    pairs: Vec<BallPair>,
    /// The self-collision walk through the culling spheres (when `culls`): culls and link
    /// pairs.
    steps: Vec<CullStep>,
    /// Each world object's walk through the culling spheres (when `culls`): culls and links.
    world_steps: Vec<WorldStep>,
    /// Whether the walks take `steps` and `world_steps` ([`CULLED_LINK_PAIRS`]); else the
    /// link pairs and links in order.
    culls: bool,
    /// Pose index of each culling sphere's link (after the groups in [`FastScratch::bounds`]).
    origins: Vec<u32>,
    /// Largest distance of any point of the robot from the world origin, in any configuration
    /// (a bound from the joint offsets).
    reach: f64,
    /// Most movable joints between the root and a link.
    depth: usize,
    /// Whether the spheres are the model itself (a sphere model), so that a certain contact is
    /// a certain collision; otherwise they enclose the bodies and only screen: contact is
    /// uncertain.
    exact: bool,
}

/// A world object as the single-precision checks see it.
#[derive(Debug, Clone, Copy)]
enum Object {
    /// A sphere, or a capsule's segment (`a` = `b` for a sphere).
    Round {
        a: [f32; 3],
        b: [f32; 3],
        radius: f32,
    },
    /// A box: centre, the rows of the transposed rotation (world → box frame) and half sizes.
    Box {
        center: [f32; 3],
        axes: [[f32; 3]; 3],
        half: [f32; 3],
    },
    /// A cylinder along its z axis: centre, the rows of the transposed rotation, radius and
    /// half length.
    Cylinder {
        center: [f32; 3],
        axes: [[f32; 3]; 3],
        radius: f32,
        half: f32,
    },
    /// Anything else, through its bounding sphere: near it is uncertain, never colliding.
    Bounded { center: [f32; 3], radius: f32 },
}

/// A world compiled for a [`FastModel`] (made by [`FastModel::world`]; compile it again when
/// the world changes).
#[derive(Debug, Clone)]
pub struct FastWorld {
    /// The objects, nearest the robot's root first.
    objects: Vec<Object>,
    /// The world's index of each of `objects`.
    original: Vec<u32>,
    /// The index in `objects` of each of the world's objects.
    compiled_of: Vec<u32>,
    margin: f32,
    /// Per ball pair of the model ([`FastModel::pairs`]): its [`limits`] with this margin.
    limits: Vec<[f32; 2]>,
}

impl FastWorld {
    /// The band, m, around contact within which a verdict is uncertain: 1 µm per metre of the
    /// largest coordinate involved (the robot's reach and the farthest object, plus one metre)
    /// per joint of the deepest chain (plus two, for placing the spheres and measuring their
    /// distance, and one more for taking spheres into a box link's frame when the model has
    /// one). Single precision errs by a few units of 2⁻²⁴ (6e-8) of relative error per
    /// step — under 0.5 µm per metre per joint — so the band is at least twice the worst
    /// rounding of both spheres of a pair (25 µm on the Panda; measured FK rounding: 0.7 µm on
    /// the 75-joint iCub).
    pub fn margin(&self) -> f64 {
        f64::from(self.margin)
    }

    /// Number of objects.
    pub fn len(&self) -> usize {
        self.objects.len()
    }

    /// Whether the world has no object.
    pub fn is_empty(&self) -> bool {
        self.objects.is_empty()
    }
}

/// What a block's check found.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Verdict {
    /// Lanes certainly colliding. The check stops at the first it finds, so this holds at
    /// least one lane when any lane collides, not necessarily all of them.
    pub colliding: LaneMask,
    /// Lanes neither certainly colliding nor certainly free (a pair within the margin of
    /// contact): check them exactly. Meaningful only when `colliding` is 0.
    pub uncertain: LaneMask,
}

/// What a block's count found ([`FastModel::count`]): per lane, the link pairs and the (link,
/// world object) pairs certainly colliding, and the lanes with pairs left uncertain (the
/// suspects), whose counts are complete only once those are checked exactly.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Tally {
    /// Link pairs certainly colliding, per lane.
    pub self_pairs: [u32; FAST_LANES],
    /// (link, world object) pairs certainly colliding, per lane.
    pub world_pairs: [u32; FAST_LANES],
    /// Lanes with a pair neither certainly colliding nor certainly free.
    pub uncertain: LaneMask,
    counting_self: bool,
}

/// Caller-owned scratch of [`FastModel::check`] (made by [`FastModel::scratch`]): world
/// centres of every sphere and bounding sphere in every lane. Checks do not allocate.
#[derive(Debug, Clone)]
pub struct FastScratch {
    balls: Vec<[F; 3]>,
    inner: Vec<[F; 3]>,
    bounds: Vec<[F; 3]>,
    /// Per link group: its frame (rotation rows, translation) in every lane.
    frames: Vec<([F; 9], [F; 3])>,
    /// Per link group: whether its balls are placed for the current block.
    placed: Vec<bool>,
    /// What left lanes uncertain in the last check, and in which lanes.
    suspects: Vec<(Suspect, LaneMask)>,
    /// The pair the last check that stopped at a collision stopped at: tested first by the
    /// next check (consecutive blocks, such as the points of a planner's edges, mostly collide
    /// where the last one did).
    last_hit: Option<Suspect>,
}

impl FastModel {
    /// Compiles `model`: its spheres as they are when every body is a sphere, else the spheres
    /// enclosing each body ([`CollisionModel::enclosing_spheres`]), which only screen.
    pub fn new(model: &CollisionModel) -> Result<Self> {
        let bodies = model.bodies();
        let tree = model.robot().tree();
        let exact = Self::is_sphere_model(model);
        // balls grouped by link, in link order: the bodies themselves (a sphere model), or the
        // spheres enclosing each body
        let mut by_link: BTreeMap<usize, Vec<usize>> = BTreeMap::new();
        for (i, b) in bodies.iter().enumerate() {
            by_link.entry(b.link).or_default().push(i);
        }
        let (mut balls, mut ball_bodies, mut groups) = (Vec::new(), Vec::new(), Vec::new());
        let mut inner = Vec::new();
        let mut inner_of_body = vec![0..0; bodies.len()];
        let mut group_of_body = vec![usize::MAX; bodies.len()];
        let mut balls_of_body = vec![0..0; bodies.len()];
        for (&link, members) in &by_link {
            let (start, inner_start) = (balls.len(), inner.len());
            let mut spheres: Vec<(Point3<f64>, f64)> = Vec::new();
            for &i in members {
                let first = balls.len();
                for s in model.enclosing_spheres(i) {
                    spheres.push((s.center, s.radius));
                    balls.push(Ball {
                        center: to_f32(s.center.coords),
                        radius: s.radius as f32,
                    });
                    ball_bodies.push(i);
                }
                if balls.len() == first {
                    return Err(CollisionError::InvalidValue {
                        what: format!("body `{}`", bodies[i].name),
                        problem: "has no enclosing sphere (an invalid shape)".into(),
                    });
                }
                group_of_body[i] = groups.len();
                balls_of_body[i] = first..balls.len();
                if !exact {
                    let first = inner.len();
                    inner.extend(model.inscribed_spheres(i).iter().map(|s| Ball {
                        center: to_f32(s.center.coords),
                        radius: s.radius as f32,
                    }));
                    inner_of_body[i] = first..inner.len();
                }
            }
            let solid = match (members.as_slice(), exact) {
                (&[i], false) => match bodies[i].shape {
                    Shape::Box { size } => Some(Object::Box {
                        center: to_f32(bodies[i].local.translation.vector),
                        axes: inverse_axes(&bodies[i].local),
                        half: size.map(|s| (0.5 * s) as f32),
                    }),
                    _ => None,
                },
                _ => None,
            };
            let kdop = (!exact)
                .then(|| kdop_of(members.iter().map(|&i| &bodies[i])))
                .flatten();
            groups.push(Group {
                frame: link,
                bound: bounding_ball(&spheres),
                balls: start..balls.len(),
                inner: inner_start..inner.len(),
                bodies: members.iter().map(|&i| i as u32).collect(),
                solid,
                kdop,
            });
        }
        // the model's checked body pairs as ball pairs, grouped by link pair
        let mut by_pair: BTreeMap<(usize, usize), LinkPairTests> = BTreeMap::new();
        for p in model.pairs() {
            let (a, b) = (p.a as usize, p.b as usize);
            let (list, body_pairs) = by_pair
                .entry((group_of_body[a], group_of_body[b]))
                .or_default();
            body_pairs.push((p.a, p.b));
            for x in balls_of_body[a].clone() {
                for y in balls_of_body[b].clone() {
                    let r = balls[x].radius + balls[y].radius;
                    list.push((x as u32, y as u32, r));
                }
            }
        }
        let (mut pairs, mut group_pairs) = (Vec::new(), Vec::new());
        for ((a, b), (mut list, bodies)) in by_pair {
            list.sort_by_key(|&(x, y, _)| (x, y));
            let mut runs: Vec<(u32, std::ops::Range<usize>)> = Vec::new();
            for pair in list {
                match runs.last_mut() {
                    Some((x, range)) if *x == pair.0 => range.end += 1,
                    _ => runs.push((pair.0, pairs.len()..pairs.len() + 1)),
                }
                pairs.push(pair);
            }
            let inner_pairs = bodies
                .iter()
                .flat_map(|&(x, y)| {
                    let (x, y) = (
                        inner_of_body[x as usize].clone(),
                        inner_of_body[y as usize].clone(),
                    );
                    x.flat_map(move |i| y.clone().map(move |j| (i, j)))
                })
                .map(|(i, j)| (i as u32, j as u32, inner[i].radius + inner[j].radius))
                .collect();
            // a box against every body of the other link: its spheres against the box
            let against = |s: usize, o: usize| {
                (groups[s].solid.is_some() && bodies.len() == groups[o].bodies.len())
                    .then_some((s, o))
            };
            let solid = against(a, b).or_else(|| against(b, a));
            group_pairs.push(GroupPair {
                a,
                b,
                runs,
                bodies,
                inner: inner_pairs,
                solid,
            });
        }
        // the walk: the culling steps of the exact model, each link pair's block one step
        let index: BTreeMap<(usize, usize), u32> = group_pairs
            .iter()
            .enumerate()
            .map(|(k, gp)| ((gp.a, gp.b), k as u32))
            .collect();
        let culling = model.culling();
        let cull_ball = |ball: crate::cull::Ball| match ball {
            crate::cull::Ball::Origin { slot, radius } => (groups.len() as u32 + slot, radius),
            crate::cull::Ball::Body(b) => {
                let g = group_of_body[b as usize];
                (g as u32, f64::from(groups[g].bound.radius))
            }
        };
        let culls = group_pairs.len() >= CULLED_LINK_PAIRS;
        let steps: Vec<CullStep> = if !culls {
            Vec::new()
        } else {
            culling
                .self_steps
                .iter()
                .map(|step| match *step {
                    crate::cull::Step::Cull { a, b, end } => {
                        let ((a, ra), (b, rb)) = (cull_ball(a), cull_ball(b));
                        CullStep::Cull {
                            a,
                            b,
                            reach: (ra + rb) as f32,
                            end,
                        }
                    }
                    // a block of one checked link pair: `by_pair` made its group pair
                    crate::cull::Step::Test { start, .. } => {
                        let p = model.pairs()[start as usize];
                        CullStep::Pair(
                            index[&(group_of_body[p.a as usize], group_of_body[p.b as usize])],
                        )
                    }
                })
                .collect()
        };
        // a block of one link's bodies: its group
        let world_steps = if !culls {
            Vec::new()
        } else {
            culling
                .world_steps
                .iter()
                .map(|step| match *step {
                    crate::cull::Step::Cull { a, end, .. } => {
                        let (ball, radius) = cull_ball(a);
                        WorldStep::Cull {
                            ball,
                            radius: radius as f32,
                            end,
                        }
                    }
                    crate::cull::Step::Test { start, .. } => {
                        WorldStep::Link(group_of_body[start as usize] as u32)
                    }
                })
                .collect()
        };
        let origins = if culls {
            culling.origin_links.clone()
        } else {
            Vec::new()
        };
        // reach: every joint offset and prismatic travel end to end, then the farthest sphere
        let chain: f64 = tree
            .joints
            .iter()
            .map(|j| {
                let travel = if j.kind == JointKind::Prismatic {
                    j.limits.lower.abs().max(j.limits.upper.abs())
                } else {
                    0.0
                };
                j.local_origin.translation.vector.norm() + travel
            })
            .sum();
        let farthest = balls
            .iter()
            .map(|b| norm(b.center) + f64::from(b.radius))
            .fold(0.0, f64::max);
        // joints are in tree order: a parent link's depth is known before its children's
        let mut depth_of = vec![0usize; tree.links.len()];
        for j in &tree.joints {
            depth_of[j.child] = depth_of[j.parent] + usize::from(j.kind != JointKind::Fixed);
        }
        Ok(FastModel {
            exact,
            depth: depth_of.into_iter().max().unwrap_or(0),
            balls,
            inner,
            bodies: ball_bodies,
            groups,
            group_pairs,
            pairs,
            steps,
            world_steps,
            culls,
            origins,
            reach: chain + farthest,
        })
    }

    /// `model` compiled by [`FastModel::new`] once and kept with it: later calls (from clones
    /// of `model` too) share that compilation, so that checkers made per query cost no
    /// compiling.
    pub fn of(model: &CollisionModel) -> Result<Arc<FastModel>> {
        let cell = model.fast_cell();
        if let Some(fast) = cell.get() {
            return Ok(fast.clone());
        }
        let fast = Arc::new(FastModel::new(model)?);
        Ok(cell.get_or_init(|| fast).clone())
    }

    /// Whether every body of `model` is a sphere: whether [`FastModel::new`] makes an exact
    /// model of it ([`FastModel::is_exact`]), known without compiling it.
    pub fn is_sphere_model(model: &CollisionModel) -> bool {
        model
            .bodies()
            .iter()
            .all(|b| matches!(b.shape, Shape::Sphere { .. }))
    }

    /// Whether the spheres are the model itself (every body a sphere): its certain contacts
    /// are certain collisions. Otherwise the spheres enclose the bodies and only screen.
    pub fn is_exact(&self) -> bool {
        self.exact
    }

    /// Number of spheres.
    pub fn num_spheres(&self) -> usize {
        self.balls.len()
    }

    /// Number of sphere pairs self-collision checks may test.
    pub fn num_pairs(&self) -> usize {
        self.pairs.len()
    }

    /// A scratch buffer for [`FastModel::check`].
    pub fn scratch(&self) -> FastScratch {
        FastScratch {
            balls: vec![[F::default(); 3]; self.balls.len()],
            inner: vec![[F::default(); 3]; self.inner.len()],
            bounds: vec![[F::default(); 3]; self.groups.len() + self.origins.len()],
            frames: vec![([F::default(); 9], [F::default(); 3]); self.groups.len()],
            placed: vec![false; self.groups.len()],
            suspects: Vec::with_capacity(self.group_pairs.len() + self.groups.len()),
            last_hit: None,
        }
    }

    /// `world` compiled for [`FastModel::check`], with its margin (see [`FastWorld::margin`]).
    pub fn world(&self, world: &World) -> FastWorld {
        let mut farthest: f64 = 0.0;
        let objects: Vec<Object> = world
            .objects()
            .iter()
            .map(|o| {
                let pose = o.pose();
                let bounds = o.bounding_box();
                let (mins, maxs) = (bounds.mins, bounds.maxs);
                farthest = farthest.max(mins.coords.amax()).max(maxs.coords.amax());
                let t = pose.translation.vector;
                match o.shape() {
                    Shape::Sphere { radius } => Object::Round {
                        a: to_f32(t),
                        b: to_f32(t),
                        radius: *radius as f32,
                    },
                    Shape::Capsule { radius, length } => {
                        let half = pose.rotation * Vector3::new(0.0, 0.0, 0.5 * length);
                        Object::Round {
                            a: to_f32(t - half),
                            b: to_f32(t + half),
                            radius: *radius as f32,
                        }
                    }
                    Shape::Box { size } => Object::Box {
                        center: to_f32(t),
                        axes: inverse_axes(pose),
                        half: size.map(|s| (0.5 * s) as f32),
                    },
                    Shape::Cylinder { radius, length } => Object::Cylinder {
                        center: to_f32(t),
                        axes: inverse_axes(pose),
                        radius: *radius as f32,
                        half: (0.5 * length) as f32,
                    },
                    Shape::Convex { .. } => {
                        let c = bounds.center();
                        Object::Bounded {
                            center: to_f32(c.coords),
                            radius: (0.5 * (maxs - mins).norm()) as f32,
                        }
                    }
                }
            })
            .collect();
        // nearest the robot's root first (as VAMP sorts its environment): a block that collides
        // mostly collides there, and the walk stops at its first collision
        let mut order: Vec<u32> = (0..objects.len() as u32).collect();
        let reach_of = |o: &Object| {
            let (center, radius) = o.bounding_sphere();
            norm(center) - f64::from(radius)
        };
        order.sort_by(|&a, &b| {
            reach_of(&objects[a as usize]).total_cmp(&reach_of(&objects[b as usize]))
        });
        let mut compiled_of = vec![0; order.len()];
        for (k, &o) in order.iter().enumerate() {
            compiled_of[o as usize] = k as u32;
        }
        let objects = order.iter().map(|&o| objects[o as usize]).collect();
        let largest = self.reach.max(farthest);
        // placing and measuring, one more step where a sphere is taken into a box link's frame
        let solid = (self.groups.iter()).any(|g| g.solid.is_some() || g.kdop.is_some());
        let steps = self.depth + 2 + usize::from(solid);
        let margin = (MARGIN_PER_METRE_JOINT * (1.0 + largest) * steps as f64) as f32;
        FastWorld {
            objects,
            original: order,
            compiled_of,
            margin,
            limits: self
                .pairs
                .iter()
                .map(|&(_, _, r)| limits(r, margin))
                .collect(),
        }
    }

    /// The body of the collision model a sphere came from (spheres are ordered by link).
    pub fn body_of_sphere(&self, sphere: usize) -> usize {
        self.bodies[sphere]
    }

    /// Checks the configurations of a block against themselves and `world`: `poses` holds their
    /// link poses ([`PoseBlock::lanes`] of the collision model's robot), `live` the lanes in
    /// use. Stops at the first certain collision.
    ///
    /// # Panics
    /// If the poses or the scratch belong to another model.
    pub fn check(
        &self,
        poses: &[PoseLanes32],
        live: LaneMask,
        world: &FastWorld,
        scratch: &mut FastScratch,
    ) -> Verdict {
        screen::<Verdict>(self, poses, live, world, scratch)
    }

    /// Counts, in the configurations of a block (as [`FastModel::check`] takes them), the link
    /// pairs and (link, object) pairs that certainly collide; the pairs left uncertain are
    /// kept in `scratch` for an exact check ([`FastChecker::count_unchecked`] does both).
    ///
    /// # Panics
    /// If the poses or the scratch belong to another model.
    pub fn count(
        &self,
        poses: &[PoseLanes32],
        live: LaneMask,
        world: &FastWorld,
        scratch: &mut FastScratch,
    ) -> Tally {
        screen::<Tally>(self, poses, live, world, scratch)
    }
}

/// Exact collision checks, [`FAST_LANES`] configurations at a time: forward kinematics of a
/// block in `f32`, the [`FastModel`] screen, and for each lane it leaves uncertain the exact
/// `f64` check of the pairs that left it so. Its answers are the exact model's
/// ([`CollisionModel::is_colliding`]); only the work differs. Caller-owned: make one per thread.
#[derive(Debug, Clone)]
pub struct FastChecker {
    fast: Arc<FastModel>,
    collision: CollisionModel,
    active: ActiveSet,
    /// `FAST_LANES × dim` inputs (unused lanes repeat the first configuration).
    inputs: Vec<f64>,
    block: PoseBlock,
    scratch: FastScratch,
    pose: PoseBuffer,
    placed: PlacedBodies,
    /// Configurations the `f32` screen left uncertain so far (each then checked exactly).
    pub uncertain: u64,
}

impl FastChecker {
    /// A checker of `collision`'s robot moved by `active`'s coordinates; an error for an active
    /// set of another robot.
    pub fn new(collision: &CollisionModel, active: ActiveSet) -> Result<Self> {
        let fast = FastModel::of(collision)?;
        let robot = collision.robot();
        if active.model().num_frames() != robot.num_frames()
            || active.model().name() != robot.name()
        {
            return Err(CollisionError::InvalidValue {
                what: format!("active set of `{}`", active.model().name()),
                problem: format!("belongs to another robot than `{}`", robot.name()),
            });
        }
        // forward kinematics of the links the checks read only (bodies' links and the culling
        // spheres' centres), not of frames and links without geometry
        let links = (collision.bodies().iter().map(|b| b.link))
            .chain(fast.origins.iter().map(|&o| o as usize));
        let active = active.pruned_to(links);
        Ok(FastChecker {
            scratch: fast.scratch(),
            inputs: vec![0.0; FAST_LANES * active.len()],
            block: robot.pose_block(),
            pose: robot.pose_buffer(),
            placed: collision.placed_bodies(),
            fast,
            collision: collision.clone(),
            active,
            uncertain: 0,
        })
    }

    /// A checker and `world` compiled for it; `None` when the model cannot be compiled (a
    /// body without enclosing spheres: an invalid shape), for the `f64` path to answer.
    pub fn for_model(
        collision: &CollisionModel,
        active: &ActiveSet,
        world: &World,
    ) -> Option<(FastChecker, FastWorld)> {
        let checker = FastChecker::new(collision, active.clone()).ok()?;
        let fast_world = checker.model().world(world);
        Some((checker, fast_world))
    }

    /// The compiled model.
    pub fn model(&self) -> &FastModel {
        &self.fast
    }

    /// Coordinates per configuration.
    pub fn dim(&self) -> usize {
        self.active.len()
    }

    /// Whether every configuration of `qs` (1 to [`FAST_LANES`] of them, one after the other)
    /// is free of self-collisions and of `world` (`fast_world` is `world` compiled by
    /// [`FastModel::world`]): the exact model's answer. An error for a length that is not 1 to
    /// [`FAST_LANES`] whole configurations or a value that is not finite.
    pub fn all_free(&mut self, qs: &[f64], world: &World, fast_world: &FastWorld) -> Result<bool> {
        self.check_block(qs)?;
        Ok(self.all_free_unchecked(qs, world, fast_world))
    }

    /// The number of configurations in `qs` (1 to [`FAST_LANES`] whole configurations of
    /// finite values), or an error that says what is wrong.
    fn check_block(&self, qs: &[f64]) -> Result<usize> {
        let d = self.active.len();
        let n = qs.len() / d.max(1);
        if d == 0 || n == 0 || n > FAST_LANES || qs.len() != n * d {
            return Err(CollisionError::InvalidValue {
                what: format!("{} configuration values", qs.len()),
                problem: format!(
                    "are not 1 to {FAST_LANES} whole configurations of {d} active motors"
                ),
            });
        }
        if let Some(i) = qs.iter().position(|v| !v.is_finite()) {
            return Err(CollisionError::InvalidValue {
                what: format!("value {} of configuration {}", i % d, i / d),
                problem: format!("is {}, not a finite number", qs[i]),
            });
        }
        Ok(n)
    }

    /// [`FastChecker::all_free`] without its checks, for callers that made `qs` themselves:
    /// false for NaN; `qs` must hold 1 to [`FAST_LANES`] whole configurations (checked in debug
    /// builds; otherwise a wrong length gives a wrong answer or a panic, never unsafety).
    pub fn all_free_unchecked(
        &mut self,
        qs: &[f64],
        world: &World,
        fast_world: &FastWorld,
    ) -> bool {
        let d = self.active.len();
        let n = qs.len() / d.max(1);
        debug_assert!(
            d > 0 && n > 0 && n <= FAST_LANES && qs.len() == n * d,
            "1 to {FAST_LANES} whole configurations"
        );
        // every value looked at (a vector loop), not the first NaN searched for
        if qs.iter().fold(false, |nan, v| nan | v.is_nan()) {
            return false;
        }
        let live = self.forward_block(qs, n);
        let verdict = self
            .fast
            .check(self.block.lanes(), live, fast_world, &mut self.scratch);
        if verdict.colliding != 0 {
            return false;
        }
        // each uncertain lane: its suspects alone, exactly
        let FastChecker {
            fast,
            collision,
            active,
            scratch,
            pose,
            placed,
            uncertain,
            ..
        } = self;
        for l in (0..n).filter(|l| verdict.uncertain & (1 << l) != 0) {
            *uncertain += 1;
            active.forward_unchecked(&qs[l * d..(l + 1) * d], pose);
            for &(suspect, lanes) in &scratch.suspects {
                if lanes & (1 << l) != 0
                    && suspect_collides(fast, collision, pose, placed, world, suspect)
                {
                    return false;
                }
            }
        }
        true
    }

    /// The exact model's counts ([`CollisionModel::count_self`], [`CollisionModel::count_world`])
    /// of each configuration of `qs` (1 to [`FAST_LANES`] of them, one after the other) into
    /// `self_pairs` and `world_pairs`, as [`FastChecker::count_unchecked`] gives them. An error
    /// for a length that is not 1 to [`FAST_LANES`] whole configurations, a value that is not
    /// finite, or outputs shorter than the configurations.
    pub fn count(
        &mut self,
        qs: &[f64],
        world: &World,
        fast_world: &FastWorld,
        self_pairs: &mut [usize],
        world_pairs: &mut [usize],
    ) -> Result<()> {
        let n = self.check_block(qs)?;
        if self_pairs.len() < n || world_pairs.len() < n {
            return Err(CollisionError::InvalidValue {
                what: format!(
                    "outputs of {} and {} values",
                    self_pairs.len(),
                    world_pairs.len()
                ),
                problem: format!("hold fewer than the {n} configurations' counts"),
            });
        }
        self.count_unchecked(qs, world, fast_world, self_pairs, world_pairs);
        Ok(())
    }

    /// The exact model's counts ([`CollisionModel::count_self`], [`CollisionModel::count_world`])
    /// of each configuration of `qs` (1 to [`FAST_LANES`] of them, as
    /// [`FastChecker::all_free_unchecked`] takes them) into `self_pairs` and `world_pairs`: the
    /// pairs the screen finds certainly colliding ([`FastChecker::screen_counts_unchecked`]),
    /// and each pair it leaves uncertain checked exactly ([`FastChecker::exact_counts`], with
    /// the configuration's `f64` forward kinematics). `qs` must hold 1 to [`FAST_LANES`] whole
    /// configurations and the outputs one value per configuration (checked in debug builds).
    pub fn count_unchecked(
        &mut self,
        qs: &[f64],
        world: &World,
        fast_world: &FastWorld,
        self_pairs: &mut [usize],
        world_pairs: &mut [usize],
    ) {
        let d = self.active.len();
        debug_assert!(self_pairs.len() * d >= qs.len() && world_pairs.len() * d >= qs.len());
        let tally = self.screen_counts_unchecked(qs, fast_world);
        for (l, q) in qs.chunks_exact(d).enumerate() {
            if tally.uncertain & (1 << l) != 0 || q.iter().any(|v| !v.is_finite()) {
                self.active.forward_unchecked(q, &mut self.pose);
            }
            [self_pairs[l], world_pairs[l]] = self.counts_in(&tally, l, q, None, world);
        }
    }

    /// The screen's counts of the configurations of `qs` (as [`FastChecker::count_unchecked`]
    /// takes them): the pairs certainly colliding in each lane, and the lanes with pairs left
    /// uncertain, which stay in the checker for [`FastChecker::exact_counts`] until the next
    /// screen.
    pub fn screen_counts_unchecked(&mut self, qs: &[f64], fast_world: &FastWorld) -> Tally {
        let d = self.active.len();
        let n = qs.len() / d.max(1);
        debug_assert!(
            d > 0 && n > 0 && n <= FAST_LANES && qs.len() == n * d,
            "1 to {FAST_LANES} whole configurations"
        );
        let live = self.forward_block(qs, n);
        self.fast
            .count(self.block.lanes(), live, fast_world, &mut self.scratch)
    }

    /// The exact counts [link pairs, (link, object) pairs] of lane `l` of the last screen
    /// (`tally`, its configuration `q`): the screen's, plus each pair it left uncertain in that
    /// lane checked exactly in the link poses `pose` (read only then). A configuration with a
    /// value that is not finite is counted by the `f64` model alone.
    pub fn exact_counts(
        &mut self,
        tally: &Tally,
        l: usize,
        q: &[f64],
        pose: &PoseBuffer,
        world: &World,
    ) -> [usize; 2] {
        self.counts_in(tally, l, q, Some(pose), world)
    }

    /// [`FastChecker::exact_counts`] in `pose`, or in the checker's own pose buffer.
    fn counts_in(
        &mut self,
        tally: &Tally,
        l: usize,
        q: &[f64],
        pose: Option<&PoseBuffer>,
        world: &World,
    ) -> [usize; 2] {
        let FastChecker {
            fast,
            collision,
            placed,
            scratch,
            uncertain,
            pose: own,
            ..
        } = self;
        let pose = pose.unwrap_or(own);
        if q.iter().any(|v| !v.is_finite()) {
            collision.place(pose, placed);
            return [
                collision.count_self(placed),
                collision.count_world(placed, world),
            ];
        }
        let mut counts = [tally.self_pairs[l] as usize, tally.world_pairs[l] as usize];
        if tally.uncertain & (1 << l) != 0 {
            *uncertain += 1;
            for &(suspect, lanes) in &scratch.suspects {
                if lanes & (1 << l) != 0
                    && suspect_collides(fast, collision, pose, placed, world, suspect)
                {
                    counts[matches!(suspect, Suspect::Object { .. }) as usize] += 1;
                }
            }
        }
        counts
    }

    /// Forward kinematics (`f32`) of the `n` configurations of `qs` into the block, a partial
    /// block padded with its first configuration; the lanes in use.
    fn forward_block(&mut self, qs: &[f64], n: usize) -> LaneMask {
        let d = self.active.len();
        // a full block straight from the caller; a partial one padded with its first lane
        let inputs = if n == FAST_LANES {
            qs
        } else {
            self.inputs[..n * d].copy_from_slice(qs);
            for l in n..FAST_LANES {
                self.inputs.copy_within(..d, l * d);
            }
            &self.inputs
        };
        self.active.forward_block_unchecked(inputs, &mut self.block);
        if n == FAST_LANES {
            ALL_LANES
        } else {
            (1 << n) - 1
        }
    }
}

/// Whether `suspect` collides exactly (`f64`) in the configuration whose link poses are `pose`.
fn suspect_collides(
    fast: &FastModel,
    collision: &CollisionModel,
    pose: &PoseBuffer,
    placed: &mut PlacedBodies,
    world: &World,
    suspect: Suspect,
) -> bool {
    match suspect {
        Suspect::Pair(k) => fast.group_pairs[k as usize].bodies.iter().any(|&(a, b)| {
            let (a, b) = (a as usize, b as usize);
            collision.place_body(pose, a, placed);
            collision.place_body(pose, b, placed);
            collision.bodies_touch(placed, a, b)
        }),
        Suspect::Object { object, group } => fast.groups[group as usize].bodies.iter().any(|&b| {
            collision.place_body(pose, b as usize, placed);
            collision.body_touches_object(placed, b as usize, world, object as usize)
        }),
    }
}

/// [`FastModel::check`] and [`FastModel::count`], compiled for several instruction sets with the
/// best one chosen at run time.
#[allow(unsafe_code)] // multiversion's run-time CPU-feature dispatch
#[multiversion::multiversion(targets("x86_64+avx2+fma", "x86_64+avx", "aarch64+neon"))]
fn screen<O: Outcome + Default>(
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
fn walk<const AVX: bool, O: Outcome>(
    model: &FastModel,
    poses: &[PoseLanes32],
    live: LaneMask,
    world: &FastWorld,
    scratch: &mut FastScratch,
    verdict: &mut O,
) {
    place::<AVX>(model, poses, scratch);
    scratch.suspects.clear();
    if O::STOPS_AT_FIRST && last_hit_again::<AVX, O>(model, live, world, scratch, verdict) {
        return;
    }
    let m = world.margin;
    // the world first: in a planner's queries most collisions are with the world, and the
    // objects nearest the robot first. A model of few links: link by link, the links last in
    // the tree first (the hand and the forearm sweep the most space: most collisions are
    // theirs), each link's bounding sphere against each object, then its spheres. A model of
    // many links: each object against the culling spheres of the kinematic tree's subtrees
    // first
    if !model.culls {
        for g in (0..model.groups.len()).rev() {
            for (&o, object) in world.original.iter().zip(&world.objects) {
                let o = o as usize;
                if object_link::<AVX>(model, o, object, g, live, world, scratch, verdict) {
                    return;
                }
            }
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
                        if object_link::<AVX>(model, o, object, g, mask, world, scratch, verdict) {
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
        for (k, gp) in model.group_pairs.iter().enumerate() {
            if link_pair::<AVX>(model, gp, k, live, world, scratch, verdict) {
                return;
            }
        }
        clear_suspects::<AVX, _>(model, scratch, m, verdict);
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
            CullStep::Pair(k) => {
                let gp = &model.group_pairs[k as usize];
                if link_pair::<AVX>(model, gp, k as usize, mask, world, scratch, verdict) {
                    return;
                }
            }
        }
        i += 1;
    }
    clear_suspects::<AVX, _>(model, scratch, m, verdict);
}

/// Whether the pair the last stopped walk stopped at (when there is one, and its object is in
/// `world`) certainly collides in a lane of `live`: then `verdict` says so and the walk may
/// end. Otherwise `verdict` and the suspects are left as they were (the walk tests the pair
/// again in its turn).
#[inline(always)]
fn last_hit_again<const AVX: bool, O: Outcome>(
    model: &FastModel,
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
                object_link::<AVX>(
                    model,
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
            link_pair::<AVX>(model, gp, k as usize, live, world, scratch, verdict)
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
/// beyond a slab of the other's k-DOP (when both are convex hulls): a second, tighter screen
/// that only a block left uncertain pays for, before its lanes are checked exactly.
#[inline(always)]
fn clear_suspects<const AVX: bool, O: Outcome>(
    model: &FastModel,
    scratch: &mut FastScratch,
    m: f32,
    verdict: &mut O,
) {
    if verdict.settled() || *verdict.uncertain() == 0 || model.exact {
        return;
    }
    let mut suspects = std::mem::take(&mut scratch.suspects);
    let uncertain = verdict.uncertain();
    *uncertain = 0;
    for (suspect, lanes) in &mut suspects {
        if let Suspect::Pair(k) = *suspect {
            let gp = &model.group_pairs[k as usize];
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

/// Checks world object `o` against link group `g` in the lanes of `live`: the link's bounding
/// sphere, then its spheres (and the spheres inside its bodies). True when a lane certainly
/// collides (then `verdict` says which); lanes left uncertain are added to `verdict` and the
/// suspects.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn object_link<const AVX: bool>(
    model: &FastModel,
    o: usize,
    object: &Object,
    g: usize,
    live: LaneMask,
    world: &FastWorld,
    scratch: &mut FastScratch,
    verdict: &mut impl Outcome,
) -> bool {
    let (m, group) = (world.margin, &model.groups[g]);
    let near = live & object.near::<AVX>(&scratch.bounds[g], group.bound.radius + m);
    if near == 0 {
        return false;
    }
    place_balls::<AVX>(model, g, scratch);
    let mut contact = Contact::default();
    for i in group.balls.clone() {
        object.test::<AVX>(&mut contact, &scratch.balls[i], model.balls[i].radius, m);
    }
    let (mut hit, close) = (contact.hit.mask::<AVX>(), contact.close.mask::<AVX>());
    if !model.exact {
        // enclosing spheres only say "maybe"; a sphere inside a body says "certainly"
        let mut inside = Contact::default();
        if near & close != 0 {
            for i in group.inner.clone() {
                let r = model.inner[i].radius;
                object.test::<AVX>(&mut inside, &scratch.inner[i], r, m);
            }
        }
        hit = inside.hit.mask::<AVX>();
    }
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

/// Checks link pair `gp` (index `k` in [`FastModel::group_pairs`]) in the lanes of `live`:
/// bounding spheres, then a box against the other link's spheres or the two links' spheres.
/// True when a lane certainly collides (then `verdict` says which); lanes left uncertain are
/// added to `verdict` and the suspects.
#[inline(always)]
fn link_pair<const AVX: bool>(
    model: &FastModel,
    gp: &GroupPair,
    k: usize,
    live: LaneMask,
    world: &FastWorld,
    scratch: &mut FastScratch,
    verdict: &mut impl Outcome,
) -> bool {
    let m = world.margin;
    let (ga, gb) = (&model.groups[gp.a], &model.groups[gp.b]);
    let reach = ga.bound.radius + gb.bound.radius + m;
    let near = live
        & distance2(&scratch.bounds[gp.a], &scratch.bounds[gp.b])
            .within(reach * reach)
            .mask::<AVX>();
    if near == 0 {
        return false;
    }
    let (hit, close) = if let Some((s, o)) = gp.solid {
        // the other link's spheres in the box link's frame, against the box itself
        place_balls::<AVX>(model, o, scratch);
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
        place_balls::<AVX>(model, gp.a, scratch);
        place_balls::<AVX>(model, gp.b, scratch);
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

/// Fewest link pairs for which the self-collision walk takes the culling spheres: with fewer,
/// testing every link pair's bounding spheres in order is faster (measured: the Panda, 1.12×,
/// and the Fetch, 1.11×, slower with culls; the iCub's 958 link pairs 1.3× faster with them).
const CULLED_LINK_PAIRS: usize = 256;

/// The lanes in which link pair `gp`'s spheres certainly collide, and those in which they come
/// within the margin `m` of contact (or NaN): each sphere of link a against link b's bounding
/// sphere, then b's spheres. Without a branch per pair: flags or-ed together, turned into lane
/// masks once.
#[inline(always)]
fn pair_contacts<const AVX: bool>(
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
    let bound_b = model.groups[gp.b].bound.radius;
    let mut contact = Contact::default();
    for (a, run) in &gp.runs {
        let ball = &balls[*a as usize];
        let reach = model.balls[*a as usize].radius + bound_b + m;
        if !distance2(ball, &bounds[gp.b]).any_within::<PORTABLE>(reach * reach) {
            continue;
        }
        let pairs = model.pairs[run.clone()]
            .iter()
            .zip(&world.limits[run.clone()]);
        for (&(_, b, _), &limits) in pairs {
            contact.add_within(distance2(ball, &balls[b as usize]), limits);
        }
    }
    (
        contact.hit.mask::<PORTABLE>(),
        contact.close.mask::<PORTABLE>(),
    )
}

/// The lanes in which every sphere of link group `a` lies beyond a slab of group `b`'s k-DOP
/// (with the margin `m`): there `a`'s bodies are clear of `b`'s. None without `b`'s k-DOP.
#[inline(always)]
fn kdop_clear<const AVX: bool>(
    model: &FastModel,
    a: usize,
    b: usize,
    scratch: &FastScratch,
    m: f32,
) -> LaneMask {
    let Some(kdop) = &model.groups[b].kdop else {
        return 0;
    };
    #[cfg(target_arch = "x86_64")]
    if AVX {
        // SAFETY: as in `F::any_within`
        #[allow(unsafe_code)]
        return unsafe { avx::kdop_clear(model, a, kdop, &scratch.frames[b], scratch, m) };
    }
    let frame = &scratch.frames[b];
    let mut clear = ALL_LANES;
    for i in model.groups[a].balls.clone() {
        let c = inverse_transform(frame, &scratch.balls[i]);
        let r = model.balls[i].radius + m;
        let mut beyond = Flags::default();
        for (n, &[lo, hi]) in KDOP.iter().zip(kdop) {
            let s = c[0] * F::splat(n[0]) + c[1] * F::splat(n[1]) + c[2] * F::splat(n[2]);
            let scale = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
            beyond = beyond | s.above(hi + r * scale) | s.below(lo - r * scale);
        }
        clear &= beyond.mask::<PORTABLE>();
        if clear == 0 {
            break;
        }
    }
    clear
}

/// The k-DOP of `bodies` in their link's frame when all are convex hulls.
fn kdop_of<'a>(
    bodies: impl Iterator<Item = &'a crate::model::Body>,
) -> Option<[[f32; 2]; KDOP.len()]> {
    let mut slabs = [[f32::INFINITY, f32::NEG_INFINITY]; KDOP.len()];
    for body in bodies {
        let Shape::Convex { points } = &body.shape else {
            return None;
        };
        for p in points {
            let p = body.local * Point3::from(*p);
            for (n, slab) in KDOP.iter().zip(&mut slabs) {
                let s = f64::from(n[0]) * p.x + f64::from(n[1]) * p.y + f64::from(n[2]) * p.z;
                // rounded outwards: the slab holds every point
                slab[0] = slab[0].min((s as f32).next_down());
                slab[1] = slab[1].max((s as f32).next_up());
            }
        }
    }
    slabs.iter().all(|s| s[0] <= s[1]).then_some(slabs)
}

/// The squared distances below which two spheres whose radii sum to `r` certainly collide,
/// and beyond which they are certainly clear, with the margin `m`.
#[inline(always)]
fn limits(r: f32, m: f32) -> [f32; 2] {
    let (inner, outer) = ((r - m).max(0.0), r + m);
    [inner * inner, outer * outer]
}

/// Lane flags of a group of pairs: certainly colliding, or within the margin of contact (or
/// NaN).
#[derive(Debug, Clone, Copy, Default)]
struct Contact {
    hit: Flags,
    close: Flags,
}

impl Contact {
    /// Adds a pair at squared distance `d2` whose radii sum to `r`.
    #[inline(always)]
    fn add(&mut self, d2: F, r: f32, m: f32) {
        self.add_within(d2, limits(r, m));
    }

    /// Adds a pair at squared distance `d2` whose [`limits`] are `[inner2, outer2]`.
    #[inline(always)]
    fn add_within(&mut self, d2: F, [inner2, outer2]: [f32; 2]) {
        self.hit = self.hit | d2.below(inner2);
        self.close = self.close | d2.within(outer2);
    }

    /// Flags certainly uncertain in every lane (a shape seen through its bounding sphere).
    #[inline(always)]
    fn add_uncertain(&mut self, d2: F, reach: f32) {
        self.close = self.close | d2.within(reach * reach);
    }
}

/// What the screen's walk makes of each group of pairs' contacts: a [`Verdict`] (stops at the
/// first certain collision) or a [`Tally`] (counts every colliding pair).
trait Outcome {
    /// Whether the walk ends at the first certain collision (then the pair the last walk
    /// ended at is tested first).
    const STOPS_AT_FIRST: bool;
    /// Adds the contacts of a group of pairs in the lanes of `lanes`: `hit`, the lanes certainly
    /// colliding (for bodies screened through enclosing spheres, those touching a sphere inside
    /// them), and `close`, those within the margin of contact. `None` when the walk may stop,
    /// else the lanes the group left uncertain.
    fn add(&mut self, lanes: LaneMask, hit: LaneMask, close: LaneMask) -> Option<LaneMask>;
    /// The world's objects are done; link pairs follow.
    fn enter_self(&mut self) {}
    /// Whether the outcome is known without the uncertain lanes.
    fn settled(&self) -> bool;
    /// The lanes left uncertain.
    fn uncertain(&mut self) -> &mut LaneMask;
}

impl Outcome for Verdict {
    const STOPS_AT_FIRST: bool = true;
    #[inline(always)]
    fn add(&mut self, lanes: LaneMask, hit: LaneMask, close: LaneMask) -> Option<LaneMask> {
        let hit = lanes & hit;
        if hit != 0 {
            self.colliding |= hit;
            return None;
        }
        let uncertain = lanes & close;
        self.uncertain |= uncertain;
        Some(uncertain)
    }
    fn settled(&self) -> bool {
        self.colliding != 0
    }
    fn uncertain(&mut self) -> &mut LaneMask {
        &mut self.uncertain
    }
}

impl Outcome for Tally {
    const STOPS_AT_FIRST: bool = false;
    #[inline(always)]
    fn add(&mut self, lanes: LaneMask, hit: LaneMask, close: LaneMask) -> Option<LaneMask> {
        let hit = lanes & hit;
        let counts = if self.counting_self {
            &mut self.self_pairs
        } else {
            &mut self.world_pairs
        };
        let mut bits = hit;
        while bits != 0 {
            counts[bits.trailing_zeros() as usize] += 1;
            bits &= bits - 1;
        }
        let uncertain = lanes & close & !hit;
        self.uncertain |= uncertain;
        Some(uncertain)
    }
    fn enter_self(&mut self) {
        self.counting_self = true;
    }
    fn settled(&self) -> bool {
        false
    }
    fn uncertain(&mut self) -> &mut LaneMask {
        &mut self.uncertain
    }
}

impl Object {
    /// Centre and radius of a sphere around the object.
    fn bounding_sphere(&self) -> ([f32; 3], f32) {
        match *self {
            Object::Round { a, b, radius } => {
                let center = std::array::from_fn(|k| 0.5 * (a[k] + b[k]));
                let half = std::array::from_fn(|k| 0.5 * (b[k] - a[k]));
                (center, norm(half) as f32 + radius)
            }
            Object::Box { center, half, .. } => (center, norm(half) as f32),
            Object::Cylinder {
                center,
                radius,
                half,
                ..
            } => (center, radius.hypot(half)),
            Object::Bounded { center, radius } => (center, radius),
        }
    }

    /// The reach of a sphere of radius `r` from the object's own geometry: the sum of the radii
    /// for round objects (and a bounded object's sphere), `r` for the others.
    #[inline(always)]
    fn reach(&self, r: f32) -> f32 {
        match *self {
            Object::Round { radius, .. } | Object::Bounded { radius, .. } => r + radius,
            Object::Box { .. } | Object::Cylinder { .. } => r,
        }
    }

    /// Squared distance from the point in every lane to the object's geometry (the segment of
    /// a round object, the centre of a bounded one; 0 inside).
    #[inline(always)]
    fn distance2(&self, c: &[F; 3]) -> F {
        match *self {
            Object::Round { a, b, .. } => segment_distance2(c, a, b),
            Object::Box { center, axes, half } => box_distance2(c, center, &axes, half),
            Object::Cylinder {
                center,
                axes,
                radius,
                half,
            } => cylinder_distance2(c, center, &axes, radius, half),
            Object::Bounded { center, .. } => distance2(c, &splat(center)),
        }
    }

    /// Lanes whose sphere at `c` of radius `r` may come within reach of the object (its
    /// bounding sphere for [`Object::Bounded`]).
    #[inline(always)]
    fn near<const AVX: bool>(&self, c: &[F; 3], r: f32) -> LaneMask {
        let reach = self.reach(r);
        #[cfg(target_arch = "x86_64")]
        if AVX {
            // SAFETY: as in `F::any_within`
            #[allow(unsafe_code)]
            return unsafe { avx::near(self, c, reach * reach) };
        }
        self.distance2(c).within(reach * reach).mask::<PORTABLE>()
    }

    /// Adds the sphere at `c` of radius `r` against the object.
    #[inline(always)]
    fn test<const AVX: bool>(&self, contact: &mut Contact, c: &[F; 3], r: f32, m: f32) {
        let reach = self.reach(r);
        #[cfg(target_arch = "x86_64")]
        if AVX {
            // SAFETY: as in `F::any_within`
            #[allow(unsafe_code)]
            return unsafe { avx::test(self, contact, c, reach, m) };
        }
        let d2 = self.distance2(c);
        match self {
            Object::Bounded { .. } => contact.add_uncertain(d2, reach + m),
            _ => contact.add(d2, reach, m),
        }
    }
}

/// The frame and bounding-sphere centre of every link group in every lane; balls are placed
/// later, for the groups that come near something ([`place_balls`]).
#[inline(always)]
fn place<const AVX: bool>(model: &FastModel, poses: &[PoseLanes32], scratch: &mut FastScratch) {
    // the culling spheres' centres: their links' origins
    let groups = model.groups.len();
    for (s, &frame) in model.origins.iter().enumerate() {
        let p = &poses[frame as usize];
        scratch.bounds[groups + s] = [F(p[4]), F(p[5]), F(p[6])];
    }
    #[cfg(target_arch = "x86_64")]
    if AVX {
        // SAFETY: as in `F::any_within`
        #[allow(unsafe_code)]
        return unsafe { avx::place(model, poses, scratch) };
    }
    for (g, group) in model.groups.iter().enumerate() {
        let (rot, t) = link_frame(poses, group.frame);
        scratch.bounds[g] = transform(&rot, &t, group.bound.center);
        scratch.frames[g] = (rot, t);
        scratch.placed[g] = false;
    }
}

/// The centres of group `g`'s balls in every lane, placed once per block.
#[inline(always)]
fn place_balls<const AVX: bool>(model: &FastModel, g: usize, scratch: &mut FastScratch) {
    if scratch.placed[g] {
        return;
    }
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

/// Rotation matrix (row-major) and translation of link `frame` in every lane, in `f32`.
#[inline(always)]
fn link_frame(poses: &[PoseLanes32], frame: usize) -> ([F; 9], [F; 3]) {
    let p = &poses[frame];
    let q = [
        F(p[0]),
        F(p[1]),
        F(p[2]),
        F(p[3]),
        F(p[4]),
        F(p[5]),
        F(p[6]),
    ];
    let [w, x, y, z, tx, ty, tz] = q;
    let two = F::splat(2.0);
    let one = F::splat(1.0);
    let (xx, yy, zz) = (x * x, y * y, z * z);
    let (xy, xz, yz) = (x * y, x * z, y * z);
    let (wx, wy, wz) = (w * x, w * y, w * z);
    let r = [
        one - two * (yy + zz),
        two * (xy - wz),
        two * (xz + wy),
        two * (xy + wz),
        one - two * (xx + zz),
        two * (yz - wx),
        two * (xz - wy),
        two * (yz + wx),
        one - two * (xx + yy),
    ];
    (r, [tx, ty, tz])
}

/// `rot · p + t` in every lane.
#[inline(always)]
fn transform(rot: &[F; 9], t: &[F; 3], p: [f32; 3]) -> [F; 3] {
    // no array::from_fn or array::map in the hot path: their closures may stay calls, compiled
    // without the vector instruction set this function is compiled for
    let (x, y, z) = (F::splat(p[0]), F::splat(p[1]), F::splat(p[2]));
    [
        rot[0] * x + rot[1] * y + rot[2] * z + t[0],
        rot[3] * x + rot[4] * y + rot[5] * z + t[1],
        rot[6] * x + rot[7] * y + rot[8] * z + t[2],
    ]
}

/// The point in every lane in the frame `(rot, t)` (row-major rotation and translation in
/// every lane, as [`link_frame`] gives them) maps to the world: `rotᵀ (p − t)`.
#[inline(always)]
fn inverse_transform((rot, t): &([F; 9], [F; 3]), p: &[F; 3]) -> [F; 3] {
    let (x, y, z) = (p[0] - t[0], p[1] - t[1], p[2] - t[2]);
    [
        rot[0] * x + rot[3] * y + rot[6] * z,
        rot[1] * x + rot[4] * y + rot[7] * z,
        rot[2] * x + rot[5] * y + rot[8] * z,
    ]
}

/// Squared distance between two points in every lane.
#[inline(always)]
fn distance2(a: &[F; 3], b: &[F; 3]) -> F {
    let (dx, dy, dz) = (a[0] - b[0], a[1] - b[1], a[2] - b[2]);
    dx * dx + dy * dy + dz * dz
}

/// The point in every lane relative to `origin`, in the frame whose axes are the rows of `axes`.
#[inline(always)]
fn local(c: &[F; 3], origin: [f32; 3], axes: &[[f32; 3]; 3]) -> [F; 3] {
    let p = [
        c[0] - F::splat(origin[0]),
        c[1] - F::splat(origin[1]),
        c[2] - F::splat(origin[2]),
    ];
    let along =
        |a: &[f32; 3]| p[0] * F::splat(a[0]) + p[1] * F::splat(a[1]) + p[2] * F::splat(a[2]);
    [along(&axes[0]), along(&axes[1]), along(&axes[2])]
}

/// Squared distance from the point in every lane to the segment a–b.
#[inline(always)]
fn segment_distance2(c: &[F; 3], a: [f32; 3], b: [f32; 3]) -> F {
    let ab = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
    let len2 = ab[0] * ab[0] + ab[1] * ab[1] + ab[2] * ab[2];
    let inv = F::splat(if len2 > 0.0 { 1.0 / len2 } else { 0.0 });
    let p = [
        c[0] - F::splat(a[0]),
        c[1] - F::splat(a[1]),
        c[2] - F::splat(a[2]),
    ];
    let ab = [F::splat(ab[0]), F::splat(ab[1]), F::splat(ab[2])];
    let s = ((p[0] * ab[0] + p[1] * ab[1] + p[2] * ab[2]) * inv).map(|s| s.clamp(0.0, 1.0));
    let d = [p[0] - s * ab[0], p[1] - s * ab[1], p[2] - s * ab[2]];
    d[0] * d[0] + d[1] * d[1] + d[2] * d[2]
}

/// Squared distance from the point in every lane to the box (0 inside).
#[inline(always)]
fn box_distance2(c: &[F; 3], center: [f32; 3], axes: &[[f32; 3]; 3], half: [f32; 3]) -> F {
    let p = local(c, center, axes);
    let out = |k: usize| p[k].map(|v| (v.abs() - half[k]).max(0.0));
    let (x, y, z) = (out(0), out(1), out(2));
    x * x + y * y + z * z
}

/// Squared distance from the point in every lane to the solid cylinder along the z axis of
/// `axes` (0 inside).
#[inline(always)]
fn cylinder_distance2(
    c: &[F; 3],
    center: [f32; 3],
    axes: &[[f32; 3]; 3],
    radius: f32,
    half: f32,
) -> F {
    let [x, y, z] = local(c, center, axes);
    let radial = (x * x + y * y).map(|v| (v.sqrt() - radius).max(0.0));
    let axial = z.map(|v| (v.abs() - half).max(0.0));
    radial * radial + axial * axial
}

/// The rows of the transposed rotation of `pose` (world → object frame), in `f32`.
fn inverse_axes(pose: &nalgebra::Isometry3<f64>) -> [[f32; 3]; 3] {
    let m = pose.rotation.to_rotation_matrix();
    let m = m.matrix();
    std::array::from_fn(|r| to_f32(Vector3::new(m[(0, r)], m[(1, r)], m[(2, r)])))
}

/// The same point in every lane.
fn splat(p: [f32; 3]) -> [F; 3] {
    [F::splat(p[0]), F::splat(p[1]), F::splat(p[2])]
}

fn to_f32(v: Vector3<f64>) -> [f32; 3] {
    [v.x as f32, v.y as f32, v.z as f32]
}

fn norm(v: [f32; 3]) -> f64 {
    Vector3::new(f64::from(v[0]), f64::from(v[1]), f64::from(v[2])).norm()
}

/// A sphere enclosing the spheres (centre: the middle of their bounding box), rounded up so
/// that it still encloses them in `f32`.
fn bounding_ball(spheres: &[(Point3<f64>, f64)]) -> Ball {
    let mut lo = Vector3::repeat(f64::INFINITY);
    let mut hi = Vector3::repeat(f64::NEG_INFINITY);
    for (c, r) in spheres {
        lo = lo.inf(&(c.coords - Vector3::repeat(*r)));
        hi = hi.sup(&(c.coords + Vector3::repeat(*r)));
    }
    let center = (lo + hi) / 2.0;
    let radius = spheres
        .iter()
        .map(|(c, r)| (c.coords - center).norm() + r)
        .fold(0.0, f64::max);
    Ball {
        center: to_f32(center),
        radius: (radius * (1.0 + 1e-6) + 1e-7) as f32,
    }
}

#[cfg(all(test, target_arch = "x86_64"))]
mod tests {
    use super::*;
    use rand::{RngExt, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// The written-out AVX distances ([`avx`]) are the portable ones up to rounding, for every
    /// kind of object, points inside and outside (where the CPU has AVX2 and FMA).
    #[test]
    fn avx_distances_are_the_portable_ones() {
        if !(is_x86_feature_detected!("avx2") && is_x86_feature_detected!("fma")) {
            return;
        }
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        let mut v = || rng.random_range(-0.5f32..0.5);
        let pose =
            nalgebra::Isometry3::new(Vector3::new(0.1, -0.2, 0.3), Vector3::new(0.4, -0.7, 1.1));
        let axes = inverse_axes(&pose);
        let center = to_f32(pose.translation.vector);
        let objects = [
            Object::Round {
                a: [0.1, 0.0, -0.1],
                b: [0.1, 0.0, -0.1],
                radius: 0.05,
            },
            Object::Round {
                a: [-0.2, 0.1, 0.0],
                b: [0.2, -0.1, 0.1],
                radius: 0.05,
            },
            Object::Box {
                center,
                axes,
                half: [0.2, 0.1, 0.05],
            },
            Object::Cylinder {
                center,
                axes,
                radius: 0.1,
                half: 0.2,
            },
            Object::Bounded {
                center,
                radius: 0.3,
            },
        ];
        for object in &objects {
            for _ in 0..200 {
                let c = [0; 3].map(|_| F(std::array::from_fn(|_| v())));
                let want = object.distance2(&c);
                // SAFETY: the CPU has AVX2 and FMA (checked above)
                #[allow(unsafe_code)]
                let got: [f32; FAST_LANES] = unsafe {
                    std::mem::transmute::<std::arch::x86_64::__m256, [f32; FAST_LANES]>(
                        avx::distance2(object, &c),
                    )
                };
                for l in 0..FAST_LANES {
                    let (w, g) = (want.0[l], got[l]);
                    assert!((w - g).abs() <= 1e-6 * (1.0 + w), "{object:?}: {w} vs {g}");
                }
                let (r, m) = (0.05, 1e-3);
                let reach = object.reach(r);
                // SAFETY: as above
                #[allow(unsafe_code)]
                let (near, contact) = unsafe {
                    let mut contact = Contact::default();
                    avx::test(object, &mut contact, &c, reach, m);
                    (avx::near(object, &c, reach * reach), contact)
                };
                let mut portable = Contact::default();
                object.test::<false>(&mut portable, &c, r, m);
                for l in 0..FAST_LANES {
                    // lanes at the limits within rounding may go either way
                    let w = want.0[l];
                    let at = |limit: f32| (w - limit * limit).abs() <= 1e-6;
                    if !at(reach) {
                        assert_eq!(near >> l & 1 == 1, w <= reach * reach, "{object:?}");
                    }
                    if !at(reach + m) && !at((reach - m).max(0.0)) {
                        assert_eq!(contact.close.0[l], portable.close.0[l], "{object:?}");
                        assert_eq!(contact.hit.0[l], portable.hit.0[l], "{object:?}");
                    }
                }
            }
        }
    }

    /// The written-out AVX pair tests give the portable ones' lane masks, on the spherized
    /// Panda's link pairs in random blocks of configurations.
    #[test]
    fn avx_pair_contacts_are_the_portable_ones() {
        if !(is_x86_feature_detected!("avx2") && is_x86_feature_detected!("fma")) {
            return;
        }
        let file = concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../models/panda-mbm/panda_spherized.ron"
        );
        let robot = trm_kinematics::RobotModel::load(file).unwrap();
        let model = FastModel::new(&CollisionModel::new(&robot).unwrap()).unwrap();
        let active = robot.all_active();
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        let (mut block, mut scratch) = (robot.pose_block(), model.scratch());
        let world = model.world(&World::new());
        let mut contacts = 0;
        for _ in 0..200 {
            let qs: Vec<f64> = (0..FAST_LANES)
                .flat_map(|_| active.random(&mut rng))
                .collect();
            active.forward_block_unchecked(&qs, &mut block);
            place::<false>(&model, block.lanes(), &mut scratch);
            for gp in &model.group_pairs {
                place_balls::<false>(&model, gp.a, &mut scratch);
                place_balls::<false>(&model, gp.b, &mut scratch);
                let avx = pair_contacts::<true>(&model, gp, &scratch, &world);
                assert_eq!(avx, pair_contacts::<false>(&model, gp, &scratch, &world));
                contacts += usize::from(avx.0 != 0);
            }
        }
        assert!(
            contacts > 100,
            "{contacts} pairs in contact: the test saw too few"
        );
    }

    /// The k-DOP screen: every hull point lies within each link's slabs, and a sphere it
    /// clears is clear of the hulls, as GJK finds; the AVX code clears the same lanes.
    #[test]
    fn kdop_slabs_hold_the_hulls_and_clear_only_what_is_clear() {
        let file = concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../models/panda-mbm/panda.ron"
        );
        let robot = trm_kinematics::RobotModel::load(file).unwrap();
        let collision = CollisionModel::new(&robot).unwrap();
        let model = FastModel::new(&collision).unwrap();
        for group in &model.groups {
            let kdop = group.kdop.expect("every Panda link is a hull");
            for &b in &group.bodies {
                let body = &collision.bodies()[b as usize];
                let Shape::Convex { points } = &body.shape else {
                    panic!("a hull")
                };
                for p in points {
                    let p = body.local * Point3::from(*p);
                    for (n, &[lo, hi]) in KDOP.iter().zip(&kdop) {
                        let s =
                            f64::from(n[0]) * p.x + f64::from(n[1]) * p.y + f64::from(n[2]) * p.z;
                        assert!(
                            f64::from(lo) <= s && s <= f64::from(hi),
                            "{s} not in [{lo}, {hi}]"
                        );
                    }
                }
            }
        }
        let active = robot.all_active();
        let mut rng = ChaCha8Rng::seed_from_u64(9);
        let (mut block, mut scratch) = (robot.pose_block(), model.scratch());
        let (mut pose, mut placed) = (robot.pose_buffer(), collision.placed_bodies());
        let world = model.world(&World::new());
        let avx = is_x86_feature_detected!("avx2") && is_x86_feature_detected!("fma");
        let (mut cleared, mut close) = (0, 0);
        for _ in 0..100 {
            let qs: Vec<f64> = (0..FAST_LANES)
                .flat_map(|_| active.random(&mut rng))
                .collect();
            active.forward_block_unchecked(&qs, &mut block);
            place::<false>(&model, block.lanes(), &mut scratch);
            for gp in &model.group_pairs {
                place_balls::<false>(&model, gp.a, &mut scratch);
                place_balls::<false>(&model, gp.b, &mut scratch);
                let (_, near) = pair_contacts::<false>(&model, gp, &scratch, &world);
                let m = world.margin;
                let clear = kdop_clear::<false>(&model, gp.a, gp.b, &scratch, m);
                if avx {
                    assert_eq!(clear, kdop_clear::<true>(&model, gp.a, gp.b, &scratch, m));
                }
                close += near.count_ones();
                for l in 0..FAST_LANES {
                    if clear & near & (1 << l) == 0 {
                        continue;
                    }
                    cleared += 1;
                    let q = &qs[l * active.len()..(l + 1) * active.len()];
                    active.forward(q, &mut pose).unwrap();
                    collision.place(&pose, &mut placed);
                    for &(a, b) in &gp.bodies {
                        assert!(!collision.bodies_touch(&placed, a as usize, b as usize));
                    }
                }
            }
        }
        assert!(
            cleared > 10 && cleared < close,
            "{cleared} of {close} close lanes cleared"
        );
    }
}
