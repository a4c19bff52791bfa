//! Clearance tables: a link pair that one or two revolute joints alone move relative to each
//! other (a forearm and the hand beyond its wrist) is looked up in a table over those joints'
//! angles before any of its spheres is tested.
//!
//! Such pairs are near in almost every configuration, so the screen tests them in almost every
//! block and, for bodies screened through enclosing spheres, leaves many of their lanes to the
//! exact checks (on the Panda's mesh hulls, most of them). Their relative pose is a function
//! of one or two angles, so it can be decided once, when compiling: the angles' ranges are cut
//! into cells, and a cell is marked *free* or *colliding* when a certificate proves every
//! configuration in it so. The certificate is a bubble (Quinlan 1994): the exact (`f64`)
//! signed distance `d` between the two links' checked bodies at one configuration, and the
//! joints' lever arms ([`Levers`]): a change `Δθ` of the angles moves no point of the far link,
//! seen from the near one, by more than `Σⱼ |Δθⱼ| λⱼ`, so every cell within that reach of a
//! gap `d > 0` is free, and every cell within that reach of a depth `−d` collides (were the
//! moved bodies apart, a translation no longer than the reach would part the measured ones,
//! so their penetration depth could not exceed it). Cells are measured coarse to fine, each
//! measurement deciding every cell its bubble holds. A lane whose angles fall in a decided
//! cell is decided; every other lane is tested as before. Pairs tested as solids (boxes,
//! capsules) and sphere models get no table: their screen decides almost every lane itself,
//! and a table spares a block's tests only when all its lanes fall in decided cells.
//!
//! The angles are read from the block's poses (the joint's parent and child link), not from
//! the inputs, so that a table serves every active set and coupling: with `A` the parent's
//! orientation times the joint origin's, the child's orientation is `±A ⊗ (cos θ/2, sin θ/2 n)`.
//! Cells are uniform in `u = tan((θ − θ̄)/4)` (`θ̄` the middle of the joint's range), which
//! needs no arc tangent at run time and stretches cells by at most 2 against uniform angles.
//! Each cell's angle interval is widened by [`ANGLE_PAD`] for the `f32` poses' rounding, a
//! lane outside the table (or NaN) is undecided, and gaps and depths must exceed the bubble by
//! [`SLACK`] and [`DEPTH_SLACK`] (the exact distance's own tolerance).

use super::LaneMask;
use super::lanes::{F, Flags, PORTABLE};
use crate::levers::Levers;
use crate::model::CollisionModel;
use trm_kinematics::{JointKind, PoseLanes32};

/// Radians added on each side of a cell's angle interval: the `f32` poses' rounding (a few
/// 10⁻⁷ rad) many times over.
const ANGLE_PAD: f64 = 1e-4;

/// Metres by which a gap must exceed the bubble's reach: the exact distance's tolerance.
const SLACK: f64 = 1e-5;

/// Metres by which a depth must exceed the bubble's reach. The depth of touching convex
/// bodies is parry's EPA: the distance to a face of a polytope inside their Minkowski
/// difference, so never more than the true depth; this covers its rounding many times over.
const DEPTH_SLACK: f64 = 1e-4;

/// The farthest a cell's configurations may move the far link's points, per joint (metres):
/// cells are sized so that each joint's half-width times its lever arm is at most this, until
/// [`MAX_CELLS`] stops them.
const REACH_PER_JOINT: f64 = 1.5e-3;

/// Most cells in one table (a bit each).
const MAX_CELLS: usize = 1 << 17;

/// How a tabled joint's angle is read from a block's poses: one per joint, shared by every
/// table over it ([`FastModel`](super::FastModel) keeps them; a block reads each at most once).
#[derive(Debug, Clone)]
pub(super) struct AngleReader {
    /// The joint (tree index), and the pose indices of its parent and child links.
    joint: u32,
    parent: u32,
    child: u32,
    /// The joint origin's rotation `w, x, y, z`.
    origin: [f32; 4],
    /// The joint's unit axis in its own frame.
    axis: [f32; 3],
    /// `cos`, `sin` of half the middle of the joint's tabled range.
    middle: [f32; 2],
    /// The lowest `u` of the tabled range.
    u_low: f32,
}

