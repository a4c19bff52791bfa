//! Keeping a map valid in a world that changes ([`LiveMap`]) and repairing it ([`repair`]).
//!
//! A live map holds every node and edge it has ever had — the map's own, those its file keeps
//! parked, and those grown by repairs — each flagged blocked or clear in the current world.
//! A world change re-checks only what lies near the objects that changed ([`BlockIndex`]):
//! newly blocked nodes and edges are parked, parked ones the change frees come back without a
//! search. A repair then grows points with E-TRM where coverage was lost — searches start only
//! from points near the hole, CHECK accepts only points within a spacing of a lost one, and
//! every candidate is evaluated in the current world — and connects them.

use std::collections::BTreeSet;
use std::time::{Duration, Instant};

use trm_collision::World;
use trm_tasks::Problem;

use crate::blocked::{BlockIndex, Changes};
use crate::build::{Region, Setup, State, run};
use crate::edges::connect_from;
use crate::error::{Result, RoadmapError};
use crate::index::TaskIndex;
use crate::map::{MapPoint, Parked, Roadmap, cell};
use crate::team::Solo;

/// Consecutive failed searches after which a repair stops growing near the hole (at most the
/// map's own `failure_limit`).
pub const REPAIR_FAILURE_LIMIT: usize = 20;

/// Edge check step for maps that have no edges yet, rad.
const DEFAULT_RESOLUTION: f64 = 0.05;

/// How much a repair may grow.
#[derive(Debug, Clone, PartialEq)]
pub struct RepairOptions {
    /// Stop growing after this long (a scenario's per-step budget). A repair under a time
    /// budget depends on the machine's speed; one without is reproducible.
    pub seconds: Option<f64>,
    /// Stop growing after this many cost evaluations (reproducible). With both budgets set,
    /// growing stops at whichever is spent first.
    pub evaluations: Option<u64>,
    /// After the hole, grow wherever the map can until it has its size again (nodes clear
    /// and parked counted).
    pub refill: bool,
}

impl Default for RepairOptions {
    /// No budget, refill: what `repair-map` does.
    fn default() -> Self {
        RepairOptions {
            seconds: None,
            evaluations: None,
            refill: true,
        }
    }
}

/// What a world change and a repair did.
#[derive(Debug, Clone, Default, PartialEq, serde::Serialize)]
pub struct RepairReport {
    /// Nodes the new world blocks (parked).
    pub blocked_nodes: usize,
    /// Edges it blocks (parked; the edges of blocked nodes among them).
    pub blocked_edges: usize,
    /// Parked nodes and edges it frees: back in the map without a search.
    pub restored_nodes: usize,
    /// Parked edges it frees.
    pub restored_edges: usize,
    /// Points grown.
    pub added_nodes: usize,
    /// Edges added for them.
    pub added_edges: usize,
    /// Task-space cells of side d (the map's spacing) that hold a parked node and no clear
    /// one before growing.
    pub lost_cells: usize,
    /// Of `lost_cells`, those that hold a clear point after the repair.
    pub restored_cells: usize,
    /// Why growing stopped ("nothing lost" when there was nothing to grow).
    pub stopped_because: String,
    /// Seconds: finding what changed, growing, connecting.
    pub seconds: [f64; 3],
}

impl std::fmt::Display for RepairReport {
    /// One line: what was blocked, restored and grown, and the coverage lost and regained.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let report = self;
        write!(
            f,
            "blocked: {} nodes, {} edges parked; restored from the parked ones: {} nodes, {} edges; grown: {} nodes, {} edges ({}); lost cells of side d: {}, {} hold a point again",
            report.blocked_nodes,
            report.blocked_edges,
            report.restored_nodes,
            report.restored_edges,
            report.added_nodes,
            report.added_edges,
            report.stopped_because,
            report.lost_cells,
            report.restored_cells
        )
    }
}

/// A map kept valid in a changing world; see the module documentation.
pub struct LiveMap<'p> {
    problem: &'p Problem,
    /// Every node and edge: clear ones and parked ones; it only grows.
    all: Roadmap,
    index: BlockIndex,
    world: World,
    node_blocked: Vec<bool>,
    edge_blocked: Vec<bool>,
    /// Blocked nodes whose coverage no repair has finished growing back yet.
    pending: BTreeSet<usize>,
    /// The number of clear nodes a refill grows the map back to.
    size: usize,
    repairs: u64,
}

