//! Forward kinematics of [`LANES`] configurations at once.
//!
//! The compiled FK [`Plan`](crate::fk) runs once over structure-of-arrays data: every number of
//! a pose is an array of one value per configuration (`[f64; LANES]`), so each arithmetic step
//! processes all lanes in one vector instruction (4 × f64 with AVX2, selected at run time; 2 × f64
//! with SSE2 or NEON). Sine and cosine are a vectorised polynomial ([`sin_cos`]), accurate to a
//! few units in the last place. The poses equal the one-configuration path's to ≤ 1e-12.

use nalgebra::{Isometry3, Quaternion, Translation3, UnitQuaternion};

use crate::fk::{FrameId, Plan, PoseBuffer, StepConstants, affine};

/// Configurations per batch.
pub const LANES: usize = 4;

/// One number in every lane.
pub type Lanes = [f64; LANES];

/// A pose in every lane: quaternion `w, i, j, k` then translation `x, y, z`, each one value per
/// lane.
pub type PoseLanes = [Lanes; 7];

/// Caller-owned scratch for batched forward kinematics (made by
/// [`RobotModel::pose_batch`](crate::RobotModel::pose_batch)): the world pose of every link and
/// named frame in each of [`LANES`] configurations. Reuse it: batched FK does not allocate.
#[derive(Debug, Clone)]
pub struct PoseBatch {
    slots: Vec<[Lanes; 3]>,
    poses: Vec<PoseLanes>,
}

impl PoseBatch {
    pub(crate) fn new(num_joints: usize, num_frames: usize) -> Self {
        PoseBatch {
            slots: vec![[[0.0; LANES], [1.0; LANES], [0.0; LANES]]; num_joints + 1],
            poses: vec![IDENTITY; num_frames],
        }
    }

    /// Whether the batch was made for a model with these many joints and frames.
    pub fn fits(&self, num_joints: usize, num_frames: usize) -> bool {
        self.poses.len() == num_frames && self.slots.len() == num_joints + 1
    }

    /// Number of poses per lane (links and named frames).
    pub fn len(&self) -> usize {
        self.poses.len()
    }

    /// Whether the batch holds no pose.
    pub fn is_empty(&self) -> bool {
        self.poses.is_empty()
    }

    /// World pose of a link or named frame in configuration `lane` (< [`LANES`]).
    #[inline]
    pub fn pose(&self, lane: usize, frame: FrameId) -> Isometry3<f64> {
        lane_pose(&self.poses[frame.index()], lane)
    }

    /// Every pose (links, then named frames, as [`PoseBuffer::poses`] orders them) in every lane:
    /// the structure-of-arrays form batched consumers (collision placement, costs) read.
    #[inline]
    pub fn lanes(&self) -> &[PoseLanes] {
        &self.poses
    }

    /// Copies the poses of configuration `lane` (< [`LANES`]) into a one-configuration buffer
    /// of the same model, so everything written for [`PoseBuffer`] (costs, collision placement)
    /// runs on it. No allocation.
    ///
    /// # Panics
    /// If the buffer belongs to another model (another number of links and frames).
    pub fn lane_into(&self, lane: usize, out: &mut PoseBuffer) {
        assert_eq!(
            out.poses.len(),
            self.poses.len(),
            "pose buffer of another model"
        );
        for (p, o) in self.poses.iter().zip(out.poses.iter_mut()) {
            *o = lane_pose(p, lane);
        }
    }

    /// World position of a link or named frame in every lane: `[x, y, z]`, each one value per
    /// lane.
    #[inline]
    pub fn positions(&self, frame: FrameId) -> [Lanes; 3] {
        let p = &self.poses[frame.index()];
        [p[4], p[5], p[6]]
    }
}

/// The pose of configuration `lane` (< [`LANES`]) out of a pose in every lane.
#[inline]
pub fn lane_pose(p: &PoseLanes, lane: usize) -> Isometry3<f64> {
    Isometry3::from_parts(
        Translation3::new(p[4][lane], p[5][lane], p[6][lane]),
        UnitQuaternion::new_unchecked(Quaternion::new(
            p[0][lane], p[1][lane], p[2][lane], p[3][lane],
        )),
    )
}

const IDENTITY: PoseLanes = [
    [1.0; LANES],
    [0.0; LANES],
    [0.0; LANES],
    [0.0; LANES],
    [0.0; LANES],
    [0.0; LANES],
    [0.0; LANES],
];

