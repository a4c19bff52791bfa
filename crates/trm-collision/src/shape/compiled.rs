//! A shape compiled for the hot path (bounding radius, segment or box form, parry form where
//! needed) and placed at a pose.

use nalgebra::{Isometry3, Point3, Translation3, UnitQuaternion, Vector3};
use std::f64::consts::PI;
use std::sync::{Arc, OnceLock};

use parry3d_f64::bounding_volume::Aabb;
use parry3d_f64::shape::{Ball, Capsule, Segment, Shape as ParryShape, SharedShape};

use super::hull::HullWalk;

/// A shape in the form the hot path uses, fixed in a parent frame (a link or the world).
#[derive(Clone)]
pub(crate) struct Compiled {
    /// Bounding-sphere centre in the parent frame.
    pub center: Point3<f64>,
    /// Bounding-sphere radius.
    pub bound: f64,
    pub geometry: Geometry,
}

#[derive(Clone)]
pub(crate) enum Geometry {
    /// A segment swept by a ball (a ball when `a == b`), end points in the parent frame:
    /// tested analytically.
    Round {
        a: Point3<f64>,
        b: Point3<f64>,
        radius: f64,
    },
    /// Any other convex shape at `local`: tested by parry, except boxes (`half_extents`)
    /// against round shapes, which are tested analytically.
    General {
        local: Isometry3<f64>,
        shape: LazyShape,
        half_extents: Option<Vector3<f64>>,
        /// Convex hulls: their vertex graph, for support points by hill climbing.
        walk: Option<Arc<HullWalk>>,
        /// Cylinders: the capsules about the shape's local y axis that enclose it and that it
        /// holds, for exact answers against round shapes before GJK.
        axial: Option<Axial>,
    },
}

/// A parry shape, made when first used where that is dear: a point cloud's compound of balls
/// (parry's BVH, about a millisecond per 5 000 points) is built by the first distance query
/// (intersection tests go through the cloud's [`PointGrid`]), so that a world holding a cloud
/// is ready in the time the grids take. Clones share the one build.
#[derive(Clone)]
pub(crate) struct LazyShape {
    shape: Arc<OnceLock<SharedShape>>,
    /// The cloud to build from, when not built yet.
    cloud: Option<Arc<super::Shape>>,
    /// A cloud's points in a grid: what intersection tests use, so that they never need the
    /// tree.
    pub(crate) grid: Option<Arc<PointGrid>>,
    /// The box enclosing the shape in its own frame.
    local_box: Aabb,
}

/// A cloud's points (radius `radius`, in the cloud's frame) counting-sorted into a uniform grid
/// of about one cell per point: which points lie near a place, without a tree.
#[derive(Debug)]
pub(crate) struct PointGrid {
    origin: Point3<f64>,
    cell: f64,
    dims: [usize; 3],
    /// Cell `c`'s points are `points[starts[c]..starts[c + 1]]` (x fastest).
    starts: Vec<u32>,
    points: Vec<Point3<f64>>,
    pub(crate) radius: f64,
}

impl PointGrid {
    /// The grid of `points` (finite, at least one) inside `bounds`.
    pub(crate) fn new(points: &[[f64; 3]], radius: f64, bounds: &Aabb) -> Self {
        let extent = bounds.extents();
        let budget = points.len().max(64) as f64;
        let count = |cell: f64| -> [usize; 3] {
            std::array::from_fn(|k| (extent[k] / cell).floor() as usize + 1)
        };
        // the cube root of the volume per point, coarsened until the cells fit the budget
        let volume = extent.iter().map(|e| e.max(2.0 * radius)).product::<f64>();
        let mut cell = (volume / budget).cbrt().max(2.0 * radius).max(1e-6);
        while count(cell).iter().map(|&n| n as f64).product::<f64>() > budget {
            cell *= 1.25;
        }
        let dims = count(cell);
        let origin = bounds.mins;
        let index = |p: &[f64; 3]| -> usize {
            let i: [usize; 3] = std::array::from_fn(|k| {
                (((p[k] - origin[k]) / cell).max(0.0) as usize).min(dims[k] - 1)
            });
            i[0] + dims[0] * (i[1] + dims[1] * i[2])
        };
        let cells = dims[0] * dims[1] * dims[2];
        let mut starts = vec![0u32; cells + 1];
        let homes: Vec<usize> = points.iter().map(index).collect();
        for &h in &homes {
            starts[h + 1] += 1;
        }
        for c in 0..cells {
            starts[c + 1] += starts[c];
        }
        let mut next = starts[..cells].to_vec();
        let mut sorted = vec![Point3::origin(); points.len()];
        for (p, &h) in points.iter().zip(&homes) {
            sorted[next[h] as usize] = Point3::from(*p);
            next[h] += 1;
        }
        PointGrid {
            origin,
            cell,
            dims,
            starts,
            points: sorted,
            radius,
        }
    }

