//! The hostile-input battery: several hundred malformed files, flag values and output paths
//! across the commands, each run through the `trm` binary (the study commands' cases, which only xtask has, are
//! `xtask/tests/hostile_studies.rs`). Every one must end in a clear
//! error: exit code 1–100, no panic, no hang (240 s, far above any case's time on a loaded
//! machine), naming the file (or flag) at fault, and writing nothing.
//!
//! Files are mutated mechanically from valid ones (specs/, models/, and a map, posture and
//! trajectory this test makes): every number of a file (or an even sample of them) replaced by a
//! non-finite or out-of-range value, truncations, duplicated and unknown keys, wrong types,
//! numeric arrays one element short.

mod commands;
mod files;
mod flags;
mod harness;

use std::path::Path;

#[test]
fn hostile_inputs_get_clear_errors_and_write_nothing() {
    let bin = Path::new(env!("CARGO_BIN_EXE_trm"));
    let dir = std::env::temp_dir().join(format!("trm-hostile-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    harness::valid_files(bin, &dir);
    let mut cases = files::cases(&dir);
    cases.extend(flags::cases(&dir));
    cases.extend(commands::cases(&dir));
    harness::run_all(bin, &dir, &cases, 400);
}
