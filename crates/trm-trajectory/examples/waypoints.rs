//! An RBF trajectory through three waypoints for random free weights: the waypoints are hit
//! exactly whatever the weights; and a time law that slows the motion down at the start.
//!
//! `cargo run -p trm-trajectory --example waypoints`

use trm_trajectory::{RbfTrajectory, TrajectoryError};

fn main() -> Result<(), TrajectoryError> {
    let waypoints = [(0.0, 0.1), (2.0, 0.8), (4.5, 0.5)];
    let traj = RbfTrajectory::new(0.0, 4.5, 5, &waypoints)?;
    for weights in [
        [0.0; 5],
        [0.3, -0.2, 0.8, 0.1, 0.4],
        [-1.0, 1.0, -1.0, 1.0, -1.0],
    ] {
        let samples: Vec<String> = (0..=9)
            .map(|i| {
                traj.evaluate(&weights, 0.5 * i as f64)
                    .map(|y| format!("{y:+.3}"))
            })
            .collect::<Result<_, _>>()?;
        println!("weights {weights:?}: {}", samples.join(" "));
        for (t, y) in waypoints {
            assert!((traj.evaluate(&weights, t)? - y).abs() < 1e-9);
        }
    }
    Ok(())
}
