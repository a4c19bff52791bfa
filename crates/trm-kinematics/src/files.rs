//! Writing files safely.

use std::io::Write as _;
use std::path::Path;

/// Reads a text file, naming it in the error.
pub(crate) fn read_text(path: &Path) -> crate::Result<String> {
    std::fs::read_to_string(path).map_err(|source| crate::KinematicsError::Io {
        path: path.to_path_buf(),
        source,
    })
}

/// Writes `bytes` to `path` through a temporary file in the same directory and a rename, so a
/// crash never leaves a half-written file.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    let dir = path
        .parent()
        .filter(|d| !d.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    std::fs::create_dir_all(dir)?;
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().to_string())
        .unwrap_or_default();
    let tmp = dir.join(format!(".{name}.{}.tmp", std::process::id()));
    let result = (|| {
        let mut f = std::fs::File::create(&tmp)?;
        f.write_all(bytes)?;
        f.sync_all()?;
        std::fs::rename(&tmp, path)
    })();
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result
}

/// Why a versioned JSON file (`{"format": NAME, "version": N, …}`) could not be read or written.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum FileError {
    /// The operating system refused to read or write it.
    #[error("{}: {source}", path.display())]
    Io {
        /// The file.
        path: std::path::PathBuf,
        /// The operating-system error.
        source: std::io::Error,
    },
    /// The file ends early: a crash while something else wrote it, or a copy cut short.
    #[error("{}: truncated ({source})\n  fix: write the file again", path.display())]
    Truncated {
        /// The file.
        path: std::path::PathBuf,
        /// The JSON parser's error.
        source: serde_json::Error,
    },
    /// The file is not JSON, or not this kind of file.
    #[error("{}: not a {format} file{}\n  fix: give a {format} file written by trm", path.display(), detail.as_ref().map(|d| format!(" ({d})")).unwrap_or_default())]
    WrongFormat {
        /// The file.
        path: std::path::PathBuf,
        /// The format expected.
        format: &'static str,
        /// What was found instead.
        detail: Option<String>,
    },
    /// The file is of the right kind but of a version this software does not read.
    #[error("{}: {format} version {found}; this software reads version {expected}\n  fix: write the file again with this version of trm", path.display())]
    WrongVersion {
        /// The file.
        path: std::path::PathBuf,
        /// The format.
        format: &'static str,
        /// The version in the file (as written there).
        found: String,
        /// The version this software reads.
        expected: u32,
    },
    /// The file has the right format and version but its content does not fit the schema.
    #[error("{}: malformed {format}: {source}", path.display())]
    Malformed {
        /// The file.
        path: std::path::PathBuf,
        /// The format.
        format: &'static str,
        /// The JSON error, with line and column.
        source: serde_json::Error,
    },
    /// A value cannot be written (e.g. it does not serialise).
    #[error("{}: cannot write {format}: {source}", path.display())]
    Serialize {
        /// The file.
        path: std::path::PathBuf,
        /// The format.
        format: &'static str,
        /// The serialiser's error.
        source: serde_json::Error,
    },
}

/// Reads a versioned JSON document from `text` (from `path`, for messages): checks that its
/// `"format"` is `format` and its `"version"` is `version`, then deserialises it. The one reader
/// behind every versioned file of trm (maps, task maps, scenes).
pub fn parse_versioned<T: serde::de::DeserializeOwned>(
    path: &Path,
    text: &str,
    format: &'static str,
    version: u32,
) -> Result<T, FileError> {
    let path_buf = || path.to_path_buf();
    let value: serde_json::Value = serde_json::from_str(text).map_err(|source| {
        if source.is_eof() {
            FileError::Truncated {
                path: path_buf(),
                source,
            }
        } else {
            FileError::WrongFormat {
                path: path_buf(),
                format,
                detail: Some(source.to_string()),
            }
        }
    })?;
    match value.get("format").and_then(|f| f.as_str()) {
        Some(f) if f == format => {}
        found => {
            return Err(FileError::WrongFormat {
                path: path_buf(),
                format,
                detail: Some(match found {
                    Some(f) => format!("its \"format\" is \"{f}\""),
                    None => format!("no \"format\": \"{format}\""),
                }),
            });
        }
    }
    match value.get("version") {
        Some(v) if v.as_u64() == Some(u64::from(version)) => {}
        found => {
            return Err(FileError::WrongVersion {
                path: path_buf(),
                format,
                found: found.map_or("(none)".into(), |v| v.to_string()),
                expected: version,
            });
        }
    }
    serde_json::from_value(value).map_err(|source| FileError::Malformed {
        path: path_buf(),
        format,
        source,
    })
}

/// Reads the file at `path` with [`parse_versioned`].
pub fn load_versioned<T: serde::de::DeserializeOwned>(
    path: &Path,
    format: &'static str,
    version: u32,
) -> Result<T, FileError> {
    let text = std::fs::read_to_string(path).map_err(|source| FileError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    parse_versioned(path, &text, format, version)
}

/// Writes `value` as compact JSON to `path` atomically ([`write_atomic`]).
pub fn save_json<T: serde::Serialize>(
    path: &Path,
    value: &T,
    format: &'static str,
) -> Result<(), FileError> {
    let text = serde_json::to_string(value).map_err(|source| FileError::Serialize {
        path: path.to_path_buf(),
        format,
        source,
    })?;
    write_atomic(path, text.as_bytes()).map_err(|source| FileError::Io {
        path: path.to_path_buf(),
        source,
    })
}
