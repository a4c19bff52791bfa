//! The crate's error type.

use thiserror::Error;

/// Result alias of this crate.
pub type Result<T, E = RoadmapError> = std::result::Result<T, E>;

/// Roadmap errors.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum RoadmapError {
    /// A map file could not be read or written.
    #[error(transparent)]
    MapFile(#[from] trm_io::FileError),
    /// From the task layer (specs, objective, solver); boxed, it is large.
    #[error(transparent)]
    Tasks(Box<trm_tasks::TaskError>),
    /// From the optimiser.
    #[error(transparent)]
    Optim(#[from] trm_optim::OptimError),
    /// The spec cannot make a map.
    #[error("{0}")]
    Unsuitable(String),
    /// A map file problem.
    #[error("{path}: {problem}")]
    File {
        /// The file.
        path: String,
        /// What is wrong.
        problem: String,
    },
}

impl From<trm_tasks::TaskError> for RoadmapError {
    fn from(e: trm_tasks::TaskError) -> Self {
        RoadmapError::Tasks(Box::new(e))
    }
}

impl From<trm_collision::CollisionError> for RoadmapError {
    fn from(e: trm_collision::CollisionError) -> Self {
        RoadmapError::Tasks(Box::new(trm_tasks::TaskError::Collision(e)))
    }
}
