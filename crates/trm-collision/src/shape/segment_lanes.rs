//! The round–round narrow phase of [`crate::shape::intersects`] for every lane of a batch at
//! once: the squared distance between two segments as parry's
//! `closest_points_segment_segment_with_locations_nD` (Ericson's algorithm) and nalgebra compute
//! it, operation for operation, with its branches turned into per-lane selects so the loops
//! vectorise. Each lane's value is the one-configuration value bit for bit (tested against parry
//! on random, degenerate, parallel and touching segments).

use trm_kinematics::{LANES, Lanes};

/// A point in every lane: `[x, y, z]`, one value per lane each.
pub(crate) type PointLanes = [Lanes; 3];

/// parry's `DEFAULT_EPSILON` for f64.
const EPS: f64 = f64::EPSILON;

/// `na::clamp(v, 0, 1)`: NaN gives 0, as there.
#[inline(always)]
fn clamp01(v: f64) -> f64 {
    if v > 0.0 {
        if v < 1.0 { v } else { 1.0 }
    } else {
        0.0
    }
}

/// nalgebra's 3-vector dot product: (x₁x₂ + y₁y₂) + z₁z₂.
#[inline(always)]
fn dot(u: &PointLanes, v: &PointLanes) -> Lanes {
    let mut out = [0.0; LANES];
    for (l, o) in out.iter_mut().enumerate() {
        *o = u[0][l] * v[0][l] + u[1][l] * v[1][l] + u[2][l] * v[2][l];
    }
    out
}

/// `q − p` in every lane.
#[inline(always)]
fn sub(q: &PointLanes, p: &PointLanes) -> PointLanes {
    let mut out = [[0.0; LANES]; 3];
    for (o, (q, p)) in out.iter_mut().zip(q.iter().zip(p)) {
        for l in 0..LANES {
            o[l] = q[l] - p[l];
        }
    }
    out
}

/// The point at parameter `s` of `[a, b]`: `a` at 0, `b` at 1, `a (1 − s) + b s` between, as
/// parry's segment locations place it.
#[inline(always)]
fn point_at(a: &PointLanes, b: &PointLanes, s: &Lanes) -> PointLanes {
    let mut out = [[0.0; LANES]; 3];
    for (o, (a, b)) in out.iter_mut().zip(a.iter().zip(b)) {
        for l in 0..LANES {
            let edge = a[l] * (1.0 - s[l]) + b[l] * s[l];
            o[l] = if s[l] == 0.0 {
                a[l]
            } else if s[l] == 1.0 {
                b[l]
            } else {
                edge
            };
        }
    }
    out
}

/// Whether `ae` and `bb` are `approx::ulps_eq!` with its defaults (ε = f64::EPSILON, 4 ulps),
/// for the case that matters here: both ≥ 0 and `ae − bb > ε` (so only the ulps test can say
/// yes).
#[inline(always)]
fn ulps_close(ae: f64, bb: f64) -> bool {
    ae.to_bits().wrapping_sub(bb.to_bits()) <= 4
}

