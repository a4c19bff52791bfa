//! Point clouds in the single-precision screen.
//!
//! The points are sorted into a uniform grid (a counting sort: one pass to count, one to
//! place), cells in x-fastest order, so that every run of cells along x is one contiguous run of
//! points. A sphere's query visits only the rows of cells its ball crosses, and in each row only
//! the cells under the ball's chord: the points it scans lie within about one cell of the ball.
//! Most queries end before that, at their cell's clearance: near the points, the distance from
//! the cell to the box about each nearby cell's points (a few cells about every occupied one,
//! written row by row); farther, a distance transform of the occupied cells, truncated where
//! no link's bounding sphere reaches. Deep among the points a query ends at its cell's
//! witness, a point near the cell: one within the sphere settles a collision. A walk that
//! stops at the first collision leaves the remaining scans for its end, where most blocks
//! never arrive. Building costs a sort of the points, a window of cells per occupied cell and
//! a few passes over the cells — the difference from CAPT (Ramsey et al., RSS 2024), which
//! stores, for every leaf of a k-d tree, every point its queries could reach.
//!
//! **Exact, as the other objects**: the scan finds the nearest point among all those within the
//! query's range (its reach plus the margin, padded by a few units of rounding), so the
//! distance the screen compares with the limits is the nearest point's whenever that point
//! could decide the verdict; the points are the truth, the exact check of an uncertain lane
//! tests the same balls in `f64`.

use super::lanes::{F, PORTABLE};
use super::model::FastModel;
use super::outcome::Contact;
use super::solid::Solid;
use super::walk::{FastScratch, place_solids};
use super::{FAST_LANES, LaneMask};
use trm_kinematics::PoseLanes32;

/// Cells at most per point of the cloud (and at least this many in all): a grid finer than
/// this over a sparse, wide cloud is coarsened so that its cells stay cheap to build.
const CELLS_PER_POINT: usize = 32;

/// Most cells of a grid (their records' offsets, four values each, fit an `i32`).
const MOST_CELLS: usize = 1 << 28;

/// A cell's clearance, then its witness's coordinates ([`CloudGrid`]), aligned so that it
/// lies in one cache line.
#[derive(Debug, Clone, Copy)]
#[repr(C, align(16))]
struct Record([f32; 4]);

/// A point cloud in a uniform grid, in the world frame, single precision.
#[derive(Debug, Clone)]
pub(super) struct CloudGrid {
    /// Corner of cell (0, 0, 0).
    origin: [f32; 3],
    cell: f32,
    inv_cell: f32,
    dims: [usize; 3],
    /// Per cell (x fastest), the index of its first point; one more entry at the end.
    starts: Vec<u32>,
    /// Per cell (one record: a query reads one cache line): its clearance — no point of the
    /// cloud lies nearer than this to any place in the cell, m ([`near_clearances`]; most
    /// queries end at this one look-up) — then its witness, a point of the cloud near it
    /// ([`witnesses`]; infinite where none is near): a query about a place in the cell that
    /// finds it within its reach ends there.
    records: Vec<Record>,
    /// The points' coordinates, cell by cell.
    xyz: [Vec<f32>; 3],
    /// Added to every query's range: a few units of rounding of the largest coordinate, so
    /// that no point within the range is missed by the cell arithmetic.
    slack: f32,
    /// The points' axis-aligned box: its centre and half sizes.
    pub(super) center: [f32; 3],
    pub(super) half: [f32; 3],
    /// How far a point of the object may lie from the nearest of its points: 0 for a point
    /// cloud; a triangle mesh sampled by [`CloudGrid::of_mesh`] lies within this of its samples.
    pub(super) gap: f32,
}

/// The spacing of the samples a triangle mesh is screened through, m: lanes within this of
/// contact are left to the exact check.
pub(super) const MESH_SPACING: f32 = 0.004;

/// Most samples of a mesh's screen; a mesh that needs more is screened through its bounding
/// sphere.
const MESH_SAMPLES: usize = 1 << 21;