impl std::fmt::Debug for LiveMap<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("LiveMap")
            .field("nodes", &self.all.points.len())
            .field("parked", &self.parked_nodes())
            .field("objects", &self.world.len())
            .finish()
    }
}

impl<'p> LiveMap<'p> {
    /// The map, valid in its own world (`problem`'s, its [`Roadmap::problem`]); its parked
    /// nodes and edges are kept aside, blocked.
    pub fn new(map: &Roadmap, problem: &'p Problem) -> Result<Self> {
        let mut all = map.clone();
        let parked = all.parked.take().unwrap_or_default();
        let (clear_nodes, clear_edges) = (all.points.len(), all.edges.len());
        all.points.extend(parked.points);
        all.edges.extend(parked.edges);
        if !all.edges.is_empty() {
            crate::check_edge_resolution(all.edge_resolution)?;
        }
        let index = BlockIndex::new(&all, &problem.objective)?;
        let mut node_blocked = vec![true; all.points.len()];
        node_blocked[..clear_nodes].fill(false);
        let mut edge_blocked = vec![true; all.edges.len()];
        edge_blocked[..clear_edges].fill(false);
        Ok(LiveMap {
            problem,
            world: problem.objective.world().clone(),
            all,
            index,
            node_blocked,
            edge_blocked,
            pending: BTreeSet::new(),
            size: clear_nodes,
            repairs: 0,
        })
    }

    /// The current world.
    pub fn world(&self) -> &World {
        &self.world
    }

    /// Every node and edge, clear or parked (indices stay valid: it only grows).
    pub fn all(&self) -> &Roadmap {
        &self.all
    }

    /// Whether node `i` of [`LiveMap::all`] is blocked in the current world.
    pub fn is_blocked(&self, i: usize) -> bool {
        self.node_blocked[i]
    }

    /// How many nodes are parked.
    pub fn parked_nodes(&self) -> usize {
        self.node_blocked.iter().filter(|&&b| b).count()
    }

    /// Moves to `world`: parks what it blocks, brings back what it frees (exactly what
    /// checking everything would find; see [`BlockIndex::changes`]).
    pub fn set_world(&mut self, world: World) -> Result<Changes> {
        let changes = self.index.changes(
            &self.all,
            &self.problem.objective,
            &self.world,
            &world,
            &self.node_blocked,
            &self.edge_blocked,
        )?;
        for &i in &changes.blocked_nodes {
            self.node_blocked[i] = true;
            self.pending.insert(i);
        }
        for &i in &changes.freed_nodes {
            self.node_blocked[i] = false;
            self.pending.remove(&i);
        }
        for &k in &changes.blocked_edges {
            self.edge_blocked[k] = true;
        }
        for &k in &changes.freed_edges {
            self.edge_blocked[k] = false;
        }
        self.world = world;
        Ok(changes)
    }

    /// Whether edge k of [`LiveMap::all`] is usable in the current world: clear, between
    /// clear nodes.
    pub fn is_usable(&self, k: usize) -> bool {
        let (a, b, _) = self.all.edges[k];
        !self.edge_blocked[k] && !self.node_blocked[a] && !self.node_blocked[b]
    }

    /// The map valid in the current world: the clear nodes and usable edges, renumbered in
    /// order, the rest in [`Roadmap::parked`], and the world recorded.
    pub fn map(&self) -> Roadmap {
        let n = self.all.points.len();
        let clear = self.node_blocked.iter().filter(|&&b| !b).count();
        let mut renumber = vec![0; n];
        let (mut next_clear, mut next_parked) = (0, clear);
        let mut points = Vec::with_capacity(clear);
        let mut parked = Parked::default();
        for (i, p) in self.all.points.iter().enumerate() {
            if self.node_blocked[i] {
                renumber[i] = next_parked;
                next_parked += 1;
                parked.points.push(p.clone());
            } else {
                renumber[i] = next_clear;
                next_clear += 1;
                points.push(p.clone());
            }
        }
        let mut edges = Vec::new();
        for (k, &(a, b, l)) in self.all.edges.iter().enumerate() {
            let (a, b) = (renumber[a], renumber[b]);
            let e = (a.min(b), a.max(b), l);
            if self.is_usable(k) {
                edges.push(e);
            } else {
                parked.edges.push(e);
            }
        }
        let mut map = self.all.clone();
        map.points = points;
        map.edges = edges;
        map.parked = (!parked.points.is_empty() || !parked.edges.is_empty()).then_some(parked);
        map.world = Some(self.world.to_spec());
        map
    }

