//! The Python package (crates/trm-py): the wheel is built with maturin, installed into a fresh
//! virtual environment, and its pytest suite runs there (kinematics against Pinocchio when
//! `pin` is installed). Runs where `python3 -m maturin` and pytest exist; `.ci/run` installs
//! them (and `pin`) and sets TRM_PYTHON_TEST=1, which makes their absence a failure.

use std::path::{Path, PathBuf};
use std::process::Command;

fn run(command: &mut Command, what: &str) {
    let out = command.output().unwrap_or_else(|e| panic!("{what}: {e}"));
    assert!(
        out.status.success(),
        "{what} failed ({}):\n{}\n{}",
        out.status,
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    print!("{}", String::from_utf8_lossy(&out.stdout));
}

fn has(python: &str, module: &str) -> bool {
    Command::new(python)
        .args(["-c", &format!("import {module}")])
        .output()
        .is_ok_and(|o| o.status.success())
}

#[test]
#[ignore = "slow (a build of the wheel); CI runs it with --ignored"]
fn the_python_package_builds_installs_and_passes_its_tests() {
    let required = std::env::var_os("TRM_PYTHON_TEST").is_some_and(|v| v == "1");
    let python = std::env::var("TRM_PYTHON").unwrap_or_else(|_| "python3".into());
    if !(has(&python, "maturin") && has(&python, "pytest") && has(&python, "numpy")) {
        assert!(
            !required,
            "TRM_PYTHON_TEST=1 but {python} lacks maturin, pytest or numpy"
        );
        eprintln!(
            "skipped: needs `{python} -m pip install maturin numpy pytest` (.ci/run installs them)"
        );
        return;
    }
    let root: PathBuf = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let work = root.join("target/python-test");
    let _ = std::fs::remove_dir_all(&work);
    let wheels = work.join("wheels");
    run(
        Command::new(&python)
            // trm's own crates optimised a little (its dependencies already are, by the
            // workspace's dev profile): the pytest suite then takes 6 s instead of 89
            .env("CARGO_PROFILE_DEV_OPT_LEVEL", "1")
            .args(["-m", "maturin", "build", "--quiet", "-m"])
            .arg(root.join("crates/trm-py/Cargo.toml"))
            .arg("--out")
            .arg(&wheels)
            .current_dir(&root),
        "maturin build",
    );
    let wheel = std::fs::read_dir(&wheels)
        .unwrap()
        .map(|e| e.unwrap().path())
        .find(|p| p.extension().is_some_and(|e| e == "whl"))
        .expect("a wheel");
    // a fresh environment that sees numpy, pytest (and pin) from the interpreter's site
    let venv = work.join("venv");
    run(
        Command::new(&python)
            .args(["-m", "venv", "--system-site-packages"])
            .arg(&venv),
        "venv",
    );
    let venv_python = venv.join("bin/python");
    run(
        Command::new(&venv_python)
            .args([
                "-m",
                "pip",
                "install",
                "--quiet",
                "--no-deps",
                "--disable-pip-version-check",
            ])
            .arg(&wheel),
        "pip install the wheel",
    );
    run(
        Command::new(&venv_python)
            .args([
                "-m",
                "pytest",
                "-q",
                "-p",
                "no:cacheprovider",
                "--durations=5",
            ])
            .arg(root.join("crates/trm-py/python/tests"))
            .current_dir(&work),
        "pytest",
    );
}
