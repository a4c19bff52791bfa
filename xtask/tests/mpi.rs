//! Map builds across MPI processes: the same map on 1, 2 and 3 ranks (oversubscribed on this
//! machine) as on threads, and a checkpointed MPI build resumed on another number of ranks to
//! that same map. Needs `mpirun` and the `mpi` feature:
//! `cargo test -p xtask --features mpi --test mpi` (what `.ci/run` runs).
#![cfg(feature = "mpi")]

mod common;

use std::path::{Path, PathBuf};
use std::process::Command;

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// Runs `xtask args` in `dir`, under `mpirun -n ranks` when `ranks` is given; panics with its
/// output when it fails.
fn xtask(dir: &Path, ranks: Option<usize>, args: &[&str]) -> String {
    let bin = env!("CARGO_BIN_EXE_xtask");
    let mut command = match ranks {
        Some(n) => {
            let mut c = Command::new("mpirun");
            c.args(["--oversubscribe", "-n", &n.to_string(), bin]);
            // CI runs as root; Open MPI refuses that unless told
            c.env("OMPI_ALLOW_RUN_AS_ROOT", "1")
                .env("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1");
            c
        }
        None => Command::new(bin),
    };
    let output = command
        .args(args)
        .current_dir(dir)
        .output()
        .expect("mpirun (Open MPI: Debian's openmpi-bin) and xtask start");
    let text = format!(
        "{}{}",
        String::from_utf8_lossy(&output.stdout),
        String::from_utf8_lossy(&output.stderr)
    );
    assert!(
        output.status.success(),
        "xtask {args:?} on {ranks:?} ranks: {text}"
    );
    text
}

/// A map file without its timing statistics.
fn map(dir: &Path, name: &str) -> String {
    common::map_without_timings(&dir.join(name))
}

#[test]
fn mpi_builds_give_the_threaded_map_on_any_number_of_ranks_and_resume() {
    let dir = std::env::temp_dir().join(format!("trm-mpi-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let spec = root().join("specs/reach.ron");
    let spec = spec.to_str().unwrap();
    let build = |ranks, out: &str, more: &[&str]| {
        let mut args = vec!["build-map", spec, "--points", "120", "--out", out];
        args.extend(more);
        xtask(&dir, ranks, &args)
    };
    build(None, "threads.map.json", &["--threads", "2"]);
    let threads = map(&dir, "threads.map.json");
    for ranks in [1, 2, 3] {
        let out = format!("ranks{ranks}.map.json");
        let said = build(Some(ranks), &out, &["--mpi"]);
        assert!(said.contains(&format!("MPI: {ranks} ranks")), "{said}");
        assert!(map(&dir, &out) == threads, "{ranks} ranks: another map");
    }
    // a checkpointed build on 2 ranks stopped at 60 points, resumed to 120 on 3
    xtask(
        &dir,
        Some(2),
        &[
            "build-map",
            spec,
            "--points",
            "60",
            "--out",
            "part.map.json",
            "--mpi",
            "--checkpoint-every",
            "20",
        ],
    );
    xtask(
        &dir,
        Some(3),
        &[
            "build-map",
            "--resume",
            "part.map.checkpoint",
            "--points",
            "120",
            "--out",
            "resumed.map.json",
            "--mpi",
        ],
    );
    assert!(
        map(&dir, "resumed.map.json") == threads,
        "the resumed map differs"
    );
    let _ = std::fs::remove_dir_all(&dir);
}