impl Plan {
    /// Runs the pass on [`LANES`] inputs: lane `l`'s input is `inputs[l * stride..][..stride]`.
    /// Lengths must have been checked.
    #[inline]
    pub(crate) fn run_batch(&self, inputs: &[f64], stride: usize, batch: &mut PoseBatch) {
        run_batch(self, inputs, stride, batch);
    }
}

/// [`Plan::run_batch`], compiled for several instruction sets with the best one chosen at run
/// time.
#[allow(unsafe_code)] // multiversion's run-time CPU-feature dispatch
#[multiversion::multiversion(targets("x86_64+avx2+fma", "x86_64+avx", "aarch64+neon"))]
fn run_batch(plan: &Plan, inputs: &[f64], stride: usize, batch: &mut PoseBatch) {
    let slots = &mut batch.slots[..plan.rows.len()];
    for ((out, &(constant, start, end)), &revolute) in
        slots.iter_mut().zip(&plan.rows).zip(&plan.revolute)
    {
        let terms = &plan.terms[start as usize..end as usize];
        let v: Lanes =
            std::array::from_fn(|l| affine(constant, terms, &inputs[l * stride..(l + 1) * stride]));
        *out = if revolute {
            let (s, c) = sin_cos(v);
            [s, c, [0.0; LANES]]
        } else {
            [[0.0; LANES], [1.0; LANES], v]
        };
    }
    run_steps(plan, &batch.slots, &mut batch.poses);
}

/// The float types batched forward kinematics runs in: `f64` ([`PoseBatch`]) and `f32`
/// ([`PoseBlock`]).
pub(crate) trait Real:
    Copy + std::ops::Add<Output = Self> + std::ops::Sub<Output = Self> + std::ops::Mul<Output = Self>
{
    const ZERO: Self;
    const ONE: Self;
    const TWO: Self;
    /// The constants of step `k` of `plan` in this type.
    fn step(plan: &Plan, k: usize) -> StepConstants<Self>;
}

impl Real for f64 {
    const ZERO: f64 = 0.0;
    const ONE: f64 = 1.0;
    const TWO: f64 = 2.0;
    #[inline(always)]
    fn step(plan: &Plan, k: usize) -> StepConstants<f64> {
        let step = &plan.steps[k];
        let (r, b) = (&step.rotation, &step.axis_quat);
        let (t, a) = (&step.translation, &step.axis_in_parent);
        StepConstants {
            rotation: [r.w, r.i, r.j, r.k],
            axis_quat: [b.w, b.i, b.j, b.k],
            translation: [t.x, t.y, t.z],
            axis_in_parent: [a.x, a.y, a.z],
        }
    }
}

impl Real for f32 {
    const ZERO: f32 = 0.0;
    const ONE: f32 = 1.0;
    const TWO: f32 = 2.0;
    #[inline(always)]
    fn step(plan: &Plan, k: usize) -> StepConstants<f32> {
        plan.steps32[k]
    }
}

/// The steps of `plan` over slot values `[sin, cos, displacement]` per lane: the world pose
/// (quaternion `w, i, j, k`, translation `x, y, z`) of every link and frame in every lane.
#[inline(always)]
fn run_steps<T: Real, const L: usize>(
    plan: &Plan,
    slots: &[[[T; L]; 3]],
    poses: &mut [[[T; L]; 7]],
) {
    let identity = {
        let mut p = [[T::ZERO; L]; 7];
        p[0] = [T::ONE; L];
        p
    };
    poses[0] = identity;
    for (k, step) in plan.steps.iter().enumerate() {
        let parent = poses[step.parent as usize];
        let [s, c, d] = slots[step.slot as usize];
        let constants = T::step(plan, k);
        let [rw, ri, rj, rk] = constants.rotation;
        let [bw, bi, bj, bk] = constants.axis_quat;
        let [tx0, ty0, tz0] = constants.translation;
        let [ax, ay, az] = constants.axis_in_parent;
        let mut child = identity;
        for l in 0..L {
            // local rotation c·r + s·b, local translation t + d·axis
            let lw = c[l] * rw + s[l] * bw;
            let li = c[l] * ri + s[l] * bi;
            let lj = c[l] * rj + s[l] * bj;
            let lk = c[l] * rk + s[l] * bk;
            let tx = tx0 + ax * d[l];
            let ty = ty0 + ay * d[l];
            let tz = tz0 + az * d[l];
            let (w, x, y, z) = (parent[0][l], parent[1][l], parent[2][l], parent[3][l]);
            // parent rotation applied to the local translation: v + w·u + q×u, u = 2 q×v
            let ux = T::TWO * (y * tz - z * ty);
            let uy = T::TWO * (z * tx - x * tz);
            let uz = T::TWO * (x * ty - y * tx);
            child[4][l] = parent[4][l] + tx + w * ux + (y * uz - z * uy);
            child[5][l] = parent[5][l] + ty + w * uy + (z * ux - x * uz);
            child[6][l] = parent[6][l] + tz + w * uz + (x * uy - y * ux);
            child[0][l] = w * lw - x * li - y * lj - z * lk;
            child[1][l] = w * li + x * lw + y * lk - z * lj;
            child[2][l] = w * lj - x * lk + y * lw + z * li;
            child[3][l] = w * lk + x * lj - y * li + z * lw;
        }
        poses[step.child as usize] = child;
    }
}

