//! `build-map` killed at any moment: the old map or a complete new one, and a resumed build
//! equal to the uninterrupted one (run through the `xtask` binary, as `mpi.rs`).

mod common;

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::Duration;

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// `kill -9` at any moment of `build-map` leaves the earlier map or a complete new one, and the
/// next run clears the temporary files the killed ones left.
#[test]
fn a_killed_build_leaves_the_old_map_or_a_complete_new_one() {
    let dir = std::env::temp_dir().join(format!("trm-kill-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let spec = root().join("specs/reach.ron");
    let build = |points: &str, seed: &str| {
        Command::new(env!("CARGO_BIN_EXE_xtask"))
            .args(["build-map", spec.to_str().unwrap(), "--points", points])
            .args(["--seed", seed, "--out", "map.json"])
            .current_dir(&dir)
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .expect("xtask starts")
    };
    assert!(build("3", "1").wait().unwrap().success());
    let old = std::fs::read(dir.join("map.json")).unwrap();
    let mut outcomes = (0, 0);
    for (k, delay) in [30u64, 120, 250, 400, 600, 900, 1300, 1800]
        .iter()
        .enumerate()
    {
        let mut child = build("40", &(k + 2).to_string());
        std::thread::sleep(Duration::from_millis(*delay));
        let _ = child.kill(); // SIGKILL
        let _ = child.wait();
        let now = std::fs::read(dir.join("map.json")).unwrap();
        if now == old {
            outcomes.0 += 1;
        } else {
            trm_roadmap::Roadmap::load(dir.join("map.json"))
                .expect("a changed map file is a complete map");
            outcomes.1 += 1;
        }
    }
    eprintln!(
        "killed builds: {} left the old map, {} a complete new one",
        outcomes.0, outcomes.1
    );
    // a run that finishes clears what the killed ones left
    assert!(build("3", "1").wait().unwrap().success());
    let left: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .flatten()
        .map(|e| e.file_name().to_string_lossy().to_string())
        .filter(|n| n.ends_with(".tmp"))
        .collect();
    assert!(left.is_empty(), "temporary files left: {left:?}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// `kill -9` in the middle of a checkpointed build, then `--resume`: the same map file as an
/// uninterrupted build, byte for byte apart from the timing statistics. The kill comes as soon
/// as the first checkpoint is on disk; should a machine finish the whole build before that
/// (the map file is there), the test doubles the map and tries again, so its verdict does not
/// depend on the machine's speed.
#[test]
fn a_killed_build_resumes_to_the_uninterrupted_map() {
    let dir = std::env::temp_dir().join(format!("trm-resume-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let spec = root().join("specs/reach.ron");
    let xtask = |args: &[&str]| {
        let mut command = Command::new(env!("CARGO_BIN_EXE_xtask"));
        command.args(args).current_dir(&dir).stderr(Stdio::null());
        command
    };
    let build = |points: &str, out: &str, more: &[&str]| {
        let mut args = vec!["build-map", spec.to_str().unwrap(), "--points", points];
        args.extend(["--out", out]);
        args.extend(more);
        xtask(&args)
    };
    let checkpoint = dir.join("killed.map.checkpoint");
    let mut points = 300;
    let killed_mid_way = loop {
        assert!(
            points <= 4800,
            "every build finished before it could be killed"
        );
        let _ = std::fs::remove_file(&checkpoint);
        let _ = std::fs::remove_file(dir.join("killed.map.json"));
        let mut child = build(
            &points.to_string(),
            "killed.map.json",
            &["--checkpoint-every", "20"],
        )
        .stdout(Stdio::null())
        .spawn()
        .unwrap();
        let finished = loop {
            if checkpoint.exists() {
                break false;
            }
            if child.try_wait().unwrap().is_some() {
                break true;
            }
            std::thread::sleep(Duration::from_millis(2));
        };
        let _ = child.kill(); // SIGKILL
        let _ = child.wait();
        if !finished && !dir.join("killed.map.json").exists() {
            break points;
        }
        points *= 2;
    };
    let status = build(&killed_mid_way.to_string(), "whole.map.json", &[])
        .stdout(Stdio::null())
        .status();
    assert!(status.unwrap().success());
    let resumed = xtask(&["build-map", "--resume", "killed.map.checkpoint"])
        .output()
        .unwrap();
    let said = String::from_utf8_lossy(&resumed.stdout);
    assert!(resumed.status.success(), "{said}");
    eprintln!("{}", said.lines().next().unwrap_or_default());
    assert!(said.starts_with("resuming"), "{said}");
    let read = |name: &str| common::map_without_timings(&dir.join(name));
    assert!(read("whole.map.json") == read("killed.map.json"));
    let _ = std::fs::remove_dir_all(&dir);
}
