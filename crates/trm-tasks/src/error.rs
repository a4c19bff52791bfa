//! The crate's error type.

use thiserror::Error;

/// Result alias of this crate.
pub type Result<T, E = TaskError> = std::result::Result<T, E>;

/// Spec and catalogue errors.
#[derive(Debug, Error)]
pub enum TaskError {
    /// A spec file problem, located in the file.
    #[error("{origin}{}: {field}: {problem}{}", position.map(|(l, c)| format!(":{l}:{c}")).unwrap_or_default(), if fix.is_empty() { String::new() } else { format!("; fix: {fix}") })]
    Spec {
        /// The spec file.
        origin: String,
        /// 1-based (line, column), when known.
        position: Option<(usize, usize)>,
        /// The field or element.
        field: String,
        /// What is wrong.
        problem: String,
        /// How to fix it.
        fix: String,
    },
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
    #[error("{path}: {message}")]
    Io {
        /// The file.
        path: String,
        /// The reason.
        message: String,
    },
}