/// Configurations per single-precision block.
pub const BLOCK_LANES: usize = 2 * LANES;

/// A pose in every lane of a block, in `f32`: quaternion `w, i, j, k` then translation
/// `x, y, z`.
pub type PoseLanes32 = [[f32; BLOCK_LANES]; 7];

/// Caller-owned scratch for single-precision forward kinematics of [`BLOCK_LANES`]
/// configurations at once (made by [`RobotModel::pose_block`](crate::RobotModel::pose_block)):
/// for consumers that do not need double precision, such as collision screens with a stated
/// rounding margin. Joint values and the reduction of their half angles to [-π/4, π/4] are
/// computed in `f64`, sines and cosines in `f32` (`sin_cos_block`, within 2⁻²³); the chain is
/// composed in `f32` (each step adds a few units of 2⁻²⁴ of relative error).
#[derive(Debug, Clone)]
pub struct PoseBlock {
    /// The inputs transposed: per input value, its lanes.
    inputs: Vec<[f64; BLOCK_LANES]>,
    slots: Vec<[[f32; BLOCK_LANES]; 3]>,
    poses: Vec<PoseLanes32>,
}

impl PoseBlock {
    /// A block for passes of at most `num_inputs` input values.
    pub(crate) fn new(num_inputs: usize, num_joints: usize, num_frames: usize) -> Self {
        PoseBlock {
            inputs: vec![[0.0; BLOCK_LANES]; num_inputs],
            slots: vec![
                [[0.0; BLOCK_LANES], [1.0; BLOCK_LANES], [0.0; BLOCK_LANES]];
                num_joints + 1
            ],
            poses: vec![[[0.0; BLOCK_LANES]; 7]; num_frames],
        }
    }

    /// Whether the block was made for a model with these many joints and frames.
    pub fn fits(&self, num_joints: usize, num_frames: usize) -> bool {
        self.poses.len() == num_frames && self.slots.len() == num_joints + 1
    }

    /// Every pose (links, then named frames, as [`PoseBuffer::poses`] orders them) in every
    /// lane.
    #[inline]
    pub fn lanes(&self) -> &[PoseLanes32] {
        &self.poses
    }
}

impl Plan {
    /// Runs the pass in `f32` on [`BLOCK_LANES`] inputs: lane `l`'s input is
    /// `inputs[l * stride..][..stride]`. Lengths must have been checked.
    #[inline]
    pub(crate) fn run_block(&self, inputs: &[f64], stride: usize, block: &mut PoseBlock) {
        run_block(self, inputs, stride, block);
    }
}

/// `out[k][l] = inputs[l * out.len() + k]`: [`BLOCK_LANES`] inputs of `out.len()` values
/// each, transposed.
#[inline(always)]
fn transpose(inputs: &[f64], out: &mut [[f64; BLOCK_LANES]]) {
    let stride = out.len();
    for (l, input) in inputs.chunks_exact(stride).take(BLOCK_LANES).enumerate() {
        for (lanes, &v) in out.iter_mut().zip(input) {
            lanes[l] = v;
        }
    }
}

