//! The error type of this crate.

use std::path::PathBuf;

/// Everything that can go wrong while loading a motion spec or simulating and optimising a
/// motion.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum WholeBodyError {
    /// A motion spec holds something invalid: where (file, line:column, field path), what,
    /// fix (boxed: errors stay small).
    #[error(transparent)]
    Spec(Box<trm_io::SpecError>),
    /// A file could not be read.
    #[error("{}: {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The operating-system error.
        source: std::io::Error,
    },
    /// From the kinematics (model loading, names, vector lengths).
    #[error(transparent)]
    Kinematics(#[from] trm_kinematics::KinematicsError),
    /// From collision checking (world objects, collision models).
    #[error(transparent)]
    Collision(#[from] trm_collision::CollisionError),
    /// From the optimiser.
    #[error(transparent)]
    Optim(#[from] trm_optim::OptimError),
    /// From the trajectory parametrisation.
    #[error(transparent)]
    Trajectory(#[from] trm_trajectory::TrajectoryError),
    /// An argument of a call that does not fit the problem (parameter counts, phase ends).
    #[error("{what}: {problem}")]
    Invalid {
        /// What was given.
        what: String,
        /// What is wrong.
        problem: String,
    },
}

impl WholeBodyError {
    /// A spec error at `field`, located in `text` by its field path (or its nearest ancestor).
    pub(crate) fn spec(
        text: &str,
        origin: &str,
        field: &str,
        problem: impl Into<String>,
        fix: impl Into<String>,
    ) -> Self {
        WholeBodyError::Spec(Box::new(trm_io::SpecError::at(
            text, origin, field, problem, fix,
        )))
    }
}
