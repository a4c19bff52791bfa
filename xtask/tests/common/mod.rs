//! Helpers shared by the xtask integration tests.

use std::path::Path;

/// A map file's JSON without its timing statistics (build and edge seconds, threads): what two
/// builds of the same map have in common byte for byte.
pub fn map_without_timings(path: &Path) -> String {
    let mut map: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
    for timing in ["build_seconds", "edge_seconds", "threads"] {
        map["stats"][timing] = serde_json::Value::Null;
    }
    serde_json::to_string(&map).unwrap()
}