impl CloudGrid {
    /// The points in a grid of cells about `cell` wide (coarser when the cloud is sparse and
    /// wide; see [`CELLS_PER_POINT`]), each cell's clearance exact up to about `near` (see
    /// [`near_clearances`]) and bounded up to about `far` ([`far_clearances`]), and its
    /// witness ([`witnesses`]). `points` must be finite and not empty.
    pub(super) fn new(points: &[[f32; 3]], cell: f32, near: f32, far: f32) -> CloudGrid {
        let mut lo = [f32::INFINITY; 3];
        let mut hi = [f32::NEG_INFINITY; 3];
        for p in points {
            for k in 0..3 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
        let extent: [f32; 3] = std::array::from_fn(|k| (hi[k] - lo[k]).max(0.0));
        let budget = (CELLS_PER_POINT * points.len()).clamp(4096, MOST_CELLS) as f64;
        let count = |cell: f32| -> [usize; 3] {
            std::array::from_fn(|k| (extent[k] / cell).floor() as usize + 1)
        };
        let mut cell = cell.max(1e-4);
        while count(cell).iter().map(|&n| n as f64).product::<f64>() > budget {
            cell *= 1.25;
        }
        let dims = count(cell);
        let inv_cell = 1.0 / cell;
        let cells = dims[0] * dims[1] * dims[2];
        let index = |p: &[f32; 3]| -> usize {
            let i: [usize; 3] =
                std::array::from_fn(|k| (((p[k] - lo[k]) * inv_cell) as usize).min(dims[k] - 1));
            i[0] + dims[0] * (i[1] + dims[1] * i[2])
        };
        // counting sort: counts, then each cell's start, then the points in place
        let mut starts = vec![0u32; cells + 1];
        let homes: Vec<u32> = points.iter().map(|p| index(p) as u32).collect();
        for &h in &homes {
            starts[h as usize + 1] += 1;
        }
        for c in 0..cells {
            starts[c + 1] += starts[c];
        }
        let mut next = starts[..cells].to_vec();
        let mut xyz = [
            vec![0.0; points.len()],
            vec![0.0; points.len()],
            vec![0.0; points.len()],
        ];
        for (p, &h) in points.iter().zip(&homes) {
            let at = next[h as usize] as usize;
            next[h as usize] += 1;
            for k in 0..3 {
                xyz[k][at] = p[k];
            }
        }
        // far from the points, the cells' distance transform; near them, exact
        let far_cells = ((far / cell).ceil() as usize + 2).clamp(1, FAR_CELLS);
        let far = far_clearances(&starts, dims, cell, far_cells);
        let cells_near = ((near / cell).ceil() as usize).clamp(1, NEAR_CELLS);
        let sorted = Sorted {
            starts: &starts,
            xyz: &xyz,
            lo,
            dims,
            cell,
        };
        let clear = near_clearances(&sorted, cells_near, far);
        let records = witnesses(&sorted, cells_near.min(WITNESS_CELLS), clear);

        let largest = (0..3)
            .map(|k| lo[k].abs().max(hi[k].abs()))
            .fold(cell, f32::max);
        CloudGrid {
            origin: lo,
            cell,
            inv_cell,
            dims,
            starts,
            records,
            xyz,
            slack: 16.0 * f32::EPSILON * (largest + cell),
            center: std::array::from_fn(|k| 0.5 * (lo[k] + hi[k])),
            half: std::array::from_fn(|k| 0.5 * extent[k]),
            gap: 0.0,
        }
    }

    /// A triangle mesh (`corners` of each triangle, world frame) screened through samples on
    /// it: each triangle cut into n² alike pieces whose sides are at most [`MESH_SPACING`], the
    /// pieces' corners kept. Every point of a piece lies within its longest side of each of its
    /// corners, so every point of the mesh lies within the spacing of a sample (the grid's
    /// `gap`), and the samples lie on the mesh: the nearest sample's distance `d` bounds the
    /// mesh's to `[d − gap, d]`. Clearances bounded up to `far` as by [`CloudGrid::new`].
    /// `None` past [`MESH_SAMPLES`] samples.
    pub(super) fn of_mesh(corners: &[[[f64; 3]; 3]], cell: f32, far: f32) -> Option<CloudGrid> {
        let spacing = f64::from(MESH_SPACING);
        let mut points: Vec<[f32; 3]> = Vec::new();
        for [a, b, c] in corners {
            let side = |p: &[f64; 3], q: &[f64; 3]| {
                ((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2) + (p[2] - q[2]).powi(2)).sqrt()
            };
            let longest = side(a, b).max(side(b, c)).max(side(c, a));
            let n = (longest / spacing).ceil().max(1.0) as usize;
            if points.len() + (n + 1) * (n + 2) / 2 > MESH_SAMPLES {
                return None;
            }
            for i in 0..=n {
                for j in 0..=n - i {
                    let (u, v) = (i as f64 / n as f64, j as f64 / n as f64);
                    points.push(std::array::from_fn(|k| {
                        (a[k] + u * (b[k] - a[k]) + v * (c[k] - a[k])) as f32
                    }));
                }
            }
        }
        let mut grid = CloudGrid::new(&points, cell, 2.0 * cell, far);
        // the samples' rounding to f32 is within the slack; the spacing bounds the rest
        grid.gap = MESH_SPACING + grid.slack;
        Some(grid)
    }

    /// Number of points.
    #[cfg(test)]
    pub(super) fn len(&self) -> usize {
        self.xyz[0].len()
    }

    /// A distance within which no point of the cloud lies from `p` (0 where one may): the
    /// clearance of the cell nearest `p` (every point lies in the grid's box, and `p`'s nearest
    /// place in the box is at least as near every point as `p`).
    #[inline(always)]
    pub(super) fn clearance(&self, p: [f32; 3]) -> f32 {
        self.records[self.cell_index(p)].0[0]
    }

    /// The index of the cell nearest `p`.
    #[inline(always)]
    fn cell_index(&self, p: [f32; 3]) -> usize {
        // truncation is the floor of what is not negative
        let i: [usize; 3] = std::array::from_fn(|k| {
            let v = (p[k] - self.origin[k]) * self.inv_cell;
            (v.max(0.0) as usize).min(self.dims[k] - 1)
        });
        i[0] + self.dims[0] * (i[1] + self.dims[1] * i[2])
    }

    /// The lanes of `lanes` whose sphere at `c` of radius `reach` may touch a point's centre
    /// (NaN lanes included).
    #[inline(always)]
    pub(super) fn may_touch<const AVX: bool>(
        &self,
        c: &[F; 3],
        reach: f32,
        lanes: LaneMask,
    ) -> LaneMask {
        #[cfg(target_arch = "x86_64")]
        if AVX {
            // SAFETY: as in `F::any_within`
            #[allow(unsafe_code)]
            return lanes & unsafe { self.may_touch_avx(c, reach + self.slack) };
        }
        lanes_where(c, lanes, true, |p| self.clearance(p) <= reach + self.slack)
    }

    /// [`CloudGrid::may_touch`] in every lane at once: the cells' clearances gathered.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    fn may_touch_avx(&self, c: &[F; 3], reach: f32) -> LaneMask {
        use std::arch::x86_64::{_CMP_NGT_UQ, _mm256_cmp_ps, _mm256_movemask_ps, _mm256_set1_ps};
        let (cell, finite) = self.cells_avx(c);
        let clear = self.gather_avx(cell, 0);
        let within = _mm256_cmp_ps::<_CMP_NGT_UQ>(clear, _mm256_set1_ps(reach));
        // (a mask's eight bits: one per lane)
        (_mm256_movemask_ps(within) as LaneMask) | !(_mm256_movemask_ps(finite) as LaneMask)
    }

