//! The hostile-input battery for the study commands only xtask has (`map-scaling`, `speedup`,
//! `task-map-studies`): flag values out of range and output directories that are files, run
//! through the `xtask` binary with trm's battery's harness.

#[path = "../../crates/trm/tests/hostile/harness.rs"]
mod harness;

use std::path::Path;

use harness::{file_flag_cases, flag_cases};

#[test]
fn study_commands_refuse_bad_flags_and_outputs_in_the_way() {
    let bin = Path::new(env!("CARGO_BIN_EXE_xtask"));
    let dir = std::env::temp_dir().join(format!("trm-hostile-studies-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    // a regular file where an output directory is asked for
    std::fs::write(dir.join("posture.json"), "{}").unwrap();
    let spec = harness::root().join("specs/reach.ron");
    let spec = spec.to_str().unwrap();
    let mut cases = Vec::new();
    let scaling = ["map-scaling", spec, "--out-dir", "ms"];
    cases.extend(flag_cases(
        &scaling,
        "--points",
        &["0", "-1", "x", "100000000"],
    ));
    cases.extend(flag_cases(&scaling, "--threads", &["0", "-1", "x"]));
    cases.extend(file_flag_cases(
        &["map-scaling", spec],
        "--out-dir",
        &["posture.json"],
    ));
    let speedup = ["speedup", spec, "--out-dir", "sp"];
    cases.extend(flag_cases(&speedup, "--points", &["0", "", "1,x", "-4"]));
    cases.extend(flag_cases(&speedup, "--threads", &["0", "1,0", "1000"]));
    cases.extend(flag_cases(&speedup, "--searches", &["0", "5000"]));
    let studies = ["task-map-studies", "--out-dir", "st"];
    cases.extend(flag_cases(
        &studies,
        "--iterations",
        &["0", "18446744073709551615"],
    ));
    cases.extend(harness::output_cases(
        &[
            vec!["task-map-studies", "--out-dir"],
            vec!["speedup", spec, "--points", "2", "--out-dir"],
        ],
        "posture.json",
    ));
    harness::run_all(bin, &dir, &cases, 20);
}
