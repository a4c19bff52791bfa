//! What a query asks and what it gets: goals, options, statistics, the planned motion.

use crate::PlanError;
use crate::trajectory::Trajectory;

/// A goal.
#[derive(Debug, Clone, PartialEq)]
pub enum Goal {
    /// A configuration (active values), attached to the graph like the start.
    Configuration(Vec<f64>),
    /// Any map node within `tolerance` of a task-space point.
    TaskPoint {
        /// The point.
        t: Vec<f64>,
        /// Task-space tolerance.
        tolerance: f64,
    },
    /// Any map node inside a task-space box.
    TaskRegion {
        /// Lower corner.
        min: Vec<f64>,
        /// Upper corner.
        max: Vec<f64>,
    },
}

impl Goal {
    /// Checks the goal against a configuration space of `active` motors and a task space of
    /// `task` dimensions: vectors of the right length, finite values, a finite non-negative
    /// tolerance, region corners in order.
    pub fn check(&self, active: usize, task: usize) -> Result<(), PlanError> {
        let bad = |problem: String, fix: &str| PlanError::InvalidGoal {
            problem,
            fix: fix.to_string(),
        };
        let vector = |what: &str, v: &[f64], n: usize, space: &str| {
            if v.len() != n {
                return Err(bad(
                    format!("{what} has {} values; the {space} has {n}", v.len()),
                    &format!("give {n} values"),
                ));
            }
            match v.iter().position(|x| !x.is_finite()) {
                Some(k) => Err(bad(
                    format!("{what}[{k}] is {}", v[k]),
                    "give finite values",
                )),
                None => Ok(()),
            }
        };
        match self {
            Goal::Configuration(q) => vector(
                "the goal configuration",
                q,
                active,
                "configuration space (active motors)",
            ),
            Goal::TaskPoint { t, tolerance } => {
                vector("the goal point", t, task, "task space")?;
                if tolerance.is_finite() && *tolerance >= 0.0 {
                    Ok(())
                } else {
                    Err(bad(
                        format!("the tolerance is {tolerance}"),
                        "give a finite tolerance, 0 or more (task-space units)",
                    ))
                }
            }
            Goal::TaskRegion { min, max } => {
                vector("the region's min", min, task, "task space")?;
                vector("the region's max", max, task, "task space")?;
                match (0..task).find(|&k| min[k] > max[k]) {
                    Some(k) => Err(bad(
                        format!("min[{k}] = {} is above max[{k}] = {}", min[k], max[k]),
                        "give the lower corner as min and the upper as max",
                    )),
                    None => Ok(()),
                }
            }
        }
    }
}

/// Query settings.
#[derive(Debug, Clone, PartialEq)]
pub struct PlanOptions {
    /// Largest joint step (rad) between collision checks along an edge.
    pub resolution: f64,
    /// Map nodes the start (and a configuration goal) connect to.
    pub attach_neighbours: usize,
    /// Shortcut attempts (0 = none).
    pub shortcuts: usize,
    /// Seed of the shortcut choices.
    pub seed: u64,
    /// How the path is timed: limits, blends, sampling ([`crate::Timing`]).
    pub timing: crate::Timing,
    /// Finish a task-point goal at the point itself, not at the map node within the tolerance:
    /// NGIK from the last node (the map's costs plus [`EXACT_WEIGHT`] · the task error, in the
    /// current world) and a collision-checked straight final segment. When that fails, the
    /// path ends at the node and [`PlanStats::exact`] says why.
    pub exact_goal: bool,
    /// Task error the exact finish must reach (task units: metres for positions).
    pub exact_tolerance: f64,
    /// Evaluation budget of the exact finish.
    pub exact_evaluations: u64,
    /// When the maps do not join the start and a configuration goal in the current world,
    /// RRT-Connect with these settings finishes the query ([`PlanStats::sampled`] says so);
    /// `None`: the maps alone answer.
    pub sampling: Option<crate::rrt::RrtOptions>,
    /// A* searches the lazy search through the graph may run (each followed by the checks of
    /// the path it found; `None`: no bound). When they are spent the query is
    /// [`PlanError::Unreachable`] or, with [`PlanOptions::sampling`], finished by RRT-Connect.
    pub max_searches: Option<usize>,
}

/// Weight of the task error in the exact finish of a task-point goal: large enough to dominate
/// the map's costs near the target (an unsquared error has a constant gradient there, so the
/// minimum sits on the target when its weight beats the other terms' slopes).
pub const EXACT_WEIGHT: f64 = 100.0;

