//! The error type of this crate.

use std::fmt;
use std::path::PathBuf;

/// What kind of name a lookup failed on.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum NameKind {
    /// A URDF link.
    Link,
    /// A URDF joint.
    Joint,
    /// A motor (an optimisation variable before active-joint selection).
    Motor,
    /// A link or a named frame.
    Frame,
    /// A motor group.
    Group,
    /// A motor or a group of motors.
    MotorOrGroup,
    /// A named posture.
    Posture,
}

impl fmt::Display for NameKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            NameKind::Link => "link",
            NameKind::Joint => "joint",
            NameKind::Motor => "motor",
            NameKind::Frame => "link or frame",
            NameKind::Group => "group",
            NameKind::MotorOrGroup => "motor or group",
            NameKind::Posture => "posture",
        })
    }
}

/// Everything that can go wrong while loading or using a robot model.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum KinematicsError {
    /// A versioned JSON file could not be read or written.
    #[error(transparent)]
    File(#[from] trm_io::FileError),
    /// A file trm reads (a posture file, a configuration file) holds something invalid.
    #[error("{}: {}{problem}\n  fix: {fix}", path.display(), if field.is_empty() { String::new() } else { format!("{field}: ") })]
    InvalidFile {
        /// The file.
        path: PathBuf,
        /// The field path inside it (`motors.r_elbow`), or empty for the whole file.
        field: String,
        /// What is wrong.
        problem: String,
        /// What to do about it.
        fix: String,
    },
    /// A file could not be read.
    #[error("{}: cannot read file: {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The operating-system error.
        source: std::io::Error,
    },
    /// The URDF is not well-formed XML or does not follow the URDF schema.
    #[error(
        "{origin}: malformed URDF: {message}\n  fix: the file must be well-formed XML with one <robot name=\"…\"> element holding <link> and <joint> elements"
    )]
    MalformedUrdf {
        /// The file (or `<string>`) the URDF came from.
        origin: String,
        /// The parser's message.
        message: String,
    },
    /// A model description (RON) could not be parsed.
    #[error(
        "{origin}:{line}:{column}: malformed model description: {message}\n  fix: see models/README.md for the format"
    )]
    MalformedDescription {
        /// The file (or `<string>`) the description came from.
        origin: String,
        /// 1-based line.
        line: usize,
        /// 1-based column.
        column: usize,
        /// The parser's message.
        message: String,
    },
    /// The model parses but is not a valid kinematic tree or description.
    #[error("{origin}{}: {element}: {problem}\n  fix: {fix}", line.map(|l| format!(":{l}")).unwrap_or_default())]
    InvalidModel {
        /// The file (or `<string>`) the model came from.
        origin: String,
        /// The line of the offending element, when it could be found.
        line: Option<usize>,
        /// The offending element, e.g. `<joint name="r_elbow">`.
        element: String,
        /// What is wrong.
        problem: String,
        /// What to do about it.
        fix: String,
    },
    /// A name lookup failed.
    #[error("unknown {kind} `{name}`{}", suggest(suggestions))]
    UnknownName {
        /// What was looked up.
        kind: NameKind,
        /// The name given.
        name: String,
        /// The closest existing names, best first.
        suggestions: Vec<String>,
    },
    /// A model name that is neither embedded nor a file.
    #[error("unknown model `{name}`: no embedded model has that name and {} is no file{}\n  fix: give a .urdf or .ron path, or an embedded model", looked_for.display(), suggest(suggestions))]
    UnknownModel {
        /// The name given.
        name: String,
        /// The file looked for.
        looked_for: PathBuf,
        /// The closest embedded model names.
        suggestions: Vec<String>,
    },
    /// A vector had the wrong number of entries.
    #[error("{what}: expected {expected} values, got {got}")]
    WrongLength {
        /// Which vector.
        what: &'static str,
        /// Entries expected.
        expected: usize,
        /// Entries given.
        got: usize,
    },
    /// A value was NaN or infinite.
    #[error("{what}: entry {index} (`{name}`) is {value}; all values must be finite")]
    NonFinite {
        /// Which vector.
        what: &'static str,
        /// Position of the entry.
        index: usize,
        /// Name of the entry.
        name: String,
        /// The value.
        value: f64,
    },
    /// A value outside its range.
    #[error("{what}: {problem}")]
    OutOfRange {
        /// Which value.
        what: String,
        /// What is wrong and how to fix it.
        problem: String,
    },
}

fn suggest(suggestions: &[String]) -> String {
    if suggestions.is_empty() {
        String::new()
    } else {
        format!(
            "; did you mean {}?",
            suggestions
                .iter()
                .map(|s| format!("`{s}`"))
                .collect::<Vec<_>>()
                .join(", ")
        )
    }
}

/// Result alias of this crate.
pub type Result<T, E = KinematicsError> = std::result::Result<T, E>;

/// Reads a text file, naming it in the error.
pub(crate) fn read_text(path: &std::path::Path) -> Result<String> {
    trm_io::read_input(path).map_err(|source| KinematicsError::Io {
        path: path.to_path_buf(),
        source,
    })
}

/// An [`KinematicsError::UnknownName`] with suggestions drawn from `candidates`.
pub(crate) fn unknown<'a>(
    kind: NameKind,
    name: &str,
    candidates: impl IntoIterator<Item = &'a str>,
) -> KinematicsError {
    KinematicsError::UnknownName {
        kind,
        name: name.to_string(),
        suggestions: trm_io::closest_names(name, candidates),
    }
}

/// 1-based line of the first `<tag ... name="name"` in `source`, if any.
pub(crate) fn line_of_element(source: &str, tag: &str, name: &str) -> Option<usize> {
    let open = format!("<{tag}");
    let needles = [format!("name=\"{name}\""), format!("name='{name}'")];
    let mut search_from = 0;
    while let Some(rel) = source[search_from..].find(&open) {
        let start = search_from + rel;
        let end = source[start..]
            .find('>')
            .map_or(source.len(), |e| start + e);
        let head = &source[start..end];
        if needles.iter().any(|n| head.contains(n.as_str())) {
            return Some(source[..start].matches('\n').count() + 1);
        }
        search_from = start + open.len();
    }
    None
}
