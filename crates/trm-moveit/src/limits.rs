//! MoveIt's `joint_limits.yaml` (the file MoveIt's setup assistant writes in a robot's
//! `config/`): per-joint velocity, acceleration and jerk limits, each used when its
//! `has_*_limits` flag is true, and the default scaling factors.

use std::collections::BTreeMap;
use std::path::Path;

use trm_kinematics::MotionLimitSpec;

use crate::error::MoveItError;
use crate::reader::Reader;
use crate::yaml::Node;

/// What a `joint_limits.yaml` holds.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct JointLimitsFile {
    /// Limits by joint name (only those whose `has_*_limits` flag is true).
    pub limits: BTreeMap<String, MotionLimitSpec>,
    /// `default_velocity_scaling_factor` (absent or 0: none).
    pub velocity_scaling: Option<f64>,
    /// `default_acceleration_scaling_factor`.
    pub acceleration_scaling: Option<f64>,
}

impl JointLimitsFile {
    /// Reads the file at `path`.
    pub fn load(path: impl AsRef<Path>) -> Result<Self, MoveItError> {
        let path = path.as_ref();
        let text = std::fs::read_to_string(path).map_err(|e| MoveItError::Invalid {
            path: path.to_path_buf(),
            line: 0,
            problem: format!("cannot read it: {e}"),
            fix: "give the path of a joint_limits.yaml".into(),
        })?;
        Self::parse(&text, path)
    }

    /// Parses a `joint_limits.yaml`; `origin` names it in errors. Every limit given with its
    /// flag true must be a finite positive number; a flag must be `true` or `false`.
    pub fn parse(text: &str, origin: &Path) -> Result<Self, MoveItError> {
        let r = Reader { origin };
        let doc = r.parse(text)?;
        let mut out = JointLimitsFile {
            limits: Default::default(),
            velocity_scaling: r.factor(&doc, "default_velocity_scaling_factor")?,
            acceleration_scaling: r.factor(&doc, "default_acceleration_scaling_factor")?,
        };
        let joints = r.field(&doc, "joint_limits", "the file")?;
        let crate::yaml::Value::Map(entries) = &joints.value else {
            return Err(r.err(
                joints.line,
                format!("joint_limits is {}", joints.kind()),
                "give joint_limits as a mapping from joint names to their limits",
            ));
        };
        for (name, node) in entries {
            let mut spec = MotionLimitSpec::default();
            for (what, slot) in [
                ("velocity", &mut spec.velocity),
                ("acceleration", &mut spec.acceleration),
                ("jerk", &mut spec.jerk),
            ] {
                if !flag(&r, node, &format!("has_{what}_limits"), name)? {
                    continue;
                }
                let key = format!("max_{what}");
                let here = format!("joint_limits.{name}.{key}");
                let value = r.field(node, &key, &format!("joint_limits.{name}"))?;
                let v = r.number(value, &here)?;
                if v <= 0.0 {
                    return Err(r.err(
                        value.line,
                        format!("{here} is {v}"),
                        format!("give a positive limit, or set has_{what}_limits: false"),
                    ));
                }
                *slot = Some(v);
            }
            if spec != MotionLimitSpec::default() {
                out.limits.insert(name.clone(), spec);
            }
        }
        Ok(out)
    }
}

/// The boolean `key` of joint `joint`'s entry (false when absent).
fn flag(r: &Reader, node: &Node, key: &str, joint: &str) -> Result<bool, MoveItError> {
    match node.get(key) {
        None => Ok(false),
        Some(f) => match f.scalar().map(str::trim) {
            Some("true" | "True" | "TRUE") => Ok(true),
            Some("false" | "False" | "FALSE") => Ok(false),
            _ => Err(r.err(
                f.line,
                format!(
                    "joint_limits.{joint}.{key} is `{}`",
                    f.scalar().unwrap_or(f.kind())
                ),
                "give true or false",
            )),
        },
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const PANDA: &str = "default_velocity_scaling_factor: 0.5\njoint_limits:\n  panda_joint1:\n    has_velocity_limits: true\n    max_velocity: 2.175\n    has_acceleration_limits: true\n    max_acceleration: 3.75\n  panda_joint2:\n    has_velocity_limits: false\n    max_velocity: 9\n    has_acceleration_limits: true\n    max_acceleration: 1.875\n    has_jerk_limits: false\n  panda_finger_joint1:\n    has_velocity_limits: false\n    has_acceleration_limits: false\n    max_acceleration: 0\n";

    #[test]
    fn a_moveit_joint_limits_file_reads_its_flagged_limits() {
        let f = JointLimitsFile::parse(PANDA, Path::new("joint_limits.yaml")).unwrap();
        assert_eq!(f.velocity_scaling, Some(0.5));
        assert_eq!(f.acceleration_scaling, None);
        let j1 = f.limits["panda_joint1"];
        assert_eq!((j1.velocity, j1.acceleration), (Some(2.175), Some(3.75)));
        let j2 = f.limits["panda_joint2"];
        assert_eq!((j2.velocity, j2.acceleration), (None, Some(1.875)));
        assert!(!f.limits.contains_key("panda_finger_joint1"));
    }

    #[test]
    fn bad_limits_are_located() {
        for (text, needle) in [
            (
                "joint_limits:\n  j:\n    has_acceleration_limits: true\n",
                "max_acceleration",
            ),
            (
                "joint_limits:\n  j:\n    has_velocity_limits: yes please\n",
                "true or false",
            ),
            (
                "joint_limits:\n  j:\n    has_velocity_limits: true\n    max_velocity: -1\n",
                "is -1",
            ),
            (
                "default_acceleration_scaling_factor: 2\njoint_limits: {}\n",
                "(0, 1]",
            ),
            ("joint_limits: [1, 2]\n", "mapping"),
            ("limits: {}\n", "joint_limits"),
        ] {
            let e = JointLimitsFile::parse(text, Path::new("jl.yaml"))
                .unwrap_err()
                .to_string();
            assert!(e.contains("jl.yaml") && e.contains(needle), "{text}: {e}");
        }
    }

    #[test]
    fn a_request_s_scaling_factors_are_read_and_written() {
        let text = "start_state:\n  joint_state:\n    name: [a]\n    position: [0]\ngoal_constraints:\n  - joint_constraints:\n      - joint_name: a\n        position: 1\nmax_velocity_scaling_factor: 0.25\nmax_acceleration_scaling_factor: 0\n";
        let r = crate::MotionPlanRequest::parse(text, Path::new("r.yaml")).unwrap();
        assert_eq!(
            (r.velocity_scaling, r.acceleration_scaling),
            (Some(0.25), None)
        );
        let again =
            crate::MotionPlanRequest::parse(&r.to_yaml().unwrap(), Path::new("r.yaml")).unwrap();
        assert_eq!(again.velocity_scaling, Some(0.25));
        let bad = text.replace("0.25", "1.5");
        let e = crate::MotionPlanRequest::parse(&bad, Path::new("r.yaml"))
            .unwrap_err()
            .to_string();
        assert!(e.contains("max_velocity_scaling_factor is 1.5"), "{e}");
    }
}
