//! Task-space nearest neighbours with kiddo kd-trees (dimension 1–6; brute force above).

use std::collections::HashMap;

use kiddo::{KdTree, SquaredEuclidean};

macro_rules! trees {
    ($($variant:ident => $k:literal),*) => {
        /// A kd-tree over task vectors, of the task's dimension.
        #[derive(Debug)]
        enum Tree {
            $($variant(Box<KdTree<f64, $k>>),)*
            /// Dimensions above 6: linear scan.
            Brute(Vec<Vec<f64>>),
        }

        impl Tree {
            fn new(dim: usize) -> Self {
                match dim {
                    $($k => Tree::$variant(Box::new(KdTree::new())),)*
                    _ => Tree::Brute(Vec::new()),
                }
            }

            fn add(&mut self, t: &[f64], item: usize) {
                match self {
                    $(Tree::$variant(tree) => {
                        let mut p = [0.0; $k];
                        p.copy_from_slice(t);
                        tree.add(&p, item as u64);
                    })*
                    Tree::Brute(points) => points.push(t.to_vec()),
                }
            }

            fn nearest(&self, t: &[f64], n: usize, out: &mut Vec<(f64, usize)>) {
                out.clear();
                match self {
                    $(Tree::$variant(tree) => {
                        let mut p = [0.0; $k];
                        p.copy_from_slice(t);
                        for nb in tree.nearest_n::<SquaredEuclidean>(&p, n) {
                            out.push((nb.distance.sqrt(), nb.item as usize));
                        }
                    })*
                    Tree::Brute(points) => {
                        out.extend(points.iter().enumerate().map(|(i, p)| (brute_distance(p, t), i)));
                        out.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
                        out.truncate(n);
                    }
                }
            }

            /// Items at most `radius` from `t` (in no particular order).
            fn within(&self, t: &[f64], radius: f64, out: &mut Vec<usize>) {
                out.clear();
                match self {
                    $(Tree::$variant(tree) => {
                        let mut p = [0.0; $k];
                        p.copy_from_slice(t);
                        // a margin for rounding, then the exact test
                        let bound = radius * radius * (1.0 + 1e-9);
                        for nb in tree.within_unsorted::<SquaredEuclidean>(&p, bound) {
                            if nb.distance.sqrt() <= radius {
                                out.push(nb.item as usize);
                            }
                        }
                    })*
                    Tree::Brute(points) => out.extend(
                        points.iter().enumerate().filter(|(_, p)| brute_distance(p, t) <= radius).map(|(i, _)| i),
                    ),
                }
            }
        }
    };
}

fn brute_distance(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).powi(2))
        .sum::<f64>()
        .sqrt()
}

trees!(D1 => 1, D2 => 2, D3 => 3, D4 => 4, D5 => 5, D6 => 6);

/// The task vectors of a map, indexed for nearest-neighbour queries.
#[derive(Debug)]
pub struct TaskIndex {
    dim: usize,
    tree: Tree,
    len: usize,
    /// The first item at each exact task vector, and the later items at the same vector:
    /// kiddo's buckets cannot hold more identical points than their size, so only the first
    /// goes into the tree and the others are added to every answer that holds it.
    first: HashMap<Vec<u64>, usize>,
    copies: HashMap<usize, Vec<usize>>,
}

impl TaskIndex {
    /// An empty index for task vectors of dimension `dim`.
    pub fn new(dim: usize) -> Self {
        TaskIndex {
            dim,
            tree: Tree::new(dim),
            len: 0,
            first: HashMap::new(),
            copies: HashMap::new(),
        }
    }

    /// Adds a point; its item is its insertion order. Any number of points may share a task
    /// vector.
    pub fn add(&mut self, t: &[f64]) {
        debug_assert_eq!(t.len(), self.dim);
        // −0.0 and 0.0 are one place
        let key: Vec<u64> = t.iter().map(|v| (v + 0.0).to_bits()).collect();
        match self.first.get(&key) {
            Some(&first) => self.copies.entry(first).or_default().push(self.len),
            None => {
                self.tree.add(t, self.len);
                self.first.insert(key, self.len);
            }
        }
        self.len += 1;
    }

