#[cfg(target_arch = "x86_64")]
use super::avx;
use super::cloud::{CloudGrid, MESH_SPACING};
use super::lanes::{
    F, PORTABLE, aligned_box_distance2, box_distance2, cylinder_distance2, distance2, inverse_axes,
    segment_distance2, splat, to_f32,
};
use super::model::{Ball, FastModel};
use super::outcome::{Contact, Verdict};
use super::walk::enclosing_near;
use super::{ALL_LANES, FAST_LANES, LaneMask};
use crate::error::{CollisionError, Result};
use crate::shape::Shape;
use crate::world::World;
use nalgebra::{Point3, Vector3};
use std::sync::Arc;

/// Rounding budget of the margin, m per metre of the largest coordinate per joint of the
/// deepest chain (see [`FastWorld::margin`]).
pub(super) const MARGIN_PER_METRE_JOINT: f64 = 1e-6;

/// A world object as the single-precision checks see it.
#[derive(Debug, Clone, Copy)]
pub(super) enum Object {
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
    /// A point cloud, or a triangle mesh through samples on it: the points' box (centre and
    /// half sizes) and their radius (0 for a mesh); the points are
    /// [`FastWorld::clouds`]`[index]`.
    Cloud {
        index: u32,
        center: [f32; 3],
        half: [f32; 3],
        radius: f32,
    },
}

/// A world compiled for a [`FastModel`] (made by [`FastModel::world`]; compile it again when
/// the world changes).
#[derive(Debug, Clone)]
pub struct FastWorld {
    /// The objects, nearest the robot's root first.
    pub(super) objects: Vec<Object>,
    /// The world's index of each of `objects`.
    pub(super) original: Vec<u32>,
    /// Per object of `objects` (ascending): a lower bound of its distance from the world's
    /// origin ([`Object::origin_distance`]).
    pub(super) from_origin: Vec<f32>,
    /// Per object of `objects`: an axis-aligned box enclosing it (centre, half sizes;
    /// [`Object::enclosing_box`]), the first and cheapest test of a link against it.
    pub(super) boxes: Vec<([f32; 3], [f32; 3])>,
    /// The index in `objects` of each of the world's objects.
    pub(super) compiled_of: Vec<u32>,
    pub(super) margin: f32,
    /// Per ball pair of the model ([`FastModel::pairs`]): its [`limits`] with this margin.
    pub(super) limits: Vec<[f32; 2]>,
    /// The point clouds' grids ([`Object::Cloud`]), shared with the worlds compiled from this
    /// one ([`FastModel::world_after`]).
    pub(super) clouds: Vec<Arc<CloudGrid>>,
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

    /// [`Object::test`] for any object: a point cloud's nearest point, in the lanes of `lanes`
    /// near its box, as a sphere of the points' radius; with `first`, a cloud's lanes after the
    /// first certainly colliding one are left out (for a walk that ends there).
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    pub(super) fn test<const AVX: bool>(
        &self,
        object: &Object,
        contact: &mut Contact,
        c: &[F; 3],
        r: f32,
        m: f32,
        lanes: LaneMask,
        first: bool,
    ) {
        if let Object::Cloud { index, .. } = *object {
            let (certain, near) = self.glance::<AVX>(object, c, r, m, lanes);
            if near != 0 {
                let grid = &self.clouds[index as usize];
                let reach = object.reach(r);
                let outer = reach + grid.gap + m;
                // a point certainly colliding settles the lane: the scan may stop there
                let [inner2, _] = limits(reach, m);
                let d2 = grid.distance2(c, outer, inner2, near, certain, first);
                contact.add_within(d2, [inner2, outer * outer]);
            }
        } else {
            object.test::<AVX>(contact, c, r, m);
        }
    }

    /// [`FastWorld::glance`] for the spheres at `centres` (radii in `balls`) in turn, their
    /// lanes gathered, ending at the first sphere with a certain lane.
    #[inline(always)]
    pub(super) fn glance_balls<const AVX: bool>(
        &self,
        object: &Object,
        centres: &[[F; 3]],
        balls: &[Ball],
        m: f32,
        lanes: LaneMask,
    ) -> (LaneMask, LaneMask) {
        #[cfg(target_arch = "x86_64")]
        if AVX
            && let Object::Cloud {
                index,
                center,
                half,
                radius,
            } = *object
        {
            let grid = &self.clouds[index as usize];
            // SAFETY: as in `F::any_within`
            #[allow(unsafe_code)]
            return unsafe {
                grid.glance_balls_avx(center, half, radius, centres, balls, m, lanes)
            };
        }
        let (mut hit, mut close) = (0, 0);
        for (c, ball) in centres.iter().zip(balls) {
            let (h, o) = self.glance::<AVX>(object, c, ball.radius, m, lanes);
            (hit, close) = (hit | h, close | o);
            if hit != 0 {
                break;
            }
        }
        (hit, close)
    }

