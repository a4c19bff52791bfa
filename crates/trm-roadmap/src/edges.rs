//! Configuration-space edges: each point to its n nearest neighbours in joint space, kept when
//! the straight segment between them is collision-free at the given interpolation step.

use std::time::Instant;

use rayon::prelude::*;
use trm_collision::World;
use trm_kinematics::LANES;
use trm_tasks::{Objective, Scratch};

use crate::error::{Result, RoadmapError};
use crate::map::Roadmap;
use crate::team::{Solo, Team, all_gather_f64, share};

/// The finest edge-checking step, rad: below it a check costs more than it can find.
pub const MIN_RESOLUTION: f64 = 1e-4;

/// Checks an edge-checking step: finite and at least [`MIN_RESOLUTION`] rad (a zero or tiny
/// step would never finish). [`connect`] calls it; call it yourself before long work.
pub fn check_edge_resolution(resolution: f64) -> Result<()> {
    if resolution.is_finite() && resolution >= MIN_RESOLUTION {
        Ok(())
    } else {
        Err(RoadmapError::Unsuitable(format!(
            "edge resolution {resolution}: give a finite step of at least {MIN_RESOLUTION} rad"
        )))
    }
}

/// Adds edges to `map` (replacing any): `neighbours` per point (≥ 1), segments checked every
/// `resolution` radians of the largest joint change (finite, ≥ [`MIN_RESOLUTION`]).
pub fn connect(
    map: &mut Roadmap,
    objective: &Objective,
    neighbours: usize,
    resolution: f64,
) -> Result<()> {
    connect_with(map, objective, neighbours, resolution, &mut Solo)
}

/// [`connect`] shared among the processes of `team` (each checks the edges of a slice of the
/// points; every one calls it and gets every edge): the same edges.
pub fn connect_with(
    map: &mut Roadmap,
    objective: &Objective,
    neighbours: usize,
    resolution: f64,
    team: &mut dyn Team,
) -> Result<()> {
    if neighbours == 0 {
        return Err(RoadmapError::Unsuitable(
            "0 edge neighbours: give at least 1 (spec `map.edge_neighbours`)".into(),
        ));
    }
    check_edge_resolution(resolution)?;
    if objective.dim() != map.active.len() {
        return Err(RoadmapError::Unsuitable(format!(
            "the objective has {} active motors, the map {}",
            objective.dim(),
            map.active.len()
        )));
    }
    let started = Instant::now();
    let points = share(map.points.len(), team.size(), team.rank());
    let mine = edges_of(map, objective, neighbours, resolution, points);
    let flat: Vec<f64> = mine
        .iter()
        .flat_map(|&(i, j, l)| [i as f64, j as f64, l])
        .collect();
    let all = if team.size() > 1 {
        all_gather_f64(team, &flat)?
    } else {
        flat
    };
    let n = map.points.len();
    let foreign = || {
        RoadmapError::Unsuitable(
            "a process of the build sent edges of another map; start every process with the same spec and options".into(),
        )
    };
    if all.len() % 3 != 0 {
        return Err(foreign());
    }
    let mut edges = Vec::with_capacity(all.len() / 3);
    for e in all.chunks_exact(3) {
        let (i, j) = (e[0] as usize, e[1] as usize);
        if i >= n || j >= n {
            return Err(foreign());
        }
        edges.push((i, j, e[2]));
    }
    sorted_unique(&mut edges);
    map.edges = edges;
    map.edge_resolution = resolution;
    map.stats.edge_seconds = started.elapsed().as_secs_f64();
    Ok(())
}

/// Sorts edges by their ends and drops repeats.
fn sorted_unique(edges: &mut Vec<(usize, usize, f64)>) {
    edges.sort_by_key(|e| (e.0, e.1));
    edges.dedup_by(|a, b| a.0 == b.0 && a.1 == b.1);
}