/// [`Plan::run_block`], compiled for several instruction sets with the best one chosen at run
/// time.
#[allow(unsafe_code)] // multiversion's run-time CPU-feature dispatch
#[multiversion::multiversion(targets("x86_64+avx2+fma", "x86_64+avx", "aarch64+neon"))]
fn run_block(plan: &Plan, inputs: &[f64], stride: usize, block: &mut PoseBlock) {
    // the AVX paths need AVX2 and FMA: the plain-AVX clone goes without them
    const AVX: bool = multiversion::target::selected_target!().supports_feature_str("avx2")
        && multiversion::target::selected_target!().supports_feature_str("fma");
    // the inputs transposed once (each value's lanes side by side), so that every slot's
    // affine map is a few vector multiply-adds instead of a scalar sum per lane
    let lanes = &mut block.inputs[..stride];
    let inputs = &inputs[..BLOCK_LANES * stride];
    #[cfg(target_arch = "x86_64")]
    if AVX {
        // SAFETY: as below
        #[allow(unsafe_code)]
        unsafe {
            avx::transpose(inputs, lanes)
        };
    } else {
        transpose(inputs, lanes);
    }
    #[cfg(not(target_arch = "x86_64"))]
    transpose(inputs, lanes);
    let slots = &mut block.slots[..plan.rows.len()];
    for ((out, &(constant, start, end)), &revolute) in
        slots.iter_mut().zip(&plan.rows).zip(&plan.revolute)
    {
        let mut v = [constant; BLOCK_LANES];
        for &(k, f) in &plan.terms[start as usize..end as usize] {
            let x = &block.inputs[k];
            for l in 0..BLOCK_LANES {
                v[l] += f * x[l];
            }
        }
        if revolute {
            #[cfg(target_arch = "x86_64")]
            let (s, c) = if AVX {
                // SAFETY: as below
                #[allow(unsafe_code)]
                unsafe {
                    avx::sin_cos_block(&v)
                }
            } else {
                sin_cos_block(v)
            };
            #[cfg(not(target_arch = "x86_64"))]
            let (s, c) = sin_cos_block(v);
            out[0] = s;
            out[1] = c;
            out[2] = [0.0; BLOCK_LANES];
        } else {
            for l in 0..BLOCK_LANES {
                out[0][l] = 0.0;
                out[1][l] = 1.0;
                out[2][l] = v[l] as f32;
            }
        }
    }
    #[cfg(target_arch = "x86_64")]
    if AVX {
        // SAFETY: `AVX` is true only in this function's clone compiled for AVX2 and FMA, which
        // runs only where the CPU has them (multiversion's run-time dispatch)
        #[allow(unsafe_code)]
        return unsafe { avx::run_steps(plan, &block.slots, &mut block.poses) };
    }
    run_steps(plan, &block.slots, &mut block.poses);
}

/// The steps of a single-precision block written out in AVX2: the compiler vectorises
/// [`run_steps`]' lane loops over `[f32; 8]` arrays into shuffled 4-wide pieces.
#[cfg(target_arch = "x86_64")]
#[allow(unsafe_code)]
mod avx {
    use super::{BLOCK_LANES, C32, PIO2_1, PIO2_2, PIO2_3, Plan, PoseLanes32, S32};
    use std::arch::x86_64::*;

    const _: () = assert!(BLOCK_LANES == 8, "one 8-lane AVX register per block");

    /// [`super::transpose`] in 4 × 4 tiles: four values of four inputs loaded, transposed in
    /// registers and stored as four values' lanes.
    #[target_feature(enable = "avx2,fma")]
    pub(super) fn transpose(inputs: &[f64], out: &mut [[f64; BLOCK_LANES]]) {
        let stride = out.len();
        assert!(inputs.len() >= BLOCK_LANES * stride);
        let tiles = stride / 4 * 4;
        for k in (0..tiles).step_by(4) {
            for l0 in [0, 4] {
                // SAFETY: lane `l0 + i`'s values `k..k + 4` lie within `inputs` (asserted
                // above, `k + 4 <= stride`); `out[k + j]` has eight lanes
                unsafe {
                    let row =
                        |i: usize| _mm256_loadu_pd(inputs.as_ptr().add((l0 + i) * stride + k));
                    let (r0, r1, r2, r3) = (row(0), row(1), row(2), row(3));
                    let (t0, t1) = (_mm256_unpacklo_pd(r0, r1), _mm256_unpackhi_pd(r0, r1));
                    let (t2, t3) = (_mm256_unpacklo_pd(r2, r3), _mm256_unpackhi_pd(r2, r3));
                    let columns = [
                        _mm256_permute2f128_pd::<0x20>(t0, t2),
                        _mm256_permute2f128_pd::<0x20>(t1, t3),
                        _mm256_permute2f128_pd::<0x31>(t0, t2),
                        _mm256_permute2f128_pd::<0x31>(t1, t3),
                    ];
                    for (j, c) in columns.into_iter().enumerate() {
                        _mm256_storeu_pd(out[k + j].as_mut_ptr().add(l0), c);
                    }
                }
            }
        }
        for k in tiles..stride {
            for l in 0..BLOCK_LANES {
                out[k][l] = inputs[l * stride + k];
            }
        }
    }

