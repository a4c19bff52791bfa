//! Repairing a map for a world that changed: the nodes and edges the new world blocks go
//! ([`BlockIndex`]), then E-TRM grows new points where points were lost — searches start only
//! from points near the hole, CHECK accepts only points within a spacing of a lost one, and
//! every candidate is evaluated in the new world — and the new points are connected.

use std::collections::BTreeSet;
use std::time::Instant;

use trm_collision::World;
use trm_tasks::Problem;

use crate::blocked::BlockIndex;
use crate::build::{Region, Setup, State, Threads, run};
use crate::edges::connect_from;
use crate::error::Result;
use crate::index::TaskIndex;
use crate::map::{Roadmap, cell};

/// Consecutive failed searches after which a repair stops growing (at most the map's own
/// `failure_limit`).
pub const REPAIR_FAILURE_LIMIT: usize = 20;

/// What [`repair`] did.
#[derive(Debug, Clone, PartialEq)]
pub struct RepairReport {
    /// Nodes and edges the new world blocked (removed).
    pub blocked_nodes: usize,
    /// Edges removed (blocked, or ending at a removed node).
    pub removed_edges: usize,
    /// Points grown in their place, and the edges added for them.
    pub added_nodes: usize,
    /// Edges added.
    pub added_edges: usize,
    /// Task-space cells of side d (the map's spacing) that held a removed node and no
    /// remaining one, and how many of them hold a point again.
    pub lost_cells: usize,
    /// Of `lost_cells`, those that hold a point after the repair.
    pub restored_cells: usize,
    /// Seconds: finding what is blocked, growing, connecting.
    pub seconds: [f64; 3],
}

/// Repairs `map` (built for `problem`, its [`Roadmap::problem`]) for `world`: removes what the
/// world blocks and re-grows coverage where points were lost, with the map's own settings and
/// seed (so a repair is reproducible); returns the repaired map, valid in `world` (every node
/// and edge collision-free in it), and a report.
pub fn repair(map: &Roadmap, problem: &Problem, world: &World) -> Result<(Roadmap, RepairReport)> {
    let started = Instant::now();
    let index = BlockIndex::new(map, &problem.objective)?;
    let blocked = index.blocked(map, &problem.objective, world)?;
    let gone: BTreeSet<usize> = blocked.nodes.iter().copied().collect();
    let blocked_edges: BTreeSet<usize> = blocked.edges.iter().copied().collect();
    // the remaining points, renumbered, and the edges between them
    let mut renumber = vec![usize::MAX; map.points.len()];
    let mut points = Vec::with_capacity(map.points.len() - gone.len());
    for (i, p) in map.points.iter().enumerate() {
        if !gone.contains(&i) {
            renumber[i] = points.len();
            points.push(p.clone());
        }
    }
    let edges: Vec<(usize, usize, f64)> = map
        .edges
        .iter()
        .enumerate()
        .filter(|(k, (a, b, _))| {
            !blocked_edges.contains(k) && !gone.contains(a) && !gone.contains(b)
        })
        .map(|(_, &(a, b, l))| (renumber[a], renumber[b], l))
        .collect();
    let d = map.settings.spacing;
    let dim = points
        .first()
        .or(map.points.first())
        .map_or(0, |p| p.t.len());
    let occupied: BTreeSet<Vec<i64>> = points.iter().map(|p| cell(&p.t, d)).collect();
    let lost_cells: BTreeSet<Vec<i64>> = gone
        .iter()
        .map(|&i| cell(&map.points[i].t, d))
        .filter(|c| !occupied.contains(c))
        .collect();
    let find_seconds = started.elapsed().as_secs_f64();

    // grow in the new world, near the lost points only
    let started = Instant::now();
    let objective = problem.objective.clone().with_world(world.clone());
    let mut lost = TaskIndex::new(dim);
    for &i in &gone {
        lost.add(&map.points[i].t);
    }
    let remaining = points.len();
    let mut setup = Setup::new(
        problem,
        Some(remaining + gone.len()),
        Some(map.searches),
        Some(map.seed),
    )?;
    setup.objective = &objective;
    setup.region = Some(Region { lost, radius: d });
    setup.max_generations = 400;
    setup.repel_weight = 1.0;
    // a hole is small: give up on it sooner than a whole build would
    setup.settings.failure_limit = setup.settings.failure_limit.min(REPAIR_FAILURE_LIMIT);
    let mut repaired = if gone.is_empty() {
        let mut same = map.clone();
        same.points = points;
        same
    } else {
        // first where points were lost, then — for what the new world no longer allows there —
        // anywhere, until the map has its size again
        let state = State::from_points(&setup, points);
        let near_hole = run(&setup, state, None, &mut Threads, |_| {})?;
        let in_hole = near_hole.points.len() - remaining;
        setup.region = None;
        setup.settings.failure_limit = map.settings.failure_limit;
        let state = State::from_points(&setup, near_hole.points);
        let mut grown = run(&setup, state, None, &mut Threads, |_| {})?;
        // the points grown near the hole come first among the new ones
        debug_assert!(grown.points.len() >= remaining + in_hole);
        grown.stats = near_hole.stats;
        grown
    };
    let grow_seconds = started.elapsed().as_secs_f64();

    // connect the new points to their neighbours (old edges stay)
    let started = Instant::now();
    repaired.edges = edges;
    let kept_edges = repaired.edges.len();
    let neighbours = map.settings.edge_neighbours.max(1);
    let resolution = if map.edge_resolution > 0.0 {
        map.edge_resolution
    } else {
        0.05
    };
    connect_from(&mut repaired, &objective, neighbours, resolution, remaining)?;
    let connect_seconds = started.elapsed().as_secs_f64();
    repaired.world = Some(world.to_spec());
    repaired.stats = map.stats.clone();
    let restored_cells = repaired
        .points
        .iter()
        .map(|p| cell(&p.t, d))
        .filter(|c| lost_cells.contains(c))
        .collect::<BTreeSet<_>>()
        .len();
    let report = RepairReport {
        blocked_nodes: gone.len(),
        removed_edges: map.edges.len() - kept_edges,
        added_nodes: repaired.points.len() - remaining,
        added_edges: repaired.edges.len() - kept_edges,
        lost_cells: lost_cells.len(),
        restored_cells,
        seconds: [find_seconds, grow_seconds, connect_seconds],
    };
    Ok((repaired, report))
}
