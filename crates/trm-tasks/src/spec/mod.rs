//! Task specs in RON: robot model and active motors, start posture, world, weighted costs, task
//! function, robustness noise, solver and map settings. The format is documented in
//! [`crate::formats::task_spec`]; [`Problem::load`] turns a file into an [`Objective`](crate::Objective) with errors that name
//! the file, line, column and field, and suggest the closest valid names.
//!
//! The schema is in this module; `problem` turns a parsed spec into a [`Problem`] (model,
//! frames, active motors, world, start), `resolve` turns cost and task entries into catalogue
//! objects. Every error names its field path (`costs[2].cost.part`) and is located there.

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};
use trm_collision::WorldSpec;
use trm_kinematics::FrameSpec;

use crate::error::TaskError;

mod problem;
mod resolve;

pub use problem::Problem;

fn all_axes() -> [bool; 3] {
    [true; 3]
}

fn yes() -> bool {
    true
}

/// A whole spec file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Spec {
    /// `icub_upper_body` (embedded) or a `.urdf`/`.ron` model path relative to the spec.
    pub model: String,
    /// Extra named frames (a link or frame plus an offset), usable as parts in this spec.
    #[serde(default)]
    pub frames: Vec<FrameSpec>,
    /// Active motors: motor or group names; empty = every motor.
    #[serde(default)]
    pub active: Vec<String>,
    /// The start posture (and values of locked motors): a posture name of the model; by default
    /// `home` if the model has one, else every motor at 0 clamped into its limits.
    #[serde(default)]
    pub start: Option<String>,
    /// Motor values overriding the start posture, by motor name.
    #[serde(default)]
    #[serde(deserialize_with = "trm_io::unique_names")]
    pub start_values: BTreeMap<String, f64>,
    /// World objects.
    #[serde(default)]
    pub world: WorldSpec,
    /// Weighted cost terms (at least one).
    pub costs: Vec<CostSpec>,
    /// Optional task function (needed for maps).
    #[serde(default)]
    pub task: Option<TaskSpec>,
    /// Optional robustness noise on q.
    #[serde(default)]
    pub noise: Option<NoiseSpec>,
    /// Solver settings.
    #[serde(default)]
    pub solver: SolverSpec,
    /// Roadmap settings (used by `build-map`).
    #[serde(default)]
    pub map: Option<MapSpec>,
}

/// `(weight: a, cost: …)`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CostSpec {
    /// aᵢ ≥ 0.
    pub weight: f64,
    /// The term.
    pub cost: CostKind,
}

/// A point: a robot frame (link or named frame), a world object's origin, or fixed coordinates.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum AnchorSpec {
    /// A link or named frame.
    Part(String),
    /// A world object.
    Object(String),
    /// World coordinates.
    Point([f64; 3]),
}

/// Target of a position term.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum TargetSpec {
    /// A link or named frame.
    Part(String),
    /// A world object's origin.
    Object(String),
    /// World coordinates.
    Point([f64; 3]),
    /// Anywhere inside an axis-aligned box.
    Box {
        /// Lower corner.
        min: [f64; 3],
        /// Upper corner.
        max: [f64; 3],
    },
    /// Anywhere inside a ball.
    Sphere {
        /// Centre.
        center: AnchorSpec,
        /// Radius.
        radius: f64,
    },
}

/// A desired direction.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum DirectionSpec {
    /// A fixed world direction.
    Fixed([f64; 3]),
    /// Another frame's axis.
    Axis {
        /// The frame.
        part: String,
        /// The axis in that frame.
        axis: [f64; 3],
    },
}

/// The cost catalogue (Table I).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum CostKind {
    /// ‖W (q − q*)‖; q* a posture of the model (default: the spec's start), W per motor or group.
    HomePosture {
        /// Posture name; the spec's start when absent.
        #[serde(default)]
        posture: Option<String>,
        /// Weights by motor or group name; 1 for the rest.
        #[serde(default)]
        #[serde(deserialize_with = "trm_io::unique_names")]
        weights: BTreeMap<String, f64>,
    },
    /// Number of colliding pairs.
    Collision {
        /// Count self-collisions.
        #[serde(default = "yes")]
        self_collision: bool,
        /// Count collisions with world objects.
        #[serde(default = "yes")]
        world: bool,
    },
    /// Attract a part to a point, part, object, box or ball.
    Position {
        /// The part.
        part: String,
        /// Where to.
        target: TargetSpec,
        /// Axes that count.
        #[serde(default = "all_axes")]
        mask: [bool; 3],
    },
    /// Align a part's axis with a direction.
    Orientation {
        /// The part.
        part: String,
        /// Its axis.
        axis: [f64; 3],
        /// The direction.
        toward: DirectionSpec,
    },
    /// Point a part's axis at something, optionally from a distance.
    Pointing {
        /// The part.
        part: String,
        /// Its axis.
        axis: [f64; 3],
        /// The target.
        at: AnchorSpec,
        /// Distance to keep.
        #[serde(default)]
        distance: Option<f64>,
    },
    /// Push two anchors apart up to a distance.
    Repel {
        /// First.
        a: AnchorSpec,
        /// Second.
        b: AnchorSpec,
        /// Distance from which repulsion starts.
        min_distance: f64,
        /// Axes that count.
        #[serde(default = "all_axes")]
        mask: [bool; 3],
    },
    /// Soft joint limits.
    JointLimits {
        /// Margin inside the limits (radians).
        margin: f64,
    },
    /// Minimal displacement from the start posture.
    Displacement,
    /// Distance (metric W of the map) from the part's pose relative to a world object to the
    /// nearest point of a task map file (`cargo xtask explore-task-map`).
    TaskMap {
        /// The task map file, relative to the spec.
        file: String,
        /// The part (e.g. `r_hand`).
        part: String,
        /// The world object the map is relative to.
        object: String,
    },
}

