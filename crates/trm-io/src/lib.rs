//! File plumbing shared by every trm crate, with no robotics in it:
//!
//! - **Reading**: [`read_input`] and [`read_input_bytes`] read regular files under
//!   [`MAX_INPUT_BYTES`] (a pipe, a device or a directory is an error, not a hang);
//!   [`check_xml_nesting`] bounds XML nesting before any parser recurses.
//! - **Writing**: [`write_atomic`] (temporary file + rename: a killed run leaves the old file or
//!   the new one), [`StagedFile`] (written now, put in place later, as a command that fails
//!   writes nothing), [`check_output`] (refused before the work starts).
//! - **Versioned files**: JSON ([`json_text`], [`parse_versioned`], [`load_versioned`],
//!   [`save_json`]) and a checksummed binary twin ([`binary_bytes`],
//!   [`parse_binary_versioned`]) carrying a format name and a version a reader checks;
//!   duplicate keys refused ([`check_unique_keys`]).
//! - **Point clouds**: [`read_points`] reads PLY and PCD files (ASCII and binary).
//! - **Located errors**: [`SpecError`] and [`locate_ron_path`] turn a RON field path into
//!   `file:line:column`, [`explain_ron_error`] says what a RON parse error means and how to fix
//!   it, [`closest_names`] gives the "did you mean" candidates.
//!
//! ```
//! let dir = std::env::temp_dir().join(format!("trm-io-doc-{}", std::process::id()));
//! std::fs::create_dir_all(&dir)?;
//! let path = dir.join("settings.txt");
//! trm_io::write_atomic(&path, b"threads: 2\n")?;
//! assert_eq!(trm_io::read_input(&path)?, "threads: 2\n");
//! assert_eq!(trm_io::closest_names("treads", ["threads", "seed"]), ["threads"]);
//! # std::fs::remove_dir_all(&dir)?;
//! # Ok::<(), std::io::Error>(())
//! ```

mod files;
mod names;
mod points;
mod ron_path;
mod xml;

pub use files::{
    FileError, MAX_INPUT_BYTES, StagedFile, binary_bytes, check_output, check_unique_keys,
    json_text, load_versioned, parse_binary_versioned, parse_versioned, parse_versioned_since,
    read_file, read_file_bytes, read_input, read_input_bytes, save_json, unique_names,
    write_atomic, write_file, write_file_bytes, write_files,
};
pub use names::closest_names;
pub use points::{PointFile, parse_points, read_points};
pub use ron_path::{RonProblem, SpecError, explain_ron_error, locate_ron_field, locate_ron_path};
pub use xml::{TooDeep, XML_NESTING_LIMIT, check_xml_nesting};
