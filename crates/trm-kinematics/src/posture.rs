//! Posture files — a robot's motor values by name (JSON), with whatever the writer adds — and
//! configuration files — URDF joint values by joint name, many samples (JSON).
//!
//! Format (what `cargo xtask solve --out` writes and `plan`/`view` read):
//!
//! ```json
//! { "motors": { "r_shoulder_pitch": -0.5, "r_elbow": 1.1, … },
//!   "q": [ … ],
//!   "cost": 0.12, "breakdown": [ … ], … }
//! ```
//!
//! `motors` names motors of the model (missing ones keep a start posture's values); `q` instead
//! holds the values of a task's active motors in their order (needs that task's [`ActiveSet`]).
//! One of the two must be there. Any other key is metadata, kept on reading and written back.
//!
//! A configuration file ([`ConfigurationsFile`], what `cargo xtask fk` and `collide` read) holds
//! URDF joint values, one column per named joint:
//!
//! ```json
//! { "joint_names": ["r_shoulder_pitch", "r_elbow"], "samples": [ { "q": [0.1, 0.5] }, … ] }
//! ```

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::error::{KinematicsError, Result};
use crate::{ActiveSet, RobotModel};
use trm_io::FileError;

/// A posture file: motor values by name and/or a task's active values, plus metadata.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct PostureFile {
    /// Motor values by motor name (radians or metres).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub motors: Option<BTreeMap<String, f64>>,
    /// Values of a task's active motors, in the task's order.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub q: Option<Vec<f64>>,
    /// Everything else in the file (cost, breakdown, frames, the spec it came from, …).
    #[serde(flatten)]
    pub metadata: serde_json::Map<String, serde_json::Value>,
}

impl PostureFile {
    /// A posture file holding every motor of `robot` at `motors` (one value per motor).
    pub fn from_motors(robot: &RobotModel, motors: &[f64]) -> Result<Self> {
        check_len("motor values", robot.motors().len(), motors.len())?;
        Ok(PostureFile {
            motors: Some(
                robot
                    .motors()
                    .iter()
                    .zip(motors)
                    .map(|(m, v)| (m.name.clone(), *v))
                    .collect(),
            ),
            ..Default::default()
        })
    }

    /// Adds (or replaces) a metadata entry; chainable.
    pub fn with(mut self, key: &str, value: impl Into<serde_json::Value>) -> Self {
        self.metadata.insert(key.to_string(), value.into());
        self
    }

    /// Parses posture-file JSON; `origin` names it in errors.
    pub fn from_json(text: &str, origin: &Path) -> Result<Self> {
        crate::check_unique_keys(text)
            .and_then(|()| serde_json::from_str(text))
            .map_err(|e| invalid(origin, "", e.to_string(), FIX))
    }

    /// Reads a posture file.
    pub fn load(path: impl AsRef<Path>) -> Result<Self> {
        let path = path.as_ref();
        let text = crate::error::read_text(path)?;
        Self::from_json(&text, path)
    }

    /// The file as pretty JSON; refuses non-finite values (`path` names the file it is for).
    pub fn to_json(&self, path: &Path) -> Result<String> {
        for (field, values) in [
            (
                "motors",
                self.motors
                    .iter()
                    .flat_map(|m| m.values())
                    .copied()
                    .collect::<Vec<_>>(),
            ),
            ("q", self.q.clone().unwrap_or_default()),
        ] {
            if let Some(v) = values.iter().find(|v| !v.is_finite()) {
                return Err(invalid(
                    path,
                    field,
                    format!("holds {v}, which JSON cannot carry"),
                    "only finite values can be written",
                ));
            }
        }
        serde_json::to_string_pretty(self).map_err(|source| {
            KinematicsError::File(FileError::Serialize {
                path: path.to_path_buf(),
                format: "posture",
                source,
            })
        })
    }

    /// Writes the file atomically ([`PostureFile::to_json`]).
    pub fn save(&self, path: impl AsRef<Path>) -> Result<()> {
        let path = path.as_ref();
        let text = self.to_json(path)?;
        crate::write_atomic(path, text.as_bytes()).map_err(|source| KinematicsError::Io {
            path: path.to_path_buf(),
            source,
        })
    }

