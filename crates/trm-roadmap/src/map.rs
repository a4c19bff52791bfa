//! Roadmaps and their files: versioned JSON with the spec, seed, settings, software version and
//! statistics inside, written atomically.
//!
//! File format (`trm-roadmap`, version 1; the fields of [`Roadmap`]):
//!
//! ```json
//! { "format": "trm-roadmap", "version": 1, "software": "trm 0.1.0",
//!   "spec_path": "specs/reach.ron", "spec": "<the spec text, verbatim>",
//!   "seed": 0, "searches": 4, "settings": { "spacing": 0.025, … },
//!   "active": ["torso_pitch", …],            // the columns of every q
//!   "task": "position r_palm_center",
//!   "points": [ { "q": [ … ], "t": [x, y, z], "cost": 0.03 }, … ],
//!   "edges": [ [i, j, length], … ],           // i < j, checked collision-free
//!   "edge_resolution": 0.05,
//!   "world": { "objects": [ … ] },           // only in a repaired map: the world it is valid in
//!   "stats": { "build_seconds": 2.7, "evaluations": 123456, … } }
//! ```
//!
//! [`Roadmap::load`] refuses another format or version, a truncated file, and points and edges
//! that do not fit together (lengths, indices, non-finite values); [`Roadmap::problem`]
//! rebuilds the task from the embedded spec.

use std::path::Path;

use serde::{Deserialize, Serialize};
use trm_tasks::SpecLoaders;
use trm_tasks::spec::MapSpec;

use crate::error::{Result, RoadmapError};

/// The file format's name and version.
pub const FORMAT: &str = "trm-roadmap";
/// Current file version.
pub const VERSION: u32 = 1;

/// A map point: a posture and its task vector.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MapPoint {
    /// Active motor values.
    pub q: Vec<f64>,
    /// Task vector g(q).
    pub t: Vec<f64>,
    /// The task cost h(q) (without the map-building terms).
    pub cost: f64,
}

/// The nodes and edges of a repaired map that its world blocks ([`Roadmap::parked`]).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Parked {
    /// Blocked points.
    pub points: Vec<MapPoint>,
    /// Blocked edges and the edges of blocked points, `(i, j, length)`, i < j, over the map's
    /// points followed by the parked ones: node i ≥ `points.len()` of the map is parked point
    /// i − `points.len()`.
    pub edges: Vec<(usize, usize, f64)>,
}

/// How a map was built.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BuildStats {
    /// Wall time of construction, seconds.
    pub build_seconds: f64,
    /// Wall time of edge construction, seconds.
    pub edge_seconds: f64,
    /// Cost evaluations (centre evaluations included).
    pub evaluations: u64,
    /// Searches started.
    pub searches_started: u64,
    /// Searches whose result was rejected by CHECK.
    pub failures: u64,
    /// Why construction stopped.
    pub stopped_because: String,
    /// Threads used.
    pub threads: usize,
}

/// A task-relevant roadmap.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Roadmap {
    /// Always [`FORMAT`].
    pub format: String,
    /// File version.
    pub version: u32,
    /// The software that built it.
    pub software: String,
    /// Where the spec came from.
    pub spec_path: String,
    /// The spec text, verbatim.
    pub spec: String,
    /// Seed.
    pub seed: u64,
    /// Concurrent searches P.
    pub searches: usize,
    /// Map settings used.
    pub settings: MapSpec,
    /// Names of the active motors (the columns of q).
    pub active: Vec<String>,
    /// Label of the task function.
    pub task: String,
    /// The points.
    pub points: Vec<MapPoint>,
    /// Configuration-space edges `(i, j, length)`, i < j, checked collision-free.
    pub edges: Vec<(usize, usize, f64)>,
    /// Interpolation step (rad) at which edges were checked.
    pub edge_resolution: f64,
    /// The world the map is valid for when it is not its spec's (a repaired map's); absent
    /// otherwise.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub world: Option<trm_collision::WorldSpec>,
    /// Nodes and edges that `world` blocks, kept aside (a repaired map's): they come back,
    /// without a search, when a later repair finds them clear again.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub parked: Option<Parked>,
    /// Statistics.
    pub stats: BuildStats,
}