impl AngleReader {
    /// The reader of the joint of `axis` (its range checked by [`range`]).
    fn new(tree: &trm_kinematics::Tree, axis: &Axis) -> Self {
        let joint = &tree.joints[axis.joint];
        let o = joint.local_origin.rotation;
        let middle = 0.25 * (axis.low + axis.high);
        AngleReader {
            joint: axis.joint as u32,
            parent: joint.parent as u32,
            child: joint.child as u32,
            origin: [o.w, o.i, o.j, o.k].map(|v| v as f32),
            axis: [joint.axis.x, joint.axis.y, joint.axis.z].map(|v| v as f32),
            middle: [middle.cos() as f32, middle.sin() as f32],
            u_low: axis.u_low as f32,
        }
    }

    /// The joint it reads (tree index).
    pub(super) fn joint(&self) -> usize {
        self.joint as usize
    }

    /// `u − u_low` of the joint's angle in every lane (NaN in, NaN out).
    #[inline(always)]
    fn read(&self, poses: &[PoseLanes32]) -> F {
        let (p, b) = (&poses[self.parent as usize], &poses[self.child as usize]);
        let (pw, px, py, pz) = (F(p[0]), F(p[1]), F(p[2]), F(p[3]));
        let (bw, bx, by, bz) = (F(b[0]), F(b[1]), F(b[2]), F(b[3]));
        let [ow, ox, oy, oz] = self.origin.map(F::splat);
        // A = parent ⊗ origin
        let aw = pw * ow - px * ox - py * oy - pz * oz;
        let ax = pw * ox + px * ow + py * oz - pz * oy;
        let ay = pw * oy - px * oz + py * ow + pz * ox;
        let az = pw * oz + px * oy - py * ox + pz * ow;
        // conj(A) ⊗ child = (cos θ/2, sin θ/2 · axis)
        let [nx, ny, nz] = self.axis.map(F::splat);
        let c = aw * bw + ax * bx + ay * by + az * bz;
        let (n_b, n_a) = (nx * bx + ny * by + nz * bz, nx * ax + ny * ay + nz * az);
        let cross = nx * (ay * bz - az * by) + ny * (az * bx - ax * bz) + nz * (ax * by - ay * bx);
        let s = aw * n_b - bw * n_a - cross;
        // φ = θ/2 − θ̄/2, then u = tan(φ/2)
        let (cm, sm) = (F::splat(self.middle[0]), F::splat(self.middle[1]));
        let (sin_phi, cos_phi) = (s * cm - c * sm, c * cm + s * sm);
        // q and −q are one rotation: the one with cos φ ≥ 0 (θ within π of θ̄)
        let sign = cos_phi.map(|v| if v < 0.0 { -1.0 } else { 1.0 });
        let (sin_phi, cos_phi) = (sin_phi * sign, cos_phi * sign);
        sin_phi / (F::splat(1.0) + cos_phi) - F::splat(self.u_low)
    }
}

/// The joints' readings of a block, made when first needed: [`FastScratch`](super::FastScratch)
/// keeps one, cleared per block.
#[derive(Debug, Clone, Default)]
pub(super) struct Angles {
    /// Per reader: `u − u_low` in every lane, valid when `read`.
    values: Vec<F>,
    read: Vec<bool>,
}

impl Angles {
    /// Room for `readers` readings, none made.
    pub(super) fn new(readers: usize) -> Self {
        Angles {
            values: vec![F::default(); readers],
            read: vec![false; readers],
        }
    }

    /// Forgets the readings (a new block).
    #[inline(always)]
    pub(super) fn clear(&mut self) {
        self.read.fill(false);
    }
}

/// One joint of a table: its reader (an index into the model's readers) and its cells.
#[derive(Debug, Clone)]
struct TableAxis {
    reader: u32,
    /// Cells per unit of `u`.
    per_u: f32,
    cells: u32,
}

/// The decided cells of a link pair moved relative to each other by one or two revolute joints
/// (made by [`PairTable::build`]).
#[derive(Debug, Clone)]
pub(super) struct PairTable {
    /// Nearest the near link first; the cell index is row-major in this order.
    axes: Vec<TableAxis>,
    /// One bit per cell: set when every configuration in it is free.
    free: Vec<u64>,
    /// One bit per cell: set when every configuration in it collides.
    hit: Vec<u64>,
}

