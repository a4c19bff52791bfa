//! Motions as ROS 2 messages: `trajectory_msgs/msg/JointTrajectory` in YAML, the form
//! `ros2 topic pub` and the message tools read.

use crate::RobotModel;
use crate::error::{KinematicsError, Result};

/// A ROS 2 `trajectory_msgs/msg/JointTrajectory` in YAML for a controller of `robot`, from motor
/// positions (one full motor vector per waypoint, at `times` seconds from the start) and,
/// optionally, motor velocities (zero at every waypoint without them: right for motions that
/// stop at each waypoint) and accelerations (an empty list without them). Joints: the URDF's movable joints without `<mimic>` (a controller
/// commands those), through the model's couplings; velocities through the same linear maps.
/// Floats are written without exponents, so YAML 1.1 readers (PyYAML, which ROS's tools use)
/// read them as floats, and exactly (shortest round-trip decimals).
pub fn joint_trajectory_yaml(
    robot: &RobotModel,
    times: &[f64],
    motors: &[Vec<f64>],
    velocities: Option<&[Vec<f64>]>,
    accelerations: Option<&[Vec<f64>]>,
) -> Result<String> {
    let wrong = |what: &'static str, got: usize| KinematicsError::WrongLength {
        what,
        expected: times.len(),
        got,
    };
    if motors.len() != times.len() {
        return Err(wrong("waypoints of motor positions", motors.len()));
    }
    if let Some(v) = velocities {
        if v.len() != times.len() {
            return Err(wrong("waypoints of motor velocities", v.len()));
        }
    }
    if let Some(a) = accelerations {
        if a.len() != times.len() {
            return Err(wrong("waypoints of motor accelerations", a.len()));
        }
    }
    if let Some((k, t)) = times
        .iter()
        .enumerate()
        .find(|(_, t)| !(t.is_finite() && **t >= 0.0))
    {
        return Err(KinematicsError::OutOfRange {
            what: format!("waypoint {k}'s time"),
            problem: format!("{t} s; give finite times from 0 up"),
        });
    }
    let commanded: Vec<usize> = (0..robot.num_joints())
        .filter(|&j| robot.joint(j).mimic.is_none())
        .collect();
    let quoted = |name: &str| format!("\"{}\"", name.replace('\\', "\\\\").replace('"', "\\\""));
    let list = |values: &mut dyn Iterator<Item = String>| {
        format!("[{}]", values.collect::<Vec<_>>().join(", "))
    };
    let mut out = String::from(
        "# trajectory_msgs/msg/JointTrajectory (ROS 2), written by trm\nheader:\n  stamp:\n    sec: 0\n    nanosec: 0\n  frame_id: \"\"\n",
    );
    out.push_str(&format!(
        "joint_names: {}\npoints:\n",
        list(&mut commanded.iter().map(|&j| quoted(&robot.joint(j).name)))
    ));
    let n = robot.num_joints();
    let (mut joints, mut rates, mut zero) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    let mut accels = vec![0.0; n];
    robot.motors_to_joints(&vec![0.0; robot.motors().len()], &mut zero)?;
    for (k, (time, q)) in times.iter().zip(motors).enumerate() {
        robot.motors_to_joints(q, &mut joints)?;
        if let Some(v) = velocities {
            // the couplings are affine: their linear part maps velocities
            robot.motors_to_joints(&v[k], &mut rates)?;
            for (r, z) in rates.iter_mut().zip(&zero) {
                *r -= z;
            }
        }
        if let Some(a) = accelerations {
            robot.motors_to_joints(&a[k], &mut accels)?;
            for (r, z) in accels.iter_mut().zip(&zero) {
                *r -= z;
            }
        }
        if let Some(j) = (0..n)
            .find(|&j| !(joints[j].is_finite() && rates[j].is_finite() && accels[j].is_finite()))
        {
            return Err(KinematicsError::NonFinite {
                what: "joint positions and velocities of a waypoint",
                index: j,
                name: format!("{} at waypoint {k}", robot.joint(j).name),
                value: if !joints[j].is_finite() {
                    joints[j]
                } else if !rates[j].is_finite() {
                    rates[j]
                } else {
                    accels[j]
                },
            });
        }
        // nanoseconds, rounded once, so that sec and nanosec never disagree
        let total = (time * 1e9).round() as u64;
        out.push_str(&format!(
            "  - positions: {}\n    velocities: {}\n    accelerations: {}\n    effort: []\n    time_from_start:\n      sec: {}\n      nanosec: {}\n",
            list(&mut commanded.iter().map(|&j| yaml_float(joints[j]))),
            list(&mut commanded.iter().map(|&j| yaml_float(rates[j]))),
            if accelerations.is_some() {
                list(&mut commanded.iter().map(|&j| yaml_float(accels[j])))
            } else {
                "[]".to_string()
            },
            total / 1_000_000_000,
            total % 1_000_000_000
        ));
    }
    Ok(out)
}

/// A float as YAML 1.1 reads it: plain decimal digits with a point, no exponent (Rust's
/// `Display` of f64 never writes one and round-trips exactly).
pub fn yaml_float(v: f64) -> String {
    let text = format!("{v}");
    if text.contains('.') {
        text
    } else {
        text + ".0"
    }
}