    /// The motor vector of `robot` this file describes: `start` (one value per motor) with the
    /// file's `motors` set by name, or with `active`'s motors set from `q`. `origin` names the
    /// file in errors. Unknown motor names get suggestions; non-finite values and values outside
    /// the motor's limits are refused.
    pub fn to_motors(
        &self,
        robot: &RobotModel,
        active: Option<&ActiveSet>,
        start: &[f64],
        origin: &Path,
    ) -> Result<Vec<f64>> {
        check_len("start motor values", robot.motors().len(), start.len())?;
        let mut motors = start.to_vec();
        if let Some(named) = &self.motors {
            for (name, &value) in named {
                let i = robot.motor_index(name).map_err(|e| {
                    invalid(
                        origin,
                        &format!("motors.{name}"),
                        e.to_string(),
                        "use the model's motor names (`cargo xtask model-info`)",
                    )
                })?;
                robot.motors()[i].limits.check(value).map_err(|problem| {
                    invalid(
                        origin,
                        &format!("motors.{name}"),
                        problem,
                        "give a value within the motor's limits (`cargo xtask model-info`)",
                    )
                })?;
                motors[i] = value;
            }
            return Ok(motors);
        }
        if let Some(q) = &self.q {
            let Some(active) = active else {
                return Err(invalid(
                    origin,
                    "q",
                    "holds active values, which need the task they belong to".into(),
                    "give the task spec, or write \"motors\": {name: value}",
                ));
            };
            if q.len() != active.len() {
                return Err(invalid(
                    origin,
                    "q",
                    format!("has {} values for {} active motors", q.len(), active.len()),
                    "write one value per active motor of the task",
                ));
            }
            for (k, (&m, &v)) in active.motor_indices().iter().zip(q).enumerate() {
                robot.motors()[m].limits.check(v).map_err(|problem| {
                    invalid(
                        origin,
                        &format!("q[{k}] ({})", robot.motors()[m].name),
                        problem,
                        "give a value within the motor's limits (`cargo xtask model-info`)",
                    )
                })?;
                motors[m] = v;
            }
            return Ok(motors);
        }
        Err(invalid(
            origin,
            "",
            "neither \"motors\" nor \"q\"".into(),
            FIX,
        ))
    }
}

/// A configurations file: URDF joint values by joint name, one row per sample.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ConfigurationsFile {
    /// URDF joint names, one per column of every sample's `q`.
    pub joint_names: Vec<String>,
    /// The configurations.
    pub samples: Vec<ConfigurationSample>,
}

/// One configuration of a [`ConfigurationsFile`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ConfigurationSample {
    /// Values of the file's `joint_names`, radians (metres for prismatic joints).
    pub q: Vec<f64>,
    /// Anything else a sample carries (kept, e.g. the poses `fk` adds).
    #[serde(flatten)]
    pub extra: serde_json::Map<String, serde_json::Value>,
}

impl ConfigurationsFile {
    /// Reads a configurations file.
    pub fn load(path: impl AsRef<Path>) -> Result<Self> {
        let path = path.as_ref();
        Self::from_json(&crate::error::read_text(path)?, path)
    }