    /// Eight lanes as one register.
    #[target_feature(enable = "avx")]
    #[inline]
    fn load(v: &[f32; BLOCK_LANES]) -> __m256 {
        // SAFETY: eight `f32`
        unsafe { _mm256_loadu_ps(v.as_ptr()) }
    }

    /// One register into eight lanes.
    #[target_feature(enable = "avx")]
    #[inline]
    fn store(v: __m256, out: &mut [f32; BLOCK_LANES]) {
        // SAFETY: eight `f32`
        unsafe { _mm256_storeu_ps(out.as_mut_ptr(), v) }
    }

    /// [`super::sin_cos_block`] written out: the reduction in two `f64` registers, the
    /// polynomials and the quadrant's signs in one `f32` register.
    #[target_feature(enable = "avx2,fma")]
    pub(super) fn sin_cos_block(
        x: &[f64; BLOCK_LANES],
    ) -> ([f32; BLOCK_LANES], [f32; BLOCK_LANES]) {
        let reduce = |v: __m256d| {
            let k = _mm256_round_pd::<{ _MM_FROUND_TO_NEAREST_INT | _MM_FROUND_NO_EXC }>(
                _mm256_mul_pd(v, _mm256_set1_pd(std::f64::consts::FRAC_2_PI)),
            );
            let r = _mm256_fnmadd_pd(k, _mm256_set1_pd(PIO2_1), v);
            let r = _mm256_fnmadd_pd(k, _mm256_set1_pd(PIO2_2), r);
            let r = _mm256_fnmadd_pd(k, _mm256_set1_pd(PIO2_3), r);
            (_mm256_cvtpd_ps(r), _mm256_cvtpd_epi32(k))
        };
        // SAFETY: eight `f64`, read as two registers of four
        let (lo, hi) = unsafe {
            (
                _mm256_loadu_pd(x.as_ptr()),
                _mm256_loadu_pd(x.as_ptr().add(4)),
            )
        };
        let ((r_lo, k_lo), (r_hi, k_hi)) = (reduce(lo), reduce(hi));
        let r = _mm256_set_m128(r_hi, r_lo);
        let q = _mm256_set_m128i(k_hi, k_lo);
        let z = _mm256_mul_ps(r, r);
        let set = _mm256_set1_ps;
        let ps = _mm256_fmadd_ps(z, _mm256_fmadd_ps(z, set(S32[2]), set(S32[1])), set(S32[0]));
        let sin = _mm256_fmadd_ps(_mm256_mul_ps(r, z), ps, r);
        let pc = _mm256_fmadd_ps(z, _mm256_fmadd_ps(z, set(C32[2]), set(C32[1])), set(C32[0]));
        let cos = _mm256_fmadd_ps(
            _mm256_mul_ps(z, z),
            pc,
            _mm256_fnmadd_ps(set(0.5), z, set(1.0)),
        );
        // quadrant k mod 4: odd swaps sine and cosine; bit 1 flips the sine's sign, bit 1 of
        // k + 1 the cosine's
        let odd = _mm256_castsi256_ps(_mm256_cmpeq_epi32(
            _mm256_and_si256(q, _mm256_set1_epi32(1)),
            _mm256_set1_epi32(1),
        ));
        let (a, b) = (
            _mm256_blendv_ps(sin, cos, odd),
            _mm256_blendv_ps(cos, sin, odd),
        );
        let sign = |bits: __m256i| {
            _mm256_castsi256_ps(_mm256_slli_epi32::<30>(_mm256_and_si256(
                bits,
                _mm256_set1_epi32(2),
            )))
        };
        let sin = _mm256_xor_ps(a, sign(q));
        let cos = _mm256_xor_ps(b, sign(_mm256_add_epi32(q, _mm256_set1_epi32(1))));
        let (mut s, mut c) = ([0.0; BLOCK_LANES], [0.0; BLOCK_LANES]);
        store(sin, &mut s);
        store(cos, &mut c);
        (s, c)
    }

