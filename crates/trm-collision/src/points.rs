//! Point clouds as cameras give them, made fit to plan among: thinned to a spacing (VAMP's
//! `filter_pointcloud`: a dense cloud costs time and says little more).

use std::collections::HashMap;
use std::hash::{BuildHasherDefault, Hasher};

/// A hasher for integer cell coordinates (a multiply and a rotation per word): the cells of a
/// cloud need no defence against chosen keys, and SipHash took most of the thinning's time.
#[derive(Default)]
struct CellHasher(u64);

impl Hasher for CellHasher {
    fn finish(&self) -> u64 {
        self.0
    }

    fn write(&mut self, bytes: &[u8]) {
        for word in bytes.chunks(8) {
            let mut padded = [0; 8];
            padded[..word.len()].copy_from_slice(word);
            self.write_u64(u64::from_le_bytes(padded));
        }
    }

    fn write_i64(&mut self, v: i64) {
        self.write_u64(v as u64);
    }

    fn write_u64(&mut self, v: u64) {
        self.0 = (self.0.rotate_left(23) ^ v).wrapping_mul(0x9e37_79b9_7f4a_7c15);
    }
}

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
    let mut cells: HashMap<[i64; 3], Vec<usize>, BuildHasherDefault<CellHasher>> =
        HashMap::default();
    let mut kept: Vec<[f64; 3]> = Vec::new();
    let spacing2 = spacing * spacing;
    for p in points {
        if !p.iter().all(|v| v.is_finite()) {
            continue;
        }
        let [x, y, z] = cell(p);
        // the point's own cell first: a dropped point is mostly crowded there
        let crowded = [0, -1, 1].into_iter().any(|dx| {
            [0, -1, 1].into_iter().any(|dy| {
                [0, -1, 1].into_iter().any(|dz| {
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