    /// Per lane, value `k` of the record of cell `cell` (0: the clearance, 1 to 3: the
    /// witness).
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    #[inline]
    fn gather_avx(&self, cell: std::arch::x86_64::__m256i, k: usize) -> std::arch::x86_64::__m256 {
        use std::arch::x86_64::{_mm256_i32gather_ps, _mm256_slli_epi32};
        // SAFETY: every index lies in the grid, `records` holds one record of four values per
        // cell (fewer than 2²⁸ cells: the offsets fit an `i32`), `k` < 4
        #[allow(unsafe_code)]
        unsafe {
            _mm256_i32gather_ps::<4>(
                self.records.as_ptr().cast::<f32>().add(k),
                _mm256_slli_epi32::<2>(cell),
            )
        }
    }

    /// Per lane, the index of the cell nearest `c` (the same arithmetic as
    /// [`CloudGrid::cell_index`]: every index lies in the grid) and whether `c` is finite.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    fn cells_avx(&self, c: &[F; 3]) -> (std::arch::x86_64::__m256i, std::arch::x86_64::__m256) {
        use std::arch::x86_64::{
            _CMP_LT_OQ, _mm256_add_epi32, _mm256_and_ps, _mm256_andnot_ps, _mm256_cmp_ps,
            _mm256_cvttps_epi32, _mm256_load_ps, _mm256_max_ps, _mm256_min_ps, _mm256_mul_ps,
            _mm256_mullo_epi32, _mm256_set1_epi32, _mm256_set1_ps, _mm256_setzero_ps,
            _mm256_sub_ps,
        };
        let index = |k: usize| {
            // SAFETY: `F` is eight `f32` aligned to 32 bytes
            #[allow(unsafe_code)]
            let p = unsafe { _mm256_load_ps(c[k].0.as_ptr()) };
            // |p| < ∞ (NaN fails too)
            let magnitude = _mm256_andnot_ps(_mm256_set1_ps(-0.0), p);
            let ok = _mm256_cmp_ps::<_CMP_LT_OQ>(magnitude, _mm256_set1_ps(f32::INFINITY));
            let v = _mm256_mul_ps(
                _mm256_sub_ps(p, _mm256_set1_ps(self.origin[k])),
                _mm256_set1_ps(self.inv_cell),
            );
            // NaN to 0 (the second operand), as `f32::max` does
            let v = _mm256_max_ps(v, _mm256_setzero_ps());
            let v = _mm256_min_ps(v, _mm256_set1_ps((self.dims[k] - 1) as f32));
            (_mm256_cvttps_epi32(v), ok)
        };
        let ((i, a), (j, b), (k, d)) = (index(0), index(1), index(2));
        let (d0, d1) = (self.dims[0] as i32, self.dims[1] as i32);
        let cell = _mm256_add_epi32(
            i,
            _mm256_mullo_epi32(
                _mm256_set1_epi32(d0),
                _mm256_add_epi32(j, _mm256_mullo_epi32(_mm256_set1_epi32(d1), k)),
            ),
        );
        (cell, _mm256_and_ps(a, _mm256_and_ps(b, d)))
    }

    /// The lanes of `lanes` whose cell's witness lies within `inside` of `c`: those whose sphere
    /// at `c` of radius `inside` certainly holds a point's centre (NaN lanes never).
    #[inline(always)]
    pub(super) fn holding<const AVX: bool>(
        &self,
        c: &[F; 3],
        inside: f32,
        lanes: LaneMask,
    ) -> LaneMask {
        let inside = inside - self.slack;
        if inside <= 0.0 {
            return 0;
        }
        #[cfg(target_arch = "x86_64")]
        if AVX {
            // SAFETY: as in `F::any_within`
            #[allow(unsafe_code)]
            return lanes & unsafe { self.holding_avx(c, inside * inside) };
        }
        lanes_where(c, lanes, false, |p| {
            let i = self.cell_index(p);
            let d2: f32 = (0..3)
                .map(|k| (self.records[i].0[k + 1] - p[k]).powi(2))
                .sum();
            d2 < inside * inside
        })
    }

    /// [`CloudGrid::holding`] in every lane at once: the cells' witnesses gathered.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    fn holding_avx(&self, c: &[F; 3], inside2: f32) -> LaneMask {
        use std::arch::x86_64::_mm256_load_ps;
        let (cell, _) = self.cells_avx(c);
        // SAFETY: `F` is eight `f32` aligned to 32 bytes
        #[allow(unsafe_code)]
        let p: [_; 3] = std::array::from_fn(|k| unsafe { _mm256_load_ps(c[k].0.as_ptr()) });
        self.held_avx(cell, &p, inside2)
    }

    /// The lanes whose cell `cell`'s witness lies within `√inside2` of `p` (NaN lanes never).
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    #[inline]
    fn held_avx(
        &self,
        cell: std::arch::x86_64::__m256i,
        p: &[std::arch::x86_64::__m256; 3],
        inside2: f32,
    ) -> LaneMask {
        use std::arch::x86_64::{
            _CMP_LT_OQ, _mm256_cmp_ps, _mm256_fmadd_ps, _mm256_movemask_ps, _mm256_set1_ps,
            _mm256_setzero_ps, _mm256_sub_ps,
        };
        let mut d2 = _mm256_setzero_ps();
        for (k, &p) in p.iter().enumerate() {
            let d = _mm256_sub_ps(self.gather_avx(cell, k + 1), p);
            d2 = _mm256_fmadd_ps(d, d, d2);
        }
        _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_LT_OQ>(d2, _mm256_set1_ps(inside2))) as LaneMask
    }

    /// [`super::world::FastWorld::glance`] for every sphere at `centres` (radii in `balls`)
    /// in turn, for the cloud whose points' box has centre `center` and half sizes `half`
    /// (points of radius `radius`): the lanes of `lanes` whose witness settles a collision,
    /// and those the cells leave open (the certain ones included); it ends at the first sphere
    /// with a certain lane. The box's and the grid's constants are broadcast once; most
    /// spheres end at the box.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    #[allow(clippy::too_many_arguments)]
    pub(super) fn glance_balls_avx(
        &self,
        center: [f32; 3],
        half: [f32; 3],
        radius: f32,
        centres: &[[F; 3]],
        balls: &[super::model::Ball],
        m: f32,
        lanes: LaneMask,
    ) -> (LaneMask, LaneMask) {
        use std::arch::x86_64::_mm256_set1_ps;
        let centre: [_; 3] = std::array::from_fn(|k| _mm256_set1_ps(center[k]));
        let halves: [_; 3] = std::array::from_fn(|k| _mm256_set1_ps(half[k]));
        let (mut hit, mut close) = (0, 0);
        for (c, ball) in centres.iter().zip(balls) {
            let (h, open) = self.glance_avx(&centre, &halves, radius, c, ball.radius, m, lanes);
            (hit, close) = (hit | h, close | open);
            if hit != 0 {
                break;
            }
        }
        (hit, close)
    }

    /// [`super::world::FastWorld::glance`] of the sphere of radius `r` at `c`, for the cloud
    /// whose points' box has centre `centre` and half sizes `halves` (broadcast to every lane),
    /// points of radius `radius`: the box, then the cells' clearances, then their witnesses
    /// ([`CloudGrid::may_touch`], [`CloudGrid::holding`]), each lane's cell found once.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    #[inline]
    #[allow(clippy::too_many_arguments)]
    pub(super) fn glance_avx(
        &self,
        centre: &[std::arch::x86_64::__m256; 3],
        halves: &[std::arch::x86_64::__m256; 3],
        radius: f32,
        c: &[F; 3],
        r: f32,
        m: f32,
        lanes: LaneMask,
    ) -> (LaneMask, LaneMask) {
        use std::arch::x86_64::{
            _CMP_NGT_UQ, _mm256_andnot_ps, _mm256_cmp_ps, _mm256_fmadd_ps, _mm256_load_ps,
            _mm256_max_ps, _mm256_movemask_ps, _mm256_set1_ps, _mm256_setzero_ps, _mm256_sub_ps,
        };
        // SAFETY: `F` is eight `f32` aligned to 32 bytes
        #[allow(unsafe_code)]
        let p: [_; 3] = std::array::from_fn(|k| unsafe { _mm256_load_ps(c[k].0.as_ptr()) });
        // the box about the points, as `Object::near` measures it
        let reach = r + radius;
        let mut d2 = _mm256_setzero_ps();
        for k in 0..3 {
            let d = _mm256_andnot_ps(_mm256_set1_ps(-0.0), _mm256_sub_ps(p[k], centre[k]));
            let out = _mm256_max_ps(_mm256_sub_ps(d, halves[k]), _mm256_setzero_ps());
            d2 = _mm256_fmadd_ps(out, out, d2);
        }
        // (summed in `Object::near`'s order)
        let outer = r + m + radius;
        let near = _mm256_cmp_ps::<_CMP_NGT_UQ>(d2, _mm256_set1_ps(outer * outer));
        let near = lanes & _mm256_movemask_ps(near) as LaneMask;
        if near == 0 {
            return (0, 0);
        }
        let (cell, finite) = self.cells_avx(c);
        let clear = self.gather_avx(cell, 0);
        let limit = reach + self.gap + m + self.slack;
        let within = _mm256_cmp_ps::<_CMP_NGT_UQ>(clear, _mm256_set1_ps(limit));
        let open = near
            & ((_mm256_movemask_ps(within) as LaneMask)
                | !(_mm256_movemask_ps(finite) as LaneMask));
        let inside = (reach - m).max(0.0) - self.slack;
        if open == 0 || inside <= 0.0 {
            return (0, open);
        }
        (open & self.held_avx(cell, &p, inside * inside), open)
    }

    /// The range of cells along axis `k` that `[a, b]` overlaps, `None` when it misses them.
    #[inline(always)]
    fn cells(&self, k: usize, a: f32, b: f32) -> Option<(usize, usize)> {
        let lo = (a - self.origin[k]) * self.inv_cell;
        let hi = (b - self.origin[k]) * self.inv_cell;
        if !(hi >= 0.0 && lo < self.dims[k] as f32) {
            return None;
        }
        // truncation is the floor of what is not negative
        Some((lo.max(0.0) as usize, (hi as usize).min(self.dims[k] - 1)))
    }

    /// The squared distance from `p` to the slab of cells `i` along axis `k` (0 inside).
    #[inline(always)]
    fn gap2(&self, k: usize, i: usize, p: f32) -> f32 {
        let a = self.origin[k] + i as f32 * self.cell;
        let d = (a - p).max(p - (a + self.cell)).max(0.0);
        d * d
    }

    /// The smallest squared distance from `p` to a point of the cloud, among the points within
    /// `range` of it (every one of them is scanned, unless one closer than `√stop2` turns up
    /// first: then a distance below `stop2`); infinity when none is.
    pub(super) fn nearest2(&self, p: [f32; 3], range: f32, stop2: f32) -> f32 {
        self.nearest_by(p, range, stop2, |x, y, z| {
            let (dx, dy, dz) = (x - p[0], y - p[1], z - p[2]);
            dx * dx + dy * dy + dz * dz
        })
    }

    /// The least `d2(point)` over the points within `range` of `p` (every one of them is
    /// scanned, unless one below `stop2` turns up first); infinity when none is. `d2` is a
    /// squared distance from the point to a body within `range` of `p`.
    #[inline(always)]
    pub(super) fn nearest_by(
        &self,
        p: [f32; 3],
        range: f32,
        stop2: f32,
        d2: impl Fn(f32, f32, f32) -> f32 + Copy,
    ) -> f32 {
        let range = range + self.slack;
        if self.clearance(p) > range {
            return f32::INFINITY;
        }
        let range2 = range * range;
        let Some((k0, k1)) = self.cells(2, p[2] - range, p[2] + range) else {
            return f32::INFINITY;
        };
        let Some((j0, j1)) = self.cells(1, p[1] - range, p[1] + range) else {
            return f32::INFINITY;
        };
        let mut best = [f32::INFINITY; FAST_LANES];
        for k in k0..=k1 {
            let dz2 = self.gap2(2, k, p[2]);
            for j in j0..=j1 {
                let row = self.dims[0] * (j + self.dims[1] * k);
                let left = range2 - dz2 - self.gap2(1, j, p[1]);
                // rows the ball misses, and rows without points
                if left < 0.0 || self.starts[row] == self.starts[row + self.dims[0]] {
                    continue;
                }
                let chord = left.sqrt() + self.slack;
                let Some((i0, i1)) = self.cells(0, p[0] - chord, p[0] + chord) else {
                    continue;
                };
                let (from, to) = (
                    self.starts[row + i0] as usize,
                    self.starts[row + i1 + 1] as usize,
                );
                self.scan(from, to, &mut best, d2);
                if best.iter().any(|&b| b < stop2) {
                    return best.into_iter().fold(f32::INFINITY, f32::min);
                }
            }
        }
        best.into_iter().fold(f32::INFINITY, f32::min)
    }

    /// Lowers `best` (lane `l` holds the least over the points `l` modulo [`FAST_LANES`]) by
    /// `d2` of points `from..to`: eight at a time, so the compiler turns each step into a
    /// vector instruction.
    #[inline(always)]
    fn scan(
        &self,
        from: usize,
        to: usize,
        best: &mut [f32; FAST_LANES],
        d2: impl Fn(f32, f32, f32) -> f32,
    ) {
        let [xs, ys, zs] = &self.xyz;
        let (xs, ys, zs) = (&xs[from..to], &ys[from..to], &zs[from..to]);
        let whole = xs.len() / FAST_LANES * FAST_LANES;
        for ((x, y), z) in xs[..whole]
            .chunks_exact(FAST_LANES)
            .zip(ys[..whole].chunks_exact(FAST_LANES))
            .zip(zs[..whole].chunks_exact(FAST_LANES))
        {
            for l in 0..FAST_LANES {
                let d = d2(x[l], y[l], z[l]);
                best[l] = if d < best[l] { d } else { best[l] };
            }
        }
        for i in whole..xs.len() {
            let d = d2(xs[i], ys[i], zs[i]);
            best[0] = if d < best[0] { d } else { best[0] };
        }
    }

    /// Per lane of `lanes`, [`CloudGrid::nearest2`] of the point at `c` (NaN where `c` is not
    /// finite: never certainly clear), −1 in the lanes of `certain` (known to hold a point
    /// within `√stop2`: they are not scanned); infinity in the other lanes, and with `first`,
    /// in the lanes after the first one found below `stop2` (all but `certain` when it has
    /// any).
    pub(super) fn distance2(
        &self,
        c: &[F; 3],
        range: f32,
        stop2: f32,
        lanes: LaneMask,
        certain: LaneMask,
        first: bool,
    ) -> F {
        let mut out = [f32::INFINITY; FAST_LANES];
        if certain != 0 {
            for (l, d2) in out.iter_mut().enumerate() {
                if certain & (1 << l) != 0 {
                    *d2 = -1.0;
                }
            }
            if first {
                return F(out);
            }
        }
        for (l, d2) in out.iter_mut().enumerate() {
            if (lanes & !certain) & (1 << l) == 0 {
                continue;
            }
            let p = [c[0].0[l], c[1].0[l], c[2].0[l]];
            *d2 = if p.iter().all(|v| v.is_finite()) {
                self.nearest2(p, range, stop2)
            } else {
                f32::NAN
            };
            if first && *d2 < stop2 {
                break;
            }
        }
        F(out)
    }
}

