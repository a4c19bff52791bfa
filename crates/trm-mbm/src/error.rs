//! The crate's error type.

use std::path::PathBuf;

use thiserror::Error;

/// Result alias of this crate.
pub type Result<T, E = MbmError> = std::result::Result<T, E>;

/// What can go wrong reading, generating, solving or reporting a problem set.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum MbmError {
    /// A problem of the set holds something the benchmark cannot take.
    #[error("{}{}: {problem}\n  fix: {fix}", path.display(), if *line > 0 { format!(":{line}") } else { String::new() })]
    Invalid {
        /// The file.
        path: PathBuf,
        /// 1-based line, 0 when unknown.
        line: usize,
        /// What is wrong.
        problem: String,
        /// What to do about it.
        fix: String,
    },
    /// A setting out of range.
    #[error("plan options: {what} {problem}")]
    InvalidOptions {
        /// The setting.
        what: String,
        /// What is wrong and what to give.
        problem: String,
    },
    /// A file or folder could not be read or written.
    #[error("{}: {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The operating-system error.
        source: std::io::Error,
    },
    /// A problem set could not be generated as asked.
    #[error("generating {what}: {problem}\n  fix: {fix}")]
    Generate {
        /// The problem or setting.
        what: String,
        /// What went wrong.
        problem: String,
        /// What to change.
        fix: String,
    },
    /// From the planner.
    #[error(transparent)]
    Plan(Box<trm_plan::PlanError>),
    /// From MoveIt's formats.
    #[error(transparent)]
    MoveIt(Box<trm_moveit::MoveItError>),
    /// From the kinematics.
    #[error(transparent)]
    Kinematics(#[from] trm_kinematics::KinematicsError),
    /// From the collision crate.
    #[error(transparent)]
    Collision(#[from] trm_collision::CollisionError),
    /// From the task crate.
    #[error(transparent)]
    Tasks(Box<trm_tasks::TaskError>),
}

impl From<trm_plan::PlanError> for MbmError {
    fn from(e: trm_plan::PlanError) -> Self {
        MbmError::Plan(Box::new(e))
    }
}

impl From<trm_tasks::TaskError> for MbmError {
    fn from(e: trm_tasks::TaskError) -> Self {
        MbmError::Tasks(Box::new(e))
    }
}

impl From<trm_moveit::MoveItError> for MbmError {
    fn from(e: trm_moveit::MoveItError) -> Self {
        MbmError::MoveIt(Box::new(e))
    }
}
