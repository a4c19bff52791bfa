//! Point clouds as cameras give them, made fit to plan among: thinned to a spacing (VAMP's
//! `filter_pointcloud`: a dense cloud costs time and says little more).

use std::collections::HashMap;

/// The points kept, in their order, each at least `spacing` (m, > 0) from every point kept
/// before it: a cloud thinned to about one point per `spacing`, whose every dropped point lies
/// within `spacing` of a kept one. Non-finite points are dropped.
pub fn thin_points(points: &[[f64; 3]], spacing: f64) -> Vec<[f64; 3]> {
    if !(spacing.is_finite() && spacing > 0.0) {
        return points
            .iter()
            .filter(|p| p.iter().all(|v| v.is_finite()))
            .copied()
            .collect();
    }
    // kept points by cell of side `spacing`: a point's rivals lie in the 27 cells about it
    let cell = |p: &[f64; 3]| p.map(|v| (v / spacing).floor() as i64);
    let mut cells: HashMap<[i64; 3], Vec<usize>> = HashMap::new();
    let mut kept: Vec<[f64; 3]> = Vec::new();
    let spacing2 = spacing * spacing;
    for p in points {
        if !p.iter().all(|v| v.is_finite()) {
            continue;
        }
        let [x, y, z] = cell(p);
        let crowded = (-1..=1).any(|dx| {
            (-1..=1).any(|dy| {
                (-1..=1).any(|dz| {
                    cells.get(&[x + dx, y + dy, z + dz]).is_some_and(|near| {
                        near.iter().any(|&k| {
                            let q = kept[k];
                            (0..3).map(|a| (p[a] - q[a]).powi(2)).sum::<f64>() < spacing2
                        })
                    })
                })
            })
        });
        if !crowded {
            cells.entry([x, y, z]).or_default().push(kept.len());
            kept.push(*p);
        }
    }
    kept
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{RngExt, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// Kept points are `spacing` apart, every dropped point lies within `spacing` of a kept
    /// one, and the first point is always kept.
    #[test]
    fn thinned_clouds_keep_spacing_and_cover_the_rest() {
        let mut rng = ChaCha8Rng::seed_from_u64(2);
        let points: Vec<[f64; 3]> = (0..5000)
            .map(|_| std::array::from_fn(|_| rng.random_range(-0.3..0.3)))
            .collect();
        let d =
            |a: &[f64; 3], b: &[f64; 3]| (0..3).map(|k| (a[k] - b[k]).powi(2)).sum::<f64>().sqrt();
        let kept = thin_points(&points, 0.05);
        assert_eq!(kept[0], points[0]);
        assert!(kept.len() > 100 && kept.len() < 2000, "{}", kept.len());
        for (i, a) in kept.iter().enumerate() {
            for b in &kept[..i] {
                assert!(d(a, b) >= 0.05);
            }
        }
        for p in &points {
            assert!(kept.iter().any(|k| d(p, k) < 0.05));
        }
        assert_eq!(
            thin_points(&[[f64::NAN, 0.0, 0.0], [1.0; 3]], 0.1),
            [[1.0; 3]]
        );
    }
}
