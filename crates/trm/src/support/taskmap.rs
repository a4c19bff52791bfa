//! Task maps explored for the commands that need one.

use anyhow::Result;
use trm_taskmap::{Explored, TaskMapSpec};

/// Reads a task-map spec, finds the first grasp if needed and explores the map.
pub fn explore_spec(path: &std::path::Path) -> Result<Explored> {
    let loaded = TaskMapSpec::load(path)?;
    let explored = loaded.explore()?;
    if loaded.spec.start.is_none() {
        eprintln!("first grasp found by search: {:?}", explored.start);
    }
    Ok(explored)
}