/// Every named posture of `robot` as a one-point `trajectory_msgs/msg/JointTrajectory` (the
/// posture reached `seconds` after the start, at rest), one YAML document per posture, each
/// headed by a comment naming it: what a controller needs to go to "home".
pub fn named_postures_yaml(robot: &RobotModel, seconds: f64) -> Result<String> {
    if !(seconds.is_finite() && seconds > 0.0) {
        return Err(KinematicsError::OutOfRange {
            what: "posture time".into(),
            problem: format!("{seconds} s: give a positive time to reach each posture"),
        });
    }
    if robot.posture_names().next().is_none() {
        return Err(KinematicsError::OutOfRange {
            what: "named postures".into(),
            problem: format!(
                "model `{}` has none; name postures in its description (`postures`)",
                robot.name()
            ),
        });
    }
    let mut text = String::new();
    for name in robot.posture_names() {
        let q = robot.posture(name)?.to_vec();
        text.push_str(&format!("---\n# posture `{name}` of `{}`\n", robot.name()));
        text.push_str(&joint_trajectory_yaml(robot, &[seconds], &[q], None, None)?);
    }
    Ok(text)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn icub() -> RobotModel {
        RobotModel::load(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../models/icub_upper_body.ron"
        ))
        .unwrap()
    }

    /// Numbers of the `key: [..]` lists of the `k`-th point.
    fn list(text: &str, key: &str, k: usize) -> Vec<f64> {
        let line = text
            .lines()
            .filter(|l| l.trim_start().trim_start_matches("- ").starts_with(key))
            .nth(k)
            .unwrap();
        let inner = line.split('[').nth(1).unwrap().trim_end_matches(']');
        inner.split(", ").map(|v| v.parse().unwrap()).collect()
    }

    #[test]
    fn named_postures_are_one_point_trajectories() {
        let robot = icub();
        let text = named_postures_yaml(&robot, 2.5).unwrap();
        let names: Vec<&str> = robot.posture_names().collect();
        assert!(!names.is_empty());
        assert_eq!(text.matches("---\n").count(), names.len());
        for (k, name) in names.iter().enumerate() {
            assert!(text.contains(&format!("# posture `{name}`")));
            let single = joint_trajectory_yaml(
                &robot,
                &[2.5],
                &[robot.posture(name).unwrap().to_vec()],
                None,
                None,
            )
            .unwrap();
            assert_eq!(list(&text, "positions", k), list(&single, "positions", 0));
        }
        assert!(text.contains("sec: 2") && text.contains("nanosec: 500000000"));
        for bad in [0.0, -1.0, f64::NAN] {
            assert!(named_postures_yaml(&robot, bad).is_err());
        }
    }

    #[test]
    fn velocities_map_through_the_couplings_like_positions() {
        let robot = icub();
        let n = robot.motors().len();
        let q0 = robot.neutral_motors();
        let v: Vec<f64> = (0..n).map(|i| 0.01 * (i as f64 + 1.0)).collect();
        let dt = 1e-3;
        let q1: Vec<f64> = q0.iter().zip(&v).map(|(q, v)| q + v * dt).collect();
        let text = joint_trajectory_yaml(
            &robot,
            &[0.0, dt],
            &[q0.clone(), q1],
            Some(&[v.clone(), v.clone()]),
            None,
        )
        .unwrap();
        let (p0, p1, rate) = (
            list(&text, "positions", 0),
            list(&text, "positions", 1),
            list(&text, "velocities", 0),
        );
        assert_eq!(rate.len(), p0.len());
        for j in 0..rate.len() {
            let fd = (p1[j] - p0[j]) / dt;
            assert!(
                (fd - rate[j]).abs() < 1e-9,
                "joint {j}: {fd} vs {}",
                rate[j]
            );
        }
        assert!(rate.iter().any(|r| *r != 0.0));
        assert!(text.contains("nanosec: 1000000"), "{text}");
        // without velocities: zeros; tiny values without exponents (YAML 1.1 floats)
        let mut tiny = q0.clone();
        tiny[0] = 1e-7;
        let still = joint_trajectory_yaml(&robot, &[0.0], &[tiny], None, None).unwrap();
        assert!(list(&still, "velocities", 0).iter().all(|r| *r == 0.0));
        for line in still
            .lines()
            .filter(|l| l.contains("positions") || l.contains("velocities"))
        {
            assert!(!line.split('[').nth(1).unwrap().contains('e'), "{line}");
        }
        assert!(list(&still, "positions", 0).contains(&1e-7));
    }

    #[test]
    fn bad_input_is_refused() {
        let robot = icub();
        let q = robot.neutral_motors();
        let e = joint_trajectory_yaml(&robot, &[0.0, 1.0], std::slice::from_ref(&q), None, None)
            .unwrap_err();
        assert!(e.to_string().contains("expected 2 values, got 1"), "{e}");
        let e = joint_trajectory_yaml(&robot, &[-1.0], std::slice::from_ref(&q), None, None)
            .unwrap_err();
        assert!(e.to_string().contains("from 0 up"), "{e}");
        let mut nan = q.clone();
        nan[5] = f64::NAN;
        let e = joint_trajectory_yaml(&robot, &[0.0], &[nan], None, None).unwrap_err();
        assert!(e.to_string().contains("finite"), "{e}");
        let e = joint_trajectory_yaml(&robot, &[0.0], &[q[1..].to_vec()], None, None).unwrap_err();
        assert!(e.to_string().contains("motor values"), "{e}");
    }
}
