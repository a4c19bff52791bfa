//! Task maps, their metric and files, and the task-map cost.

use std::path::Path;

use kiddo::{KdTree, SquaredEuclidean};
use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};
use serde::{Deserialize, Serialize};
use thiserror::Error;

/// Task-map errors.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum TaskMapError {
    /// A task-map file could not be read or written.
    #[error(transparent)]
    MapFile(#[from] trm_io::FileError),
    /// A task-map spec holds something invalid: where (file, line:column, field path), what,
    /// fix (boxed: errors stay small).
    #[error(transparent)]
    Spec(Box<trm_io::SpecError>),
    /// From the kinematics (model loading, hand motors and links).
    #[error(transparent)]
    Kinematics(#[from] trm_kinematics::KinematicsError),
    /// From collision checking.
    #[error(transparent)]
    Collision(#[from] trm_collision::CollisionError),
    /// A setting out of range.
    #[error("invalid {what}: {problem}")]
    Invalid {
        /// The setting.
        what: String,
        /// What is wrong.
        problem: String,
    },
    /// A start point that is not feasible.
    #[error(
        "start g₀ #{index} is infeasible: C = {value} is not above the threshold {threshold}; give a feasible grasp to start from"
    )]
    InfeasibleStart {
        /// Which start.
        index: usize,
        /// Its evaluation.
        value: f64,
        /// θ.
        threshold: f64,
    },
    /// A file problem.
    #[error("{path}: {problem}")]
    File {
        /// The file.
        path: String,
        /// What is wrong.
        problem: String,
    },
}

/// The metric W = diag(w_p, w_p, w_p, w_o, w_o, w_o): metres against radians.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Metric {
    /// Weight of squared position differences (1/m²).
    pub position: f64,
    /// Weight of squared rotation-vector differences (1/rad²).
    pub orientation: f64,
}

impl Default for Metric {
    /// 1 cm counts as much as about 0.1 rad (5.7°).
    fn default() -> Self {
        Metric {
            position: 1.0,
            orientation: 0.01,
        }
    }
}

impl Metric {
    /// Checks that both weights are positive and finite.
    pub fn check(&self) -> Result<(), TaskMapError> {
        for (what, w) in [
            ("position weight", self.position),
            ("orientation weight", self.orientation),
        ] {
            if !(w.is_finite() && w > 0.0) {
                return Err(TaskMapError::Invalid {
                    what: format!("metric {what}"),
                    problem: format!("{w} is not a positive finite number (a degenerate metric)"),
                });
            }
        }
        Ok(())
    }

    /// √W ⊙ g: coordinates in which the metric is Euclidean.
    pub fn scale(&self, g: &[f64; 6]) -> [f64; 6] {
        let (p, o) = (self.position.sqrt(), self.orientation.sqrt());
        [g[0] * p, g[1] * p, g[2] * p, g[3] * o, g[4] * o, g[5] * o]
    }

    /// The metric distance ‖a − b‖_W.
    pub fn distance(&self, a: &[f64; 6], b: &[f64; 6]) -> f64 {
        let w = [
            self.position,
            self.position,
            self.position,
            self.orientation,
            self.orientation,
            self.orientation,
        ];
        (0..6)
            .map(|i| w[i] * (a[i] - b[i]).powi(2))
            .sum::<f64>()
            .sqrt()
    }
}

/// A pose as goal parameters: translation and rotation vector (axis × angle, |angle| ≤ π).
pub fn to_params(pose: &Isometry3<f64>) -> [f64; 6] {
    let t = pose.translation.vector;
    let r = pose.rotation.scaled_axis();
    [t.x, t.y, t.z, r.x, r.y, r.z]
}

/// The pose of goal parameters.
pub fn to_pose(g: &[f64; 6]) -> Isometry3<f64> {
    Isometry3::from_parts(
        Translation3::new(g[0], g[1], g[2]),
        UnitQuaternion::from_scaled_axis(Vector3::new(g[3], g[4], g[5])),
    )
}

