//! Point clouds in the single-precision screen.
//!
//! The points are sorted into a uniform grid (a counting sort: one pass to count, one to
//! place), cells in x-fastest order, so that every run of cells along x is one contiguous run of
//! points. A sphere's query visits only the rows of cells its ball crosses, and in each row only
//! the cells under the ball's chord: the points it scans lie within about one cell of the ball.
//! Building costs two passes over the points and one over the cells, nothing per point per
//! cell — the difference from CAPT (Ramsey et al., RSS 2024), which stores, for every leaf of a
//! k-d tree, every point its queries could reach, and from voxel distance fields.
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
    /// Per cell: no point of the cloud lies nearer than this to any place in the cell, m (from
    /// the cells' Euclidean distance transform): most queries end at this one look-up.
    clear: Vec<f32>,
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
    /// wide; see [`CELLS_PER_POINT`]). `points` must be finite and not empty.
    pub(super) fn new(points: &[[f32; 3]], cell: f32) -> CloudGrid {
        let mut lo = [f32::INFINITY; 3];
        let mut hi = [f32::NEG_INFINITY; 3];
        for p in points {
            for k in 0..3 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
        let extent: [f32; 3] = std::array::from_fn(|k| (hi[k] - lo[k]).max(0.0));
        let budget = (CELLS_PER_POINT * points.len()).max(4096) as f64;
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
        let clear = clearances(&starts, dims, cell);
        let largest = (0..3)
            .map(|k| lo[k].abs().max(hi[k].abs()))
            .fold(cell, f32::max);
        CloudGrid {
            origin: lo,
            cell,
            inv_cell,
            dims,
            starts,
            clear,
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
    /// mesh's to `[d − gap, d]`. `None` past [`MESH_SAMPLES`] samples.
    pub(super) fn of_mesh(corners: &[[[f64; 3]; 3]], cell: f32) -> Option<CloudGrid> {
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
        let mut grid = CloudGrid::new(&points, cell);
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
        let i: [usize; 3] = std::array::from_fn(|k| {
            let v = ((p[k] - self.origin[k]) * self.inv_cell).floor();
            if v >= 0.0 {
                (v as usize).min(self.dims[k] - 1)
            } else {
                0
            }
        });
        self.clear[i[0] + self.dims[0] * (i[1] + self.dims[1] * i[2])]
    }

    /// The lanes of `lanes` whose sphere at `c` of radius `reach` may touch a point's centre
    /// (NaN lanes included).
    pub(super) fn may_touch(&self, c: &[F; 3], reach: f32, lanes: LaneMask) -> LaneMask {
        let mut out = 0;
        for l in 0..FAST_LANES {
            if lanes & (1 << l) == 0 {
                continue;
            }
            let p = [c[0].0[l], c[1].0[l], c[2].0[l]];
            if !p.iter().all(|v| v.is_finite()) || self.clearance(p) <= reach + self.slack {
                out |= 1 << l;
            }
        }
        out
    }

    /// The range of cells along axis `k` that `[a, b]` overlaps, `None` when it misses them.
    #[inline(always)]
    fn cells(&self, k: usize, a: f32, b: f32) -> Option<(usize, usize)> {
        let lo = ((a - self.origin[k]) * self.inv_cell).floor();
        let hi = ((b - self.origin[k]) * self.inv_cell).floor();
        let last = (self.dims[k] - 1) as f32;
        if !(hi >= 0.0 && lo <= last) {
            return None;
        }
        Some((lo.max(0.0) as usize, hi.min(last) as usize))
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
                let left = range2 - dz2 - self.gap2(1, j, p[1]);
                if left < 0.0 {
                    continue;
                }
                let chord = left.sqrt() + self.slack;
                let Some((i0, i1)) = self.cells(0, p[0] - chord, p[0] + chord) else {
                    continue;
                };
                let row = self.dims[0] * (j + self.dims[1] * k);
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
    /// finite: never certainly clear); infinity in the other lanes, and with `first`, in the
    /// lanes after the first one found below `stop2`.
    pub(super) fn distance2(
        &self,
        c: &[F; 3],
        range: f32,
        stop2: f32,
        lanes: LaneMask,
        first: bool,
    ) -> F {
        let mut out = [f32::INFINITY; FAST_LANES];
        for (l, d2) in out.iter_mut().enumerate() {
            if lanes & (1 << l) == 0 {
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

/// Per cell of a grid of `dims` cells of side `cell` whose points start at `starts`: a
/// distance from any place in the cell within which no point lies, m. The squared Euclidean
/// distance transform of the occupied cells over cell indices (Felzenszwalb and Huttenlocher,
/// 2012: the lower envelope of parabolas, one axis after the other), `d` cells to the nearest
/// occupied one; two places in cells `d` apart are at least `(d − √3)` cells apart.
fn clearances(starts: &[u32], dims: [usize; 3], cell: f32) -> Vec<f32> {
    let n = dims[0] * dims[1] * dims[2];
    let far = 1e20_f32;
    // along x, where cells are either occupied or not: the squared distance to the nearest
    // occupied cell of the row, by one sweep each way
    let mut d2 = vec![far; n];
    for (r, row) in d2.chunks_mut(dims[0]).enumerate() {
        let occupied = |x: usize| starts[r * dims[0] + x + 1] > starts[r * dims[0] + x];
        let mut last: Option<usize> = None;
        for x in 0..dims[0] {
            if occupied(x) {
                last = Some(x);
            }
            if let Some(l) = last {
                row[x] = ((x - l) * (x - l)) as f32;
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
    let stride = [1, dims[0], dims[0] * dims[1]];
    let (mut f, mut out) = (Vec::new(), Vec::new());
    let (mut v, mut z) = (Vec::new(), Vec::new());
    // then along y and z: the lower envelope of parabolas; a line holding no finite value
    // stays as it is
    for axis in 1..3 {
        let len = dims[axis];
        let (a, b) = ((axis + 1) % 3, (axis + 2) % 3);
        for i in 0..dims[a] {
            for j in 0..dims[b] {
                let base = i * stride[a] + j * stride[b];
                f.clear();
                f.extend((0..len).map(|k| d2[base + k * stride[axis]]));
                if f.iter().all(|&x| x >= far) {
                    continue;
                }
                envelope(&f, &mut out, &mut v, &mut z);
                for (k, value) in out.iter().enumerate() {
                    d2[base + k * stride[axis]] = *value;
                }
            }
        }
    }
    d2.iter()
        .map(|&d| ((d.sqrt() - 3f32.sqrt()) * cell).max(0.0) * (1.0 - 1e-6))
        .collect()
}

/// The 1-D squared distance transform of `f` (`out[q] = min_p f[p] + (q − p)²`).
fn envelope(f: &[f32], out: &mut Vec<f32>, v: &mut Vec<usize>, z: &mut Vec<f32>) {
    let n = f.len();
    out.clear();
    v.clear();
    z.clear();
    // parabolas of the lower envelope, and where each takes over
    for q in 0..n {
        if f[q] >= 1e20 {
            continue;
        }
        loop {
            let Some(&p) = v.last() else {
                v.push(q);
                z.push(f32::NEG_INFINITY);
                break;
            };
            let s = ((f[q] + (q * q) as f32) - (f[p] + (p * p) as f32)) / (2.0 * (q - p) as f32);
            if s <= *z.last().expect("one per parabola") {
                v.pop();
                z.pop();
            } else {
                v.push(q);
                z.push(s);
                break;
            }
        }
    }
    if v.is_empty() {
        out.extend(std::iter::repeat_n(1e20, n));
        return;
    }
    let mut k = 0;
    for q in 0..n {
        while k + 1 < v.len() && z[k + 1] < q as f32 {
            k += 1;
        }
        let p = v[k];
        let d = q as f32 - p as f32;
        out.push(d * d + f[p]);
    }
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
mod tests {
    use super::*;
    use rand::{RngExt, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// Every query finds the nearest point within its range, as a scan of all points does,
    /// on clouds of every shape: a plane, a cluster, a line, a single point, wide and sparse.
    #[test]
    fn nearest_within_range_is_the_brute_force_nearest() {
        let mut rng = ChaCha8Rng::seed_from_u64(11);
        for case in 0..60 {
            let n = [1, 7, 300, 5000][case % 4];
            let spread: [f32; 3] = match case % 5 {
                0 => [1.0, 1.0, 0.0],
                1 => [0.1, 0.1, 0.1],
                2 => [2.0, 0.0, 0.0],
                3 => [30.0, 30.0, 5.0],
                _ => [0.6, 0.8, 1.2],
            };
            let points: Vec<[f32; 3]> = (0..n)
                .map(|_| std::array::from_fn(|k| rng.random_range(-0.5..=0.5) * spread[k] + 0.3))
                .collect();
            let grid = CloudGrid::new(&points, rng.random_range(0.005..0.2));
            assert_eq!(grid.len(), n);
            for _ in 0..200 {
                let p: [f32; 3] =
                    std::array::from_fn(|k| rng.random_range(-0.7..=0.7) * (spread[k] + 0.2) + 0.3);
                let range = rng.random_range(0.0..0.3);
                let brute = points
                    .iter()
                    .map(|q| (0..3).map(|k| (q[k] - p[k]) * (q[k] - p[k])).sum::<f32>())
                    .fold(f32::INFINITY, f32::min);
                let found = grid.nearest2(p, range, 0.0);
                let clearance = grid.clearance(p);
                assert!(
                    clearance * clearance <= brute,
                    "case {case}: clearance {clearance}, nearest {}",
                    brute.sqrt()
                );
                if brute <= range * range {
                    assert_eq!(found, brute, "case {case}: {p:?} range {range}");
                } else {
                    assert!(found >= brute, "case {case}: {found} < {brute}");
                }
            }
        }
    }
}