/// The lanes of `lanes` whose place in `c` passes `test`, or is not finite and `not_finite`.
#[inline(always)]
fn lanes_where(
    c: &[F; 3],
    lanes: LaneMask,
    not_finite: bool,
    test: impl Fn([f32; 3]) -> bool,
) -> LaneMask {
    let mut out = 0;
    for l in 0..FAST_LANES {
        if lanes & (1 << l) == 0 {
            continue;
        }
        let p = [c[0].0[l], c[1].0[l], c[2].0[l]];
        let pass = if p.iter().all(|v| v.is_finite()) {
            test(p)
        } else {
            not_finite
        };
        out |= LaneMask::from(pass) << l;
    }
    out
}

/// Per cell of a grid of `dims` cells of side `cell` whose points start at `starts`: a
/// distance from any place in the cell within which no point lies, up to about `t` cells, m.
/// The squared Euclidean distance transform of the cells holding points over cell indices, one
/// axis after the other (exact sweeps along x; along y and z the least of `f[j + s] + s²` over
/// `|s| ≤ t`, whole rows of x at once), each pass capped at `(t + 1)²`: a nearer cell beyond
/// the window would lie more than `t` cells away along that axis alone, so the capped value
/// never exceeds the true one. Two places in cells `d` apart are at least `(d − √3)` cells
/// apart.
fn far_clearances(starts: &[u32], dims: [usize; 3], cell: f32, t: usize) -> Vec<f32> {
    let cap = ((t + 1) * (t + 1)) as f32;
    let mut d2 = vec![cap; dims[0] * dims[1] * dims[2]];
    // along x, where cells are either occupied or not: one sweep each way
    for (r, row) in d2.chunks_exact_mut(dims[0]).enumerate() {
        let occupied = |x: usize| starts[r * dims[0] + x + 1] > starts[r * dims[0] + x];
        let mut last: Option<usize> = None;
        for x in 0..dims[0] {
            if occupied(x) {
                last = Some(x);
            }
            if let Some(l) = last {
                row[x] = row[x].min(((x - l) * (x - l)) as f32);
            }
        }
        let mut last: Option<usize> = None;
        for x in (0..dims[0]).rev() {
            if occupied(x) {
                last = Some(x);
            }
            if let Some(l) = last {
                row[x] = row[x].min(((l - x) * (l - x)) as f32);
            }
        }
    }
    // along y within each slab of z, then along z: lines of whole rows, whole slabs
    let mut out = vec![0.0; d2.len()];
    let slab = dims[0] * dims[1];
    for (from, to) in d2.chunks_exact(slab).zip(out.chunks_exact_mut(slab)) {
        min_plus(from, to, dims[0], dims[1], t, cap);
    }
    min_plus(&out, &mut d2, slab, dims[2], t, cap);
    d2.iter()
        .map(|&d| ((d.sqrt() - 3f32.sqrt()) * cell).max(0.0) * (1.0 - 1e-6))
        .collect()
}

