//! Simplifying a path found by RRT-Connect or through a graph: the greedy shortcut, random
//! shortcuts and corner cutting, with a record of how each edge of the result was checked.
//! Re-exported from [`crate::rrt`].

use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use trm_collision::WorldChecker;
use trm_collision::edge::distance;

use crate::PlanError;
use crate::rrt::{RrtOptions, rrt_connect_in};

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
    let mut seen = Verdicts::default();
    greedy(path, &mut edges, options.resolution, checker, &mut seen);
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
        greedy(path, &mut edges, options.resolution, checker, &mut seen);
    }
    edges
}

/// From each kept waypoint of `path`, the farthest later one it sees: the waypoints between
/// are dropped, and `edges` (one per edge) says how each edge of the result was checked.
/// `seen` holds the verdicts of earlier passes (an edge between the same two points is not
/// checked again: corner cutting moves a few waypoints, and the next pass asks again about
/// most of the long edges the last one found blocked).
fn greedy(
    path: &mut Vec<Vec<f64>>,
    edges: &mut Vec<EdgeCheck>,
    resolution: f64,
    checker: &mut WorldChecker,
    seen: &mut Verdicts,
) {
    let mut kept = vec![path[0].clone()];
    let mut kept_edges = Vec::with_capacity(edges.len());
    let mut i = 0;
    while i + 1 < path.len() {
        let mut j = path.len() - 1;
        while j > i + 1 && !seen.edge_free(&path[i], &path[j], resolution, checker) {
            j -= 1;
        }
        kept.push(path[j].clone());
        // j > i + 1: that edge was found free; else the edge i → i + 1, as it was
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

/// The verdicts of [`WorldChecker::edge_free`] on the edges [`greedy`] asked about, by their
/// ends' exact values.
#[derive(Default)]
struct Verdicts(std::collections::HashMap<Vec<u64>, bool>);

impl Verdicts {
    /// Whether a → b is free at `resolution`, checked only if not asked before.
    fn edge_free(
        &mut self,
        a: &[f64],
        b: &[f64],
        resolution: f64,
        checker: &mut WorldChecker,
    ) -> bool {
        let key: Vec<u64> = a.iter().chain(b).map(|v| v.to_bits()).collect();
        *self
            .0
            .entry(key)
            .or_insert_with(|| checker.edge_free(a, b, resolution))
    }
}

/// One round of corner cutting, VAMP's B-spline step (see [`RrtOptions::smoothing`]): each
/// interior waypoint `v` between `a` and `b`, with `m₁` and `m₂` the midpoints of `a v` and
/// `v b`, is moved to `v' = (m₁ + 2v + m₂) / 4` where that moves it by at least
/// [`SMOOTHING_MIN_CHANGE`] and `m₁`, `v'`, `m₂` and the edges `m₁ v'` and `v' m₂` are free;
/// the path then runs through `m₁` and `m₂` around each moved waypoint (a midpoint between
/// two moved waypoints once). Each move depends only on the waypoints given, so the moves are
/// independent. Whether any waypoint moved.
fn cut_corners(
    path: &mut Vec<Vec<f64>>,
    edges: &mut Vec<EdgeCheck>,
    resolution: f64,
    checker: &mut WorldChecker,
) -> bool {
    let (d, n) = (path[0].len(), path.len());
    let mid = |a: &[f64], b: &[f64]| -> Vec<f64> {
        a.iter().zip(b).map(|(x, y)| 0.5 * (x + y)).collect()
    };
    // the moved waypoints (None: left where it was)
    let mut moved: Vec<Option<Vec<f64>>> = vec![None; n];
    let mut points = vec![0.0; 3 * d];
    for i in 1..n.saturating_sub(1) {
        let (a, v, b) = (&path[i - 1], &path[i], &path[i + 1]);
        let (m1, rest) = points.split_at_mut(d);
        let (cut, m2) = rest.split_at_mut(d);
        for k in 0..d {
            m1[k] = 0.5 * (a[k] + v[k]);
            m2[k] = 0.5 * (v[k] + b[k]);
            cut[k] = 0.25 * (m1[k] + 2.0 * v[k] + m2[k]);
        }
        if distance(cut, v) >= SMOOTHING_MIN_CHANGE
            && checker.all_free(&points)
            && checker.edge_free(&points[..d], &points[d..2 * d], resolution)
            && checker.edge_free(&points[d..2 * d], &points[2 * d..], resolution)
        {
            moved[i] = Some(points[d..2 * d].to_vec());
        }
    }
    if moved.iter().all(Option::is_none) {
        return false;
    }
    let is_moved: Vec<bool> = moved.iter().map(Option::is_some).collect();
    let (mut out, mut out_edges) = (vec![path[0].clone()], Vec::with_capacity(2 * n));
    for i in 1..n {
        let (left, right) = (is_moved[i - 1], is_moved[i]);
        if left || right {
            // the edge's midpoint joins the moved ends; an unmoved end's side is a piece of
            // the edge as it was
            out.push(mid(&path[i - 1], &path[i]));
            let side = |m: bool| {
                if m {
                    EdgeCheck::Checked
                } else {
                    EdgeCheck::Piece
                }
            };
            out_edges.extend([side(left), side(right)]);
        } else {
            out_edges.push(edges[i - 1]);
        }
        out.push(moved[i].take().unwrap_or_else(|| path[i].clone()));
    }
    *path = out;
    *edges = out_edges;
    true
}

/// `raw`, a path whose edges are free at `options.resolution`, simplified again ([`shortcut`])
/// with the simplifier's new edges checked at half that resolution, where it passes
/// [`recheck`] (`asked`: the resolution first asked for): where the first simplification's new
/// edges grazed an obstacle between their points, the search's own edges are most often free
/// at half the resolution. `None` where its path still grazes.
pub(crate) fn simplified_finer(
    checker: &mut WorldChecker,
    raw: &[Vec<f64>],
    options: &RrtOptions,
    asked: f64,
) -> Option<Vec<Vec<f64>>> {
    let finer = RrtOptions {
        resolution: options.resolution / 2.0,
        ..options.clone()
    };
    let mut path = raw.to_vec();
    let mut rng = ChaCha8Rng::seed_from_u64(options.seed);
    let edges = shortcut(&mut path, &finer, checker, &mut rng);
    recheck(checker, &path, &edges, options.resolution, asked).then_some(path)
}

/// Whether `path`, whose edges were checked at `resolution` as `edges` says, is free at half
/// that: the edges checked at `resolution` (by the search: the edges it kept, or by the
/// shortcut) need only their midpoints; a piece of an edge a random shortcut cut needs its own
/// points too. A refined search's points are not those of the `asked` resolution: those too,
/// so that the path is free at every point a check at `asked / 2` visits.
pub(crate) fn recheck(
    checker: &mut WorldChecker,
    path: &[Vec<f64>],
    edges: &[EdgeCheck],
    resolution: f64,
    asked: f64,
) -> bool {
    path.windows(2).zip(edges).all(|(w, e)| {
        (*e != EdgeCheck::Piece || checker.edge_free(&w[0], &w[1], resolution))
            && checker.edge_midpoints_free(&w[0], &w[1], resolution)
            && (resolution == asked
                || checker.edge_free(&w[0], &w[1], asked)
                    && checker.edge_midpoints_free(&w[0], &w[1], asked))
    })
}

/// Proves every segment of `path` free in continuous motion ([`WorldChecker::prove`]), in
/// `checker`'s world; a segment that cannot be proved is replaced by RRT-Connect between its
/// ends within `bounds`, with every accepted edge proved ([`WorldChecker::set_proving`]). An
/// error when no proved path joins them within `options`' budget.
pub(crate) fn prove_path(
    checker: &mut WorldChecker,
    bounds: &(Vec<f64>, Vec<f64>),
    path: &mut Vec<Vec<f64>>,
    options: &RrtOptions,
) -> Result<(), PlanError> {
    let mut i = 0;
    while i + 1 < path.len() {
        if checker
            .prover()?
            .segment_unchecked(&path[i], &path[i + 1])
            .is_free()
        {
            i += 1;
            continue;
        }
        // the segment grazes or crosses an obstacle between its checked points
        checker.set_proving(true)?;
        let repaired = rrt_connect_in(checker, bounds, &path[i], &path[i + 1], options);
        checker.set_proving(false)?;
        match repaired {
            Ok(found) => {
                let n = found.path.len();
                path.splice(i..i + 2, found.path);
                i += n - 1;
            }
            Err(e) => {
                return Err(PlanError::Unreachable {
                    reason: format!(
                        "segment {i} of the path found cannot be proved free in continuous motion, and no proved path replaces it: {e}"
                    ),
                    closest_node: None,
                    closest_distance: f64::INFINITY,
                });
            }
        }
    }
    Ok(())
}

/// Length of a path, rad.
pub fn path_length(path: &[Vec<f64>]) -> f64 {
    path.windows(2).map(|w| distance(&w[0], &w[1])).sum()
}

#[cfg(test)]
mod tests {
    use super::*;
    use trm_collision::{CollisionModel, World};

    /// A checker of the iCub's right arm (three joints) in an empty world, and its home.
    fn arm() -> (WorldChecker, Vec<f64>) {
        let robot = trm_models::icub_upper_body();
        let home = robot.posture("home").unwrap().to_vec();
        let joints = ["r_shoulder_pitch", "r_shoulder_roll", "r_elbow"];
        let active = robot.active_set(&joints, &home).unwrap();
        let start = active.from_motors(&home);
        let collision = CollisionModel::new(&robot).unwrap();
        (
            WorldChecker::new(&collision, &active, World::new()).unwrap(),
            start,
        )
    }

    /// A corner moves as VAMP's B-spline step moves it, to `(a + 6v + b) / 8`, the path
    /// running through the midpoints of its two edges (their outer halves pieces of the edges
    /// given); a corner that would move by less than the least change stays.
    #[test]
    fn a_corner_moves_an_eighth_of_the_way_and_a_flat_one_stays() {
        let (mut checker, s) = arm();
        let at = |x: f64, y: f64| vec![s[0] + x, s[1] + y, s[2]];
        let mut path = vec![at(0.0, 0.0), at(0.6, 0.0), at(0.6, 0.6)];
        assert!(checker.all_free(&path.concat()));
        let mut edges = vec![EdgeCheck::Given; 2];
        assert!(cut_corners(&mut path, &mut edges, 0.05, &mut checker));
        let expected = [
            at(0.0, 0.0),
            at(0.3, 0.0),
            at(0.525, 0.075),
            at(0.6, 0.3),
            at(0.6, 0.6),
        ];
        assert_eq!(path.len(), expected.len());
        for (p, e) in path.iter().zip(&expected) {
            assert!(distance(p, e) < 1e-12, "{p:?} against {e:?}");
        }
        use EdgeCheck::{Checked, Piece};
        assert_eq!(edges, [Piece, Checked, Checked, Piece]);
        // two corners that both move share the midpoint between them
        let mut zigzag = vec![at(0.0, 0.0), at(0.6, 0.0), at(0.6, 0.6), at(1.2, 0.6)];
        let mut edges = vec![EdgeCheck::Given; 3];
        assert!(cut_corners(&mut zigzag, &mut edges, 0.05, &mut checker));
        assert_eq!(zigzag.len(), 7);
        assert!(distance(&zigzag[3], &at(0.6, 0.3)) < 1e-12);
        assert_eq!(edges, [Piece, Checked, Checked, Checked, Checked, Piece]);
        // |a − 2v + b| / 8 = |(−0.6, 0.3)| / 8 ≈ 0.084 < 0.1
        let mut flat = vec![at(0.0, 0.0), at(0.6, 0.0), at(0.6, 0.3)];
        let mut edges = vec![EdgeCheck::Given; 2];
        assert!(!cut_corners(&mut flat, &mut edges, 0.05, &mut checker));
        assert_eq!(flat, [at(0.0, 0.0), at(0.6, 0.0), at(0.6, 0.3)]);
        assert_eq!(edges, [EdgeCheck::Given; 2]);
    }
}
