//! The crate's error type.

use std::path::PathBuf;

use thiserror::Error;
use trm_kinematics::KinematicsError;

/// Result alias of this crate.
pub type Result<T, E = CollisionError> = std::result::Result<T, E>;

/// Everything that can go wrong while building collision models or worlds.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum CollisionError {
    /// A file could not be read.
    #[error("{}: {source}", path.display())]
    Io {
        /// The file.
        path: std::path::PathBuf,
        /// The operating-system error.
        source: std::io::Error,
    },
    /// A name or description problem reported by the kinematics layer.
    #[error(transparent)]
    Kinematics(#[from] KinematicsError),
    /// A shape that cannot be used: unsupported, degenerate or not finite.
    #[error("{origin}{}: {element}: {problem}; fix: {fix}", line.map(|l| format!(":{l}")).unwrap_or_default())]
    InvalidShape {
        /// The file (or `<world>`) the shape comes from.
        origin: String,
        /// Line of the enclosing element, when known.
        line: Option<usize>,
        /// The element, e.g. `<collision> 1 of <link name="l_hand">`.
        element: String,
        /// What is wrong.
        problem: String,
        /// How to fix it.
        fix: String,
    },
    /// A mesh file named by a `<mesh filename>` could not be found.
    #[error(
        "{origin}{}: {element}: mesh `{uri}` not found (tried {}); fix: {}",
        line.map(|l| format!(":{l}")).unwrap_or_default(),
        if tried.is_empty() { "nothing".to_string() } else { tried.iter().map(|p| p.display().to_string()).collect::<Vec<_>>().join(", ") },
        if uri.starts_with("package://") {
            "add the directory that holds the package to the package paths (--package-path, ROS_PACKAGE_PATH)"
        } else {
            "check the path (relative paths start at the URDF's directory)"
        }
    )]
    MeshNotFound {
        /// The URDF.
        origin: String,
        /// Line of the enclosing `<link>`, when known.
        line: Option<usize>,
        /// The element.
        element: String,
        /// The filename as written.
        uri: String,
        /// Every path that was tried.
        tried: Vec<PathBuf>,
    },
    /// A mesh file exists but could not be read or holds no usable geometry.
    #[error("mesh {path}: {message} (referenced by {element} in {origin})")]
    MeshUnreadable {
        /// The mesh file.
        path: PathBuf,
        /// The URDF.
        origin: String,
        /// The element.
        element: String,
        /// What went wrong.
        message: String,
    },
    /// No collision body or world object has this name.
    #[error("unknown {kind} `{name}`{}", if suggestions.is_empty() { String::new() } else { format!("; did you mean `{}`?", suggestions.join("`, `")) })]
    UnknownName {
        /// `collision body` or `world object`.
        kind: &'static str,
        /// The name asked for.
        name: String,
        /// Close existing names.
        suggestions: Vec<String>,
    },
    /// A world object name is used twice.
    #[error("world object `{0}` already exists; fix: choose another name or move it with set_pose")]
    DuplicateObject(String),
    /// A pose or setting that is not finite or out of range.
    #[error("{what}: {problem}")]
    InvalidValue {
        /// What was given.
        what: String,
        /// What is wrong.
        problem: String,
    },
    /// A world file that RON cannot parse.
    #[error("{origin}:{line}:{column}: {message}")]
    MalformedWorld {
        /// The file.
        origin: String,
        /// 1-based line.
        line: usize,
        /// 1-based column.
        column: usize,
        /// The parser's message.
        message: String,
    },
}

pub(crate) fn unknown<'a>(
    kind: &'static str,
    name: &str,
    candidates: impl IntoIterator<Item = &'a str>,
) -> CollisionError {
    CollisionError::UnknownName {
        kind,
        name: name.to_string(),
        suggestions: trm_io::closest_names(name, candidates),
    }
}