/// How the exact finish of a task-point goal went.
#[derive(Debug, Clone, Default, PartialEq)]
#[non_exhaustive]
pub enum ExactGoal {
    /// Not attempted (not a task-point goal, or [`PlanOptions::exact_goal`] off).
    #[default]
    NotTried,
    /// The path ends at the goal: final task error and NGIK evaluations spent.
    Reached {
        /// Task-space distance of the final posture to the goal point.
        error: f64,
        /// NGIK evaluations.
        evaluations: u64,
        /// Waypoints of the short plan through the map that replaced a blocked straight last
        /// segment (0: the straight segment was free).
        detour: usize,
    },
    /// The path ends at the map node; why the exact finish was not used.
    Fallback {
        /// What failed.
        reason: String,
    },
}

impl Default for PlanOptions {
    fn default() -> Self {
        PlanOptions {
            resolution: 0.05,
            attach_neighbours: 10,
            shortcuts: 100,
            seed: 0,
            timing: crate::Timing::default(),
            exact_goal: true,
            exact_tolerance: 1e-3,
            exact_evaluations: 30_000,
            sampling: Some(crate::rrt::RrtOptions {
                max_iterations: 20_000,
                ..Default::default()
            }),
            max_searches: None,
        }
    }
}

impl PlanOptions {
    /// Checks the settings: a finite resolution of at least `trm_roadmap::MIN_RESOLUTION`, at
    /// least one attachment neighbour, a finite positive default velocity and acceleration.
    pub fn check(&self) -> Result<(), PlanError> {
        let bad = |what: &str, problem: String| {
            Err(PlanError::InvalidOptions {
                what: what.to_string(),
                problem,
            })
        };
        if !(self.resolution.is_finite() && self.resolution >= trm_roadmap::MIN_RESOLUTION) {
            return bad(
                "resolution",
                format!(
                    "{}: give a finite step of at least {} rad",
                    self.resolution,
                    trm_roadmap::MIN_RESOLUTION
                ),
            );
        }
        if self.attach_neighbours == 0 {
            return bad("attach_neighbours", "0: give at least 1".into());
        }
        self.timing.check()?;
        if !(self.exact_tolerance.is_finite() && self.exact_tolerance > 0.0) {
            return bad(
                "exact_tolerance",
                format!(
                    "{}: give a finite positive task error",
                    self.exact_tolerance
                ),
            );
        }
        if let Some(rrt) = &self.sampling {
            rrt.check()?;
        }
        if self.exact_goal && self.exact_evaluations == 0 {
            return bad(
                "exact_evaluations",
                "0: give a budget of at least 1 evaluation, or turn exact_goal off".into(),
            );
        }
        Ok(())
    }
}

/// What a query cost.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct PlanStats {
    /// A* searches run (1 + re-plans after invalid edges or nodes).
    pub searches: usize,
    /// Edges checked by interpolation.
    pub edges_checked: usize,
    /// Edges found blocked.
    pub edges_invalid: usize,
    /// Nodes found colliding.
    pub nodes_invalid: usize,
    /// Roadmap nodes on the path (before shortcutting).
    pub path_nodes: usize,
    /// Joint-space length after shortcutting.
    pub length: f64,
    /// Wall time, seconds.
    pub seconds: f64,
    /// Task-space distance of the path's end to a task-point goal (`None` for other goals).
    pub goal_error: Option<f64>,
    /// The exact finish of a task-point goal.
    pub exact: ExactGoal,
    /// The maps did not join start and goal: RRT-Connect found the path
    /// ([`PlanOptions::sampling`]); its samples and collision checks.
    pub sampled: Option<(usize, u64)>,
    /// The path is a kept one whose ends the query repeats, retrieved without a search
    /// ([`crate::RETRIEVE_STEPS`]).
    pub retrieved: bool,
}

/// A planned motion.
#[derive(Debug, Clone, PartialEq)]
pub struct Planned {
    /// The trajectory.
    pub trajectory: Trajectory,
    /// Map nodes visited (global indices over all maps).
    pub nodes: Vec<usize>,
    /// The path's waypoints in active values (the trajectory's positions are all motors').
    pub waypoints: Vec<Vec<f64>>,
    /// Statistics.
    pub stats: PlanStats,
}