/// `to[j] = min(cap, min over |s| ≤ t of from[j + s] + s²)` for the `n` lines of `width`
/// values each of `from` (line `j` at `j * width`), a whole line at a time.
#[allow(unsafe_code)] // multiversion's run-time CPU-feature dispatch
#[multiversion::multiversion(targets("x86_64+avx2+fma", "x86_64+avx", "aarch64+neon"))]
fn min_plus(from: &[f32], to: &mut [f32], width: usize, n: usize, t: usize, cap: f32) {
    for (j, out) in to.chunks_exact_mut(width).enumerate().take(n) {
        out.fill(cap);
        for k in j.saturating_sub(t)..(j + t + 1).min(n) {
            let s2 = ((k as isize - j as isize).pow(2)) as f32;
            for (o, f) in out.iter_mut().zip(&from[k * width..(k + 1) * width]) {
                let v = f + s2;
                *o = if v < *o { v } else { *o };
            }
        }
    }
}

/// Most cells of [`far_clearances`]'s window along each axis.
const FAR_CELLS: usize = 16;

/// Most cells about an occupied cell that [`witnesses`] gives its point, along each axis.
const WITNESS_CELLS: usize = 1;

/// The points of a cloud sorted into the cells of a grid.
struct Sorted<'a> {
    /// Per cell (x fastest), the index of its first point; one more entry at the end.
    starts: &'a [u32],
    /// The points' coordinates, cell by cell.
    xyz: &'a [Vec<f32>; 3],
    /// Corner of cell (0, 0, 0).
    lo: [f32; 3],
    dims: [usize; 3],
    /// The cells' side, m.
    cell: f32,
}

