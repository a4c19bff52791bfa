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
//!
//! `cargo test` runs every third case (the battery's thousand runs of the binary took 40 s of
//! the suite's three minutes); the whole battery is an ignored test that CI runs
//! (`cargo test --workspace -- --ignored`).

mod commands;
mod files;
mod flags;
mod harness;

use std::path::Path;

/// Runs every `step`-th case of the battery (at least `minimum` of them) in a folder of its own.
fn battery(name: &str, step: usize, minimum: usize) {
    let bin = Path::new(env!("CARGO_BIN_EXE_trm"));
    let dir = std::env::temp_dir().join(format!("trm-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    harness::valid_files(bin, &dir);
    let mut cases = files::cases(&dir);
    cases.extend(flags::cases(&dir));
    cases.extend(commands::cases(&dir));
    let cases: Vec<_> = cases.into_iter().step_by(step).collect();
    harness::run_all(bin, &dir, &cases, minimum);
}

#[test]
fn hostile_inputs_get_clear_errors_and_write_nothing() {
    battery("hostile", 3, 300);
}

#[test]
#[ignore = "the whole battery, a thousand runs of the binary: CI's slow tests"]
fn every_hostile_input_gets_a_clear_error_and_writes_nothing() {
    battery("hostile-all", 1, 1000);
}