    /// Grows points where the world changes since the last finished repair took coverage
    /// away (see the module documentation), within `options`' budget, and connects them; with
    /// `refill`, grows anywhere after that until the map has as many clear nodes as it had
    /// before. What a budget cuts short, the next repair continues; a finished repair is not
    /// repeated for the same world. The report's blocked/restored counts are left at zero
    /// (they belong to [`LiveMap::set_world`]).
    pub fn repair(&mut self, options: &RepairOptions) -> Result<RepairReport> {
        if let Some(s) = options.seconds.filter(|s| !(s.is_finite() && *s >= 0.0)) {
            return Err(RoadmapError::Unsuitable(format!(
                "a repair budget of {s} s: give a finite number of seconds, at least 0"
            )));
        }
        let started = Instant::now();
        let d = self.all.settings.spacing;
        let dim = self.all.points.first().map_or(0, |p| p.t.len());
        let clear: Vec<usize> = (0..self.all.points.len())
            .filter(|&i| !self.node_blocked[i])
            .collect();
        let occupied: BTreeSet<Vec<i64>> = clear
            .iter()
            .map(|&i| cell(&self.all.points[i].t, d))
            .collect();
        let mut lost = TaskIndex::new(dim);
        let mut lost_cells = BTreeSet::new();
        for &i in &self.pending {
            let t = &self.all.points[i].t;
            let c = cell(t, d);
            if !occupied.contains(&c) {
                lost.add(t);
                lost_cells.insert(c);
            }
        }
        let mut report = RepairReport {
            lost_cells: lost_cells.len(),
            stopped_because: "nothing lost".into(),
            ..Default::default()
        };
        report.seconds[0] = started.elapsed().as_secs_f64();
        let refill = options.refill && clear.len() < self.size;
        if lost.is_empty() && !refill {
            self.pending.clear();
            return Ok(report);
        }

        // grow in the current world: near the lost points, then (refill) anywhere
        let started = Instant::now();
        let objective = self
            .problem
            .objective
            .clone()
            .with_world(self.world.clone());
        let current: Vec<MapPoint> = clear.iter().map(|&i| self.all.points[i].clone()).collect();
        let mut setup = Setup::new(
            self.problem,
            Some(clear.len() + lost.len()),
            Some(self.all.searches),
            Some(self.all.seed.wrapping_add(self.repairs)),
        )?;
        self.repairs += 1;
        setup.objective = &objective;
        setup.region = Some(Region { lost, radius: d });
        setup.max_generations = 400;
        setup.repel_weight = 1.0;
        setup.settings.failure_limit = setup.settings.failure_limit.min(REPAIR_FAILURE_LIMIT);
        setup.settings.failures = trm_tasks::spec::FailureCount::Consecutive;
        setup.deadline = options
            .seconds
            .map(|s| started + Duration::from_secs_f64(s.min(1e9)));
        setup.max_evaluations = options.evaluations;
        let grown = run(
            &setup,
            State::from_points(&setup, current),
            None,
            &mut Solo,
            |_| {},
        )?;
        report.stopped_because = grown.stats.stopped_because.clone();
        let mut points = grown.points;
        let budget_left = setup.deadline.is_none_or(|d| Instant::now() < d)
            && options
                .evaluations
                .is_none_or(|m| grown.stats.evaluations < m);
        if refill && budget_left && points.len() < self.size {
            setup.region = None;
            setup.settings.failure_limit = self.all.settings.failure_limit;
            setup.settings.failures = self.all.settings.failures;
            setup.target = self.size;
            setup.max_evaluations = options
                .evaluations
                .map(|m| m.saturating_sub(grown.stats.evaluations));
            let state = State::from_points(&setup, points);
            let refilled = run(&setup, state, None, &mut Solo, |_| {})?;
            report.stopped_because = refilled.stats.stopped_because;
            points = refilled.points;
        }
        let cut_short = setup.deadline.is_some_and(|d| Instant::now() >= d)
            || report.stopped_because.contains("budget");
        if !cut_short {
            self.pending.clear();
        }
        report.seconds[1] = started.elapsed().as_secs_f64();

        // connect the new points to the clear ones and each other (old edges stay)
        let started = Instant::now();
        let new_points = points.split_off(clear.len());
        report.added_nodes = new_points.len();
        if !new_points.is_empty() {
            let mut valid = self.map();
            valid.parked = None;
            valid.points.extend(new_points.iter().cloned());
            let kept = valid.edges.len();
            let resolution = if self.all.edge_resolution > 0.0 {
                self.all.edge_resolution
            } else {
                DEFAULT_RESOLUTION
            };
            let neighbours = self.all.settings.edge_neighbours.max(1);
            connect_from(&mut valid, &objective, neighbours, resolution, clear.len())?;
            // valid's node i is clear[i] below clear.len(), a new node after
            let first_new = self.all.points.len();
            let to_all = |i: usize| {
                if i < clear.len() {
                    clear[i]
                } else {
                    first_new + i - clear.len()
                }
            };
            let added: Vec<(usize, usize, f64)> = valid
                .edges
                .iter()
                .filter(|&&(a, b, _)| a >= clear.len() || b >= clear.len())
                .map(|&(a, b, l)| (to_all(a), to_all(b), l))
                .collect();
            debug_assert_eq!(valid.edges.len() - kept, added.len());
            report.added_edges = added.len();
            self.all.points.extend(new_points);
            self.all.edges.extend(added);
            self.all.edge_resolution = resolution;
            self.node_blocked.resize(self.all.points.len(), false);
            self.edge_blocked.resize(self.all.edges.len(), false);
            self.index.extend(&self.all, &self.problem.objective)?;
        }
        report.seconds[2] = started.elapsed().as_secs_f64();
        self.size = self.size.max(clear.len() + report.added_nodes);
        report.restored_cells = (0..self.all.points.len())
            .filter(|&i| !self.node_blocked[i])
            .map(|i| cell(&self.all.points[i].t, d))
            .filter(|c| lost_cells.contains(c))
            .collect::<BTreeSet<_>>()
            .len();
        Ok(report)
    }
}