    /// What point cloud `object`'s cells say of the spheres of radius `r` at `c` in the lanes
    /// of `lanes`, without a scan of its points: the lanes certainly touching a point (the
    /// cell's witness within reach), and those a point may touch within the margin (the
    /// cell's clearance within reach; NaN lanes and the certain ones included).
    #[inline(always)]
    pub(super) fn glance<const AVX: bool>(
        &self,
        object: &Object,
        c: &[F; 3],
        r: f32,
        m: f32,
        lanes: LaneMask,
    ) -> (LaneMask, LaneMask) {
        let Object::Cloud {
            index,
            center,
            half,
            radius,
        } = *object
        else {
            return (0, lanes);
        };
        #[cfg(target_arch = "x86_64")]
        if AVX {
            use std::arch::x86_64::_mm256_set1_ps;
            let grid = &self.clouds[index as usize];
            // SAFETY: as in `F::any_within`
            #[allow(unsafe_code)]
            return unsafe {
                let centre = center.map(|v| _mm256_set1_ps(v));
                let halves = half.map(|v| _mm256_set1_ps(v));
                grid.glance_avx(&centre, &halves, radius, c, r, m, lanes)
            };
        }
        let near = lanes & object.near::<AVX>(c, r + m);
        if near == 0 {
            return (0, 0);
        }
        let grid = &self.clouds[index as usize];
        let reach = object.reach(r);
        // the lanes a cell's clearance does not settle, all at once
        let near = grid.may_touch::<AVX>(c, reach + grid.gap + m, near);
        if near == 0 {
            return (0, 0);
        }
        // and those a cell's witness settles
        (grid.holding::<AVX>(c, (reach - m).max(0.0), near), near)
    }

    /// Spheres of radius `radius` (m, 0 or more) at `centres`, one per lane (`centres[0]`
    /// holds each lane's x, `centres[1]` its y, `centres[2]` its z), screened in single
    /// precision against every object: `colliding` holds **every** lane certainly touching an
    /// object, `uncertain` the lanes within the margin of contact and certain of none (check
    /// those exactly, as [`FastWorld::spheres_touching`] does). Lanes that are not finite are
    /// uncertain.
    pub fn screen_spheres(&self, centres: &[[f32; FAST_LANES]; 3], radius: f32) -> Verdict {
        let c = [F(centres[0]), F(centres[1]), F(centres[2])];
        let (hit, close) = screen_spheres_in(self, &c, radius);
        // 0·x is 0 for a finite x, NaN otherwise
        let mut unmeasured = if radius.is_finite() { 0 } else { ALL_LANES };
        for l in 0..FAST_LANES {
            let zero: f32 = (0..3).map(|k| 0.0 * centres[k][l]).sum();
            unmeasured |= LaneMask::from(zero != 0.0) << l;
        }
        Verdict {
            colliding: hit & !unmeasured,
            uncertain: (close & !hit) | unmeasured,
        }
    }

    /// The lanes (bit `l` for `centres[l]`) in which a sphere of radius `radius` at the centre
    /// touches or overlaps an object of `world`, exactly: the single-precision screen
    /// ([`FastWorld::screen_spheres`]), then its uncertain lanes in `f64`
    /// ([`World::sphere_touches`]). `self` must be compiled from `world`. An error for more
    /// than [`FAST_LANES`] centres, a value that is not finite, or a negative radius.
    pub fn spheres_touching(
        &self,
        world: &World,
        centres: &[[f64; 3]],
        radius: f64,
    ) -> Result<LaneMask> {
        if centres.len() > FAST_LANES {
            return Err(CollisionError::InvalidValue {
                what: format!("{} sphere centres", centres.len()),
                problem: format!("one query takes at most {FAST_LANES}; split them"),
            });
        }
        // (the radius is checked with the first centre, or alone)
        for c in centres
            .iter()
            .chain(centres.is_empty().then_some(&[0.0; 3]))
        {
            crate::world::check_sphere(c, radius)?;
        }
        Ok(self.spheres_touching_unchecked(world, centres, radius))
    }

