//! Configuration-space edges: each point to its n nearest neighbours in joint space, kept when
//! the straight segment between them is collision-free at the given interpolation step.

use std::time::Instant;

use rayon::prelude::*;
use trm_collision::edge::{distance, edge_point, span_steps};
use trm_tasks::Objective;

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
    let mine = edges_of(map, objective, neighbours, resolution, points)?;
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
    )?;
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
) -> Result<Vec<(usize, usize, f64)>> {
    let points = &map.points;
    let checker = objective.world_checker(objective.world())?;
    let mut edges: Vec<(usize, usize, f64)> = of
        .into_par_iter()
        .map_init(
            || checker.clone(),
            |checker, i| {
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
                    .filter(|&(_, j)| checker.span_free(&points[i].q, &points[j].q, resolution))
                    .map(|(l, j)| (i.min(j), i.max(j), l))
                    .collect::<Vec<_>>()
            },
        )
        .flatten()
        .collect();
    sorted_unique(&mut edges);
    Ok(edges)
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
    let steps = span_steps(a, b, resolution);
    (0..=steps).all(|s| {
        edge_point(a, b, s, steps, q);
        free(q)
    })
}