/// Repairs `map` (built for `problem`, its [`Roadmap::problem`]) for `world`: parks what the
/// world blocks, brings back parked nodes and edges it frees, and re-grows coverage where
/// points were lost, with the map's own settings and seed (reproducible without a time
/// budget); returns the repaired map — every node and edge collision-free in `world`, the
/// blocked ones in [`Roadmap::parked`], `world` recorded — and a report.
pub fn repair(
    map: &Roadmap,
    problem: &Problem,
    world: &World,
    options: &RepairOptions,
) -> Result<(Roadmap, RepairReport)> {
    if map.active.len() != problem.objective.dim() {
        return Err(RoadmapError::Unsuitable(format!(
            "the map has {} active motors, the problem {}: use the map's own problem",
            map.active.len(),
            problem.objective.dim()
        )));
    }
    let started = Instant::now();
    let mut live = LiveMap::new(map, problem)?;
    let changes = live.set_world(world.clone())?;
    let find_seconds = started.elapsed().as_secs_f64();
    let mut report = live.repair(options)?;
    report.blocked_nodes = changes.blocked_nodes.len();
    report.blocked_edges = changes.blocked_edges.len();
    report.restored_nodes = changes.freed_nodes.len();
    report.restored_edges = changes.freed_edges.len();
    report.seconds[0] += find_seconds;
    let mut repaired = live.map();
    repaired.stats = map.stats.clone();
    Ok((repaired, report))
}