    /// [`FastWorld::spheres_touching`] without its checks: up to [`FAST_LANES`] centres (more
    /// panic); a lane whose centre or radius is not finite counts as touching.
    pub fn spheres_touching_unchecked(
        &self,
        world: &World,
        centres: &[[f64; 3]],
        radius: f64,
    ) -> LaneMask {
        let mut padded = [[f64::NAN; 3]; FAST_LANES];
        padded[..centres.len()].copy_from_slice(centres);
        let lanes = std::array::from_fn(|k| std::array::from_fn(|l| padded[l][k] as f32));
        let used = ((1u16 << centres.len()) - 1) as LaneMask;
        let verdict = self.screen_spheres(&lanes, radius as f32);
        let mut touching = verdict.colliding & used;
        let mut uncertain = verdict.uncertain & used;
        while uncertain != 0 {
            let l = uncertain.trailing_zeros() as usize;
            uncertain &= uncertain - 1;
            let finite = radius.is_finite() && centres[l].iter().all(|v| v.is_finite());
            if !finite || world.sphere_touches_unchecked(centres[l], radius).is_some() {
                touching |= 1 << l;
            }
        }
        touching
    }
}

/// [`FastWorld::screen_spheres`]: the lanes certainly touching an object, and those within the
/// margin of contact with one (the certain ones among them). Each object's enclosing box
/// first; a lane certain of one object is not tested against the later ones.
#[allow(unsafe_code)] // multiversion's run-time CPU-feature dispatch
#[multiversion::multiversion(targets("x86_64+avx2+fma", "x86_64+avx", "aarch64+neon"))]
fn screen_spheres_in(world: &FastWorld, c: &[F; 3], r: f32) -> (LaneMask, LaneMask) {
    // the AVX code paths take AVX2 and FMA: the plain-AVX clone goes without them
    const AVX: bool = multiversion::target::selected_target!().supports_feature_str("avx2")
        && multiversion::target::selected_target!().supports_feature_str("fma");
    let m = world.margin;
    let (mut contact, mut open) = (Contact::default(), ALL_LANES);
    for (k, object) in world.objects.iter().enumerate() {
        if !enclosing_near::<AVX>(world, k, c, r + m, open) {
            continue;
        }
        world.test::<AVX>(object, &mut contact, c, r, m, open, false);
        open = !contact.hit.mask::<AVX>();
        if open == 0 {
            break;
        }
    }
    (contact.hit.mask::<AVX>(), contact.close.mask::<AVX>())
}

impl FastModel {
    /// `world` compiled for [`FastModel::check`], with its margin (see [`FastWorld::margin`]).
    pub fn world(&self, world: &World) -> FastWorld {
        self.compile_world(world, None)
    }

    /// `world` compiled as [`FastModel::world`] does, taking from `compiled` (this model's
    /// compilation of `before`) every object that has not changed (the same name, shape and
    /// pose): only what was added, moved or reshaped is compiled again (a point cloud's or a
    /// mesh's grid is the costly part). The result is the one [`FastModel::world`] gives.
    pub fn world_after(&self, world: &World, before: &World, compiled: &FastWorld) -> FastWorld {
        self.compile_world(world, Some((before, compiled)))
    }