    /// [`super::run_steps`] for blocks of eight `f32` lanes (the same arithmetic, fused
    /// multiply-adds where they fit).
    #[target_feature(enable = "avx2,fma")]
    pub(super) fn run_steps(
        plan: &Plan,
        slots: &[[[f32; BLOCK_LANES]; 3]],
        poses: &mut [PoseLanes32],
    ) {
        let mut identity = [[0.0; BLOCK_LANES]; 7];
        identity[0] = [1.0; BLOCK_LANES];
        poses[0] = identity;
        let two = _mm256_set1_ps(2.0);
        for (step, k) in plan.steps.iter().zip(&plan.steps32) {
            let [s, c, d] = &slots[step.slot as usize];
            let (s, c, d) = (load(s), load(c), load(d));
            let p = &poses[step.parent as usize];
            let (w, x, y, z) = (load(&p[0]), load(&p[1]), load(&p[2]), load(&p[3]));
            let (px, py, pz) = (load(&p[4]), load(&p[5]), load(&p[6]));
            // local rotation c·r + s·b, local translation t + d·axis
            let local = |r: f32, b: f32| {
                _mm256_fmadd_ps(s, _mm256_set1_ps(b), _mm256_mul_ps(c, _mm256_set1_ps(r)))
            };
            let (r, b) = (k.rotation, k.axis_quat);
            let (lw, li, lj, lk) = (
                local(r[0], b[0]),
                local(r[1], b[1]),
                local(r[2], b[2]),
                local(r[3], b[3]),
            );
            let along = |t: f32, a: f32| _mm256_fmadd_ps(d, _mm256_set1_ps(a), _mm256_set1_ps(t));
            let (t, a) = (k.translation, k.axis_in_parent);
            // revolute joints and fixed transforms do not move along an axis
            let (tx, ty, tz) = if a == [0.0; 3] {
                let set = _mm256_set1_ps;
                (set(t[0]), set(t[1]), set(t[2]))
            } else {
                (along(t[0], a[0]), along(t[1], a[1]), along(t[2], a[2]))
            };
            // parent rotation applied to the local translation: v + w·u + q×u, u = 2 q×v
            let cross = |a: __m256, b: __m256, c: __m256, e: __m256| {
                _mm256_fmsub_ps(a, b, _mm256_mul_ps(c, e))
            };
            let ux = _mm256_mul_ps(two, cross(y, tz, z, ty));
            let uy = _mm256_mul_ps(two, cross(z, tx, x, tz));
            let uz = _mm256_mul_ps(two, cross(x, ty, y, tx));
            let moved = |p: __m256, t: __m256, u: __m256, q: __m256| {
                _mm256_add_ps(_mm256_add_ps(p, t), _mm256_fmadd_ps(w, u, q))
            };
            let child = &mut poses[step.child as usize];
            store(moved(px, tx, ux, cross(y, uz, z, uy)), &mut child[4]);
            store(moved(py, ty, uy, cross(z, ux, x, uz)), &mut child[5]);
            store(moved(pz, tz, uz, cross(x, uy, y, ux)), &mut child[6]);
            // parent rotation ⊗ local rotation, the signs in fused (negated) multiply-adds
            let (add, sub) = (_mm256_fmadd_ps, _mm256_fnmadd_ps);
            let w_times = |v: __m256| _mm256_mul_ps(w, v);
            let product = [
                sub(z, lk, sub(y, lj, sub(x, li, w_times(lw)))),
                sub(z, lj, add(y, lk, add(x, lw, w_times(li)))),
                add(z, li, add(y, lw, sub(x, lk, w_times(lj)))),
                add(z, lw, sub(y, li, add(x, lj, w_times(lk)))),
            ];
            for (k, v) in product.into_iter().enumerate() {
                store(v, &mut child[k]);
            }
        }
    }
}

// π/2 in three parts (the first two with trailing zero bits, so k·part is exact for the
// quadrant counts of joint angles), and the minimax polynomials of sin and cos on [-π/4, π/4]
// (the coefficients of fdlibm's kernels).
const PIO2_1: f64 = 1.570_796_326_734_125_6e0;
const PIO2_2: f64 = 6.077_100_506_303_966e-11;
const PIO2_3: f64 = 2.022_266_248_711_166_5e-21;
const S: [f64; 6] = [
    -1.666_666_666_666_663_2e-1,
    8.333_333_333_322_49e-3,
    -1.984_126_982_985_795e-4,
    2.755_731_370_707_006_8e-6,
    -2.505_076_025_340_686_3e-8,
    1.589_690_995_211_55e-10,
];
const C: [f64; 6] = [
    4.166_666_666_666_66e-2,
    -1.388_888_888_887_411e-3,
    2.480_158_728_947_673e-5,
    -2.755_731_435_139_066_3e-7,
    2.087_572_321_298_175e-9,
    -1.135_964_755_778_819_5e-11,
];

