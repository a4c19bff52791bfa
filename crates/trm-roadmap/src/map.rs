//! Roadmaps and their files: versioned JSON with the spec, seed, settings, software version and
//! statistics inside, written atomically.

use std::path::Path;

use serde::{Deserialize, Serialize};
use trm_tasks::spec::MapSpec;

use crate::error::{Result, RoadmapError};

/// The file format's name and version.
pub const FORMAT: &str = "trm-roadmap";
/// Current file version.
pub const VERSION: u32 = 1;

/// A map point: a posture and its task vector.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MapPoint {
    /// Active motor values.
    pub q: Vec<f64>,
    /// Task vector g(q).
    pub t: Vec<f64>,
    /// The task cost h(q) (without the map-building terms).
    pub cost: f64,
}

/// How a map was built.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
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
    /// Statistics.
    pub stats: BuildStats,
}

impl Roadmap {
    /// Writes the map as JSON through a temporary file and a rename.
    pub fn save(&self, path: &Path) -> Result<()> {
        let text = serde_json::to_string(self).map_err(|e| RoadmapError::File {
            path: path.display().to_string(),
            problem: e.to_string(),
        })?;
        trm_kinematics::write_atomic(path, text.as_bytes()).map_err(|e| RoadmapError::File {
            path: path.display().to_string(),
            problem: e.to_string(),
        })
    }

    /// Reads a map file; a truncated, foreign or newer file is a clear error.
    pub fn load(path: &Path) -> Result<Self> {
        let fail = |problem: String| RoadmapError::File {
            path: path.display().to_string(),
            problem,
        };
        let text = std::fs::read_to_string(path).map_err(|e| fail(e.to_string()))?;
        let value: serde_json::Value = serde_json::from_str(&text).map_err(|e| {
            if e.is_eof() {
                fail(format!("truncated ({e}); rebuild the map"))
            } else {
                fail(format!("not a trm roadmap: {e}"))
            }
        })?;
        if value.get("format").and_then(|f| f.as_str()) != Some(FORMAT) {
            return Err(fail(format!(
                "not a trm roadmap (no `\"format\": \"{FORMAT}\"`)"
            )));
        }
        let version = value.get("version").and_then(|v| v.as_u64()).unwrap_or(0);
        if version != u64::from(VERSION) {
            return Err(fail(format!(
                "roadmap file version {version}; this trm reads version {VERSION}: rebuild it"
            )));
        }
        serde_json::from_value(value).map_err(|e| fail(format!("malformed roadmap: {e}")))
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
