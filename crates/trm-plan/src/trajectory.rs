//! Time parametrisation of a piecewise-linear joint path and trajectory output.

use serde::{Deserialize, Serialize};

/// A timed joint trajectory (full motor vectors) with its task-space path.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Trajectory {
    /// Motor names, the columns of `positions`.
    pub names: Vec<String>,
    /// Time of each waypoint, seconds, from 0.
    pub times: Vec<f64>,
    /// Motor values at each waypoint.
    pub positions: Vec<Vec<f64>>,
    /// Task vector at each waypoint.
    pub task_path: Vec<Vec<f64>>,
}

impl Trajectory {
    /// CSV: `time,<names…>` then one row per waypoint.
    pub fn to_csv(&self) -> String {
        let mut out = format!("time,{}\n", self.names.join(","));
        for (t, q) in self.times.iter().zip(&self.positions) {
            let row: Vec<String> = q.iter().map(|v| format!("{v}")).collect();
            out.push_str(&format!("{t},{}\n", row.join(",")));
        }
        out
    }
}

/// Waypoint times for a path through `waypoints` (active values) that stops at every waypoint:
/// each segment takes the longest time any joint needs to cover its change at velocity
/// `velocity[i]` (and, when given, with a trapezoidal profile at acceleration `acceleration[i]`).
pub fn time_parametrise(
    waypoints: &[Vec<f64>],
    velocity: &[f64],
    acceleration: Option<&[f64]>,
) -> Vec<f64> {
    let mut times = Vec::with_capacity(waypoints.len());
    let mut t = 0.0;
    times.push(0.0);
    for w in waypoints.windows(2) {
        let mut duration: f64 = 0.0;
        for i in 0..w[0].len() {
            let d = (w[1][i] - w[0][i]).abs();
            let v = velocity[i];
            let need = match acceleration {
                None => d / v,
                Some(a) => {
                    let a = a[i];
                    if d >= v * v / a {
                        d / v + v / a
                    } else {
                        2.0 * (d / a).sqrt()
                    }
                }
            };
            duration = duration.max(need);
        }
        t += duration;
        times.push(t);
    }
    times
}
