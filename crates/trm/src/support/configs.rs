//! The `--configs` file of joint configurations that several commands read.

use std::path::PathBuf;

use anyhow::Result;
use trm_kinematics::ConfigurationsFile;

/// The configurations a command reads (`fk`, `collide`).
#[derive(clap::Args)]
pub struct ConfigsArgs {
    /// Input: {"joint_names": [...], "samples": [{"q": [...]}, ...]} (URDF joint names, radians).
    #[arg(long = "configs")]
    pub path: PathBuf,
    /// Accept joint values outside the URDF limits (refused by default).
    #[arg(long)]
    pub outside_limits: bool,
}

impl ConfigsArgs {
    /// The parsed file and, per sample, the full joint vector (joints not named are 0; mimic
    /// joints not named follow their leader).
    pub fn read(
        &self,
        model: &trm_kinematics::RobotModel,
    ) -> Result<(ConfigurationsFile, Vec<Vec<f64>>)> {
        let path = &self.path;
        let configs = ConfigurationsFile::load(path)?;
        let missing = configs.missing_joints(model);
        if !missing.is_empty() {
            eprintln!(
                "note: {} joints not in joint_names are set to 0 (mimic joints follow their leader): {}",
                missing.len(),
                missing.join(", ")
            );
        }
        let all = if self.outside_limits {
            configs.joint_vectors_outside_limits(model, path)?
        } else {
            configs.joint_vectors(model, path)?
        };
        Ok((configs, all))
    }
}
