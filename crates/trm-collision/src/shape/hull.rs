//! Support points of convex hulls found by walking the hull's vertex graph instead of scanning
//! every vertex (parry's `ConvexPolyhedron` scans all of them, 100–260 on the Panda's meshes).
//!
//! A linear function over a convex polytope has no local maximum on the polytope's edge graph
//! that is not global (the simplex method's optimality test), so climbing from any vertex to a
//! better neighbour until none is better ends at a support point. The climb starts at the
//! vertex farthest along the diagonal of the direction's octant, which is usually a few edges
//! from the answer.

use nalgebra::{Point3, Vector3};
use parry3d_f64::shape::{ConvexPolyhedron, SupportMap};

/// A convex hull's vertices and their neighbours along the hull's edges, for support points by
/// hill climbing.
#[derive(Debug, Clone)]
pub(crate) struct HullWalk {
    points: Vec<Point3<f64>>,
    /// Neighbours of vertex `v`: `neighbours[offsets[v]..offsets[v + 1]]`.
    offsets: Vec<u32>,
    neighbours: Vec<u32>,
    /// Per octant of a direction (bit 0: x ≥ 0, bit 1: y ≥ 0, bit 2: z ≥ 0): the vertex
    /// farthest along the octant's diagonal, where the climb starts.
    starts: [u32; 8],
}

impl HullWalk {
    /// The walk of `hull`; `None` when some vertex has no edge (then only a scan is certain).
    pub(crate) fn new(hull: &ConvexPolyhedron) -> Option<Self> {
        let points = hull.points().to_vec();
        let mut adjacent = vec![Vec::new(); points.len()];
        for edge in hull.edges() {
            let (a, b) = (edge.vertices[0], edge.vertices[1]);
            adjacent[a as usize].push(b);
            adjacent[b as usize].push(a);
        }
        if points.is_empty() || adjacent.iter().any(Vec::is_empty) {
            return None;
        }
        let mut offsets = Vec::with_capacity(points.len() + 1);
        let mut neighbours = Vec::new();
        offsets.push(0);
        for mut list in adjacent {
            list.sort_unstable();
            list.dedup();
            neighbours.extend(list);
            offsets.push(u32::try_from(neighbours.len()).ok()?);
        }
        let mut starts = [0; 8];
        for (octant, start) in starts.iter_mut().enumerate() {
            let sign = |bit: usize| if octant & bit != 0 { 1.0 } else { -1.0 };
            let diagonal = Vector3::new(sign(1), sign(2), sign(4));
            *start = scan(&points, &diagonal) as u32;
        }
        Some(HullWalk {
            points,
            offsets,
            neighbours,
            starts,
        })
    }

    /// Index of a vertex farthest along `dir`.
    #[inline]
    pub(crate) fn support_index(&self, dir: &Vector3<f64>) -> usize {
        let octant = usize::from(dir.x >= 0.0)
            | usize::from(dir.y >= 0.0) << 1
            | usize::from(dir.z >= 0.0) << 2;
        let mut best = self.starts[octant] as usize;
        let mut best_dot = self.points[best].coords.dot(dir);
        // steepest neighbour each step; every step strictly improves, so the climb ends (NaN
        // directions compare false and stop at the start)
        loop {
            let mut next = best;
            let (from, to) = (self.offsets[best] as usize, self.offsets[best + 1] as usize);
            for &n in &self.neighbours[from..to] {
                let dot = self.points[n as usize].coords.dot(dir);
                if dot > best_dot {
                    best_dot = dot;
                    next = n as usize;
                }
            }
            if next == best {
                return best;
            }
            best = next;
        }
    }
}

impl SupportMap for HullWalk {
    #[inline]
    fn local_support_point(&self, dir: &Vector3<f64>) -> Point3<f64> {
        self.points[self.support_index(dir)]
    }
}

/// Index of the first vertex farthest along `dir`, by scanning them all.
fn scan(points: &[Point3<f64>], dir: &Vector3<f64>) -> usize {
    let mut best = 0;
    let mut best_dot = f64::NEG_INFINITY;
    for (i, p) in points.iter().enumerate() {
        let dot = p.coords.dot(dir);
        if dot > best_dot {
            best_dot = dot;
            best = i;
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{RngExt, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// Random hulls (points on and in a squashed sphere, and a flat cloud) and random
    /// directions: the walk's support value is the scan's.
    #[test]
    fn the_walk_finds_the_scans_support_value() {
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        for case in 0..12 {
            let n = [8, 40, 300][case % 3];
            let flat = case % 4 == 3;
            let points: Vec<Point3<f64>> = (0..n)
                .map(|_| {
                    let v = Vector3::new(
                        rng.random_range(-1.0..1.0),
                        rng.random_range(-1.0..1.0),
                        if flat {
                            0.0
                        } else {
                            rng.random_range(-1.0..1.0)
                        },
                    );
                    let v = if case % 2 == 0 { v.normalize() } else { v };
                    Point3::from(v.component_mul(&Vector3::new(0.1, 0.03, 0.2)))
                })
                .collect();
            let Some(hull) = ConvexPolyhedron::from_convex_hull(&points) else {
                assert!(flat, "case {case}: no hull");
                continue;
            };
            let walk = HullWalk::new(&hull).expect("every vertex of a hull has edges");
            for _ in 0..2000 {
                let dir = Vector3::new(
                    rng.random_range(-1.0..1.0),
                    rng.random_range(-1.0..1.0),
                    rng.random_range(-1.0..1.0),
                );
                let walked = walk.local_support_point(&dir).coords.dot(&dir);
                let scanned = hull.points()[scan(hull.points(), &dir)].coords.dot(&dir);
                assert!(
                    (walked - scanned).abs() <= 1e-15,
                    "case {case}: {walked} vs {scanned}"
                );
            }
        }
    }
}
