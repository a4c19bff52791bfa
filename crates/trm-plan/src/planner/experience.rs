//! A planner's kept paths (its experience) written to a file and read into another planner.

use std::path::Path;

use super::Planner;
use crate::PlanError;

/// The `"format"` of an experience file.
pub const EXPERIENCE_FORMAT: &str = "trm-experience";

/// The version of the experience files this software writes and reads.
pub const EXPERIENCE_VERSION: u32 = 1;

/// An experience file: the moving motors' names and each kept path's waypoints (their values,
/// in the motors' order).
#[derive(serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct ExperienceFile {
    format: String,
    version: u32,
    motors: Vec<String>,
    paths: Vec<Vec<Vec<f64>>>,
}

impl Planner {
    /// Every kept path's waypoints (active values), in the order the paths were kept
    /// ([`Planner::add_path`]).
    pub fn kept_paths(&self) -> Vec<Vec<Vec<f64>>> {
        self.kept
            .iter()
            .map(|(ids, _)| ids.iter().map(|&i| self.nodes[i].0.clone()).collect())
            .collect()
    }

    /// Writes the kept paths to `path` (a versioned JSON file, [`EXPERIENCE_FORMAT`]: the
    /// moving motors' names and every path's waypoints), atomically: a file that exists stays
    /// whole until the new one replaces it.
    pub fn save_experience(&self, path: impl AsRef<Path>) -> Result<(), PlanError> {
        let file = ExperienceFile {
            format: EXPERIENCE_FORMAT.into(),
            version: EXPERIENCE_VERSION,
            motors: self.active.names().map(str::to_string).collect(),
            paths: self.kept_paths(),
        };
        Ok(trm_io::save_json(path.as_ref(), &file, EXPERIENCE_FORMAT)?)
    }

    /// Keeps the paths of an experience file ([`Planner::save_experience`]), as
    /// [`Planner::add_path`] keeps a path: checked in the current world when a search wants
    /// them. A file written for other moving motors, or holding a waypoint that is not finite
    /// values of them, is refused whole (nothing is kept). Returns the number of paths kept.
    pub fn load_experience(&mut self, path: impl AsRef<Path>) -> Result<usize, PlanError> {
        let path = path.as_ref();
        let file: ExperienceFile =
            trm_io::load_versioned(path, EXPERIENCE_FORMAT, EXPERIENCE_VERSION)?;
        let refuse = |problem: String, fix: &str| PlanError::IncompatibleExperience {
            path: path.to_path_buf(),
            problem,
            fix: fix.into(),
        };
        if file
            .motors
            .iter()
            .map(String::as_str)
            .ne(self.active.names())
        {
            let ours: Vec<&str> = self.active.names().collect();
            return Err(refuse(
                format!(
                    "its paths move {} (in that order), the planner moves {}",
                    file.motors.join(", "),
                    ours.join(", ")
                ),
                "load it into a planner of the motors it was written for",
            ));
        }
        let n = file.motors.len();
        for (k, waypoints) in file.paths.iter().enumerate() {
            if waypoints.len() < 2 {
                return Err(refuse(
                    format!("path {k} has {} waypoints", waypoints.len()),
                    "give at least a start and a goal per path",
                ));
            }
            if let Some(w) = waypoints
                .iter()
                .position(|q| q.len() != n || q.iter().any(|v| !v.is_finite()))
            {
                return Err(refuse(
                    format!(
                        "path {k}, waypoint {w}: {} values, not {n} finite ones",
                        waypoints[w].len()
                    ),
                    "write the file again with save_experience",
                ));
            }
        }
        for waypoints in &file.paths {
            self.add_path(waypoints)?;
        }
        Ok(file.paths.len())
    }
}
