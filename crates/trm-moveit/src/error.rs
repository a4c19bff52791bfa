//! The crate's error type.

use std::path::PathBuf;

use thiserror::Error;

/// Result alias of this crate.
pub type Result<T, E = MoveItError> = std::result::Result<T, E>;

/// What can go wrong reading, writing or applying MoveIt's messages.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum MoveItError {
    /// A scene or request file holds something trm cannot read.
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
    /// A file could not be read.
    #[error("{}: {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The operating-system error.
        source: std::io::Error,
    },
    /// From the kinematics (an unknown link or motor).
    #[error(transparent)]
    Kinematics(#[from] trm_kinematics::KinematicsError),
    /// From the collision crate (a world file, an allowed-collision matrix).
    #[error(transparent)]
    Collision(#[from] trm_collision::CollisionError),
}