impl PairTable {
    /// The lanes of `lanes` whose angles fall in a free cell (there the pair is clear) and
    /// those in a colliding cell (there it certainly collides): the angles read by `readers`
    /// from `poses`, or taken from `angles` when this block read them already.
    #[inline(always)]
    pub(super) fn lookup(
        &self,
        readers: &[AngleReader],
        angles: &mut Angles,
        poses: &[PoseLanes32],
        lanes: LaneMask,
    ) -> (LaneMask, LaneMask) {
        let mut index = F::splat(0.0);
        let mut outside = Flags::default();
        for axis in &self.axes {
            let r = axis.reader as usize;
            if !angles.read[r] {
                angles.values[r] = readers[r].read(poses);
                angles.read[r] = true;
            }
            let x = angles.values[r] * F::splat(axis.per_u);
            let cells = axis.cells as f32;
            outside = outside | x.outside(0.0, cells);
            // exact: cell indices stay far below 2²⁴
            index = index * F::splat(cells) + x.map(f32::floor);
        }
        let inside = lanes & !outside.mask::<PORTABLE>();
        let (mut free, mut hit) = (0, 0);
        let mut bits = inside;
        while bits != 0 {
            let l = bits.trailing_zeros() as usize;
            let i = index.0[l] as usize;
            let (word, bit) = (i / 64, i % 64);
            free |= ((self.free[word] >> bit) as u8 & 1) << l;
            hit |= ((self.hit[word] >> bit) as u8 & 1) << l;
            bits &= bits - 1;
        }
        (free, hit)
    }

    /// Points the table's axes at the model's readers (`readers`: their indices, in the order
    /// of the readers [`PairTable::build`] gave).
    pub(super) fn attach(&mut self, readers: &[u32]) {
        for (a, &r) in self.axes.iter_mut().zip(readers) {
            a.reader = r;
        }
    }

    /// The fractions of the table's cells that are free and that collide (for tests).
    #[cfg(test)]
    pub(super) fn decided(&self) -> [f64; 2] {
        let cells: usize = self.axes.iter().map(|a| a.cells as usize).product();
        let count = |bits: &[u64]| bits.iter().map(|w| w.count_ones()).sum::<u32>();
        [count(&self.free), count(&self.hit)].map(|n| f64::from(n) / cells as f64)
    }

    /// The table of the pair of links `a` and `b` whose checked bodies are `bodies` (indices
    /// into the model's bodies), when one link lies below the other and the joints between
    /// them are one or two revolute or continuous joints without `<mimic>`, besides fixed ones;
    /// `None` otherwise. A joint that turns a whole turn or more is tabled over every rotation.
    /// With the table, the readers of its joints' angles, nearest the near link first (to be
    /// shared with other tables and [attached](PairTable::attach)).
    pub(super) fn build(
        model: &CollisionModel,
        levers: &Levers,
        a: usize,
        b: usize,
        bodies: &[(u32, u32)],
    ) -> Option<(PairTable, Vec<AngleReader>)> {
        let robot = model.robot();
        let tree = robot.tree();
        let (far, path) = chain(tree, a, b)
            .map(|p| (b, p))
            .or_else(|| chain(tree, b, a).map(|p| (a, p)))?;
        let movable: Vec<usize> = path
            .into_iter()
            .filter(|&j| tree.joints[j].kind != JointKind::Fixed)
            .collect();
        if movable.is_empty() || movable.len() > 2 {
            return None;
        }
        let mut axes = Vec::new();
        for &j in &movable {
            let lever = levers.arm(far, j)?;
            axes.push(Axis::new(j, range(&tree.joints[j])?, lever));
        }
        // cells of width ≤ 4 du in angle: du = half the half-width the reach allows
        let mut counts: Vec<usize> = axes
            .iter()
            .map(|x| {
                let du = 0.5 * REACH_PER_JOINT / x.lever.max(1e-9);
                ((x.u_high - x.u_low) / du).ceil().clamp(1.0, 4096.0) as usize
            })
            .collect();
        let total: usize = counts.iter().product();
        if total > MAX_CELLS {
            let shrink = (MAX_CELLS as f64 / total as f64).powf(1.0 / counts.len() as f64);
            for c in &mut counts {
                *c = ((*c as f64 * shrink).floor() as usize).max(1);
            }
        }
        for (x, &c) in axes.iter_mut().zip(&counts) {
            x.cut(c);
        }
        let (free, hit) = Flood::new(model, &axes, bodies)?.run();
        let readers = axes.iter().map(|x| AngleReader::new(tree, x)).collect();
        let axes = axes
            .iter()
            .map(|x| TableAxis {
                reader: 0, // until attached
                per_u: (x.cells as f64 / (x.u_high - x.u_low)) as f32,
                cells: x.cells as u32,
            })
            .collect();
        Some((PairTable { axes, free, hit }, readers))
    }
}

