//! The exact squared distance between a segment and an axis-aligned box (piecewise quadratic
//! in the segment parameter), for capsule/sphere-against-box tests without GJK.

use nalgebra::{Point3, Vector3};

/// Squared distance between the segment `[a, b]` and the box `|x_i| ≤ h_i`, exactly: the squared
/// distance is convex and piecewise quadratic along the segment, with pieces separated where the
/// segment crosses a face plane; each piece is minimised in closed form.
#[inline]
pub(crate) fn segment_box_distance_squared(
    a: &Point3<f64>,
    b: &Point3<f64>,
    h: &Vector3<f64>,
) -> f64 {
    let d = b - a;
    let excess = |t: f64| {
        let p = a + d * t;
        (0..3)
            .map(|i| {
                let e = p[i].abs() - h[i];
                if e > 0.0 { e * e } else { 0.0 }
            })
            .sum::<f64>()
    };
    let mut ts = [0.0f64; 8];
    ts[1] = 1.0;
    let mut n = 2;
    for i in 0..3 {
        if d[i] != 0.0 {
            for side in [-h[i], h[i]] {
                let t = (side - a[i]) / d[i];
                if t > 0.0 && t < 1.0 {
                    ts[n] = t;
                    n += 1;
                }
            }
        }
    }
    let ts = &mut ts[..n];
    ts.sort_unstable_by(f64::total_cmp);
    let mut best = f64::INFINITY;
    for w in ts.windows(2) {
        let (t0, t1) = (w[0], w[1]);
        let mid = a + d * (0.5 * (t0 + t1));
        let (mut num, mut den) = (0.0, 0.0);
        for i in 0..3 {
            let bound = if mid[i] > h[i] {
                h[i]
            } else if mid[i] < -h[i] {
                -h[i]
            } else {
                continue;
            };
            num += (bound - a[i]) * d[i];
            den += d[i] * d[i];
        }
        let t = if den > 0.0 {
            (num / den).clamp(t0, t1)
        } else {
            0.5 * (t0 + t1)
        };
        best = best.min(excess(t));
        if best == 0.0 {
            break;
        }
    }
    best
}