    /// The joint names of `robot` the file leaves out (they are 0, or follow their leader when
    /// they mimic one).
    pub fn missing_joints<'a>(&self, robot: &'a RobotModel) -> Vec<&'a str> {
        robot
            .joint_names()
            .filter(|n| !self.joint_names.iter().any(|g| g == n))
            .collect()
    }

    /// Per sample, the full joint vector of `robot` (one value per movable joint, the order of
    /// [`RobotModel::joint_names`]): joints not named are 0, mimic joints not named follow their
    /// leader. `origin` names the file in errors. Every joint, named or not, must lie within its
    /// URDF limits ([`ConfigurationsFile::joint_vectors_outside_limits`] lets them go past).
    pub fn joint_vectors(&self, robot: &RobotModel, origin: &Path) -> Result<Vec<Vec<f64>>> {
        self.vectors(robot, origin, true)
    }

    /// [`ConfigurationsFile::joint_vectors`] without the limit check (kinematics and collision
    /// are defined outside the limits too, e.g. for cross-checks with other libraries).
    pub fn joint_vectors_outside_limits(
        &self,
        robot: &RobotModel,
        origin: &Path,
    ) -> Result<Vec<Vec<f64>>> {
        self.vectors(robot, origin, false)
    }

    /// Parses configurations-file JSON; `origin` names it in errors.
    pub fn from_json(text: &str, origin: &Path) -> Result<Self> {
        crate::check_unique_keys(text)
            .and_then(|()| serde_json::from_str(text))
            .map_err(|e| {
                invalid(
                    origin,
                    "",
                    e.to_string(),
                    "expected {\"joint_names\": [...], \"samples\": [{\"q\": [...]}]}",
                )
            })
    }

    fn vectors(&self, robot: &RobotModel, origin: &Path, limits: bool) -> Result<Vec<Vec<f64>>> {
        let columns: Vec<usize> = self
            .joint_names
            .iter()
            .enumerate()
            .map(|(i, n)| {
                robot.joint_index(n).map_err(|e| {
                    invalid(
                        origin,
                        &format!("joint_names[{i}]"),
                        e.to_string(),
                        "use the URDF's joint names",
                    )
                })
            })
            .collect::<Result<_>>()?;
        for (i, &c) in columns.iter().enumerate() {
            if columns[..i].contains(&c) {
                return Err(invalid(
                    origin,
                    &format!("joint_names[{i}]"),
                    format!("`{}` is named twice", self.joint_names[i]),
                    "name every joint once",
                ));
            }
        }
        let given: Vec<bool> = (0..robot.num_joints())
            .map(|j| columns.contains(&j))
            .collect();
        let followers: Vec<(usize, usize, f64, f64)> = (0..robot.num_joints())
            .filter(|&j| !given[j])
            .filter_map(|j| robot.joint(j).mimic.as_ref().map(|m| (j, m)))
            .map(|(j, m)| Ok((j, robot.joint_index(&m.leader)?, m.multiplier, m.offset)))
            .collect::<Result<_>>()?;
        self.samples
            .iter()
            .enumerate()
            .map(|(s, sample)| {
                if sample.q.len() != columns.len() {
                    return Err(invalid(
                        origin,
                        &format!("samples[{s}].q"),
                        format!(
                            "has {} values for {} joint_names",
                            sample.q.len(),
                            columns.len()
                        ),
                        "give one value per joint name",
                    ));
                }
                if let Some(k) = sample.q.iter().position(|v| !v.is_finite()) {
                    return Err(invalid(
                        origin,
                        &format!("samples[{s}].q[{k}] ({})", self.joint_names[k]),
                        format!("is {}", sample.q[k]),
                        "give finite joint values",
                    ));
                }
                let mut joints = vec![0.0; robot.num_joints()];
                for (&j, &v) in columns.iter().zip(&sample.q) {
                    joints[j] = v;
                }
                for &(j, leader, multiplier, offset) in &followers {
                    joints[j] = multiplier * joints[leader] + offset;
                }
                if limits {
                    for (j, &v) in joints.iter().enumerate() {
                        robot.joint(j).limits.check(v).map_err(|problem| {
                            let name = &robot.joint(j).name;
                            let (field, problem) = match columns.iter().position(|&c| c == j) {
                                Some(k) => (format!("samples[{s}].q[{k}] ({name})"), problem),
                                None => (
                                    format!("samples[{s}]"),
                                    format!("`{name}` is not in joint_names and its value {problem}"),
                                ),
                            };
                            invalid(
                                origin,
                                &field,
                                problem,
                                "give joint values within the URDF's limits (name every joint whose limits exclude 0)",
                            )
                        })?;
                    }
                }
                Ok(joints)
            })
            .collect()
    }
}

const FIX: &str = "a posture file is JSON with \"motors\": {name: value} or \"q\": [active values]";

fn check_len(what: &'static str, expected: usize, got: usize) -> Result<()> {
    if expected == got {
        Ok(())
    } else {
        Err(KinematicsError::WrongLength {
            what,
            expected,
            got,
        })
    }
}