    /// Whether `near` holds for a point within `reach` of `center` (both in the cloud's
    /// frame): every such point is offered (and some farther ones), until one holds.
    pub(crate) fn any_near(
        &self,
        center: &Point3<f64>,
        reach: f64,
        mut near: impl FnMut(&Point3<f64>) -> bool,
    ) -> bool {
        // a little over: the test decides, the grid only has to offer every point in reach
        let reach = reach + 1e-9 * (1.0 + reach);
        let range = |k: usize| -> Option<(usize, usize)> {
            let lo = (center[k] - reach - self.origin[k]) / self.cell;
            let hi = (center[k] + reach - self.origin[k]) / self.cell;
            if hi < 0.0 || lo >= self.dims[k] as f64 {
                return None;
            }
            Some((lo.max(0.0) as usize, (hi as usize).min(self.dims[k] - 1)))
        };
        let (Some(x), Some(y), Some(z)) = (range(0), range(1), range(2)) else {
            return false;
        };
        for k in z.0..=z.1 {
            for j in y.0..=y.1 {
                // a row of cells is one run of points
                let row = self.dims[0] * (j + self.dims[1] * k);
                let (from, to) = (self.starts[row + x.0], self.starts[row + x.1 + 1]);
                if self.points[from as usize..to as usize]
                    .iter()
                    .any(&mut near)
                {
                    return true;
                }
            }
        }
        false
    }
}

impl LazyShape {
    /// A shape already made.
    pub(crate) fn ready(shape: SharedShape) -> Self {
        let local_box = shape.compute_local_aabb();
        let cell = OnceLock::new();
        let _ = cell.set(shape);
        LazyShape {
            shape: Arc::new(cell),
            cloud: None,
            grid: None,
            local_box,
        }
    }

    /// `cloud` (a valid [`super::Shape::Points`], within `local_box`), its points in a grid
    /// now and in parry's form on first use.
    pub(crate) fn cloud(cloud: super::Shape, local_box: Aabb) -> Self {
        let grid = match &cloud {
            super::Shape::Points { points, radius } => {
                Some(Arc::new(PointGrid::new(points, *radius, &local_box)))
            }
            _ => None,
        };
        LazyShape {
            shape: Arc::new(OnceLock::new()),
            cloud: Some(Arc::new(cloud)),
            grid,
            local_box,
        }
    }

    /// The parry shape (made now if it has not been).
    pub(crate) fn get(&self) -> &SharedShape {
        self.shape.get_or_init(|| {
            let cloud = self.cloud.as_ref().expect("a shape not made has its cloud");
            cloud.to_parry().expect("a checked cloud converts").1
        })
    }

    /// Whether the parry shape has been made.
    #[cfg(test)]
    pub(crate) fn is_made(&self) -> bool {
        self.shape.get().is_some()
    }

    /// The box enclosing the shape at `iso`, without making it.
    pub(crate) fn compute_aabb(&self, iso: &Isometry3<f64>) -> Aabb {
        match self.shape.get() {
            Some(shape) => shape.compute_aabb(iso),
            None => self.local_box.transform_by(iso),
        }
    }
}

impl std::ops::Deref for LazyShape {
    type Target = SharedShape;

    fn deref(&self) -> &SharedShape {
        self.get()
    }
}

/// A shape between two capsules of one radius about its local y axis (a cylinder of half
/// height `outer` and that radius): every point of it lies within `radius` of the segment
/// `y ∈ [−outer, outer]`, and every point within `radius` of `y ∈ [−inner, inner]` is in it.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Axial {
    pub outer: f64,
    /// `None` when the shape is too flat to hold a capsule of its radius.
    pub inner: Option<f64>,
    pub radius: f64,
}

impl std::fmt::Debug for Compiled {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Compiled")
            .field("center", &self.center)
            .field("bound", &self.bound)
            .finish_non_exhaustive()
    }
}

