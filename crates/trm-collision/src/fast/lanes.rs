#[cfg(target_arch = "x86_64")]
use super::avx;
use super::{FAST_LANES, LaneMask};
use nalgebra::Vector3;
use trm_kinematics::PoseLanes32;

/// One `f32` per configuration of a block, aligned for one 8-wide register. Its operations are
/// element-wise loops, which the compiler turns into single vector instructions.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
#[repr(C, align(32))]
pub(super) struct F(pub(super) [f32; FAST_LANES]);

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
lane_wise!(Div, div, /);

impl F {
    /// `x` in every lane.
    #[inline(always)]
    pub(super) fn splat(x: f32) -> F {
        F([x; FAST_LANES])
    }

    /// `f` of every lane.
    #[inline(always)]
    pub(super) fn map(self, f: impl Fn(f32) -> f32) -> F {
        let mut out = self.0;
        for v in &mut out {
            *v = f(*v);
        }
        F(out)
    }

    /// The lanes ≤ `limit` or NaN (NaN is never certainly clear).
    #[inline(always)]
    pub(super) fn within(self, limit: f32) -> Flags {
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
    pub(super) fn any_within<const AVX: bool>(self, limit: f32) -> bool {
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
    pub(super) fn below(self, limit: f32) -> Flags {
        let mut flags = [0; FAST_LANES];
        for l in 0..FAST_LANES {
            flags[l] = u32::from(self.0[l] < limit);
        }
        Flags(flags)
    }

    /// The lanes outside `[low, high)`, or NaN.
    #[inline(always)]
    pub(super) fn outside(self, low: f32, high: f32) -> Flags {
        let mut flags = [0; FAST_LANES];
        for l in 0..FAST_LANES {
            flags[l] = u32::from(!(self.0[l] >= low && self.0[l] < high));
        }
        Flags(flags)
    }

    /// The lanes > `limit`.
    #[inline(always)]
    pub(super) fn above(self, limit: f32) -> Flags {
        let mut flags = [0; FAST_LANES];
        for l in 0..FAST_LANES {
            flags[l] = u32::from(self.0[l] > limit);
        }
        Flags(flags)
    }
}

/// `fn name<const AVX: bool>(args) -> ret`, calling `body::<AVX>(args)` compiled once for AVX2
/// and FMA (when `AVX`) and once portably, each out of line. For kernels too large to inline
/// into every clone of the screen at every call site: that made this crate's build take ten
/// times longer. Costs one call.
macro_rules! compiled_per_isa {
    ($(#[$doc:meta])* $name:ident => $body:ident($($arg:ident: $ty:ty),* $(,)?) -> $ret:ty) => {
        $(#[$doc])*
        #[inline(always)]
        pub(super) fn $name<const AVX: bool>($($arg: $ty),*) -> $ret {
            #[cfg(target_arch = "x86_64")]
            if AVX {
                #[target_feature(enable = "avx2,fma")]
                fn avx2($($arg: $ty),*) -> $ret {
                    $body::<true>($($arg),*)
                }
                // SAFETY: as in `F::any_within`
                #[allow(unsafe_code)]
                return unsafe { avx2($($arg),*) };
            }
            #[inline(never)]
            fn portable($($arg: $ty),*) -> $ret {
                $body::<false>($($arg),*)
            }
            portable($($arg),*)
        }
    };
}
pub(super) use compiled_per_isa;

/// [`Flags::mask`]'s lane-by-lane form: the world's tests keep it, as they vectorise worse
/// around the AVX one (measured: 0.40 → 0.60 ms median on the MBM Panda with mesh hulls).
pub(super) const PORTABLE: bool = false;

/// One flag (0 or 1) per lane, or-ed together without branches and turned into a
/// [`LaneMask`] once per group of pairs.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
#[repr(C, align(32))]
pub(super) struct Flags(pub(super) [u32; FAST_LANES]);

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
    pub(super) fn mask<const AVX: bool>(self) -> LaneMask {
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

/// The rotation (row-major) of unit quaternion `w, x, y, z` in every lane.
#[inline(always)]
pub(super) fn rotation(w: F, x: F, y: F, z: F) -> [F; 9] {
    let two = F::splat(2.0);
    let one = F::splat(1.0);
    let (xx, yy, zz) = (x * x, y * y, z * z);
    let (xy, xz, yz) = (x * y, x * z, y * z);
    let (wx, wy, wz) = (w * x, w * y, w * z);
    [
        one - two * (yy + zz),
        two * (xy - wz),
        two * (xz + wy),
        two * (xy + wz),
        one - two * (xx + zz),
        two * (yz - wx),
        two * (xz - wy),
        two * (yz + wx),
        one - two * (xx + yy),
    ]
}

/// Point `c` of a link's frame in the world, in every lane of the link's pose `p` (quaternion
/// `w, x, y, z`, translation): `t + c + w·u + q×u` with `u = 2 q×c`.
#[inline(always)]
pub(super) fn pose_point(p: &PoseLanes32, c: [f32; 3]) -> [F; 3] {
    let (w, x, y, z) = (F(p[0]), F(p[1]), F(p[2]), F(p[3]));
    let (tx, ty, tz) = (F(p[4]), F(p[5]), F(p[6]));
    let (cx, cy, cz) = (F::splat(c[0]), F::splat(c[1]), F::splat(c[2]));
    let two = F::splat(2.0);
    let (ux, uy, uz) = (
        two * (y * cz - z * cy),
        two * (z * cx - x * cz),
        two * (x * cy - y * cx),
    );
    [
        tx + cx + w * ux + (y * uz - z * uy),
        ty + cy + w * uy + (z * ux - x * uz),
        tz + cz + w * uz + (x * uy - y * ux),
    ]
}

/// `rot · p + t` in every lane.
#[inline(always)]
pub(super) fn transform(rot: &[F; 9], t: &[F; 3], p: [f32; 3]) -> [F; 3] {
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
pub(super) fn inverse_transform((rot, t): &([F; 9], [F; 3]), p: &[F; 3]) -> [F; 3] {
    let (x, y, z) = (p[0] - t[0], p[1] - t[1], p[2] - t[2]);
    [
        rot[0] * x + rot[3] * y + rot[6] * z,
        rot[1] * x + rot[4] * y + rot[7] * z,
        rot[2] * x + rot[5] * y + rot[8] * z,
    ]
}

/// Squared distance between two points in every lane.
#[inline(always)]
pub(super) fn distance2(a: &[F; 3], b: &[F; 3]) -> F {
    let (dx, dy, dz) = (a[0] - b[0], a[1] - b[1], a[2] - b[2]);
    dx * dx + dy * dy + dz * dz
}

/// The point in every lane relative to `origin`, in the frame whose axes are the rows of `axes`.
#[inline(always)]
pub(super) fn local(c: &[F; 3], origin: [f32; 3], axes: &[[f32; 3]; 3]) -> [F; 3] {
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
pub(super) fn segment_distance2(c: &[F; 3], a: [f32; 3], b: [f32; 3]) -> F {
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
pub(super) fn box_distance2(
    c: &[F; 3],
    center: [f32; 3],
    axes: &[[f32; 3]; 3],
    half: [f32; 3],
) -> F {
    let p = local(c, center, axes);
    let out = |k: usize| p[k].map(|v| (v.abs() - half[k]).max(0.0));
    let (x, y, z) = (out(0), out(1), out(2));
    x * x + y * y + z * z
}

/// Squared distance from the point in every lane to the box of half sizes `half` about
/// `center` along the world's axes (0 inside).
#[inline(always)]
pub(super) fn aligned_box_distance2(c: &[F; 3], center: [f32; 3], half: [f32; 3]) -> F {
    let out = |k: usize| c[k].map(|v| ((v - center[k]).abs() - half[k]).max(0.0));
    let (x, y, z) = (out(0), out(1), out(2));
    x * x + y * y + z * z
}

/// Squared distance from the point in every lane to the solid cylinder along the z axis of
/// `axes` (0 inside).
#[inline(always)]
pub(super) fn cylinder_distance2(
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
pub(super) fn inverse_axes(pose: &nalgebra::Isometry3<f64>) -> [[f32; 3]; 3] {
    let m = pose.rotation.to_rotation_matrix();
    let m = m.matrix();
    std::array::from_fn(|r| to_f32(Vector3::new(m[(0, r)], m[(1, r)], m[(2, r)])))
}

/// The same point in every lane.
pub(super) fn splat(p: [f32; 3]) -> [F; 3] {
    [F::splat(p[0]), F::splat(p[1]), F::splat(p[2])]
}

pub(super) fn to_f32(v: Vector3<f64>) -> [f32; 3] {
    [v.x as f32, v.y as f32, v.z as f32]
}

pub(super) fn norm(v: [f32; 3]) -> f64 {
    Vector3::new(f64::from(v[0]), f64::from(v[1]), f64::from(v[2])).norm()
}