/// The joints from link `ancestor` down to link `link` (tree indices, nearest `ancestor`
/// first), when `ancestor` is an ancestor of `link`.
fn chain(tree: &trm_kinematics::Tree, ancestor: usize, link: usize) -> Option<Vec<usize>> {
    let mut joints = Vec::new();
    let mut at = link;
    while at != ancestor {
        let j = tree.links[at].parent_joint?;
        joints.push(j);
        at = tree.joints[j].parent;
    }
    joints.reverse();
    Some(joints)
}

/// The range a joint is tabled over: its limits, or a whole turn about 0 for a joint that turns
/// (nearly) a whole turn or more; `None` unless it is a revolute or continuous joint without
/// `<mimic>`.
fn range(joint: &trm_kinematics::Joint) -> Option<(f64, f64)> {
    let pi = std::f64::consts::PI;
    let (lo, hi) = (joint.limits.lower, joint.limits.upper);
    let (lo, hi) = if hi - lo < 2.0 * pi - 0.2 {
        (lo, hi)
    } else {
        (-pi, pi)
    };
    let usable = matches!(joint.kind, JointKind::Revolute | JointKind::Continuous)
        && joint.mimic.is_none()
        && hi > lo;
    usable.then_some((lo, hi))
}

/// One joint of a table while building it: its range, lever arm and cells in `u`.
#[derive(Debug, Clone)]
struct Axis {
    joint: usize,
    low: f64,
    high: f64,
    lever: f64,
    u_low: f64,
    u_high: f64,
    cells: usize,
    /// Each cell's angle interval, widened by [`ANGLE_PAD`] (made by [`Axis::cut`]).
    intervals: Vec<[f64; 2]>,
}

impl Axis {
    fn new(joint: usize, (low, high): (f64, f64), lever: f64) -> Self {
        let quarter = 0.25 * (high - low);
        Axis {
            joint,
            low,
            high,
            lever,
            u_low: (-0.5 * quarter).tan(),
            u_high: (0.5 * quarter).tan(),
            cells: 1,
            intervals: Vec::new(),
        }
    }

    /// Cuts the joint's range into `cells` cells.
    fn cut(&mut self, cells: usize) {
        self.cells = cells;
        let du = (self.u_high - self.u_low) / cells as f64;
        self.intervals = (0..cells)
            .map(|k| {
                let u = self.u_low + k as f64 * du;
                [self.angle(u) - ANGLE_PAD, self.angle(u + du) + ANGLE_PAD]
            })
            .collect();
    }

    /// The angle at `u`: `θ̄ + 4 atan u`.
    fn angle(&self, u: f64) -> f64 {
        0.5 * (self.low + self.high) + 4.0 * u.atan()
    }
}

/// The bubble flood that marks a table's decided cells: each cell not yet decided is measured
/// at its middle, and every cell within the bubble of that signed distance is marked free (a
/// gap) or colliding (a depth).
struct Flood<'a> {
    model: &'a CollisionModel,
    axes: &'a [Axis],
    bodies: &'a [(u32, u32)],
    joints: Vec<f64>,
    pose: trm_kinematics::PoseBuffer,
    placed: crate::placed::PlacedBodies,
    /// Cells proved free and proved colliding, one bit each.
    free: Vec<u64>,
    hit: Vec<u64>,
}

impl<'a> Flood<'a> {
    fn new(model: &'a CollisionModel, axes: &'a [Axis], bodies: &'a [(u32, u32)]) -> Option<Self> {
        let robot = model.robot();
        let cells: usize = axes.iter().map(|x| x.cells).product();
        let tree = robot.tree();
        if bodies.is_empty()
            || axes
                .iter()
                .any(|x| tree.joints[x.joint].coordinate.is_none())
        {
            return None;
        }
        Some(Flood {
            model,
            axes,
            bodies,
            joints: vec![0.0; robot.num_joints()],
            pose: robot.pose_buffer(),
            placed: model.placed_bodies(),
            free: vec![0; cells.div_ceil(64)],
            hit: vec![0; cells.div_ceil(64)],
        })
    }