/// A compiled shape moved into the world frame.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Placed {
    /// Bounding-sphere centre.
    pub center: Point3<f64>,
    /// Bounding-sphere radius.
    pub bound: f64,
    /// Round shapes: segment ends; general shapes: unused.
    pub a: Point3<f64>,
    pub b: Point3<f64>,
    /// General shapes: the shape's pose; round shapes: unused.
    pub iso: Isometry3<f64>,
}

impl Placed {
    /// The axis-aligned box of the bounding sphere.
    pub fn bounding_box(&self) -> parry3d_f64::bounding_volume::Aabb {
        let r = nalgebra::Vector3::repeat(self.bound);
        parry3d_f64::bounding_volume::Aabb::new(self.center - r, self.center + r)
    }
}

impl Default for Placed {
    fn default() -> Self {
        Placed {
            center: Point3::origin(),
            bound: 0.0,
            a: Point3::origin(),
            b: Point3::origin(),
            iso: Isometry3::identity(),
        }
    }
}

impl Compiled {
    /// Moves the shape by the parent frame's world pose.
    #[inline]
    pub fn place(&self, parent: &Isometry3<f64>, out: &mut Placed) {
        match &self.geometry {
            Geometry::Round { a, b, .. } => {
                out.a = parent * a;
                out.b = parent * b;
                out.center = nalgebra::center(&out.a, &out.b);
            }
            Geometry::General { local, .. } => {
                out.iso = parent * local;
                out.center = parent * self.center;
            }
        }
        out.bound = self.bound;
    }

    /// The smallest axis-aligned box enclosing the shape placed at `p` (exact for segments
    /// swept by balls and for boxes; parry's for other shapes).
    pub fn tight_box(&self, p: &Placed) -> parry3d_f64::bounding_volume::Aabb {
        match &self.geometry {
            Geometry::Round { radius, .. } => {
                let r = Vector3::repeat(*radius);
                parry3d_f64::bounding_volume::Aabb::new(p.a.inf(&p.b) - r, p.a.sup(&p.b) + r)
            }
            Geometry::General { shape, .. } => shape.compute_aabb(&p.iso),
        }
    }

    /// The core of a round shape placed at `p` (its segment, a point for a ball) in a frame
    /// centred on it whose z axis runs along it, as [`Compiled::round_as_parry`] places it.
    pub(crate) fn round_core(p: &Placed) -> (Isometry3<f64>, Segment) {
        let (frame, half) = Self::round_frame(p);
        let end = Point3::new(0.0, 0.0, half);
        (frame, Segment::new(-end, end))
    }

    /// A frame centred on the segment of a round shape placed at `p`, its z axis along it,
    /// and the segment's half length.
    fn round_frame(p: &Placed) -> (Isometry3<f64>, f64) {
        let middle = Translation3::from(0.5 * (p.a.coords + p.b.coords));
        let axis = p.b - p.a;
        // z onto the axis (a half turn about x when they are opposite)
        let rotation = UnitQuaternion::rotation_between(&Vector3::z(), &axis)
            .unwrap_or_else(|| UnitQuaternion::from_axis_angle(&Vector3::x_axis(), PI));
        (Isometry3::from_parts(middle, rotation), 0.5 * axis.norm())
    }

    /// A parry shape and pose for a round shape placed at `p` (ball when degenerate): centred
    /// on its own frame's origin, a capsule along that frame's z axis. (Given as a segment
    /// away from its frame's origin, parry 0.25's GJK intersection test missed penetrations of
    /// up to 13 µm between a capsule and a triangle, found by `near_contact`'s random robots.)
    pub(crate) fn round_as_parry(p: &Placed, radius: f64) -> (Isometry3<f64>, RoundShape) {
        let (frame, half) = Self::round_frame(p);
        let shape = if p.a == p.b {
            RoundShape::Ball(Ball::new(radius))
        } else {
            RoundShape::Capsule(Capsule::new_z(half, radius))
        };
        (frame, shape)
    }
}

pub(crate) enum RoundShape {
    Ball(Ball),
    Capsule(Capsule),
}

impl RoundShape {
    pub(crate) fn shape(&self) -> &dyn ParryShape {
        match self {
            RoundShape::Ball(b) => b,
            RoundShape::Capsule(c) => c,
        }
    }
}