fn invalid(path: &Path, field: &str, problem: String, fix: &str) -> KinematicsError {
    KinematicsError::InvalidFile {
        path: PathBuf::from(path),
        field: field.to_string(),
        problem,
        fix: fix.to_string(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn arm() -> RobotModel {
        RobotModel::from_urdf_str(
            r#"<robot name="a"><link name="b"/><link name="c"/>
            <joint name="j" type="revolute"><parent link="b"/><child link="c"/><axis xyz="0 0 1"/>
            <limit lower="-1" upper="1" effort="1" velocity="1"/></joint></robot>"#,
            "<arm>",
        )
        .unwrap()
    }

    #[test]
    fn a_posture_file_round_trips_with_its_metadata() {
        let robot = arm();
        let file = PostureFile::from_motors(&robot, &[0.25])
            .unwrap()
            .with("cost", 1.5);
        let text = serde_json::to_string(&file).unwrap();
        let back = PostureFile::from_json(&text, Path::new("p.json")).unwrap();
        assert_eq!(back, file);
        assert_eq!(
            back.to_motors(&robot, None, &[0.0], Path::new("p.json"))
                .unwrap(),
            [0.25]
        );
    }

    #[test]
    fn unknown_motors_and_active_values_without_a_task_are_located_errors() {
        let robot = arm();
        let file =
            PostureFile::from_json(r#"{"motors": {"jj": 0.1}}"#, Path::new("p.json")).unwrap();
        let e = file
            .to_motors(&robot, None, &[0.0], Path::new("p.json"))
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("p.json: motors.jj") && e.contains("did you mean `j`"),
            "{e}"
        );
        let file = PostureFile::from_json(r#"{"q": [0.1]}"#, Path::new("p.json")).unwrap();
        let e = file
            .to_motors(&robot, None, &[0.0], Path::new("p.json"))
            .unwrap_err()
            .to_string();
        assert!(e.contains("p.json: q:"), "{e}");
        let with_task = file.to_motors(
            &robot,
            Some(&robot.all_active()),
            &[0.0],
            Path::new("p.json"),
        );
        assert_eq!(with_task.unwrap(), [0.1]);
    }

    #[test]
    fn malformed_posture_and_configuration_files_are_located_errors() {
        let robot = arm();
        let origin = Path::new("p.json");
        for (text, expected) in [
            ("", "p.json: EOF"),
            ("{\"motors\": {\"j\": ", "p.json: EOF"),
            ("{\"motors\": {\"j\": \"x\"}}", "p.json: invalid type"),
            ("[1, 2]", "p.json: invalid type"),
        ] {
            let e = PostureFile::from_json(text, origin)
                .unwrap_err()
                .to_string();
            assert!(e.starts_with(expected), "{text:?}: {e}");
        }
        let e = PostureFile::from_json("{\"cost\": 1}", origin)
            .unwrap()
            .to_motors(&robot, None, &[0.0], origin)
            .unwrap_err()
            .to_string();
        assert!(e.contains("neither \"motors\" nor \"q\""), "{e}");
        let e = PostureFile::from_json("{\"q\": [0.1, 0.2]}", origin)
            .unwrap()
            .to_motors(&robot, Some(&robot.all_active()), &[0.0], origin)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("p.json: q: has 2 values for 1 active motors"),
            "{e}"
        );
        let configs = |text: &str| {
            let c: ConfigurationsFile = serde_json::from_str(text).unwrap();
            c.joint_vectors(&robot, Path::new("c.json"))
                .unwrap_err()
                .to_string()
        };
        let e = configs("{\"joint_names\": [\"j\", \"j\"], \"samples\": []}");
        assert!(
            e.contains("c.json: joint_names[1]: `j` is named twice"),
            "{e}"
        );
        let e = configs("{\"joint_names\": [\"jj\"], \"samples\": []}");
        assert!(
            e.contains("joint_names[0]") && e.contains("did you mean `j`"),
            "{e}"
        );
        let e = configs("{\"joint_names\": [\"j\"], \"samples\": [{\"q\": [0.1, 0.2]}]}");
        assert!(
            e.contains("samples[0].q: has 2 values for 1 joint_names"),
            "{e}"
        );
        // JSON cannot carry inf or NaN: a number out of range is a parse error
        assert!(
            serde_json::from_str::<ConfigurationsFile>(
                "{\"joint_names\": [\"j\"], \"samples\": [{\"q\": [1e400]}]}"
            )
            .is_err()
        );
    }

    #[test]
    fn a_posture_is_not_written_over_a_directory() {
        let robot = arm();
        let dir = std::env::temp_dir().join(format!("trm-posture-dir-{}", std::process::id()));
        std::fs::create_dir_all(dir.join("taken")).unwrap();
        let file = PostureFile::from_motors(&robot, &[0.1]).unwrap();
        assert!(file.save(dir.join("taken")).is_err());
        assert!(dir.join("taken").is_dir());
        assert_eq!(
            std::fs::read_dir(&dir).unwrap().count(),
            1,
            "no temporary file left"
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn non_finite_values_are_not_written() {
        let robot = arm();
        let dir = std::env::temp_dir().join(format!("trm-posture-{}", std::process::id()));
        let file = PostureFile::from_motors(&robot, &[f64::NAN]).unwrap();
        assert!(file.save(dir.join("p.json")).is_err());
        assert!(!dir.join("p.json").exists());
    }
}
