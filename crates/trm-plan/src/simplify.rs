//! Simplifying a path found by RRT-Connect or through a graph: the greedy shortcut, random
//! shortcuts and corner cutting, with a record of how each edge of the result was checked.
//! Re-exported from [`crate::rrt`].

use rand::RngExt;
use trm_collision::WorldChecker;
use trm_collision::edge::distance;

use crate::rrt::RrtOptions;

/// [`RrtOptions::smoothing`]'s default: VAMP's simplifier's iterations.
pub const SMOOTHING_ROUNDS: usize = 5;

/// The least move of a waypoint corner cutting makes, rad (VAMP's B-spline `min_change`): a
/// corner flatter than this is left as it is.
pub const SMOOTHING_MIN_CHANGE: f64 = 0.1;

/// How [`shortcut`] left an edge of the path it returns.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum EdgeCheck {
    /// Found free by the shortcut at its resolution ([`WorldChecker::edge_free`]'s points).
    Checked,
    /// An edge of the given path, unchanged: checked however the path's maker checked it.
    Given,
    /// A piece of a given edge (an end of a random shortcut), not checked at points of its own.
    Piece,
}

/// Shortens `path`: first every waypoint skipped whose neighbours see each other (greedy, from
/// the start), then `options.shortcuts` random pairs of points on the path joined where the
/// straight edge is free, then `options.smoothing` rounds of corner cutting, each followed by
/// the greedy pass (see [`RrtOptions::smoothing`]). Never longer than the path given.
/// Returns how each edge of the result was checked (one per edge), so that a caller checking
/// the path again can skip what is known.
pub fn shortcut(
    path: &mut Vec<Vec<f64>>,
    options: &RrtOptions,
    checker: &mut WorldChecker,
    rng: &mut impl RngExt,
) -> Vec<EdgeCheck> {
    let mut edges = vec![EdgeCheck::Given; path.len().saturating_sub(1)];
    greedy(path, &mut edges, options.resolution, checker);
    for _ in 0..options.shortcuts {
        if path.len() < 3 {
            break;
        }
        let n = path.len();
        let (i, j) = (rng.random_range(0..n - 2), rng.random_range(0..n));
        let j = j.max(i + 2).min(n - 1);
        if j <= i + 1 {
            continue;
        }
        // points a fraction along the edges leaving i and entering j
        let (s, t) = (rng.random_range(0.0..1.0), rng.random_range(0.0..1.0));
        let lerp = |a: &[f64], b: &[f64], s: f64| -> Vec<f64> {
            a.iter().zip(b).map(|(x, y)| x + s * (y - x)).collect()
        };
        let p = lerp(&path[i], &path[i + 1], s);
        let q = lerp(&path[j - 1], &path[j], t);
        let before = distance(&p, &path[i + 1])
            + path[i + 1..j]
                .windows(2)
                .map(|w| distance(&w[0], &w[1]))
                .sum::<f64>()
            + distance(&path[j - 1], &q);
        // p and q become waypoints: checked themselves (edges are checked between their ends)
        if distance(&p, &q) < before - 1e-9
            && checker.edge_free(&p, &q, options.resolution)
            && checker.free(&p)
            && checker.free(&q)
        {
            let mut next: Vec<Vec<f64>> = path[..=i].to_vec();
            next.push(p);
            next.push(q);
            next.extend_from_slice(&path[j..]);
            let mut next_edges = edges[..i].to_vec();
            next_edges.extend([EdgeCheck::Piece, EdgeCheck::Checked, EdgeCheck::Piece]);
            next_edges.extend_from_slice(&edges[j..]);
            // repeated waypoints (a cut at an edge's end) dropped with their empty edges
            let (mut points, mut kept_edges) = (vec![next[0].clone()], Vec::new());
            for (q, e) in next.into_iter().skip(1).zip(next_edges) {
                if points.last() != Some(&q) {
                    points.push(q);
                    kept_edges.push(e);
                }
            }
            *path = points;
            edges = kept_edges;
        }
    }
    for _ in 0..options.smoothing {
        if !cut_corners(path, &mut edges, options.resolution, checker) {
            break;
        }
        greedy(path, &mut edges, options.resolution, checker);
    }
    edges
}

/// From each kept waypoint of `path`, the farthest later one it sees: the waypoints between
/// are dropped, and `edges` (one per edge) says how each edge of the result was checked.
fn greedy(
    path: &mut Vec<Vec<f64>>,
    edges: &mut Vec<EdgeCheck>,
    resolution: f64,
    checker: &mut WorldChecker,
) {
    let mut kept = vec![path[0].clone()];
    let mut kept_edges = Vec::with_capacity(edges.len());
    let mut i = 0;
    while i + 1 < path.len() {
        let mut j = path.len() - 1;
        while j > i + 1 && !checker.edge_free(&path[i], &path[j], resolution) {
            j -= 1;
        }
        kept.push(path[j].clone());
        // j > i + 1: that edge was just found free; else the edge i → i + 1, as it was
        kept_edges.push(if j > i + 1 {
            EdgeCheck::Checked
        } else {
            edges[i]
        });
        i = j;
    }
    *path = kept;
    *edges = kept_edges;
}

/// One round of corner cutting (see [`RrtOptions::smoothing`]): each interior waypoint `v`
/// (between `a` and `b`) that would move by at least [`SMOOTHING_MIN_CHANGE`] is replaced by
/// `m₁ → v' → m₂`, `m₁` and `m₂` the midpoints of `a v` and `v b` and `v'` the midpoint of
/// `m₁ m₂`, where the three points and the two edges through `v'` are free. Whether any
/// waypoint moved.
fn cut_corners(
    path: &mut Vec<Vec<f64>>,
    edges: &mut Vec<EdgeCheck>,
    resolution: f64,
    checker: &mut WorldChecker,
) -> bool {
    let d = path[0].len();
    let (mut changed, mut i) = (false, 1);
    let mut points = vec![0.0; 3 * d];
    while i + 1 < path.len() {
        let (a, v, b) = (&path[i - 1], &path[i], &path[i + 1]);
        let (m1, rest) = points.split_at_mut(d);
        let (cut, m2) = rest.split_at_mut(d);
        for k in 0..d {
            m1[k] = 0.5 * (a[k] + v[k]);
            m2[k] = 0.5 * (v[k] + b[k]);
            cut[k] = 0.5 * (m1[k] + m2[k]);
        }
        if distance(cut, v) < SMOOTHING_MIN_CHANGE
            || !checker.all_free(&points)
            || !checker.edge_free(&points[..d], &points[d..2 * d], resolution)
            || !checker.edge_free(&points[d..2 * d], &points[2 * d..], resolution)
        {
            i += 1;
            continue;
        }
        // a → m₁ and m₂ → b are pieces of the edges they cut
        let new = points.chunks(d).map(<[f64]>::to_vec);
        path.splice(i..=i, new);
        edges.splice(
            i - 1..=i,
            [
                EdgeCheck::Piece,
                EdgeCheck::Checked,
                EdgeCheck::Checked,
                EdgeCheck::Piece,
            ],
        );
        changed = true;
        // the next corner is the old b, now after m₂
        i += 3;
    }
    changed
}

/// Length of a path, rad.
pub fn path_length(path: &[Vec<f64>]) -> f64 {
    path.windows(2).map(|w| distance(&w[0], &w[1])).sum()
}