/// A feasible point of a task map.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TaskPoint {
    /// Goal parameters (position, rotation vector).
    pub g: [f64; 6],
    /// Its evaluation C(g).
    pub value: f64,
    /// Tree parent (None for a cluster's root).
    pub parent: Option<usize>,
    /// Cluster (tree) index.
    pub cluster: usize,
}

/// A task map.
#[derive(Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TaskMap {
    /// Always `trm-taskmap`.
    pub format: String,
    /// File version.
    pub version: u32,
    /// The metric.
    pub metric: Metric,
    /// θ.
    pub threshold: f64,
    /// The points.
    pub points: Vec<TaskPoint>,
    /// Evaluations of C spent exploring.
    pub evaluations: u64,
    #[serde(skip)]
    index: Option<TaskIndexCell>,
}

/// The kd-tree over √W-scaled points.
struct TaskIndexCell(KdTree<f64, 6>);

impl std::fmt::Debug for TaskIndexCell {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("TaskIndexCell")
    }
}

impl Clone for TaskMap {
    fn clone(&self) -> Self {
        TaskMap::new(
            self.metric,
            self.threshold,
            self.points.clone(),
            self.evaluations,
        )
    }
}

impl PartialEq for TaskMap {
    fn eq(&self, other: &Self) -> bool {
        self.metric == other.metric
            && self.threshold == other.threshold
            && self.points == other.points
            && self.evaluations == other.evaluations
    }
}

const FORMAT: &str = "trm-taskmap";
const VERSION: u32 = 1;

impl TaskMap {
    pub(crate) fn new(
        metric: Metric,
        threshold: f64,
        points: Vec<TaskPoint>,
        evaluations: u64,
    ) -> Self {
        let mut map = TaskMap {
            format: FORMAT.into(),
            version: VERSION,
            metric,
            threshold,
            points,
            evaluations,
            index: None,
        };
        map.reindex();
        map
    }

    fn reindex(&mut self) {
        let mut index = KdTree::new();
        // one entry per place: the kd-tree's buckets cannot hold more identical points than
        // their size, and the nearest of identical points is the first anyway
        let mut seen = std::collections::HashSet::new();
        for (i, p) in self.points.iter().enumerate() {
            let scaled = self.metric.scale(&p.g);
            if seen.insert(scaled.map(|v| (v + 0.0).to_bits())) {
                index.add(&scaled, i as u64);
            }
        }
        self.index = Some(TaskIndexCell(index));
    }

    /// Number of clusters (disjoint trees).
    pub fn clusters(&self) -> usize {
        self.points.iter().map(|p| p.cluster + 1).max().unwrap_or(0)
    }

    /// The grasp whose position lies closest to the object's origin (the "exact target at the
    /// centre" of the paper's comparison).
    pub fn center_grasp(&self) -> Option<[f64; 6]> {
        self.points
            .iter()
            .min_by(|a, b| {
                let n = |g: &[f64; 6]| g[0] * g[0] + g[1] * g[1] + g[2] * g[2];
                n(&a.g).total_cmp(&n(&b.g))
            })
            .map(|p| p.g)
    }

    /// The nearest map point to `g` and its metric distance.
    pub fn nearest(&self, g: &[f64; 6]) -> Option<(usize, f64)> {
        let index = &self.index.as_ref()?.0;
        if self.points.is_empty() {
            return None;
        }
        let nn = index.nearest_one::<SquaredEuclidean>(&self.metric.scale(g));
        Some((nn.item as usize, nn.distance.sqrt()))
    }

    /// The task-map cost c_map = (x − x_map)ᵀ W (x − x_map) to the nearest map point, and its
    /// gradient 2 W (x − x_map) with respect to x (paper eq. 18–19). An empty map costs +∞.
    pub fn cost(&self, x: &[f64; 6]) -> (f64, [f64; 6]) {
        let Some((i, d)) = self.nearest(x) else {
            return (f64::INFINITY, [0.0; 6]);
        };
        let m = &self.points[i].g;
        let w = [
            self.metric.position,
            self.metric.position,
            self.metric.position,
            self.metric.orientation,
            self.metric.orientation,
            self.metric.orientation,
        ];
        let mut grad = [0.0; 6];
        for k in 0..6 {
            grad[k] = 2.0 * w[k] * (x[k] - m[k]);
        }
        (d * d, grad)
    }