    /// Number of points.
    pub fn len(&self) -> usize {
        self.len
    }

    /// True without points.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// The `n` nearest points to `t` as (distance, item), nearest first (ties by item).
    pub fn nearest(&self, t: &[f64], n: usize, out: &mut Vec<(f64, usize)>) {
        if self.len == 0 || n == 0 {
            out.clear();
            return;
        }
        self.tree.nearest(t, n.min(self.first.len()), out);
        if !self.copies.is_empty() {
            for k in 0..out.len() {
                let (dt, item) = out[k];
                if let Some(copies) = self.copies.get(&item) {
                    out.extend(copies.iter().map(|&c| (dt, c)));
                }
            }
        }
        out.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        out.truncate(n);
    }

    /// The items within `radius` of `t` (distance ≤ radius), in no particular order.
    pub fn within(&self, t: &[f64], radius: f64, out: &mut Vec<usize>) {
        self.tree.within(t, radius, out);
        if !self.copies.is_empty() {
            for k in 0..out.len() {
                if let Some(copies) = self.copies.get(&out[k]) {
                    out.extend_from_slice(copies);
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{RngExt, SeedableRng};

    /// Any number of identical task vectors (more than a kd-tree bucket holds) are found,
    /// every one of them.
    #[test]
    fn identical_points_are_all_found() {
        let mut index = TaskIndex::new(3);
        for k in 0..100 {
            index.add(&[0.1, if k % 2 == 0 { 0.0 } else { -0.0 }, 0.3]);
        }
        index.add(&[0.2, 0.0, 0.3]);
        let mut out = Vec::new();
        index.nearest(&[0.1, 0.0, 0.3], 100, &mut out);
        assert_eq!(out.len(), 100);
        assert!(
            out.iter()
                .enumerate()
                .all(|(k, &(d, i))| d == 0.0 && i == k)
        );
        index.nearest(&[0.25, 0.0, 0.3], 2, &mut out);
        assert_eq!(out.iter().map(|p| p.1).collect::<Vec<_>>(), [100, 0]);
        let mut near = Vec::new();
        index.within(&[0.1, 0.0, 0.3], 0.05, &mut near);
        near.sort();
        assert_eq!(near, (0..100).collect::<Vec<_>>());
    }

    #[test]
    fn nearest_neighbours_equal_brute_force() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(4);
        for dim in [1, 2, 3, 6, 7] {
            let points: Vec<Vec<f64>> = (0..300)
                .map(|_| (0..dim).map(|_| rng.random::<f64>()).collect())
                .collect();
            let mut index = TaskIndex::new(dim);
            for p in &points {
                index.add(p);
            }
            let mut out = Vec::new();
            for _ in 0..50 {
                let q: Vec<f64> = (0..dim).map(|_| rng.random::<f64>()).collect();
                index.nearest(&q, 4, &mut out);
                let mut brute: Vec<(f64, usize)> = points
                    .iter()
                    .enumerate()
                    .map(|(i, p)| {
                        (
                            p.iter()
                                .zip(&q)
                                .map(|(a, b)| (a - b).powi(2))
                                .sum::<f64>()
                                .sqrt(),
                            i,
                        )
                    })
                    .collect();
                brute.sort_by(|a, b| a.0.total_cmp(&b.0));
                for (a, b) in out.iter().zip(&brute[..4]) {
                    assert!((a.0 - b.0).abs() < 1e-12, "dim {dim}");
                }
                let radius = brute[7].0;
                let mut within = Vec::new();
                index.within(&q, radius, &mut within);
                within.sort();
                let mut expected: Vec<usize> = brute
                    .iter()
                    .filter(|b| b.0 <= radius)
                    .map(|b| b.1)
                    .collect();
                expected.sort();
                assert_eq!(within, expected, "dim {dim}");
            }
        }
    }
}