impl Sorted<'_> {
    /// The cells holding points: each one's place in the grid along each axis and the range
    /// of its points.
    fn occupied(&self) -> impl Iterator<Item = ([usize; 3], std::ops::Range<usize>)> {
        let dims = self.dims;
        (self.starts.windows(2).enumerate())
            .filter(|(_, run)| run[0] < run[1])
            .map(move |(c, run)| {
                let home = [c % dims[0], c / dims[0] % dims[1], c / (dims[0] * dims[1])];
                (home, run[0] as usize..run[1] as usize)
            })
    }
}

/// Per cell of `sorted`, its record: its clearance from `clear`, then a point near it,
/// coordinate by coordinate: among the occupied cells within `k` cells along every axis, each
/// represented by its point nearest its centre, the representative nearest the cell's centre
/// (infinite coordinates where no cell is that near). Any point of the cloud bounds a query's
/// distance from above; this one is near the nearest wherever the cloud is dense.
fn witnesses(sorted: &Sorted, k: usize, clear: Vec<f32>) -> Vec<Record> {
    let (xyz, lo, dims, cell) = (sorted.xyz, sorted.lo, sorted.dims, sorted.cell);
    let cells = dims[0] * dims[1] * dims[2];
    let mut best = vec![f32::INFINITY; cells];
    let mut which = vec![u32::MAX; cells];
    let centre = |axis: usize, i: usize| lo[axis] + (i as f32 + 0.5) * cell;
    let span = |axis: usize, i: usize| i.saturating_sub(k)..=(i + k).min(dims[axis] - 1);
    for (home, points) in sorted.occupied() {
        let d2 =
            |i: usize, at: [f32; 3]| -> f32 { (0..3).map(|a| (xyz[a][i] - at[a]).powi(2)).sum() };
        let here: [f32; 3] = std::array::from_fn(|a| centre(a, home[a]));
        let chosen = points
            .min_by(|&a, &b| d2(a, here).total_cmp(&d2(b, here)))
            .expect("an occupied cell");
        let p: [f32; 3] = std::array::from_fn(|a| xyz[a][chosen]);
        for z in span(2, home[2]) {
            let dz2 = (centre(2, z) - p[2]).powi(2);
            for y in span(1, home[1]) {
                let dyz2 = dz2 + (centre(1, y) - p[1]).powi(2);
                let row = dims[0] * (y + dims[1] * z);
                for x in span(0, home[0]) {
                    let d = dyz2 + (centre(0, x) - p[0]).powi(2);
                    if d < best[row + x] {
                        best[row + x] = d;
                        which[row + x] = chosen as u32;
                    }
                }
            }
        }
    }
    let coordinate = |a: usize, i: u32| xyz[a].get(i as usize).copied().unwrap_or(f32::INFINITY);
    (which.into_iter().zip(clear))
        .map(|(i, c)| Record([c, coordinate(0, i), coordinate(1, i), coordinate(2, i)]))
        .collect()
}

