//! The `trm` binary: its help lists every command, a command runs, bad flags are refused with
//! the flag's name and a failed command writes nothing.

use std::process::Command;

fn trm(args: &[&str], dir: &std::path::Path) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_trm"))
        .args(args)
        .current_dir(dir)
        .output()
        .expect("trm starts")
}

#[test]
fn help_lists_every_command_and_commands_run() {
    let dir = std::env::temp_dir();
    let help = trm(&["--help"], &dir);
    assert!(help.status.success());
    let help = String::from_utf8_lossy(&help.stdout);
    let listed = trm::command_list();
    let names: Vec<&str> = listed
        .lines()
        .filter_map(|l| l.split_whitespace().next())
        .collect();
    assert!(names.len() >= 19, "{listed}");
    for name in [
        "build-map",
        "plan",
        "benchmark-mbm",
        "solve",
        "view",
        "compare-optimisers",
    ] {
        assert!(names.contains(&name), "{name} missing from {listed}");
    }
    for name in &names {
        assert!(
            help.contains(name),
            "`trm --help` does not list {name}:\n{help}"
        );
    }
    let info = trm(&["model-info"], &dir);
    assert!(
        info.status.success(),
        "{}",
        String::from_utf8_lossy(&info.stderr)
    );
    assert!(String::from_utf8_lossy(&info.stdout).contains("41"));
}

#[test]
fn bad_flags_name_the_flag_and_failed_commands_write_nothing() {
    let dir = std::env::temp_dir().join(format!("trm-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let bad = trm(&["optimise", "--runs", "0"], &dir);
    assert_eq!(bad.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&bad.stderr).contains("--runs"));
    std::fs::write(dir.join("spec.ron"), "(robot: \"nope\")").unwrap();
    let failed = trm(&["solve", "spec.ron", "--out", "posture.json"], &dir);
    assert_eq!(failed.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&failed.stderr).contains("spec.ron"));
    assert!(!dir.join("posture.json").exists());
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A MotionBenchMaker sample problem's scene and request (crates/trm-mbm's fixtures) and the
/// Panda they were made for.
fn panda_problem() -> [std::path::PathBuf; 3] {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let family = root.join("crates/trm-mbm/tests/fixtures/mbm/box_panda");
    [
        root.join("models/panda-mbm/panda_spherized.ron"),
        family.join("scene0001.yaml"),
        family.join("request0001.yaml"),
    ]
}

#[test]
fn plan_without_maps_answers_a_moveit_request_and_writes_every_format() {
    let dir = std::env::temp_dir().join(format!("trm-cli-plan-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let [model, scene, request] = panda_problem();
    let out = trm(
        &[
            "plan",
            "--model",
            model.to_str().unwrap(),
            "--world",
            scene.to_str().unwrap(),
            "--request",
            request.to_str().unwrap(),
            "--out",
            "traj.csv",
        ],
        &dir,
    );
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{stdout}{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(stdout.contains("7 of 7 motors move"), "{stdout}");
    for file in [
        "traj.csv",
        "traj.json",
        "traj.ros.yaml",
        "traj.response.yaml",
    ] {
        assert!(dir.join(file).is_file(), "{file} not written: {stdout}");
    }
    let response = std::fs::read_to_string(dir.join("traj.response.yaml")).unwrap();
    assert!(response.contains("group_name: \"panda_arm\"") && response.contains("val: 1"));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn plan_without_maps_refuses_what_does_not_fit_and_writes_nothing() {
    let dir = std::env::temp_dir().join(format!("trm-cli-plan-bad-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let [model, scene, request] = panda_problem();
    let (model, scene, request) = (
        model.to_str().unwrap(),
        scene.to_str().unwrap(),
        request.to_str().unwrap(),
    );
    // flags that do not go together are clap's errors, naming them
    let both = trm(
        &[
            "plan", "--map", "m.json", "--model", model, "--to", "g.json",
        ],
        &dir,
    );
    assert_eq!(both.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&both.stderr).contains("--model"));
    let no_goal = trm(&["plan", "--model", model], &dir);
    assert_eq!(no_goal.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&no_goal.stderr).contains("--to"));
    for (args, expected) in [
        (
            vec!["--joints", "panda_joint1,nope", "--request", request],
            "nope",
        ),
        (vec!["--request", "missing.yaml"], "missing.yaml"),
        (
            vec!["--world", "missing.yaml", "--request", request],
            "missing.yaml",
        ),
        (
            vec![
                "--joints",
                "panda_joint1,panda_joint2",
                "--request",
                request,
            ],
            "the goal constrains `panda_joint3`, which the planner does not move",
        ),
        (
            vec![
                "--world",
                scene,
                "--from",
                "start.json",
                "--to",
                "start.json",
            ],
            "start.json",
        ),
        // the model's zero posture folds the arm onto itself: the pair is named
        (
            vec!["--joints", "panda_arm", "--to", "home"],
            "the start collides: links `panda_link5` and `panda_hand`",
        ),
        (
            vec!["--request", request, "--max-samples", "0"],
            "--max-samples",
        ),
        (
            vec!["--request", request, "--resolution", "NaN"],
            "--resolution",
        ),
        (
            vec!["--request", request, "--max-seconds", "-1"],
            "--max-seconds",
        ),
        (vec!["--request", request, "--range", "0"], "--range"),
    ] {
        let mut full = vec!["plan", "--model", model, "--out", "traj.csv"];
        full.extend(args);
        let failed = trm(&full, &dir);
        let stderr = String::from_utf8_lossy(&failed.stderr);
        // a flag's value out of range is clap's error (2), the rest trm's (1)
        let code = if expected.starts_with("--") { 2 } else { 1 };
        assert_eq!(failed.status.code(), Some(code), "{full:?}: {stderr}");
        assert!(stderr.contains(expected), "{full:?}: {stderr}");
        assert!(!dir.join("traj.csv").exists(), "{full:?}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}
