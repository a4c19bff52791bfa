//! The crate's error type.

use thiserror::Error;

/// Result alias of this crate.
pub type Result<T, E = TaskError> = std::result::Result<T, E>;

/// Spec and catalogue errors.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum TaskError {
    /// A spec file problem, located in the file (boxed: errors stay small).
    #[error(transparent)]
    Spec(Box<trm_io::SpecError>),
    /// An invalid value given in code.
    #[error("{what}: {problem}")]
    Invalid {
        /// What was given.
        what: String,
        /// What is wrong.
        problem: String,
    },
    /// From the robot model.
    #[error(transparent)]
    Kinematics(#[from] trm_kinematics::KinematicsError),
    /// From the collision layer.
    #[error(transparent)]
    Collision(#[from] trm_collision::CollisionError),
    /// From the optimiser.
    #[error(transparent)]
    Optim(#[from] trm_optim::OptimError),
    /// A file could not be read.
    #[error("{}: {source}", path.display())]
    Io {
        /// The file.
        path: std::path::PathBuf,
        /// The operating-system error.
        source: std::io::Error,
    },
}