impl Roadmap {
    /// Writes the map as JSON through a temporary file and a rename.
    /// A map whose points and edges do not fit together (or hold NaN) is refused: every file
    /// written here reads back.
    pub fn save(&self, path: impl AsRef<Path>) -> Result<()> {
        let path = path.as_ref();
        Ok(trm_io::write_file(path, &self.to_json(path)?)?)
    }

    /// The map as JSON, refused as [`Roadmap::save`] refuses it; `path` names the file it is
    /// for.
    pub fn to_json(&self, path: &Path) -> Result<String> {
        self.check().map_err(|problem| RoadmapError::File {
            path: path.display().to_string(),
            problem: format!("not written: {problem}"),
        })?;
        Ok(trm_io::json_text(path, self, FORMAT)?)
    }

    /// Reads a map file; a truncated, foreign or newer file, or one whose points and edges do
    /// not fit together, is a clear error.
    pub fn load(path: impl AsRef<Path>) -> Result<Self> {
        let path = path.as_ref();
        Self::from_json(&trm_io::read_file(path)?, path)
    }

    /// Reads a map from JSON text (`path` names it in errors), checked as [`Roadmap::load`]
    /// checks a file.
    pub fn from_json(text: &str, path: &Path) -> Result<Self> {
        let map: Roadmap = trm_io::parse_versioned(path, text, FORMAT, VERSION)?;
        map.check().map_err(|problem| RoadmapError::File {
            path: path.display().to_string(),
            problem: format!("{problem}; rebuild the map"),
        })?;
        Ok(map)
    }

    /// Checks that points and edges fit together: one value per active motor in every posture,
    /// one task dimension for all, finite numbers, edges between existing points.
    fn check(&self) -> std::result::Result<(), String> {
        let parked = self.parked.clone().unwrap_or_default();
        let dim = self
            .points
            .iter()
            .chain(&parked.points)
            .next()
            .map_or(0, |p| p.t.len());
        self.settings
            .check()
            .map_err(|p| format!("settings.{}: {}", p.field, p.problem))?;
        check_points("points", &self.points, self.active.len(), dim)?;
        check_points("parked.points", &parked.points, self.active.len(), dim)?;
        let edges = self.edges.len() + parked.edges.len();
        if edges > 0 && crate::check_edge_resolution(self.edge_resolution).is_err() {
            return Err(format!(
                "edge_resolution {} for {edges} edges: edges are checked at a finite step of at least {} rad",
                self.edge_resolution,
                crate::MIN_RESOLUTION
            ));
        }
        check_edges("edges", &self.edges, self.points.len())?;
        check_edges(
            "parked.edges",
            &parked.edges,
            self.points.len() + parked.points.len(),
        )
    }

    /// The task this map was built for, rebuilt from the spec the map carries (its model and
    /// world files are found relative to the spec's original location, `spec_path`). Fails when
    /// the spec no longer loads or no longer has the map's active motors, or names a file
    /// another crate reads (a task map: [`Roadmap::problem_with`]).
    pub fn problem(&self) -> Result<trm_tasks::Problem> {
        self.problem_with(&SpecLoaders::default())
    }

