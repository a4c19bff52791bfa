//! Writing files safely.

use std::io::Write as _;
use std::path::{Path, PathBuf};

/// The largest input file trm reads (1 GiB): anything bigger is refused rather than exhausting
/// memory.
pub const MAX_INPUT_BYTES: u64 = 1 << 30;

/// Reads a UTF-8 input file (a model, spec, map, trajectory…) with the checks of
/// [`read_input_bytes`]; the one reader of every trm text input.
pub fn read_input(path: &Path) -> std::io::Result<String> {
    String::from_utf8(read_input_bytes(path)?)
        .map_err(|e| std::io::Error::new(std::io::ErrorKind::InvalidData, e.utf8_error()))
}

/// Reads an input file's bytes. Refuses what is not a regular file (a directory, a device such
/// as `/dev/zero`, a pipe that may never end) and files over [`MAX_INPUT_BYTES`], with a message
/// saying so.
pub fn read_input_bytes(path: &Path) -> std::io::Result<Vec<u8>> {
    let meta = std::fs::metadata(path)?;
    if !meta.is_file() {
        let what = if meta.is_dir() {
            "a directory"
        } else {
            "not a regular file (a device, socket or pipe)"
        };
        return Err(std::io::Error::new(
            std::io::ErrorKind::InvalidInput,
            format!("is {what}\n  fix: give a file"),
        ));
    }
    if meta.len() > MAX_INPUT_BYTES {
        return Err(std::io::Error::new(
            std::io::ErrorKind::InvalidInput,
            format!(
                "is {} bytes, over the {MAX_INPUT_BYTES}-byte limit for inputs\n  fix: give the right file",
                meta.len()
            ),
        ));
    }
    std::fs::read(path)
}

/// Checks, before any work is done, that an output file can go to `path`: if something is there
/// it must be a regular file (trm never replaces a symlink, directory or device with a file),
/// and the nearest existing directory above it must be a directory this process can write in.
pub fn check_output(path: &Path) -> std::io::Result<()> {
    refuse_non_regular(path)?;
    let mut dir = parent_dir(path);
    while !dir.exists() {
        dir = parent_dir(dir);
    }
    if !dir.is_dir() {
        return Err(std::io::Error::other(format!(
            "{} is not a directory\n  fix: choose an output path inside a directory",
            dir.display()
        )));
    }
    let probe = dir.join(format!(".trm-probe.{}.tmp", std::process::id()));
    std::fs::File::create(&probe)
        .and_then(|_| std::fs::remove_file(&probe))
        .map_err(|e| {
            std::io::Error::new(
                e.kind(),
                format!(
                    "cannot write in {}: {e}\n  fix: choose a directory you can write in",
                    dir.display()
                ),
            )
        })
}

/// The directory `path` is in (`.` for a bare name).
fn parent_dir(path: &Path) -> &Path {
    path.parent()
        .filter(|d| !d.as_os_str().is_empty())
        .unwrap_or(Path::new("."))
}

/// Refuses a `path` that exists and is not a regular file.
fn refuse_non_regular(path: &Path) -> std::io::Result<()> {
    match std::fs::symlink_metadata(path) {
        Ok(m) if !m.file_type().is_file() => {
            let what = if m.file_type().is_symlink() {
                "a symbolic link"
            } else if m.is_dir() {
                "a directory"
            } else {
                "not a regular file (a device, socket or pipe)"
            };
            Err(std::io::Error::new(
                std::io::ErrorKind::AlreadyExists,
                format!(
                    "{} is {what}; trm replaces only regular files\n  fix: remove it or choose another output path",
                    path.display()
                ),
            ))
        }
        _ => Ok(()),
    }
}

/// An output file written in full beside its destination but not yet in place: [`commit`]
/// renames it over the destination in one step; dropping it uncommitted deletes it. Lets a
/// command that writes several files put them all in place only once all of them are ready.
///
/// [`commit`]: StagedFile::commit
#[derive(Debug)]
pub struct StagedFile {
    tmp: std::path::PathBuf,
    path: std::path::PathBuf,
    committed: bool,
}

