//! The paper studies trm reproduces, each a command of `cargo xtask` (which only parses the
//! flags and calls `run`): [`speedup`] (the parallel E-TRM paper's Fig. 2 on this machine),
//! [`map_scaling`] (how building, memory, kd-tree queries and map files grow with a map's
//! size) and [`task_map_studies`] (Gienger et al.'s reaching studies, Figs. 7 and 9). They
//! measure and write tables and plots; the user-facing commands are the `trm` tool's.

pub mod map_scaling;
pub mod speedup;
pub mod task_map_studies;

/// The repository's directory (the studies read its specs).
fn repo_dir() -> std::path::PathBuf {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    dir.canonicalize().unwrap_or(dir)
}