/// The task catalogue (Table II and composites).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum TaskSpec {
    /// A part's position.
    Position {
        /// The part.
        part: String,
        /// Axes kept.
        #[serde(default = "all_axes")]
        mask: [bool; 3],
    },
    /// A part's axis direction.
    Rotation {
        /// The part.
        part: String,
        /// The axis.
        axis: [f64; 3],
        /// Components kept.
        #[serde(default = "all_axes")]
        mask: [bool; 3],
        /// The part (or frame) whose frame the direction is expressed in: the hand's angles
        /// relative to the head, say. The world when absent.
        #[serde(default)]
        relative_to: Option<String>,
    },
    /// Distance between two anchors.
    Distance {
        /// First.
        a: AnchorSpec,
        /// Second.
        b: AnchorSpec,
    },
    /// Angle of b→a projected on the plane (u1, u2).
    Angle {
        /// First.
        a: AnchorSpec,
        /// Second.
        b: AnchorSpec,
        /// First plane axis.
        u1: [f64; 3],
        /// Second plane axis.
        u2: [f64; 3],
    },
    /// Midpoint of two anchors.
    Midpoint {
        /// First.
        a: AnchorSpec,
        /// Second.
        b: AnchorSpec,
        /// Axes kept.
        #[serde(default = "all_axes")]
        mask: [bool; 3],
    },
    /// A part's full pose, 6-D: its position (metres), then its orientation as the rotation
    /// vector from `reference` (roll, pitch, yaw in the world frame) to the part's frame,
    /// times `scale` (metres per radian), so that task-space distances weigh 1 rad of turn like
    /// `scale` metres of travel. The rotation vector is continuous for turns below π from the
    /// reference: pick a reference near the orientations the map will hold.
    Pose {
        /// The part.
        part: String,
        /// Metres per radian (default 0.1: 1 cm of spacing ≈ 5.7°).
        #[serde(default = "default_pose_scale")]
        scale: f64,
        /// Reference orientation, roll-pitch-yaw (radians, world frame).
        #[serde(default)]
        reference: [f64; 3],
    },
    /// Direction of the rod from a to b.
    RodDirection {
        /// First.
        a: AnchorSpec,
        /// Second.
        b: AnchorSpec,
        /// Components kept.
        #[serde(default = "all_axes")]
        mask: [bool; 3],
    },
}

fn default_pose_scale() -> f64 {
    0.1
}

/// Robustness: the expected cost under N(0, σ²) noise on q.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct NoiseSpec {
    /// Noise samples per evaluation.
    pub samples: usize,
    /// Standard deviation (radians).
    pub sigma: f64,
    /// Seed of the (fixed) noise offsets.
    #[serde(default)]
    pub seed: u64,
}

/// Solver settings for NGIK.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SolverSpec {
    /// Algorithm name (see `trm_optim::ALGORITHMS`).
    pub algo: String,
    /// Initial step size (radians).
    pub sigma: f64,
    /// Population size; the algorithm's default when absent.
    pub population: Option<usize>,
    /// Evaluation budget.
    pub max_evaluations: u64,
    /// Stop when the best has not improved for this many evaluations.
    pub no_improvement: Option<u64>,
    /// Stop at this cost.
    pub target: Option<f64>,
    /// Seed.
    pub seed: u64,
}

impl SolverSpec {
    /// These settings with a caller's choices over them (`None`: the spec's): what `trm solve
    /// --algo --seed --max-evals` and Python's `Problem.solve(algo=, seed=, max_evals=)` do.
    /// An unknown algorithm is refused, naming the nearest (the solver checks the rest).
    pub fn overridden(
        &self,
        algo: Option<&str>,
        seed: Option<u64>,
        max_evaluations: Option<u64>,
    ) -> crate::Result<Self> {
        if let Some(a) = algo.filter(|a| !trm_optim::ALGORITHMS.contains(a)) {
            let near = trm_io::closest_names(a, trm_optim::ALGORITHMS.iter().copied());
            let hint = if near.is_empty() {
                format!("give one of {}", trm_optim::ALGORITHMS.join(", "))
            } else {
                format!("did you mean `{}`?", near.join("`, `"))
            };
            return Err(crate::TaskError::Invalid {
                what: format!("algorithm `{a}`"),
                problem: format!("unknown\n  fix: {hint}"),
            });
        }
        Ok(SolverSpec {
            algo: algo.map_or_else(|| self.algo.clone(), str::to_string),
            seed: seed.unwrap_or(self.seed),
            max_evaluations: max_evaluations.unwrap_or(self.max_evaluations),
            ..self.clone()
        })
    }
}

