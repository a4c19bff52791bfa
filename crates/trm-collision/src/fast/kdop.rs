#[cfg(target_arch = "x86_64")]
use super::avx;
use super::lanes::{F, Flags, PORTABLE, inverse_transform};
use super::model::FastModel;
use super::walk::FastScratch;
use super::{ALL_LANES, LaneMask};
use crate::shape::Shape;
use nalgebra::Point3;

/// The 9 directions of an 18-sided discrete orientation polytope (k-DOP): the axes and the
/// face diagonals of a cube, unnormalised (slab values scale with them). Measured against the
/// 26-sided one (adding the corner diagonals) and the 6-sided box: fewest lanes left to the
/// exact checks for the time spent on the MotionBenchMaker Panda's and Fetch's hulls.
pub(super) const KDOP: [[f32; 3]; 9] = [
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

/// The lanes in which every sphere of link group `a` lies beyond a slab of group `b`'s k-DOP
/// (with the margin `m`): there `a`'s bodies are clear of `b`'s. None without `b`'s k-DOP.
#[inline(always)]
pub(super) fn kdop_clear<const AVX: bool>(
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
pub(super) fn kdop_of<'a>(
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