    fn compile_world(&self, world: &World, reuse: Option<(&World, &FastWorld)>) -> FastWorld {
        let mut farthest: f64 = 0.0;
        // a point cloud's cells: sized by the largest sphere's reach
        let cloud_cell = (self.balls.iter().chain(&self.inner))
            .map(|b| b.radius)
            .fold(0.0, f32::max);
        // and their clearances bounded as far as the largest link's bounding sphere reaches
        let far = (self.groups.iter())
            .map(|g| g.bound.radius)
            .fold(cloud_cell, f32::max);
        let mut clouds = Vec::new();
        let objects: Vec<Object> = world
            .objects()
            .iter()
            .map(|o| {
                let pose = o.pose();
                let bounds = o.bounding_box();
                let (mins, maxs) = (bounds.mins, bounds.maxs);
                farthest = farthest.max(mins.coords.amax()).max(maxs.coords.amax());
                if let Some((object, compiled)) = reuse.and_then(|(before, compiled)| {
                    let k = before.index(o.name()).ok()?;
                    let old = &before.objects()[k];
                    (old.pose() == pose && old.shape() == o.shape())
                        .then(|| (compiled.objects[compiled.compiled_of[k] as usize], compiled))
                }) {
                    // unchanged: its compiled form, its grid shared
                    return match object {
                        Object::Cloud {
                            index,
                            center,
                            half,
                            radius,
                        } => {
                            clouds.push(Arc::clone(&compiled.clouds[index as usize]));
                            Object::Cloud {
                                index: clouds.len() as u32 - 1,
                                center,
                                half,
                                radius,
                            }
                        }
                        other => other,
                    };
                }
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
                    Shape::Points { points, radius } => {
                        let points: Vec<[f32; 3]> = points
                            .iter()
                            .map(|p| to_f32((pose * Point3::from(*p)).coords))
                            .collect();
                        // cells of 0.4 reach: finer ones cost more to build than their
                        // tighter clearances save (0.25: twice the build, the same checks)
                        let reach = cloud_cell + *radius as f32;
                        let grid =
                            CloudGrid::new(&points, 0.4 * reach, reach, far + *radius as f32);
                        let object = Object::Cloud {
                            index: clouds.len() as u32,
                            center: grid.center,
                            half: grid.half,
                            radius: *radius as f32,
                        };
                        clouds.push(Arc::new(grid));
                        object
                    }
                    Shape::Mesh {
                        vertices,
                        triangles,
                    } if let Some(grid) = {
                        let corners: Vec<[[f64; 3]; 3]> = (triangles.iter())
                            .map(|t| t.map(|v| (pose * Point3::from(vertices[v as usize])).into()))
                            .collect();
                        CloudGrid::of_mesh(&corners, 0.5 * cloud_cell, far + MESH_SPACING)
                    } =>
                    {
                        let object = Object::Cloud {
                            index: clouds.len() as u32,
                            center: grid.center,
                            half: grid.half,
                            radius: 0.0,
                        };
                        clouds.push(Arc::new(grid));
                        object
                    }
                    Shape::Convex { .. } | Shape::Mesh { .. } => {
                        let c = bounds.center();
                        Object::Bounded {
                            center: to_f32(c.coords),
                            radius: (0.5 * (maxs - mins).norm()) as f32,
                        }
                    }
                }
            })
            .collect();
        // nearest the world's origin (the robot's root) first, as VAMP sorts its environment: a
        // block that collides mostly collides there, the walk stops at its first collision, and
        // a sphere nearer the origin than an object is also clear of every later one
        let from_origin: Vec<f32> = objects.iter().map(Object::origin_distance).collect();
        let mut order: Vec<u32> = (0..objects.len() as u32).collect();
        order.sort_by(|&a, &b| from_origin[a as usize].total_cmp(&from_origin[b as usize]));
        let mut compiled_of = vec![0; order.len()];
        for (k, &o) in order.iter().enumerate() {
            compiled_of[o as usize] = k as u32;
        }
        let sorted = order.iter().map(|&o| objects[o as usize]).collect();
        let largest = self.reach.max(farthest);
        // placing and measuring, one more step where a sphere is taken into a box link's frame
        let solid = (self.groups.iter()).any(|g| g.solid.is_some() || g.kdop.is_some());
        let steps = self.depth + 2 + usize::from(solid);
        let margin = (MARGIN_PER_METRE_JOINT * (1.0 + largest) * steps as f64) as f32;
        FastWorld {
            objects: sorted,
            from_origin: order.iter().map(|&o| from_origin[o as usize]).collect(),
            boxes: order
                .iter()
                .map(|&o| objects[o as usize].enclosing_box())
                .collect(),
            original: order,
            compiled_of,
            margin,
            clouds,
            limits: self
                .pairs
                .iter()
                .map(|&(_, _, r)| limits(r, margin))
                .collect(),
        }
    }
}

impl Object {
    /// A lower bound of the distance from the world's origin to the object (0 where it holds
    /// the origin): a sphere whose every point lies nearer the origin misses it. Measured in
    /// `f64` from the object's single-precision geometry, less 1 µm per metre.
    pub(super) fn origin_distance(&self) -> f32 {
        let d2 = self.distance2(&splat([0.0; 3])).0[0];
        let d = f64::from(d2).sqrt() - f64::from(self.reach(0.0));
        (d - 1e-6 * (1.0 + d.abs())).max(0.0) as f32
    }