/// Adds to `map`'s edges those of points `from..` to their `neighbours` nearest points (as
/// [`connect`] makes them), e.g. for points added by a repair; the others' edges stay.
pub(crate) fn connect_from(
    map: &mut Roadmap,
    objective: &Objective,
    neighbours: usize,
    resolution: f64,
    from: usize,
) -> Result<()> {
    check_edge_resolution(resolution)?;
    let mut edges = edges_of(
        map,
        objective,
        neighbours,
        resolution,
        from..map.points.len(),
    );
    edges.extend_from_slice(&map.edges);
    sorted_unique(&mut edges);
    map.edges = edges;
    map.edge_resolution = resolution;
    Ok(())
}

/// The collision-free edges of the points in `of` to their `neighbours` nearest points, sorted
/// and without duplicates.
fn edges_of(
    map: &Roadmap,
    objective: &Objective,
    neighbours: usize,
    resolution: f64,
    of: std::ops::Range<usize>,
) -> Vec<(usize, usize, f64)> {
    let points = &map.points;
    let mut edges: Vec<(usize, usize, f64)> = of
        .into_par_iter()
        .map_init(
            || (objective.scratch(), Vec::new()),
            |(scratch, samples), i| {
                let mut near: Vec<(f64, usize)> = (0..points.len())
                    .filter(|&j| j != i)
                    .map(|j| (distance(&points[i].q, &points[j].q), j))
                    .collect();
                // the `neighbours` nearest (ties by index), without sorting all of them
                let order =
                    |a: &(f64, usize), b: &(f64, usize)| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1));
                if near.len() > neighbours {
                    near.select_nth_unstable_by(neighbours, order);
                    near.truncate(neighbours);
                }
                near.sort_by(order);
                near.into_iter()
                    .filter(|&(_, j)| {
                        let (a, b) = (&points[i].q, &points[j].q);
                        let world = objective.world();
                        segment_is_collision_free(
                            objective, world, a, b, resolution, samples, scratch,
                        )
                    })
                    .map(|(l, j)| (i.min(j), i.max(j), l))
                    .collect::<Vec<_>>()
            },
        )
        .flatten()
        .collect();
    sorted_unique(&mut edges);
    edges
}

/// Euclidean distance between two vectors (joint or task space).
pub fn distance(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).powi(2))
        .sum::<f64>()
        .sqrt()
}

/// Whether `free` holds along the straight segment a → b, sampled so that no joint moves more
/// than `resolution` between samples (both ends included). `q` is scratch of the same length.
pub fn segment_is_free(
    a: &[f64],
    b: &[f64],
    resolution: f64,
    q: &mut [f64],
    mut free: impl FnMut(&[f64]) -> bool,
) -> bool {
    let steps = segment_steps(a, b, resolution);
    (0..=steps).all(|s| {
        segment_point(a, b, s, steps, q);
        free(q)
    })
}

/// Intervals of the segment a → b at `resolution`.
pub(crate) fn segment_steps(a: &[f64], b: &[f64], resolution: f64) -> usize {
    let span = a
        .iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max);
    (span / resolution).ceil().max(1.0) as usize
}

/// Sample `s` of `steps` on a → b, into `q`.
pub(crate) fn segment_point(a: &[f64], b: &[f64], s: usize, steps: usize, q: &mut [f64]) {
    let u = s as f64 / steps as f64;
    for ((q, a), b) in q.iter_mut().zip(a).zip(b) {
        *q = a + u * (b - a);
    }
}

/// Whether the straight segment a → b is free of self-collisions and of collisions with
/// `world`, at the samples of [`segment_is_free`], checked [`LANES`] samples at a time with
/// [`Objective::all_collision_free_in`]. `samples` is scratch (grown to `LANES` × dim once).
///
/// # Panics
/// If `a` or `b` does not have one value per active motor of `objective`.
pub fn segment_is_collision_free(
    objective: &Objective,
    world: &World,
    a: &[f64],
    b: &[f64],
    resolution: f64,
    samples: &mut Vec<f64>,
    scratch: &mut Scratch,
) -> bool {
    segment_all(
        objective.dim(),
        a,
        b,
        resolution,
        LANES,
        samples,
        scratch,
        |qs, scratch| objective.all_collision_free_in(qs, world, scratch),
    )
}

