//! The crate's error type.

use thiserror::Error;

/// Planning failures.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum PlanError {
    /// From the kinematics (an unknown motor name, a wrong vector length).
    #[error(transparent)]
    Kinematics(#[from] trm_kinematics::KinematicsError),
    /// From the collision crate (a world file that cannot be read, an invalid object).
    #[error(transparent)]
    Collision(#[from] trm_collision::CollisionError),
    /// From the task crate (an objective that cannot be built, NGIK that cannot run).
    #[error(transparent)]
    Tasks(Box<trm_tasks::TaskError>),
    /// A file could not be read or written.
    #[error("{}: {source}", path.display())]
    Io {
        /// The file.
        path: std::path::PathBuf,
        /// The operating-system error.
        source: std::io::Error,
    },
    /// A versioned file (an experience file) could not be read or written.
    #[error(transparent)]
    File(#[from] trm_io::FileError),
    /// An experience file that does not fit the planner (other motors, a path that is not a
    /// path of its motors).
    #[error("{}: {problem}\n  fix: {fix}", path.display())]
    IncompatibleExperience {
        /// The file.
        path: std::path::PathBuf,
        /// What does not fit.
        problem: String,
        /// What to do about it.
        fix: String,
    },
    /// A trajectory file holds something invalid.
    #[error("{}{}: {problem}\n  fix: {fix}", path.display(), if *line > 0 { format!(":{line}") } else { String::new() })]
    InvalidTrajectory {
        /// The file.
        path: std::path::PathBuf,
        /// 1-based line, 0 when unknown.
        line: usize,
        /// What is wrong.
        problem: String,
        /// What to do about it.
        fix: String,
    },
    /// Maps that do not share the objective's configuration space.
    #[error("map {map}: {problem}")]
    IncompatibleMap {
        /// Index of the map.
        map: usize,
        /// What differs.
        problem: String,
    },
    /// A query setting out of range.
    #[error("plan options: {what} {problem}")]
    InvalidOptions {
        /// The setting.
        what: String,
        /// What is wrong and what to give.
        problem: String,
    },
    /// The start configuration collides in the current world, or has the wrong length.
    #[error("the start configuration is invalid: {0}")]
    InvalidStart(String),
    /// The goal does not fit the maps' spaces (wrong dimension, non-finite values, a region
    /// whose corners are swapped, a negative tolerance).
    #[error("the goal is invalid: {problem}\n  fix: {fix}")]
    InvalidGoal {
        /// What is wrong.
        problem: String,
        /// What to give.
        fix: String,
    },
    /// No collision-free path; `closest` is the reachable node nearest to the goal.
    #[error(
        "goal unreachable: {reason}{}", match closest_node { Some(n) => format!("; the closest reachable node is {n}, at task distance {closest_distance:.4}"), None => String::new() }
    )]
    Unreachable {
        /// Why.
        reason: String,
        /// The reachable node closest to the goal (task space), if any.
        closest_node: Option<usize>,
        /// Its task-space distance to the goal.
        closest_distance: f64,
    },
}

impl From<trm_tasks::TaskError> for PlanError {
    fn from(e: trm_tasks::TaskError) -> Self {
        PlanError::Tasks(Box::new(e))
    }
}
