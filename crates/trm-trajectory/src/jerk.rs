//! Jerk-limited motion along a waypoint path: on each straight segment, a rest-to-rest
//! double-S (seven-phase, "S-curve") profile of the path coordinate within the segment's
//! speed, acceleration and jerk limits (the joints' limits over the segment's direction), the
//! time-optimal one for a stop at both ends (Biagiotti and Melchiorri, *Trajectory Planning
//! for Automatic Machines and Robots*, 2008, §3.4). The motion stops at every waypoint, so the
//! path is exactly the waypoints' polyline (no blend leaves it) and every joint's jerk stays
//! within its limit.
//!
//! ```
//! use trm_trajectory::{JointLimits, jerk_limited};
//! let limits = JointLimits::new(vec![1.0, 1.0], vec![2.0, 2.0])?;
//! let motion = jerk_limited(&[vec![0.0, 0.0], vec![1.0, 0.5]], &limits, &[10.0, 10.0])?;
//! assert!(motion.duration() > 1.0);
//! let end = motion.sample(motion.duration());
//! assert!((end.position[0] - 1.0).abs() < 1e-9);
//! # Ok::<(), trm_trajectory::TrajectoryError>(())
//! ```

use crate::path::distance;
use crate::timing::{Sample, sample_every};
use crate::{JointLimits, TrajectoryError, invalid};

/// A rest-to-rest double-S profile over a distance: seven phases of constant jerk.
#[derive(Debug, Clone, PartialEq)]
struct DoubleS {
    /// Each phase's duration and jerk.
    phases: [(f64, f64); 7],
    /// Position, speed and acceleration at each phase's start.
    states: [(f64, f64, f64); 7],
    duration: f64,
}

impl DoubleS {
    /// The fastest rest-to-rest profile covering `length` within speed `v`, acceleration `a`
    /// and jerk `j` (all positive).
    fn new(length: f64, v: f64, a: f64, j: f64) -> DoubleS {
        // time at constant jerk (tj) and of the whole acceleration phase (ta)
        let (mut tj, mut ta) = if v * j >= a * a {
            (a / j, a / j + v / a)
        } else {
            let tj = (v / j).sqrt();
            (tj, 2.0 * tj)
        };
        let mut tv = length / v - ta;
        if tv < 0.0 {
            // the top speed is not reached
            tv = 0.0;
            if length >= 2.0 * a * a * a / (j * j) {
                tj = a / j;
                ta = tj / 2.0 + ((tj / 2.0).powi(2) + length / a).sqrt();
            } else {
                tj = (length / (2.0 * j)).cbrt();
                ta = 2.0 * tj;
            }
        }
        let hold = (ta - 2.0 * tj).max(0.0);
        let phases = [
            (tj, j),
            (hold, 0.0),
            (tj, -j),
            (tv, 0.0),
            (tj, -j),
            (hold, 0.0),
            (tj, j),
        ];
        let mut states = [(0.0, 0.0, 0.0); 7];
        let mut state = (0.0, 0.0, 0.0);
        for (k, &(t, jerk)) in phases.iter().enumerate() {
            states[k] = state;
            state = advance(state, jerk, t);
        }
        DoubleS {
            phases,
            states,
            duration: phases.iter().map(|p| p.0).sum(),
        }
    }

    /// Position, speed, acceleration and jerk at time `t` (clamped to the profile).
    fn at(&self, t: f64) -> (f64, f64, f64, f64) {
        let mut left = t.clamp(0.0, self.duration);
        for (k, &(d, jerk)) in self.phases.iter().enumerate() {
            if left <= d || k == 6 {
                let (p, v, a) = advance(self.states[k], jerk, left.min(d));
                return (p, v, a, jerk);
            }
            left -= d;
        }
        unreachable!("seven phases")
    }
}

/// `(position, speed, acceleration)` after `t` at constant `jerk`.
fn advance((p, v, a): (f64, f64, f64), jerk: f64, t: f64) -> (f64, f64, f64) {
    (
        p + v * t + a * t * t / 2.0 + jerk * t * t * t / 6.0,
        v + a * t + jerk * t * t / 2.0,
        a + jerk * t,
    )
}

/// A jerk-limited motion through waypoints, at rest at each one ([`jerk_limited`]).
#[derive(Debug, Clone, PartialEq)]
pub struct StopAndGo {
    /// Each segment: start, unit direction, its profile.
    segments: Vec<(Vec<f64>, Vec<f64>, DoubleS)>,
    /// Time at each segment's start.
    starts: Vec<f64>,
    /// The last waypoint.
    end: Vec<f64>,
}