impl StagedFile {
    /// Writes `bytes` (synced to disk) to a temporary file in `path`'s directory, creating the
    /// directory if needed. Refuses a `path` that exists and is not a regular file.
    pub fn new(path: &Path, bytes: &[u8]) -> std::io::Result<Self> {
        refuse_non_regular(path)?;
        let dir = parent_dir(path);
        std::fs::create_dir_all(dir)?;
        let name = path
            .file_name()
            .map(|n| n.to_string_lossy().to_string())
            .unwrap_or_default();
        remove_stale_temporaries(dir, &name);
        static NEXT: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);
        let n = NEXT.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        let staged = StagedFile {
            tmp: dir.join(format!(".{name}.{}.{n}.tmp", std::process::id())),
            path: path.to_path_buf(),
            committed: false,
        };
        let mut f = std::fs::File::create(&staged.tmp)?;
        f.write_all(bytes)?;
        f.sync_all()?;
        Ok(staged)
    }

    /// The destination.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Puts the file in place (an atomic rename over the destination).
    pub fn commit(mut self) -> std::io::Result<()> {
        refuse_non_regular(&self.path)?;
        std::fs::rename(&self.tmp, &self.path)?;
        self.committed = true;
        Ok(())
    }
}

impl Drop for StagedFile {
    fn drop(&mut self) {
        if !self.committed {
            let _ = std::fs::remove_file(&self.tmp);
        }
    }
}

/// Removes the temporary files `.NAME.PID.N.tmp` that processes killed while writing `name`
/// left in `dir` (on systems with `/proc`, where a dead process can be told from a live one).
fn remove_stale_temporaries(dir: &Path, name: &str) {
    let proc = Path::new("/proc");
    if !proc.is_dir() {
        return;
    }
    let prefix = format!(".{name}.");
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for entry in entries.flatten() {
        let file = entry.file_name().to_string_lossy().to_string();
        let Some(rest) = file
            .strip_prefix(&prefix)
            .and_then(|r| r.strip_suffix(".tmp"))
        else {
            continue;
        };
        let pid = rest.split('.').next().unwrap_or("");
        if pid.parse::<u32>().is_ok() && !proc.join(pid).exists() {
            let _ = std::fs::remove_file(entry.path());
        }
    }
}

/// Writes `bytes` to `path` through a temporary file in the same directory and a rename, so a
/// crash never leaves a half-written file. Refuses to replace anything but a regular file.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    StagedFile::new(path, bytes)?.commit()
}

/// Checks that no JSON object in `text` names a key twice (serde keeps the last silently); the
/// error carries the line and column of the second one.
pub fn check_unique_keys(text: &str) -> Result<(), serde_json::Error> {
    use serde::de::Deserializer as _;
    serde_json::Deserializer::from_str(text).deserialize_any(UniqueKeys("".into()))
}

/// Deserialises a map of names (`{"torso": 3.0, …}` in RON or JSON), refusing a name given twice
/// (serde would keep the last one silently). Use as
/// `#[serde(deserialize_with = "trm_io::unique_names")]`.
pub fn unique_names<'de, D, V>(d: D) -> Result<std::collections::BTreeMap<String, V>, D::Error>
where
    D: serde::Deserializer<'de>,
    V: serde::Deserialize<'de>,
{
    struct Names<V>(std::marker::PhantomData<V>);
    impl<'de, V: serde::Deserialize<'de>> serde::de::Visitor<'de> for Names<V> {
        type Value = std::collections::BTreeMap<String, V>;
        fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
            f.write_str("a map of names")
        }
        fn visit_map<A: serde::de::MapAccess<'de>>(
            self,
            mut map: A,
        ) -> Result<Self::Value, A::Error> {
            let mut out = std::collections::BTreeMap::new();
            while let Some(key) = map.next_key::<String>()? {
                if out.contains_key(&key) {
                    return Err(serde::de::Error::custom(format!(
                        "`{key}` is given twice (keep one)"
                    )));
                }
                let value = map.next_value()?;
                out.insert(key, value);
            }
            Ok(out)
        }
    }
    d.deserialize_map(Names(std::marker::PhantomData))
}

/// Walks a JSON value (the field path so far in `.0`), refusing a repeated key.
struct UniqueKeys(String);

impl<'de> serde::de::DeserializeSeed<'de> for UniqueKeys {
    type Value = ();
    fn deserialize<D: serde::Deserializer<'de>>(self, d: D) -> Result<(), D::Error> {
        d.deserialize_any(self)
    }
}