/// Most cells about a point whose clearances [`near_clearances`] makes exact, along each axis.
const NEAR_CELLS: usize = 4;

/// Cells in the window [`near_clearances`] updates about an occupied cell along x.
const NEAR_WINDOW: usize = 2 * NEAR_CELLS + 1;

/// Per cell of `sorted`: the distance from the cell to the nearest box about a cell's points
/// where that is below `k` cells (a point farther away along some axis than `k` cells is at
/// least `k` cells from the cell; a box about one point is the point), else `k` cells; the
/// larger of that and the cell's `far` clearance, m. Near the points, where queries land, this
/// is what decides whether a query scans: a distance transform of the cells that hold points
/// loses up to √3 cells. Each occupied cell lowers the cells of a window about it, a row of
/// the window at a time.
#[allow(unsafe_code)] // multiversion's run-time CPU-feature dispatch
#[multiversion::multiversion(targets("x86_64+avx2+fma", "x86_64+avx", "aarch64+neon"))]
fn near_clearances(sorted: &Sorted, k: usize, far: Vec<f32>) -> Vec<f32> {
    let (xyz, lo, dims, cell) = (sorted.xyz, sorted.lo, sorted.dims, sorted.cell);
    let cap2 = (k as f32 * cell).powi(2);
    // squared, in rows padded by NEAR_CELLS cells each side: every window is NEAR_WINDOW wide
    let row_len = dims[0] + 2 * NEAR_CELLS;
    let mut near2 = vec![cap2; row_len * dims[1] * dims[2]];
    // the distance from [v0, v1] to the slab of cells `i` along `axis`
    let gap = |axis: usize, i: isize, [v0, v1]: [f32; 2]| {
        let a = lo[axis] + i as f32 * cell;
        (a - v1).max(v0 - (a + cell)).max(0.0)
    };
    let span = |axis: usize, i: usize| (i.saturating_sub(k), (i + k).min(dims[axis] - 1));
    for ([hx, hy, hz], points) in sorted.occupied() {
        let bounds: [[f32; 2]; 3] = std::array::from_fn(|axis| {
            let v = &xyz[axis][points.clone()];
            [
                v.iter().fold(f32::INFINITY, |a, &b| a.min(b)),
                v.iter().fold(f32::NEG_INFINITY, |a, &b| a.max(b)),
            ]
        });
        let dx2: [f32; NEAR_WINDOW] = std::array::from_fn(|i| {
            let offset = i as isize - NEAR_CELLS as isize;
            if offset.unsigned_abs() > k {
                f32::INFINITY
            } else {
                gap(0, hx as isize + offset, bounds[0]).powi(2)
            }
        });
        let (y0, y1) = span(1, hy);
        let (z0, z1) = span(2, hz);
        let dy2: [f32; NEAR_WINDOW] =
            std::array::from_fn(|i| gap(1, (y0 + i) as isize, bounds[1]).powi(2));
        for kz in z0..=z1 {
            let dz2 = gap(2, kz as isize, bounds[2]).powi(2);
            for (ky, dy2) in (y0..=y1).zip(dy2) {
                let dyz2 = dy2 + dz2;
                if dyz2 >= cap2 {
                    continue;
                }
                let at = row_len * (ky + dims[1] * kz) + hx;
                let window: &mut [f32; NEAR_WINDOW] = (&mut near2[at..at + NEAR_WINDOW])
                    .try_into()
                    .expect("a window");
                for (d2, dx2) in window.iter_mut().zip(dx2) {
                    let d = dx2 + dyz2;
                    *d2 = if d < *d2 { d } else { *d2 };
                }
            }
        }
    }
    let mut clear = far;
    for (row, near2) in clear
        .chunks_exact_mut(dims[0])
        .zip(near2.chunks_exact(row_len))
    {
        for (c, d2) in row.iter_mut().zip(&near2[NEAR_CELLS..]) {
            let near = d2.sqrt() * (1.0 - 1e-6);
            *c = if near > *c { near } else { *c };
        }
    }
    clear
}

