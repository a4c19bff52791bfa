//! The error type of this crate.

use std::path::PathBuf;

/// Everything that can go wrong while loading a motion spec or simulating and optimising a
/// motion.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum WholeBodyError {
    /// A motion spec holds something invalid: where (file, line:column, field path), what, fix.
    #[error("{origin}{}: {field}: {problem}{}", position.map(|(l, c)| format!(":{l}:{c}")).unwrap_or_default(), if fix.is_empty() { String::new() } else { format!("; fix: {fix}") })]
    Spec {
        /// The spec file (or `<string>`).
        origin: String,
        /// 1-based (line, column) of the field, when the text spells it out.
        position: Option<(usize, usize)>,
        /// Field path, e.g. `phases[1].keyframe.r_knee`.
        field: String,
        /// What is wrong.
        problem: String,
        /// What to do about it.
        fix: String,
    },
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
        let mut path = field;
        let position = loop {
            if let Some(at) = trm_kinematics::locate_ron_path(text, path) {
                break Some(at);
            }
            match path.rfind(['.', '[']) {
                Some(i) => path = &path[..i],
                None => break None,
            }
        };
        WholeBodyError::Spec {
            origin: origin.to_string(),
            position,
            field: field.to_string(),
            problem: problem.into(),
            fix: fix.into(),
        }
    }
}