/// Sine and cosine of every lane, branch-free (one vector instruction stream for all lanes):
/// reduction to [-π/4, π/4] by the nearest multiple of π/2, then polynomials. Within 2e-16 of
/// the correctly rounded values for |x| ≤ 1e5; NaN and infinities give NaN.
#[inline(always)]
pub fn sin_cos(x: Lanes) -> (Lanes, Lanes) {
    let mut sin = [0.0; LANES];
    let mut cos = [0.0; LANES];
    for l in 0..LANES {
        let v = x[l];
        let k = (v * std::f64::consts::FRAC_2_PI).round();
        let r = ((v - k * PIO2_1) - k * PIO2_2) - k * PIO2_3;
        let z = r * r;
        let ps = S[0] + z * (S[1] + z * (S[2] + z * (S[3] + z * (S[4] + z * S[5]))));
        let pc = C[0] + z * (C[1] + z * (C[2] + z * (C[3] + z * (C[4] + z * C[5]))));
        let s = r + r * z * ps;
        let c = 1.0 - 0.5 * z + z * z * pc;
        // quadrant k mod 4 ∈ {0, 1, 2, 3}: (sin, cos) = (s, c), (c, -s), (-s, -c), (-c, s)
        let q = k - 4.0 * (0.25 * k).floor();
        let odd = q == 1.0 || q == 3.0;
        let (a, b) = if odd { (c, s) } else { (s, c) };
        sin[l] = if q >= 2.0 { -a } else { a };
        cos[l] = if q == 1.0 || q == 2.0 { -b } else { b };
    }
    (sin, cos)
}

// The minimax polynomials of sin and cos on [-π/4, π/4] in single precision (Cephes' sinf and
// cosf kernels): within 1 unit of 2⁻²⁴ there.
const S32: [f32; 3] = [-1.666_665_5e-1, 8.332_161e-3, -1.951_529_6e-4];
const C32: [f32; 3] = [4.166_664_6e-2, -1.388_731_6e-3, 2.443_315_7e-5];