    /// [`Roadmap::problem`], the spec's files read by `loaders`.
    pub fn problem_with(&self, loaders: &SpecLoaders) -> Result<trm_tasks::Problem> {
        let mut problem = problem_from_spec(&self.spec_path, &self.spec, &self.active, loaders)?;
        if let Some(world) = &self.world {
            let world = trm_collision::World::from_spec(world, &self.spec_path).map_err(|e| {
                RoadmapError::Unsuitable(format!(
                    "the map's recorded world: {e}; repair the map again"
                ))
            })?;
            problem.objective.set_world(world);
        }
        let dim = problem.objective.task().map_or(0, |t| t.dim());
        let robot = problem.objective.active().model();
        let motors = problem.objective.active().motor_indices();
        let mut scratch = problem.objective.scratch();
        let parked = self.parked.as_ref().map_or(&[][..], |p| &p.points[..]);
        let lists = [("points", &self.points[..]), ("parked.points", parked)];
        for (i, (what, p)) in lists
            .iter()
            .flat_map(|&(what, list)| list.iter().enumerate().map(move |(i, p)| (i, (what, p))))
        {
            if p.t.len() != dim {
                return Err(RoadmapError::Unsuitable(format!(
                    "{what}[{i}].t has {} dimensions, the task of the spec stored in the map ({}) {dim}: rebuild the map",
                    p.t.len(),
                    self.spec_path
                )));
            }
            for (&m, &v) in motors.iter().zip(&p.q) {
                let motor = &robot.motors()[m];
                motor.limits.check(v).map_err(|problem| {
                    RoadmapError::Unsuitable(format!(
                        "{what}[{i}]: `{}` {problem}: rebuild the map",
                        motor.name
                    ))
                })?;
            }
            // the stored task point is the task function at the stored posture
            let t = problem.objective.task_value(&p.q, &mut scratch);
            let gap = t
                .iter()
                .zip(&p.t)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max);
            if gap > 1e-6 {
                return Err(RoadmapError::Unsuitable(format!(
                    "{what}[{i}].t is {gap:.3e} away from the task value of {what}[{i}].q: the map does not fit the spec stored in it ({}); rebuild the map",
                    self.spec_path
                )));
            }
        }
        Ok(problem)
    }

    /// Spacing, coverage and cost of the map's points ([`MapSummary`]).
    pub fn summary(&self) -> MapSummary {
        let n = self.points.len();
        let extent = self.extent();
        // each point's nearest other point, through the kd-tree (n log n, not n²)
        let dim = self.points.first().map_or(0, |p| p.t.len());
        let mut index = crate::TaskIndex::new(dim);
        for p in &self.points {
            index.add(&p.t);
        }
        let mut nn = Vec::new();
        let nearest: Vec<f64> = self
            .points
            .iter()
            .enumerate()
            .map(|(i, p)| {
                index.nearest(&p.t, 2, &mut nn);
                nn.iter()
                    .find(|&&(_, j)| j != i)
                    .map_or(f64::INFINITY, |&(dt, _)| dt)
            })
            .collect();
        let spacing = (n > 1).then(|| {
            (
                nearest.iter().sum::<f64>() / n as f64,
                nearest.iter().copied().fold(f64::INFINITY, f64::min),
            )
        });
        let d = self.settings.spacing;
        let coverage = (n > 0 && d > 0.0).then(|| {
            let total: f64 = extent
                .iter()
                .map(|(lo, hi)| ((hi - lo) / d).floor() + 1.0)
                .product();
            let occupied: std::collections::BTreeSet<Vec<u64>> = self
                .points
                .iter()
                .map(|p| {
                    p.t.iter()
                        .zip(&extent)
                        .map(|(v, (lo, _))| ((v - lo) / d).floor() as u64)
                        .collect()
                })
                .collect();
            (occupied.len(), total)
        });
        MapSummary {
            points: n,
            edges: self.edges.len(),
            components: self.components(),
            extent,
            spacing,
            coverage,
            mean_cost: self.points.iter().map(|p| p.cost).sum::<f64>() / n.max(1) as f64,
        }
    }

    /// Task-space extent: per dimension (min, max).
    pub fn extent(&self) -> Vec<(f64, f64)> {
        let dim = self.points.first().map_or(0, |p| p.t.len());
        (0..dim)
            .map(|i| {
                self.points
                    .iter()
                    .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| {
                        (lo.min(p.t[i]), hi.max(p.t[i]))
                    })
            })
            .collect()
    }

    /// Number of connected components of the edge graph.
    pub fn components(&self) -> usize {
        let mut graph = petgraph::graph::UnGraph::<(), f64>::new_undirected();
        let nodes: Vec<_> = (0..self.points.len()).map(|_| graph.add_node(())).collect();
        for &(a, b, w) in &self.edges {
            graph.add_edge(nodes[a], nodes[b], w);
        }
        petgraph::algo::connected_components(&graph)
    }
}