impl<'de> serde::de::Visitor<'de> for UniqueKeys {
    type Value = ();
    fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        f.write_str("JSON")
    }
    fn visit_bool<E>(self, _: bool) -> Result<(), E> {
        Ok(())
    }
    fn visit_i64<E>(self, _: i64) -> Result<(), E> {
        Ok(())
    }
    fn visit_u64<E>(self, _: u64) -> Result<(), E> {
        Ok(())
    }
    fn visit_f64<E>(self, _: f64) -> Result<(), E> {
        Ok(())
    }
    fn visit_str<E>(self, _: &str) -> Result<(), E> {
        Ok(())
    }
    fn visit_unit<E>(self) -> Result<(), E> {
        Ok(())
    }
    fn visit_seq<A: serde::de::SeqAccess<'de>>(self, mut seq: A) -> Result<(), A::Error> {
        let mut i = 0;
        while seq
            .next_element_seed(UniqueKeys(format!("{}[{i}]", self.0)))?
            .is_some()
        {
            i += 1;
        }
        Ok(())
    }
    fn visit_map<A: serde::de::MapAccess<'de>>(self, mut map: A) -> Result<(), A::Error> {
        let mut seen = std::collections::HashSet::new();
        while let Some(key) = map.next_key::<String>()? {
            let path = if self.0.is_empty() {
                key.clone()
            } else {
                format!("{}.{key}", self.0)
            };
            if !seen.insert(key) {
                return Err(serde::de::Error::custom(format!(
                    "`{path}` is given twice (keep one)"
                )));
            }
            map.next_value_seed(UniqueKeys(path))?;
        }
        Ok(())
    }
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
    /// A binary file of the right format and version whose content does not decode.
    #[error("{}: damaged {format} file ({problem})\n  fix: write the file again", path.display())]
    Damaged {
        /// The file.
        path: std::path::PathBuf,
        /// The format.
        format: &'static str,
        /// What the decoder found.
        problem: String,
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
    parse_versioned_since(path, text, format, version, version)
}