/// Whether `check` holds for every batch of `width` samples of a → b (the samples of
/// [`segment_is_free`], `d` values each). The samples are visited raked, as VAMP validates
/// motions: of the segment's n samples, batch k holds samples k, k + m, k + 2m, …
/// (m = ⌈n / width⌉), so the first batch already spans the whole segment and a blocked segment
/// is usually refused after one batch. The verdict is the same in any order. `samples` is
/// scratch (grown to `width` × `d` once).
///
/// # Panics
/// If `a` or `b` does not hold `d` values, or `width` is 0.
#[allow(clippy::too_many_arguments)] // the segment, its batching and the caller's check
pub fn segment_all<S>(
    d: usize,
    a: &[f64],
    b: &[f64],
    resolution: f64,
    width: usize,
    samples: &mut Vec<f64>,
    scratch: &mut S,
    check: impl FnMut(&[f64], &mut S) -> bool,
) -> bool {
    let steps = segment_steps(a, b, resolution);
    let at = |s: usize| s as f64 / steps as f64;
    rake(d, a, b, steps + 1, at, width, samples, scratch, check)
}

/// Whether `check` holds for the `n` points a + at(i)·(b − a), i < n (`d` values each), in
/// batches of `width` visited raked as [`segment_all`] visits its samples: batch k holds points
/// k, k + m, k + 2m, … (m = ⌈n / width⌉). For callers with their own rule for an edge's points.
///
/// # Panics
/// If `a` or `b` does not hold `d` values, or `width` is 0.
#[allow(clippy::too_many_arguments)] // the segment, its points, their batching and the check
pub fn rake<S>(
    d: usize,
    a: &[f64],
    b: &[f64],
    n: usize,
    at: impl Fn(usize) -> f64,
    width: usize,
    samples: &mut Vec<f64>,
    scratch: &mut S,
    mut check: impl FnMut(&[f64], &mut S) -> bool,
) -> bool {
    assert!(a.len() == d && b.len() == d, "one value per active motor");
    assert!(width > 0, "at least one sample per batch");
    let stride = n.div_ceil(width);
    samples.resize(width * d, 0.0);
    for k in 0..stride {
        let mut m = 0;
        for i in (k..n).step_by(stride) {
            let u = at(i);
            for ((q, a), b) in samples[m * d..(m + 1) * d].iter_mut().zip(a).zip(b) {
                *q = a + u * (b - a);
            }
            m += 1;
        }
        if !check(&samples[..m * d], scratch) {
            return false;
        }
    }
    true
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Raked: every sample visited once when the segment is free; a segment blocked over more
    /// than 1/LANES of its length, anywhere, is refused by the first batch.
    #[test]
    fn segments_are_checked_raked() {
        let mut scratch = ();
        let (a, b) = ([0.0], [1.0]);
        let mut seen = Vec::new();
        assert!(segment_all(
            1,
            &a,
            &b,
            0.01,
            LANES,
            &mut Vec::new(),
            &mut scratch,
            |qs, _| {
                seen.extend_from_slice(qs);
                true
            }
        ));
        seen.sort_by(f64::total_cmp);
        assert_eq!(seen.len(), 101);
        assert!(
            seen.iter()
                .enumerate()
                .all(|(i, v)| (v - i as f64 / 100.0).abs() < 1e-12)
        );
        let mut batches = 0;
        assert!(!segment_all(
            1,
            &a,
            &b,
            0.01,
            LANES,
            &mut Vec::new(),
            &mut scratch,
            |qs, _| {
                batches += 1;
                qs.iter().all(|q| !(0.5..0.8).contains(q))
            }
        ));
        assert_eq!(batches, 1);
    }
}