    /// The map as JSON; a map that would not read back ([`TaskMap::load`]'s checks) is refused.
    /// `path` names the file it is for.
    pub fn to_json(&self, path: &Path) -> Result<String, TaskMapError> {
        self.check().map_err(|problem| TaskMapError::File {
            path: path.display().to_string(),
            problem: format!("not written: {problem}"),
        })?;
        Ok(trm_io::json_text(path, self, FORMAT)?)
    }

    /// Writes the map as JSON (atomically); see [`TaskMap::to_json`].
    pub fn save(&self, path: impl AsRef<Path>) -> Result<(), TaskMapError> {
        let path = path.as_ref();
        Ok(trm_io::write_file(path, &self.to_json(path)?)?)
    }

    /// Checks that the map holds something and that its points fit together: finite goal
    /// parameters and values, parents and clusters naming points of the map, a positive θ.
    fn check(&self) -> Result<(), String> {
        if self.points.is_empty() {
            return Err("the task map is empty: nothing feasible was found".into());
        }
        if !self.threshold.is_finite() {
            return Err(format!("threshold {} is not finite", self.threshold));
        }
        let n = self.points.len();
        for (i, p) in self.points.iter().enumerate() {
            if !(p.g.iter().all(|v| v.is_finite()) && p.value.is_finite()) {
                return Err(format!("points[{i}] holds a non-finite value"));
            }
            if let Some(k) = p.parent.filter(|&k| k >= i) {
                return Err(format!(
                    "points[{i}].parent = {k} does not name an earlier point"
                ));
            }
            if p.cluster >= n {
                return Err(format!(
                    "points[{i}].cluster = {} is not below the {n} points",
                    p.cluster
                ));
            }
        }
        Ok(())
    }

    /// Reads a map; truncated, foreign or newer files are clear errors.
    pub fn load(path: impl AsRef<Path>) -> Result<Self, TaskMapError> {
        let path = path.as_ref();
        Self::from_json(&trm_io::read_file(path)?, path)
    }

    /// Reads a task map from JSON text (`path` names it in errors), checked as
    /// [`TaskMap::load`] checks a file.
    pub fn from_json(text: &str, path: &Path) -> Result<Self, TaskMapError> {
        let mut map: TaskMap = trm_io::parse_versioned(path, text, FORMAT, VERSION)?;
        map.metric.check()?;
        map.check().map_err(|problem| TaskMapError::File {
            path: path.display().to_string(),
            problem: format!("{problem}; explore the task map again"),
        })?;
        map.reindex();
        Ok(map)
    }
}

/// A task map as a cost of trm-tasks' catalogue: the part's pose relative to the object, as a
/// grasp, against the map ([`TaskMap::cost`]).
impl trm_tasks::PoseMap for TaskMap {
    fn cost(&self, relative: &Isometry3<f64>) -> f64 {
        TaskMap::cost(self, &to_params(relative)).0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A map (from a file, say) holding more identical points than a kd-tree bucket: indexed
    /// without a panic, and the nearest is the first of them.
    #[test]
    fn identical_points_index_and_the_first_is_nearest() {
        let point = |x: f64| TaskPoint {
            g: [x, 0.0, 0.0, 0.0, 0.0, 0.0],
            value: 1.0,
            parent: None,
            cluster: 0,
        };
        let mut points: Vec<TaskPoint> = (0..100).map(|_| point(0.1)).collect();
        points.push(point(0.3));
        let map = TaskMap::new(Metric::default(), 0.0, points, 0);
        assert_eq!(map.nearest(&[0.12, 0.0, 0.0, 0.0, 0.0, 0.0]).unwrap().0, 0);
        assert_eq!(
            map.nearest(&[0.29, 0.0, 0.0, 0.0, 0.0, 0.0]).unwrap().0,
            100
        );
    }
}