    /// The cells' bits (free, colliding) once every cell is decided or measured: coarse to
    /// fine (every 32nd cell along each joint first, then every 16th, …), so that the wide
    /// bubbles far from contact are measured first and decide most cells.
    fn run(mut self) -> (Vec<u64>, Vec<u64>) {
        let dims: Vec<usize> = self.axes.iter().map(|x| x.cells).collect();
        let (rows, columns) = (dims[0], dims.get(1).copied().unwrap_or(1));
        for stride in [32, 16, 8, 4, 2, 1] {
            for r in (0..rows).step_by(stride) {
                for c in (0..columns).step_by(stride) {
                    let at = [r, c];
                    self.measure(r * columns + c, &at[..dims.len()], &dims);
                }
            }
        }
        (self.free, self.hit)
    }

    /// Measures cell `i` (at `at`) unless it is decided, and floods its bubble.
    fn measure(&mut self, i: usize, at: &[usize], dims: &[usize]) {
        {
            if bit(&self.free, i) || bit(&self.hit, i) {
                return;
            }
            let middle: Vec<f64> = at
                .iter()
                .zip(self.axes)
                .map(|(&k, x)| {
                    let [lo, hi] = x.intervals[k];
                    0.5 * (lo + hi)
                })
                .collect();
            let Some(d) = self.distance(&middle) else {
                return;
            };
            if d > 0.0 {
                self.mark(&middle, d - SLACK, dims, at, true);
            } else {
                self.mark(&middle, -d - DEPTH_SLACK, dims, at, false);
            }
        }
    }

    /// The signed distance between the pair's checked bodies with the joints at `angles`: the
    /// smallest gap, or minus the largest depth when some touch (`None` if forward kinematics
    /// refuses the angles).
    fn distance(&mut self, angles: &[f64]) -> Option<f64> {
        let robot = self.model.robot();
        for (x, &v) in self.axes.iter().zip(angles) {
            self.joints[robot.tree().joints[x.joint].coordinate?] = v;
        }
        robot.forward_joints(&self.joints, &mut self.pose).ok()?;
        let mut d = f64::INFINITY;
        for &(a, b) in self.bodies {
            let (a, b) = (a as usize, b as usize);
            self.model.place_body(&self.pose, a, &mut self.placed);
            self.model.place_body(&self.pose, b, &mut self.placed);
            // touching bodies certify no gap: their depth, at most 0
            let touching = self.model.bodies_touch(&self.placed, a, b);
            let pair = self
                .model
                .body_distance_knowing(&self.placed, a, b, touching);
            let pair = if touching {
                pair.min(0.0)
            } else {
                pair.max(0.0)
            };
            d = d.min(pair);
        }
        d.is_finite().then_some(d)
    }

    /// Marks free (`free`) or colliding every cell whose whole interval lies within reach
    /// `budget` of `middle` (weighted by the lever arms), walking outwards from cell `at`
    /// along each joint.
    fn mark(&mut self, middle: &[f64], budget: f64, dims: &[usize], at: &[usize], free: bool) {
        if budget <= 0.0 {
            return;
        }
        // per axis: the cells reachable and what each costs
        let reach: Vec<Vec<(usize, f64)>> = self
            .axes
            .iter()
            .zip(middle)
            .zip(at)
            .map(|((x, &m), &k)| {
                let cost = |c: usize| {
                    let [lo, hi] = x.intervals[c];
                    x.lever * (m - lo).abs().max((hi - m).abs())
                };
                let below = (0..=k).rev().map(|c| (c, cost(c)));
                let above = (k + 1..x.cells).map(|c| (c, cost(c)));
                let mut cells: Vec<(usize, f64)> = below.take_while(|&(_, v)| v < budget).collect();
                cells.extend(above.take_while(|&(_, v)| v < budget));
                cells
            })
            .collect();
        let bits = if free { &mut self.free } else { &mut self.hit };
        match reach.as_slice() {
            [only] => {
                for &(c, _) in only {
                    bits[c / 64] |= 1 << (c % 64);
                }
            }
            [first, second] => {
                for &(c0, v0) in first {
                    for &(c1, v1) in second {
                        if v0 + v1 < budget {
                            let i = c0 * dims[1] + c1;
                            bits[i / 64] |= 1 << (i % 64);
                        }
                    }
                }
            }
            _ => {}
        }
    }
}

/// Bit `i` of `bits`.
fn bit(bits: &[u64], i: usize) -> bool {
    bits[i / 64] >> (i % 64) & 1 != 0
}