impl Default for SolverSpec {
    fn default() -> Self {
        SolverSpec {
            algo: "xnes".into(),
            sigma: 0.4,
            population: None,
            max_evaluations: 100_000,
            no_improvement: Some(10_000),
            target: None,
            seed: 0,
        }
    }
}

/// Which failed searches stop a map build ([`MapSpec::failure_limit`]).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum FailureCount {
    /// All of them, as Algorithm 1 of the E-TRM paper counts (the default).
    #[default]
    Total,
    /// Only those since the last accepted point (every accepted point resets the count).
    Consecutive,
}

/// Roadmap settings (E-TRM and parallel E-TRM; defaults from the papers).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct MapSpec {
    /// Desired task-space spacing d between neighbouring points.
    pub spacing: f64,
    /// Weight of the map-building cost.
    pub construct_weight: f64,
    /// Smoothness weight c on ‖q − q′‖.
    pub smoothness: f64,
    /// Failed searches after which construction stops (k), counted as `failures` says.
    pub failure_limit: usize,
    /// Which failed searches count towards `failure_limit`.
    pub failures: FailureCount,
    /// Largest number of points.
    pub max_points: usize,
    /// (λ, σ) of the first point's search.
    pub first_search: (usize, f64),
    /// (λ, σ) of later searches.
    pub later_search: (usize, f64),
    /// Concurrent searches P of parallel E-TRM.
    pub searches: usize,
    /// Configuration-space neighbours per node for edges.
    pub edge_neighbours: usize,
}

impl Default for MapSpec {
    fn default() -> Self {
        MapSpec {
            spacing: 0.025,
            construct_weight: 1.0,
            smoothness: 0.01,
            failure_limit: 100,
            failures: FailureCount::Total,
            max_points: 1000,
            first_search: (150, 0.15),
            later_search: (30, 0.03),
            searches: 1,
            edge_neighbours: 8,
        }
    }
}

/// A value out of its range, found by a settings check: the field (relative to the settings),
/// what is wrong and the fix.
#[derive(Debug, Clone, PartialEq)]
pub struct FieldProblem {
    /// Field path relative to the checked value (`spacing`, `first_search`).
    pub field: String,
    /// What is wrong.
    pub problem: String,
    /// How to fix it.
    pub fix: String,
}

impl MapSpec {
    /// Checks every setting's range, as a spec's `map` and a map file's `settings` are checked:
    /// positive finite spacing and step sizes, non-negative finite weights, counts within
    /// bounds that keep a build finite.
    pub fn check(&self) -> std::result::Result<(), FieldProblem> {
        let problem = |field: &str, problem: String, fix: &str| FieldProblem {
            field: field.to_string(),
            problem,
            fix: fix.to_string(),
        };
        let count = |field: &str, v: usize, lo: usize, hi: usize| {
            if (lo..=hi).contains(&v) {
                Ok(())
            } else {
                Err(problem(
                    field,
                    format!("{v} is not in {lo}..={hi}"),
                    "give a count in that range",
                ))
            }
        };
        let number = |field: &str, v: f64, positive: bool| {
            if v.is_finite() && (v > 0.0 || (!positive && v >= 0.0)) {
                Ok(())
            } else {
                let what = if positive { "above 0" } else { "0 or more" };
                Err(problem(
                    field,
                    format!("{v} is not a finite number {what}"),
                    "give a finite number",
                ))
            }
        };
        number("spacing", self.spacing, true)?;
        number("construct_weight", self.construct_weight, false)?;
        number("smoothness", self.smoothness, false)?;
        count("failure_limit", self.failure_limit, 1, 10_000_000)?;
        count("max_points", self.max_points, 1, 10_000_000)?;
        count("first_search", self.first_search.0, 2, 1_000_000)?;
        number("first_search", self.first_search.1, true)?;
        count("later_search", self.later_search.0, 2, 1_000_000)?;
        number("later_search", self.later_search.1, true)?;
        count("searches", self.searches, 1, 4096)?;
        count("edge_neighbours", self.edge_neighbours, 1, 10_000)
    }
}

/// A RON error with its position and, for unknown names, the closest valid ones.
pub fn ron_error(e: &ron::error::SpannedError, origin: &str) -> TaskError {
    TaskError::Spec(Box::new(trm_io::SpecError::from_ron(e, origin)))
}