/// Squared distance between segment `[a1, b1]` and segment `[a2, b2]` in every lane.
#[inline(always)]
pub(crate) fn segment_distance_squared_lanes(
    [a1, b1]: &[PointLanes; 2],
    [a2, b2]: &[PointLanes; 2],
) -> Lanes {
    let d1 = sub(b1, a1);
    let d2 = sub(b2, a2);
    let r = sub(a1, a2);
    let a = dot(&d1, &d1);
    let e = dot(&d2, &d2);
    let f = dot(&d2, &r);
    let c = dot(&d1, &r);
    let b = dot(&d1, &d2);
    let (mut s, mut t) = ([0.0; LANES], [0.0; LANES]);
    for l in 0..LANES {
        let (a, e, f, c, b) = (a[l], e[l], f[l], c[l], b[l]);
        // both segments non-degenerate
        let ae = a * e;
        let bb = b * b;
        let denom = ae - bb;
        let s0 = if denom > EPS && !ulps_close(ae, bb) {
            clamp01((b * f - c * e) / denom)
        } else {
            0.0
        };
        let t0 = (b * s0 + f) / e;
        let (s_both, t_both) = if t0 < 0.0 {
            (clamp01(-c / a), 0.0)
        } else if t0 > 1.0 {
            (clamp01((b - c) / a), 1.0)
        } else {
            (s0, t0)
        };
        (s[l], t[l]) = if a <= EPS {
            (0.0, if e <= EPS { 0.0 } else { clamp01(f / e) })
        } else if e <= EPS {
            (clamp01(-c / a), 0.0)
        } else {
            (s_both, t_both)
        };
    }
    let gap = sub(&point_at(a1, b1, &s), &point_at(a2, b2, &t));
    dot(&gap, &gap)
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Point3;
    use proptest::prelude::*;

    /// Two segments, by their ends.
    type Pair = ([Point3<f64>; 2], [Point3<f64>; 2]);

    /// The one-configuration value, through parry.
    fn scalar(s1: [Point3<f64>; 2], s2: [Point3<f64>; 2]) -> f64 {
        super::super::pair::segment_distance_squared(&s1[0], &s1[1], &s2[0], &s2[1])
    }

    fn lanes(segments: &[Pair; LANES]) -> Lanes {
        let pack = |pick: &dyn Fn(usize) -> Point3<f64>| -> PointLanes {
            let mut p = [[0.0; LANES]; 3];
            for l in 0..LANES {
                for (i, axis) in p.iter_mut().enumerate() {
                    axis[l] = pick(l)[i];
                }
            }
            p
        };
        let first = [pack(&|l| segments[l].0[0]), pack(&|l| segments[l].0[1])];
        let second = [pack(&|l| segments[l].1[0]), pack(&|l| segments[l].1[1])];
        segment_distance_squared_lanes(&first, &second)
    }

    fn check(segments: [Pair; LANES]) {
        let got = lanes(&segments);
        for (l, (s1, s2)) in segments.iter().enumerate() {
            let want = scalar(*s1, *s2);
            assert_eq!(
                got[l].to_bits(),
                want.to_bits(),
                "lane {l}: {s1:?} {s2:?}: {} vs {want}",
                got[l]
            );
        }
    }

    fn p(x: f64, y: f64, z: f64) -> Point3<f64> {
        Point3::new(x, y, z)
    }

    #[test]
    fn degenerate_parallel_and_touching_segments_match_parry_bit_for_bit() {
        let o = p(0.0, 0.0, 0.0);
        let x = p(1.0, 0.0, 0.0);
        let cases = [
            ([o, o], [x, x]),                                        // two points
            ([o, o], [p(0.0, 1.0, 0.0), p(1.0, 1.0, 0.0)]),          // point and segment
            ([o, x], [p(0.5, 0.5, 0.0), p(0.5, 0.5, 0.0)]),          // segment and point
            ([o, x], [p(0.0, 1.0, 0.0), p(1.0, 1.0, 0.0)]),          // parallel
            ([o, x], [p(2.0, 0.0, 0.0), p(3.0, 0.0, 0.0)]),          // collinear, apart
            ([o, x], [p(0.5, 0.0, 0.0), p(3.0, 0.0, 0.0)]),          // collinear, overlapping
            ([o, x], [p(0.5, -1.0, 0.0), p(0.5, 1.0, 0.0)]),         // crossing
            ([o, x], [p(-1.0, 1.0, 0.3), p(-1.0, 2.0, 0.3)]),        // t < 0 then s clamped
            ([o, x], [p(2.0, -2.0, 0.1), p(2.0, -1.0, 0.1)]),        // beyond the end
            ([o, x], [p(0.3, 1.0, 0.0), p(0.3 + 1e-9, 2.0, 1e-12)]), // near-parallel
            ([o, x], [p(1e-9, 1.0, 0.0), p(1.0 + 1e-9, 1.0 + 1e-17, 0.0)]),
            ([x, o], [p(0.2, 0.1, 0.0), p(0.2, 0.1, 1e-8)]), // a very short segment
        ];
        for chunk in cases.chunks(LANES) {
            let mut lanes = [cases[0]; LANES];
            lanes[..chunk.len()].copy_from_slice(chunk);
            check(lanes);
        }
        // NaN and infinity behave as in parry
        let nan = p(f64::NAN, 0.0, 0.0);
        let inf = p(f64::INFINITY, 0.0, 0.0);
        check([
            ([o, nan], [x, x]),
            ([nan, nan], [o, x]),
            ([o, inf], [x, p(1.0, 1.0, 0.0)]),
            cases[3],
        ]);
    }

    fn any_point() -> impl Strategy<Value = Point3<f64>> {
        prop::array::uniform3(-1.0f64..1.0).prop_map(|[x, y, z]| p(x, y, z))
    }

    /// A second segment that is random, nearly parallel to the first, or a scaled copy of it.
    fn pair() -> impl Strategy<Value = Pair> {
        (
            any_point(),
            any_point(),
            any_point(),
            any_point(),
            0usize..4,
            -1e-6f64..1e-6,
        )
            .prop_map(|(a1, b1, a2, b2, kind, eps)| {
                let second = match kind {
                    0 => [a2, b2],
                    1 => [a2, a2 + (b1 - a1) * (1.0 + eps)],
                    2 => [a1 + (a2 - a1) * eps, b1 + (b2 - b1) * eps],
                    _ => [a2, a2],
                };
                ([a1, b1], second)
            })
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(2000))]
        #[test]
        fn random_segments_match_parry_bit_for_bit(segments in prop::array::uniform4(pair())) {
            check(segments);
        }
    }
}