/// Sine and cosine of every lane of a block, in `f32`: the reduction to [-π/4, π/4] in `f64`
/// (exact enough for any angle), the polynomials in `f32` on all lanes at once. Within 2⁻²³
/// (1.2e-7) of the true values (a unit or two of `f32` rounding, which [`PoseBlock`]'s users
/// budget for); NaN and infinities give NaN.
#[inline(always)]
pub fn sin_cos_block(x: [f64; BLOCK_LANES]) -> ([f32; BLOCK_LANES], [f32; BLOCK_LANES]) {
    let mut r = [0.0f32; BLOCK_LANES];
    let mut q = [0.0f32; BLOCK_LANES];
    for l in 0..BLOCK_LANES {
        let v = x[l];
        let k = (v * std::f64::consts::FRAC_2_PI).round();
        r[l] = (((v - k * PIO2_1) - k * PIO2_2) - k * PIO2_3) as f32;
        // quadrant k mod 4 ∈ {0, 1, 2, 3} (NaN stays NaN)
        q[l] = (k - 4.0 * (0.25 * k).floor()) as f32;
    }
    let mut sin = [0.0; BLOCK_LANES];
    let mut cos = [0.0; BLOCK_LANES];
    for l in 0..BLOCK_LANES {
        let (r, q) = (r[l], q[l]);
        let z = r * r;
        let s = r + r * z * (S32[0] + z * (S32[1] + z * S32[2]));
        let c = 1.0 - 0.5 * z + z * z * (C32[0] + z * (C32[1] + z * C32[2]));
        // (sin, cos) = (s, c), (c, -s), (-s, -c), (-c, s) by quadrant
        let odd = q == 1.0 || q == 3.0;
        let (a, b) = if odd { (c, s) } else { (s, c) };
        sin[l] = if q >= 2.0 { -a } else { a };
        cos[l] = if q == 1.0 || q == 2.0 { -b } else { b };
    }
    (sin, cos)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ulps(a: f64, b: f64) -> f64 {
        (a - b).abs() / f64::EPSILON.max(b.abs() * f64::EPSILON)
    }

    /// The AVX transposition (4 × 4 tiles and a scalar remainder) equals the plain one, for
    /// input lengths below, at and past a tile.
    #[cfg(target_arch = "x86_64")]
    #[test]
    fn tiled_transposition_equals_the_plain_one() {
        if !(is_x86_feature_detected!("avx2") && is_x86_feature_detected!("fma")) {
            return;
        }
        for stride in 1..14 {
            let inputs: Vec<f64> = (0..BLOCK_LANES * stride).map(|i| i as f64 * 0.5).collect();
            let mut plain = vec![[f64::NAN; BLOCK_LANES]; stride];
            let mut tiled = plain.clone();
            transpose(&inputs, &mut plain);
            // SAFETY: the CPU has AVX2 and FMA (checked above)
            #[allow(unsafe_code)]
            unsafe {
                avx::transpose(&inputs, &mut tiled)
            };
            assert_eq!(plain, tiled, "stride {stride}");
            assert_eq!(plain[stride - 1][BLOCK_LANES - 1], inputs[inputs.len() - 1]);
        }
    }

    #[test]
    fn block_sin_cos_is_within_two_f32_units_of_the_true_values() {
        let mut worst = 0.0f64;
        let mut x = -1e3;
        while x < 1e3 {
            let lanes: [f64; BLOCK_LANES] = std::array::from_fn(|l| x * (1.0 - 0.3 * l as f64));
            let (s, c) = sin_cos_block(lanes);
            for l in 0..BLOCK_LANES {
                let (es, ec) = lanes[l].sin_cos();
                worst = worst
                    .max((f64::from(s[l]) - es).abs())
                    .max((f64::from(c[l]) - ec).abs());
            }
            x += 0.0137;
        }
        assert!(worst < 1.2e-7, "{worst:e}");
        let mut special = [0.0; BLOCK_LANES];
        special[..3].copy_from_slice(&[f64::NAN, f64::INFINITY, f64::NEG_INFINITY]);
        let (s, c) = sin_cos_block(special);
        assert!(s[..3].iter().chain(&c[..3]).all(|v| v.is_nan()));
        assert_eq!((s[3], c[3]), (0.0, 1.0));
    }

    /// The written-out AVX sines and cosines are the portable ones up to a unit of rounding.
    #[cfg(target_arch = "x86_64")]
    #[test]
    fn avx_block_sin_cos_is_the_portable_one() {
        if !(is_x86_feature_detected!("avx2") && is_x86_feature_detected!("fma")) {
            return;
        }
        let mut x = -1e3;
        while x < 1e3 {
            let lanes: [f64; BLOCK_LANES] = std::array::from_fn(|l| x * (1.0 - 0.3 * l as f64));
            let (s, c) = sin_cos_block(lanes);
            // SAFETY: the CPU has AVX2 and FMA (checked above)
            #[allow(unsafe_code)]
            let (sa, ca) = unsafe { avx::sin_cos_block(&lanes) };
            for l in 0..BLOCK_LANES {
                assert!(
                    (s[l] - sa[l]).abs() <= 2e-7 && (c[l] - ca[l]).abs() <= 2e-7,
                    "{}",
                    lanes[l]
                );
            }
            x += 0.0137;
        }
        let mut special = [0.0; BLOCK_LANES];
        special[..3].copy_from_slice(&[f64::NAN, f64::INFINITY, f64::NEG_INFINITY]);
        // SAFETY: as above
        #[allow(unsafe_code)]
        let (s, c) = unsafe { avx::sin_cos_block(&special) };
        assert!(s[..3].iter().chain(&c[..3]).all(|v| v.is_nan()));
        assert_eq!((s[3], c[3]), (0.0, 1.0));
    }

    #[test]
    fn sin_cos_match_the_standard_library_to_a_few_ulps() {
        let mut worst = 0.0f64;
        let mut x = -1e3;
        while x < 1e3 {
            let lanes = [x, x + 1e-3, -x * 0.37, x * 1e-7];
            let (s, c) = sin_cos(lanes);
            for l in 0..LANES {
                let (es, ec) = lanes[l].sin_cos();
                // absolute error for values near 0, relative elsewhere
                worst = worst.max((s[l] - es).abs()).max((c[l] - ec).abs());
                assert!(ulps(s[l], es) < 4.0 && ulps(c[l], ec) < 4.0, "{}", lanes[l]);
            }
            x += 0.0137;
        }
        assert!(worst < 1e-15, "{worst:e}");
        let special = [
            0.0,
            -0.0,
            std::f64::consts::FRAC_PI_4,
            std::f64::consts::PI,
            1e5,
        ];
        for x in special {
            let (s, c) = sin_cos([x; LANES]);
            assert!(
                (s[0] - x.sin()).abs() < 1e-15 && (c[0] - x.cos()).abs() < 1e-15,
                "{x}"
            );
        }
        let (s, c) = sin_cos([f64::NAN, f64::INFINITY, f64::NEG_INFINITY, 0.0]);
        assert!(s[..3].iter().chain(&c[..3]).all(|v| v.is_nan()));
        assert_eq!((s[3], c[3]), (0.0, 1.0));
    }
}