    /// An axis-aligned box enclosing the object (its geometry widened by its radius): centre
    /// and half sizes, measured in `f64` from the single-precision geometry and widened by
    /// 1 µm per metre, so that a point outside the box is outside the object.
    pub(super) fn enclosing_box(&self) -> ([f32; 3], [f32; 3]) {
        let f = |v: [f32; 3]| v.map(f64::from);
        // the half sizes along the world's axes of a box with half sizes `h` along the rows
        // of `axes` (each row: one of the box's axes in world coordinates)
        let turned = |axes: &[[f32; 3]; 3], h: [f64; 3]| -> [f64; 3] {
            std::array::from_fn(|k| (0..3).map(|j| f64::from(axes[j][k]).abs() * h[j]).sum())
        };
        let (center, half): ([f64; 3], [f64; 3]) = match *self {
            Object::Round { a, b, radius } => {
                let (a, b) = (f(a), f(b));
                (
                    std::array::from_fn(|k| 0.5 * (a[k] + b[k])),
                    std::array::from_fn(|k| 0.5 * (a[k] - b[k]).abs() + f64::from(radius)),
                )
            }
            Object::Box { center, axes, half } => (f(center), turned(&axes, f(half))),
            Object::Cylinder {
                center,
                axes,
                radius,
                half,
            } => {
                // the disc's extent along k is r·√(1 − z_k²), its axis's |z_k|·half
                let z = f(axes[2]);
                (
                    f(center),
                    std::array::from_fn(|k| {
                        f64::from(half) * z[k].abs()
                            + f64::from(radius) * (1.0 - z[k] * z[k]).max(0.0).sqrt()
                    }),
                )
            }
            Object::Cloud {
                center,
                half,
                radius,
                ..
            } => (f(center), f(half).map(|h| h + f64::from(radius))),
            Object::Bounded { center, radius } => (f(center), [f64::from(radius); 3]),
        };
        let far: f64 = (0..3).map(|k| center[k].abs() + half[k]).sum();
        let widen = 1e-6 * (1.0 + far);
        (center.map(|v| v as f32), half.map(|h| (h + widen) as f32))
    }

    /// The reach of a sphere of radius `r` from the object's own geometry: the sum of the radii
    /// for round objects (and a bounded object's sphere), `r` for the others.
    #[inline(always)]
    pub(super) fn reach(&self, r: f32) -> f32 {
        match *self {
            Object::Round { radius, .. }
            | Object::Bounded { radius, .. }
            | Object::Cloud { radius, .. } => r + radius,
            Object::Box { .. } | Object::Cylinder { .. } => r,
        }
    }

    /// Squared distance from the point in every lane to the object's geometry (the segment of
    /// a round object, the centre of a bounded one, a point cloud's box; 0 inside).
    #[inline(always)]
    pub(super) fn distance2(&self, c: &[F; 3]) -> F {
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
            Object::Cloud { center, half, .. } => aligned_box_distance2(c, center, half),
        }
    }

    /// Lanes whose sphere at `c` of radius `r` may come within reach of the object (its
    /// bounding sphere for [`Object::Bounded`], its points' box for [`Object::Cloud`]).
    #[inline(always)]
    pub(super) fn near<const AVX: bool>(&self, c: &[F; 3], r: f32) -> LaneMask {
        let reach = self.reach(r);
        #[cfg(target_arch = "x86_64")]
        if AVX {
            // SAFETY: as in `F::any_within`
            #[allow(unsafe_code)]
            return unsafe { avx::near(self, c, reach * reach) };
        }
        self.distance2(c).within(reach * reach).mask::<PORTABLE>()
    }

    /// Adds the sphere at `c` of radius `r` against the object (a point cloud through
    /// [`FastWorld::test`]).
    #[inline(always)]
    pub(super) fn test<const AVX: bool>(&self, contact: &mut Contact, c: &[F; 3], r: f32, m: f32) {
        debug_assert!(!matches!(self, Object::Cloud { .. }));
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

/// The squared distances below which two spheres whose radii sum to `r` certainly collide,
/// and beyond which they are certainly clear, with the margin `m`.
#[inline(always)]
pub(super) fn limits(r: f32, m: f32) -> [f32; 2] {
    let (inner, outer) = ((r - m).max(0.0), r + m);
    [inner * inner, outer * outer]
}

#[cfg(test)]
mod tests;
