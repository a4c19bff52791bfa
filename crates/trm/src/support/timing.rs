//! The flags that say how a planned path is timed (limits, scaling, blends, sampling), shared
//! by the commands that write trajectories.

use std::path::PathBuf;

use anyhow::{Context, Result};
use trm_moveit::TimingSettings;
use trm_plan::Timing;

/// How the path becomes a trajectory: time-optimal within the joints' velocity and
/// acceleration limits, corners blended where the blends are collision-free.
#[derive(clap::Args, Debug, Clone)]
pub struct TimingArgs {
    /// Joint speed where the model has no limit, rad/s.
    #[arg(long, default_value_t = 1.0, value_parser = crate::parse::positive)]
    pub velocity: f64,
    /// Joint acceleration where neither the model nor --joint-limits gives one, rad/s²
    /// (MoveIt's default).
    #[arg(long, default_value_t = 1.0, value_parser = crate::parse::positive)]
    pub acceleration: f64,
    /// MoveIt's joint_limits.yaml: its velocity and acceleration limits replace the model's.
    #[arg(long, value_name = "FILE")]
    pub joint_limits: Option<PathBuf>,
    /// Factor on every velocity limit, (0, 1] [default: the request's
    /// max_velocity_scaling_factor, else the --joint-limits file's default, else 1].
    #[arg(long, value_parser = crate::parse::factor)]
    pub velocity_scaling: Option<f64>,
    /// Factor on every acceleration limit, (0, 1] [default: as --velocity-scaling's].
    #[arg(long, value_parser = crate::parse::factor)]
    pub acceleration_scaling: Option<f64>,
    /// Largest joint-space distance a blend may cut from a corner of the path, rad (blends
    /// that would collide are tightened); 0: stop at every waypoint.
    #[arg(long, default_value_t = 0.2, value_parser = crate::parse::non_negative)]
    pub max_deviation: f64,
    /// Keep jerk limits too (--joint-limits' max_jerk, the model's, else --jerk): the motion
    /// stops at every waypoint with a double-S profile per segment, no blends.
    #[arg(long)]
    pub jerk_limited: bool,
    /// Joint jerk where neither the model nor --joint-limits gives one, rad/s³.
    #[arg(long, default_value_t = 10.0, value_parser = crate::parse::positive)]
    pub jerk: f64,
    /// Time between the trajectory's samples, s.
    #[arg(long, default_value_t = 0.01, value_parser = crate::parse::positive)]
    pub sample_period: f64,
}

impl TimingArgs {
    /// The settings these flags give (the joint-limits file read).
    pub fn settings(&self) -> Result<TimingSettings> {
        let joint_limits = match &self.joint_limits {
            Some(path) => Some(
                trm_moveit::JointLimitsFile::load(path)
                    .with_context(|| format!("--joint-limits {}", path.display()))?,
            ),
            None => None,
        };
        Ok(TimingSettings {
            timing: Timing {
                default_velocity: self.velocity,
                default_acceleration: self.acceleration,
                default_jerk: self.jerk,
                jerk_limited: self.jerk_limited,
                max_deviation: self.max_deviation,
                sample_period: self.sample_period,
                ..Timing::default()
            },
            joint_limits,
            velocity_scaling: self.velocity_scaling,
            acceleration_scaling: self.acceleration_scaling,
        })
    }
}