/// The task of a spec stored in a map or checkpoint (its model and world files found relative
/// to the spec's original location `spec_path`, other files read by `loaders`); it must still
/// select the `active` motors.
pub(crate) fn problem_from_spec(
    spec_path: &str,
    spec: &str,
    active: &[String],
    loaders: &SpecLoaders,
) -> Result<trm_tasks::Problem> {
    let base = Path::new(spec_path).parent().unwrap_or(Path::new("."));
    let problem = trm_tasks::Problem::from_ron_with(spec, spec_path, base, loaders)?;
    let names: Vec<&str> = problem.objective.active().names().collect();
    if names != active.iter().map(String::as_str).collect::<Vec<_>>() {
        return Err(RoadmapError::Unsuitable(format!(
            "the spec stored in the file ({spec_path}) now selects {} active motors, the file has {}: build again",
            names.len(),
            active.len()
        )));
    }
    Ok(problem)
}

/// Checks a list of points: one value per active motor, `dim` task dimensions, finite values.
fn check_points(
    what: &str,
    points: &[MapPoint],
    active: usize,
    dim: usize,
) -> std::result::Result<(), String> {
    for (i, p) in points.iter().enumerate() {
        if p.q.len() != active {
            return Err(format!(
                "{what}[{i}].q has {} values for {active} active motors",
                p.q.len()
            ));
        }
        if p.t.len() != dim {
            return Err(format!(
                "{what}[{i}].t has {} dimensions, points[0].t {dim}",
                p.t.len()
            ));
        }
        if !(p.q.iter().chain(&p.t).all(|v| v.is_finite()) && p.cost.is_finite()) {
            return Err(format!("{what}[{i}] holds a non-finite value"));
        }
    }
    Ok(())
}

/// Checks a list of edges: two different nodes of `nodes`, a finite length.
fn check_edges(
    what: &str,
    edges: &[(usize, usize, f64)],
    nodes: usize,
) -> std::result::Result<(), String> {
    for (k, &(a, b, w)) in edges.iter().enumerate() {
        if a >= nodes || b >= nodes || a == b {
            return Err(format!(
                "{what}[{k}] = ({a}, {b}, {w}) does not join two of the {nodes} points"
            ));
        }
        // searches through the map (A*) are only right with non-negative costs
        if !(w.is_finite() && w >= 0.0) {
            return Err(format!(
                "{what}[{k}] = ({a}, {b}, {w}): an edge's cost is a finite length, 0 or more"
            ));
        }
    }
    Ok(())
}

/// The task-space cell of side `d` holding `t` (cells anchored at the origin).
pub(crate) fn cell(t: &[f64], d: f64) -> Vec<i64> {
    t.iter().map(|v| (v / d).floor() as i64).collect()
}

impl Roadmap {
    /// Task-space cells of side d (the map's spacing, anchored at the origin) that hold a point:
    /// the coverage a repair and a rebuild are compared by.
    pub fn occupied_cells(&self) -> usize {
        let d = self.settings.spacing;
        self.points
            .iter()
            .map(|p| cell(&p.t, d))
            .collect::<std::collections::BTreeSet<_>>()
            .len()
    }
}

/// What [`Roadmap::summary`] reports.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct MapSummary {
    /// Number of points.
    pub points: usize,
    /// Number of edges.
    pub edges: usize,
    /// Connected components of the edge graph.
    pub components: usize,
    /// Task-space extent, per dimension (min, max).
    pub extent: Vec<(f64, f64)>,
    /// Task-space distance of each point to its nearest other point: (mean, min); `None` below
    /// two points.
    pub spacing: Option<(f64, f64)>,
    /// Cells of side d (the map's spacing setting) in the extent box: (occupied, total).
    pub coverage: Option<(usize, f64)>,
    /// Mean task cost of the points.
    pub mean_cost: f64,
}
