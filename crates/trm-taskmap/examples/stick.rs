//! The task map of grasps of a 20 cm stick: feasible anywhere along it, within 1 cm of its
//! axis, at any roll about it; explored with RRT and restarts, then the task-map cost of a few
//! hand poses.
//!
//! `cargo run -p trm-taskmap --example stick`

use trm_taskmap::{ExploreOptions, Metric, TaskMapError, explore};

fn main() -> Result<(), TaskMapError> {
    let feasible = |g: &[f64; 6]| {
        0.01 - g[1]
            .abs()
            .max(g[2].abs())
            .max(g[4].abs() / 20.0)
            .max(g[5].abs() / 20.0)
            .max(g[0].abs() - 0.1)
    };
    let settings = ExploreOptions {
        iterations: 4000,
        ..ExploreOptions::around([0.0; 6], [0.15, 0.02, 0.02, 3.2, 0.3, 0.3])
    };
    let map = explore(&[[0.0; 6]], &settings, &Metric::default(), feasible)?;
    println!("{} feasible grasps", map.points.len());
    for g in [
        [0.0; 6],
        [0.05, 0.0, 0.0, 1.0, 0.0, 0.0],
        [0.3, 0.0, 0.0, 0.0, 0.0, 0.0],
    ] {
        let (cost, _) = map.cost(&g);
        println!("hand at {g:?}: task-map cost {cost:.5}");
    }
    Ok(())
}
