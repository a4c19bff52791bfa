//! From a collision-checked path to a trajectory a robot can execute: the path's corners cut
//! by circular blends whose deviation is bounded and collision-checked (a blend that would
//! collide is halved until it does not, down to the corner itself), then timed time-optimally
//! within the joints' velocity and acceleration limits (TOPP-RA, [`trm_trajectory`]), sampled
//! at a period the user sets with positions, velocities and accelerations.

use std::collections::BTreeMap;

use trm_kinematics::{ActiveSet, MotionLimitSpec};
use trm_trajectory::{BlendedPath, JointLimits, Sample, TimingOptions, jerk_limited, time_optimal};

use crate::{PlanError, Trajectory};

/// Joint speeds at or above this (rad/s) are URDF placeholders, not limits.
const PLACEHOLDER_VELOCITY: f64 = 1000.0;

/// Blends whose deviation would fall below this fraction of the check resolution are dropped
/// (the corner is kept and the motion stops there).
const BLEND_FLOOR: f64 = 0.25;

/// How a path is timed: limits (the robot's, else these defaults, then scaled), blends and
/// sampling.
#[derive(Debug, Clone, PartialEq)]
pub struct Timing {
    /// Joint speed where the robot gives none (or a placeholder ≥ 1000), rad/s.
    pub default_velocity: f64,
    /// Joint acceleration where the robot gives none, rad/s² (MoveIt's default: 1).
    pub default_acceleration: f64,
    /// Joint jerk where the robot gives none, rad/s³ (used by [`Timing::jerk_limited`]).
    pub default_jerk: f64,
    /// Keep jerk limits too: the motion stops at every waypoint, each segment a double-S
    /// profile (no blends); off: time-optimal within velocity and acceleration limits.
    pub jerk_limited: bool,
    /// Limits by motor name replacing the robot's (e.g. MoveIt's `joint_limits.yaml`).
    pub limits: BTreeMap<String, MotionLimitSpec>,
    /// Factor on every velocity limit, (0, 1] (MoveIt's `max_velocity_scaling_factor`).
    pub velocity_scaling: f64,
    /// Factor on every acceleration limit, (0, 1].
    pub acceleration_scaling: f64,
    /// Largest distance (rad, joint space) a blend may cut from a corner; 0: stop at every
    /// waypoint.
    pub max_deviation: f64,
    /// Time between trajectory samples, s.
    pub sample_period: f64,
    /// Largest gap between checked points of a blend, rad; `None`: the planner's own
    /// resolution (what its edges were checked at).
    pub resolution: Option<f64>,
}

impl Default for Timing {
    fn default() -> Self {
        Timing {
            default_velocity: 1.0,
            default_acceleration: 1.0,
            default_jerk: 10.0,
            jerk_limited: false,
            limits: BTreeMap::new(),
            velocity_scaling: 1.0,
            acceleration_scaling: 1.0,
            max_deviation: 0.2,
            sample_period: 0.01,
            resolution: None,
        }
    }
}

impl Timing {
    /// Checks the settings: finite positive defaults, period and resolution; scaling factors
    /// in (0, 1]; a finite deviation ≥ 0.
    pub fn check(&self) -> Result<(), PlanError> {
        let bad = |what: &str, problem: String| {
            Err(PlanError::InvalidOptions {
                what: what.to_string(),
                problem,
            })
        };
        for (what, v, unit) in [
            ("default_velocity", self.default_velocity, "rad/s"),
            ("default_acceleration", self.default_acceleration, "rad/s²"),
            ("default_jerk", self.default_jerk, "rad/s³"),
            ("sample_period", self.sample_period, "s"),
            ("resolution", self.resolution.unwrap_or(1.0), "rad"),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return bad(what, format!("{v} {unit}: give a finite positive value"));
            }
        }
        for (what, f) in [
            ("velocity_scaling", self.velocity_scaling),
            ("acceleration_scaling", self.acceleration_scaling),
        ] {
            if !(f > 0.0 && f <= 1.0) {
                return bad(what, format!("{f}: give a factor in (0, 1]"));
            }
        }
        if !(self.max_deviation.is_finite() && self.max_deviation >= 0.0) {
            return bad(
                "max_deviation",
                format!(
                    "{} rad: give a finite deviation ≥ 0 (0: stop at every waypoint)",
                    self.max_deviation
                ),
            );
        }
        Ok(())
    }

    /// The limits of `active`'s motors: [`Timing::limits`] where they name the motor, else
    /// the robot's (velocity from the URDF, acceleration from its model description), else
    /// the defaults; then scaled.
    pub fn joint_limits(&self, active: &ActiveSet) -> Result<JointLimits, PlanError> {
        self.check()?;
        let motors = active.model().motors();
        let (mut velocity, mut acceleration) = (Vec::new(), Vec::new());
        for &m in active.motor_indices() {
            let motor = &motors[m];
            let own = self.limits.get(&motor.name);
            let usable =
                |v: f64| (v.is_finite() && v > 0.0 && v < PLACEHOLDER_VELOCITY).then_some(v);
            velocity.push(
                own.and_then(|l| l.velocity)
                    .or_else(|| usable(motor.limits.velocity))
                    .unwrap_or(self.default_velocity),
            );
            acceleration.push(
                own.and_then(|l| l.acceleration)
                    .or_else(|| usable(motor.limits.acceleration))
                    .unwrap_or(self.default_acceleration),
            );
        }
        JointLimits::new(velocity, acceleration)
            .and_then(|l| l.scaled(self.velocity_scaling, self.acceleration_scaling))
            .map_err(|e| PlanError::InvalidOptions {
                what: "joint limits".into(),
                problem: format!("{e}: give finite positive limits in the model or the timing"),
            })
    }

    /// The jerk limit of each of `active`'s motors: [`Timing::limits`], else the model
    /// description's, else [`Timing::default_jerk`] (not scaled: MoveIt's requests scale
    /// velocity and acceleration only).
    pub fn jerk_limits(&self, active: &ActiveSet) -> Vec<f64> {
        let motors = active.model().motors();
        active
            .motor_indices()
            .iter()
            .map(|&m| {
                let motor = &motors[m];
                self.limits
                    .get(&motor.name)
                    .and_then(|l| l.jerk)
                    .or_else(|| {
                        let j = motor.limits.jerk;
                        (j.is_finite() && j > 0.0).then_some(j)
                    })
                    .unwrap_or(self.default_jerk)
            })
            .collect()
    }
}