/// [`parse_versioned`] of a format whose newer versions only add optional fields: any version
/// from `oldest` to `version` is read.
pub fn parse_versioned_since<T: serde::de::DeserializeOwned>(
    path: &Path,
    text: &str,
    format: &'static str,
    oldest: u32,
    version: u32,
) -> Result<T, FileError> {
    let path_buf = || path.to_path_buf();
    let value: serde_json::Value = check_unique_keys(text)
        .and_then(|()| serde_json::from_str(text))
        .map_err(|source| {
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
        Some(v)
            if v.as_u64()
                .is_some_and(|v| (u64::from(oldest)..=u64::from(version)).contains(&v)) => {}
        found => {
            return Err(FileError::WrongVersion {
                path: path_buf(),
                format,
                found: match found {
                    None => "(none)".into(),
                    Some(serde_json::Value::Number(n)) => n.to_string(),
                    Some(other) => format!("{other} (not a number)"),
                },
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
    parse_versioned(path, &read_file(path)?, format, version)
}

/// `value` as compact JSON (`path` names the file it is for in errors).
pub fn json_text<T: serde::Serialize>(
    path: &Path,
    value: &T,
    format: &'static str,
) -> Result<String, FileError> {
    serde_json::to_string(value).map_err(|source| FileError::Serialize {
        path: path.to_path_buf(),
        format,
        source,
    })
}

/// A value in trm's binary layout: the format name and version (postcard-encoded), the value
/// (postcard: compact, every f64 kept bit for bit, infinities and NaN included), and a CRC-32
/// of all that (little-endian), so a damaged or truncated file is found out. Read it back with
/// [`parse_binary_versioned`].
pub fn binary_bytes<T: serde::Serialize>(
    path: &Path,
    value: &T,
    format: &'static str,
    version: u32,
) -> Result<Vec<u8>, FileError> {
    let damaged = |e: postcard::Error| FileError::Damaged {
        path: path.to_path_buf(),
        format,
        problem: format!("cannot encode: {e}"),
    };
    let mut bytes = postcard::to_stdvec(&(format, version)).map_err(damaged)?;
    bytes.extend(postcard::to_stdvec(value).map_err(damaged)?);
    let crc = crc32fast::hash(&bytes);
    bytes.extend(crc.to_le_bytes());
    Ok(bytes)
}

/// Reads what [`binary_bytes`] wrote: another format, another version, a file cut short or
/// changed (checksum) and bytes that do not decode are each a clear error naming `path`.
pub fn parse_binary_versioned<T: serde::de::DeserializeOwned>(
    path: &Path,
    bytes: &[u8],
    format: &'static str,
    version: u32,
) -> Result<T, FileError> {
    let wrong = || FileError::WrongFormat {
        path: path.to_path_buf(),
        format,
        detail: Some("its first bytes do not name the format".into()),
    };
    let (found, rest): ((String, u32), &[u8]) =
        postcard::take_from_bytes(bytes).map_err(|_| wrong())?;
    if found.0 != format {
        return Err(wrong());
    }
    if found.1 != version {
        return Err(FileError::WrongVersion {
            path: path.to_path_buf(),
            format,
            found: found.1.to_string(),
            expected: version,
        });
    }
    let damaged = |problem: String| FileError::Damaged {
        path: path.to_path_buf(),
        format,
        problem,
    };
    let Some((content, crc)) = bytes.split_last_chunk::<4>() else {
        return Err(damaged("it ends early: truncated".into()));
    };
    if crc32fast::hash(content) != u32::from_le_bytes(*crc) {
        return Err(damaged(
            "its checksum does not match: truncated or changed".into(),
        ));
    }
    let rest = &rest[..rest.len().saturating_sub(4)];
    match postcard::take_from_bytes(rest) {
        Ok((value, [])) => Ok(value),
        Ok((_, extra)) => Err(damaged(format!("{} bytes after the end", extra.len()))),
        Err(postcard::Error::DeserializeUnexpectedEnd) => {
            Err(damaged("it ends early: truncated".into()))
        }
        Err(e) => Err(damaged(e.to_string())),
    }
}

/// [`read_input`] with a [`FileError`] naming the file.
pub fn read_file(path: &Path) -> Result<String, FileError> {
    read_input(path).map_err(|source| FileError::Io {
        path: path.to_path_buf(),
        source,
    })
}

/// [`read_input_bytes`] with a [`FileError`] naming the file.
pub fn read_file_bytes(path: &Path) -> Result<Vec<u8>, FileError> {
    read_input_bytes(path).map_err(|source| FileError::Io {
        path: path.to_path_buf(),
        source,
    })
}

/// [`write_atomic`] with a [`FileError`] naming the file.
pub fn write_file(path: &Path, text: &str) -> Result<(), FileError> {
    write_file_bytes(path, text.as_bytes())
}

/// Writes several files so that none is put in place unless all could be written: each is
/// staged ([`StagedFile`]), then all are renamed into place. Errors name the file.
pub fn write_files(files: &[(PathBuf, String)]) -> Result<(), FileError> {
    let error = |path: &Path| {
        let path = path.to_path_buf();
        move |source| FileError::Io { path, source }
    };
    let staged = files
        .iter()
        .map(|(path, text)| StagedFile::new(path, text.as_bytes()).map_err(error(path)))
        .collect::<Result<Vec<_>, _>>()?;
    for file in staged {
        let path = file.path().to_path_buf();
        file.commit().map_err(error(&path))?;
    }
    Ok(())
}

/// [`write_atomic`] of bytes with a [`FileError`] naming the file.
pub fn write_file_bytes(path: &Path, bytes: &[u8]) -> Result<(), FileError> {
    write_atomic(path, bytes).map_err(|source| FileError::Io {
        path: path.to_path_buf(),
        source,
    })
}

/// Writes `value` as compact JSON to `path` atomically ([`write_atomic`]).
pub fn save_json<T: serde::Serialize>(
    path: &Path,
    value: &T,
    format: &'static str,
) -> Result<(), FileError> {
    write_file(path, &json_text(path, value, format)?)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every f64 (±∞ and NaN too) reads back bit for bit; any cut or changed byte, another
    /// format and another version are errors that say which.
    #[test]
    fn binary_files_round_trip_and_damage_is_found() {
        let path = Path::new("x.bin");
        let value = (
            vec![1.5, f64::INFINITY, f64::NEG_INFINITY, -0.0, 1e-310],
            f64::NAN,
        );
        let bytes = binary_bytes(path, &value, "trm-test", 3).unwrap();
        let back: (Vec<f64>, f64) = parse_binary_versioned(path, &bytes, "trm-test", 3).unwrap();
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&back.0), bits(&value.0));
        assert_eq!(back.1.to_bits(), value.1.to_bits());
        let read = |b: &[u8]| parse_binary_versioned::<(Vec<f64>, f64)>(path, b, "trm-test", 3);
        for cut in 0..bytes.len() {
            let e = read(&bytes[..cut]).unwrap_err().to_string();
            assert!(e.contains("x.bin") && e.contains("fix:"), "{cut}: {e}");
        }
        for i in 0..bytes.len() {
            let mut changed = bytes.clone();
            changed[i] ^= 0x10;
            assert!(read(&changed).is_err(), "byte {i}");
        }
        let e = parse_binary_versioned::<(Vec<f64>, f64)>(path, &bytes, "trm-other", 3)
            .unwrap_err()
            .to_string();
        assert!(e.contains("not a trm-other file"), "{e}");
        let e = parse_binary_versioned::<(Vec<f64>, f64)>(path, &bytes, "trm-test", 4)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("version 3") && e.contains("reads version 4"),
            "{e}"
        );
        let mut longer = bytes[..bytes.len() - 4].to_vec();
        longer.push(0);
        longer.extend(crc32fast::hash(&longer).to_le_bytes());
        let e = read(&longer).unwrap_err().to_string();
        assert!(e.contains("1 bytes after the end"), "{e}");
    }
}
