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
