//! The library crates from outside the workspace: builds and runs `examples/library-user` (its
//! own workspace and lock file, depending on the library crates by path only), which builds a
//! map from its own spec, loads it, plans, writes a trajectory and posture files, runs a Table
//! III comparison on its spec and plugs its own cost and optimiser into NGIK.

use std::path::Path;
use std::process::Command;

#[test]
#[ignore = "slow (builds the library crates again for the example's own profile); CI runs it with --ignored"]
fn a_crate_outside_the_workspace_uses_the_library_end_to_end() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let manifest = root.join("examples/library-user/Cargo.toml");
    // the workspace's target directory: the example's lock file and profile for dependencies are
    // the workspace's, so the dependencies built for the tests serve it (only trm's crates build)
    let target =
        std::env::var_os("CARGO_TARGET_DIR").map_or_else(|| root.join("target"), Into::into);
    let out = std::env::temp_dir().join(format!("trm-library-user-{}", std::process::id()));
    let run = Command::new(env!("CARGO"))
        .args(["run", "--quiet", "--locked", "--manifest-path"])
        .arg(&manifest)
        .arg("--target-dir")
        .arg(&target)
        .arg("--")
        .arg(&out)
        .env_remove("RUSTFLAGS")
        .output()
        .expect("cargo runs");
    let stdout = String::from_utf8_lossy(&run.stdout);
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(
        run.status.success(),
        "stdout:\n{stdout}\nstderr:\n{stderr}\n(a library crate's dependencies changed? refresh the example's lock file: \
         `cargo metadata --manifest-path examples/library-user/Cargo.toml > /dev/null`)"
    );
    for line in [
        "map:",
        "plan:",
        "table III: xnes",
        "own optimiser + own cost",
    ] {
        assert!(stdout.contains(line), "no `{line}` in:\n{stdout}");
    }
    for file in [
        "right_hand.map.json",
        "plan.csv",
        "plan.json",
        "start.posture.json",
        "goal.posture.json",
        "table.md",
    ] {
        assert!(out.join(file).is_file(), "{file} not written");
    }
    let map = trm_roadmap::Roadmap::load(out.join("right_hand.map.json")).unwrap();
    assert!(map.points.len() >= 20, "{} points", map.points.len());
    std::fs::remove_dir_all(&out).unwrap();
}