impl StopAndGo {
    /// Total time (s).
    pub fn duration(&self) -> f64 {
        match (self.starts.last(), self.segments.last()) {
            (Some(t), Some(s)) => t + s.2.duration,
            _ => 0.0,
        }
    }

    /// Positions, velocities and accelerations at `t` (clamped to `[0, duration]`).
    pub fn sample(&self, t: f64) -> Sample {
        self.sample_with_jerk(t).0
    }

    /// [`StopAndGo::sample`] and the joints' jerk at `t`.
    pub fn sample_with_jerk(&self, t: f64) -> (Sample, Vec<f64>) {
        let n = self.end.len();
        let t = t.clamp(0.0, self.duration());
        let i = self.starts.partition_point(|&s| s <= t).max(1) - 1;
        let Some((from, direction, profile)) = self.segments.get(i) else {
            let rest = Sample {
                time: t,
                position: self.end.clone(),
                velocity: vec![0.0; n],
                acceleration: vec![0.0; n],
            };
            return (rest, vec![0.0; n]);
        };
        let (p, v, a, j) = profile.at(t - self.starts[i]);
        let along = |x: f64| direction.iter().map(|d| d * x).collect::<Vec<f64>>();
        let sample = Sample {
            time: t,
            position: from.iter().zip(direction).map(|(f, d)| f + d * p).collect(),
            velocity: along(v),
            acceleration: along(a),
        };
        (sample, along(j))
    }

    /// Samples every `period` seconds from 0, and the end (exactly the last waypoint, at
    /// rest).
    pub fn sampled(&self, period: f64) -> Result<Vec<Sample>, TrajectoryError> {
        let mut out = sample_every(self.duration(), period, |t| self.sample(t))?;
        if let Some(last) = out.last_mut() {
            last.position.clone_from(&self.end);
            last.acceleration.iter_mut().for_each(|a| *a = 0.0);
        }
        Ok(out)
    }
}

/// The fastest motion through `waypoints` that stops at each one, with every joint within its
/// velocity and acceleration `limits` and its `jerk` limit (one per joint, finite and
/// positive). Repeated waypoints are skipped.
pub fn jerk_limited(
    waypoints: &[Vec<f64>],
    limits: &JointLimits,
    jerk: &[f64],
) -> Result<StopAndGo, TrajectoryError> {
    limits.check()?;
    let Some(first) = waypoints.first() else {
        return Err(invalid("waypoints", "none given: give at least one"));
    };
    let n = first.len();
    if limits.velocity.len() != n || jerk.len() != n {
        return Err(invalid(
            "limits",
            format!(
                "{} velocity and {} jerk limits for {n} joints: give one of each per joint",
                limits.velocity.len(),
                jerk.len()
            ),
        ));
    }
    if let Some(j) = jerk.iter().position(|v| !(v.is_finite() && *v > 0.0)) {
        return Err(invalid(
            "jerk limit",
            format!("{} for joint {j}: give a finite positive limit", jerk[j]),
        ));
    }
    for (i, w) in waypoints.iter().enumerate() {
        if w.len() != n || w.iter().any(|v| !v.is_finite()) {
            return Err(invalid(
                "waypoints",
                format!("waypoint {i} is not {n} finite values"),
            ));
        }
    }
    let (mut segments, mut starts, mut t) = (Vec::new(), Vec::new(), 0.0);
    for w in waypoints.windows(2) {
        let length = distance(&w[0], &w[1]);
        if length == 0.0 {
            continue;
        }
        let direction: Vec<f64> = w[1]
            .iter()
            .zip(&w[0])
            .map(|(b, a)| (b - a) / length)
            .collect();
        // the path coordinate's limits: the tightest joint's limit over its share of the motion
        let cap = |values: &[f64]| {
            direction
                .iter()
                .zip(values)
                .filter(|(d, _)| **d != 0.0)
                .map(|(d, l)| l / d.abs())
                .fold(f64::INFINITY, f64::min)
        };
        let profile = DoubleS::new(
            length,
            cap(&limits.velocity),
            cap(&limits.acceleration),
            cap(jerk),
        );
        starts.push(t);
        t += profile.duration;
        segments.push((w[0].clone(), direction, profile));
    }
    Ok(StopAndGo {
        segments,
        starts,
        end: waypoints[waypoints.len() - 1].clone(),
    })
}