/// `waypoints` (active values, a collision-checked path) as a timed trajectory of `active`'s
/// robot: blends checked by `segment_free` as chains of segments of at most `resolution`
/// (tightened where one is not free), then timed within [`Timing::joint_limits`] and sampled
/// every [`Timing::sample_period`] (and at the end). The task path is left empty.
pub fn timed(
    active: &ActiveSet,
    waypoints: &[Vec<f64>],
    timing: &Timing,
    resolution: f64,
    segment_free: impl FnMut(&[f64], &[f64]) -> bool,
) -> Result<Trajectory, PlanError> {
    let limits = timing.joint_limits(active)?;
    if !(resolution.is_finite() && resolution > 0.0) {
        return Err(PlanError::InvalidOptions {
            what: "resolution".into(),
            problem: format!("{resolution} rad: give a finite positive gap between checks"),
        });
    }
    let mut samples = if timing.jerk_limited {
        jerk_limited(waypoints, &limits, &timing.jerk_limits(active))
            .and_then(|m| m.sampled(timing.sample_period))
            .map_err(invalid)?
    } else {
        blended(waypoints, &limits, timing, resolution, segment_free)?
    };
    // the last sample is the goal itself, not the path's end rounded
    if let (Some(last), Some(goal)) = (samples.last_mut(), waypoints.last()) {
        last.position.clone_from(goal);
    }
    let model = active.model();
    let motors = model.motors().len();
    let rates = |values: &[f64]| {
        let mut full = vec![0.0; motors];
        for (&m, v) in active.motor_indices().iter().zip(values) {
            full[m] = *v;
        }
        full
    };
    Ok(Trajectory {
        names: model.motor_names(),
        times: samples.iter().map(|s| s.time).collect(),
        positions: samples
            .iter()
            .map(|s| active.to_motors(&s.position))
            .collect(),
        velocities: samples.iter().map(|s| rates(&s.velocity)).collect(),
        accelerations: samples.iter().map(|s| rates(&s.acceleration)).collect(),
        task_path: Vec::new(),
    })
}

/// A path the timing refuses, as the planner's error.
fn invalid(e: trm_trajectory::TrajectoryError) -> PlanError {
    PlanError::InvalidOptions {
        what: "path".into(),
        problem: e.to_string(),
    }
}

/// The samples of the time-optimal motion along `waypoints` with its corners blended where
/// `segment_free` says the blends are free.
fn blended(
    waypoints: &[Vec<f64>],
    limits: &JointLimits,
    timing: &Timing,
    resolution: f64,
    mut segment_free: impl FnMut(&[f64], &[f64]) -> bool,
) -> Result<Vec<Sample>, PlanError> {
    let mut path = BlendedPath::new(waypoints, timing.max_deviation).map_err(invalid)?;
    let floor = BLEND_FLOOR * resolution;
    'check: loop {
        for (corner, range) in path.blends() {
            let steps = ((range.end - range.start) / resolution).ceil().max(1.0) as usize;
            let mut previous = path.position(range.start);
            for k in 1..=steps {
                let next = path
                    .position(range.start + (range.end - range.start) * k as f64 / steps as f64);
                if !segment_free(&previous, &next) {
                    path = path.tightened(waypoints, corner, floor).map_err(invalid)?;
                    continue 'check;
                }
                previous = next;
            }
        }
        break;
    }
    let timed = time_optimal(&path, limits, &TimingOptions::default()).map_err(invalid)?;
    timed.sampled(timing.sample_period).map_err(invalid)
}