/// The lanes of `near` in which link group `g`'s solids (boxes, capsules, spheres: the link
/// is [`super::model::Group::solids`]) certainly touch a point of `cloud` (points of radius
/// `radius`), and those within their tolerance of it: per lane, the points within each solid's
/// bounding sphere, measured to the solid itself (a box's point distance, a capsule's segment
/// distance).
#[allow(clippy::too_many_arguments)]
pub(super) fn solids_against_cloud(
    model: &FastModel,
    poses: &[PoseLanes32],
    cloud: &CloudGrid,
    radius: f32,
    g: usize,
    near: LaneMask,
    scratch: &mut FastScratch,
    m: f32,
) -> Option<(LaneMask, LaneMask)> {
    let range = model.groups[g].solids.clone()?;
    place_solids(model, poses, g, scratch);
    let mut contact = Contact::default();
    for k in range {
        let solid = model.solids[k];
        let extent = model.solid_extents[k];
        let tol = m * (1.0 + extent + radius);
        let placed = &scratch.solids[k];
        let slot = |s: usize, l: usize| [placed[s][0].0[l], placed[s][1].0[l], placed[s][2].0[l]];
        let reach = match solid {
            Solid::Box { .. } => radius,
            Solid::Round { radius: r, .. } => r + radius,
        };
        // a point certainly touching settles the lane
        let stop2 = (reach - tol).max(0.0).powi(2);
        let range = extent + radius + tol + cloud.gap;
        let mut d2 = [f32::INFINITY; FAST_LANES];
        for (l, out) in d2.iter_mut().enumerate() {
            if near & (1 << l) == 0 {
                continue;
            }
            *out = match solid {
                Solid::Box { half, .. } => {
                    let (c, axes) = (slot(0, l), [slot(1, l), slot(2, l), slot(3, l)]);
                    cloud.nearest_by(c, range, stop2, |x, y, z| {
                        let p = [x - c[0], y - c[1], z - c[2]];
                        let mut d2 = 0.0;
                        for (axis, h) in axes.iter().zip(half) {
                            let along = p[0] * axis[0] + p[1] * axis[1] + p[2] * axis[2];
                            let out = (along.abs() - h).max(0.0);
                            d2 += out * out;
                        }
                        d2
                    })
                }
                Solid::Round { .. } => {
                    let (a, b) = (slot(0, l), slot(1, l));
                    let ab = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
                    let len2 = ab[0] * ab[0] + ab[1] * ab[1] + ab[2] * ab[2];
                    let inv = if len2 > 0.0 { 1.0 / len2 } else { 0.0 };
                    let mid = std::array::from_fn(|k| 0.5 * (a[k] + b[k]));
                    cloud.nearest_by(mid, range, stop2, |x, y, z| {
                        let p = [x - a[0], y - a[1], z - a[2]];
                        let t =
                            ((p[0] * ab[0] + p[1] * ab[1] + p[2] * ab[2]) * inv).clamp(0.0, 1.0);
                        let d = [p[0] - t * ab[0], p[1] - t * ab[1], p[2] - t * ab[2]];
                        d[0] * d[0] + d[1] * d[1] + d[2] * d[2]
                    })
                }
            };
        }
        let (inner, outer) = ((reach - tol).max(0.0), reach + cloud.gap + tol);
        contact.add_within(F(d2), [inner * inner, outer * outer]);
    }
    Some((
        contact.hit.mask::<PORTABLE>(),
        contact.close.mask::<PORTABLE>(),
    ))
}

#[cfg(test)]
mod tests;
