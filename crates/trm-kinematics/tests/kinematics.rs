//! Forward kinematics against hand-computed poses, invariants (property tests), couplings,
//! active sets and named frames.

use std::f64::consts::{FRAC_PI_2, PI};
use std::path::Path;

use nalgebra::{Isometry3, Vector3};
use proptest::prelude::*;
use trm_kinematics::{KinematicsError, ModelDescription, RobotModel};

fn models() -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../models")
}

fn planar() -> RobotModel {
    RobotModel::load(models().join("planar_arm.urdf")).unwrap()
}

fn branched() -> RobotModel {
    RobotModel::load(models().join("branched_tree.urdf")).unwrap()
}

fn icub() -> RobotModel {
    RobotModel::load(models().join("icub_upper_body.ron")).unwrap()
}

fn position(model: &RobotModel, q: &[f64], frame: &str) -> Vector3<f64> {
    let mut buffer = model.pose_buffer();
    model.forward_joints(q, &mut buffer).unwrap();
    buffer
        .pose(model.frame_id(frame).unwrap())
        .translation
        .vector
}

#[test]
fn planar_arm_tool_position_matches_hand_computation() {
    let model = planar();
    let cases = [
        [0.0, 0.0, 0.0],
        [FRAC_PI_2, 0.0, 0.0],
        [0.3, -0.7, 1.1],
        [-2.0, 2.2, -1.4],
    ];
    for q in cases {
        let (a, b, c) = (q[0], q[0] + q[1], q[0] + q[1] + q[2]);
        let expected = Vector3::new(
            a.cos() + 0.8 * b.cos() + 0.5 * c.cos(),
            a.sin() + 0.8 * b.sin() + 0.5 * c.sin(),
            0.1,
        );
        let got = position(&model, &q, "tool");
        assert!(
            (got - expected).norm() < 1e-12,
            "q {q:?}: {got} vs {expected}"
        );
        let mut buffer = model.pose_buffer();
        model.forward_joints(&q, &mut buffer).unwrap();
        let yaw = buffer
            .pose(model.frame_id("tool").unwrap())
            .rotation
            .euler_angles()
            .2;
        assert!(((yaw - c + PI).rem_euclid(2.0 * PI) - PI).abs() < 1e-12);
    }
}

#[test]
fn prismatic_joint_translates_along_its_axis() {
    let model = branched();
    let extend = model.joint_index("left_extend").unwrap();
    let mut q = vec![0.0; model.num_joints()];
    let base = position(&model, &q, "left_slider");
    q[extend] = 0.2;
    let moved = position(&model, &q, "left_slider");
    // The axis is x of left_upper, whose world orientation does not depend on left_extend.
    let mut buffer = model.pose_buffer();
    model.forward_joints(&q, &mut buffer).unwrap();
    let axis = buffer.pose(model.frame_id("left_upper").unwrap()).rotation * Vector3::x();
    assert!((moved - base - axis * 0.2).norm() < 1e-12);
}

#[test]
fn continuous_joint_turns_the_whole_tree_about_z() {
    let model = branched();
    let waist = model.joint_index("waist_yaw").unwrap();
    let mut q = vec![0.1; model.num_joints()];
    q[model.joint_index("left_extend").unwrap()] = 0.1;
    let before = position(&model, &q, "right_finger_a");
    q[waist] += 5.0; // beyond ±π: continuous
    let after = position(&model, &q, "right_finger_a");
    let turn = nalgebra::Rotation3::from_axis_angle(&Vector3::z_axis(), 5.0);
    assert!((after - turn * before).norm() < 1e-12);
}

#[test]
fn zero_configuration_reproduces_the_urdf_origins() {
    for model in [planar(), branched(), icub()] {
        let mut buffer = model.pose_buffer();
        model
            .forward_joints(&vec![0.0; model.num_joints()], &mut buffer)
            .unwrap();
        let tree = model.tree();
        for joint in &tree.joints {
            let expected = buffer.poses()[joint.parent] * joint.local_origin;
            let got = buffer.poses()[joint.child];
            assert!(
                (got.translation.vector - expected.translation.vector).norm() < 1e-12,
                "{}",
                joint.name
            );
            assert!(
                got.rotation.angle_to(&expected.rotation) < 1e-9,
                "{}",
                joint.name
            );
        }
    }
}

#[test]
fn mimic_joint_follows_its_leader_in_motor_space() {
    let model = branched();
    // Motors: every independent joint; finger_b mimics finger_a (-1 · a + 0.05).
    assert_eq!(model.motors().len(), model.num_joints() - 1);
    let a = model.motor_index("finger_a").unwrap();
    assert!(model.motor_index("finger_b").is_err());
    let mut motors = model.neutral_motors();
    motors[a] = 0.4;
    let mut joints = vec![0.0; model.num_joints()];
    model.motors_to_joints(&motors, &mut joints).unwrap();
    assert!((joints[model.joint_index("finger_b").unwrap()] - (-0.4 + 0.05)).abs() < 1e-15);
    // FK from motors equals FK from the coupled joint values.
    let (mut b1, mut b2) = (model.pose_buffer(), model.pose_buffer());
    model.forward_motors(&motors, &mut b1).unwrap();
    model.forward_joints(&joints, &mut b2).unwrap();
    for (p, q) in b1.poses().iter().zip(b2.poses()) {
        assert!((p.translation.vector - q.translation.vector).norm() < 1e-14);
    }
}

#[test]
fn icub_has_41_motors_driving_63_joints_through_the_hand_and_eye_couplings() {
    let model = icub();
    assert_eq!(model.motors().len(), 41);
    assert_eq!(model.num_joints(), 63);
    assert_eq!(model.group("upper_body").unwrap().len(), 41);
    for (group, n) in [
        ("torso", 3),
        ("left_arm", 7),
        ("right_arm", 7),
        ("left_hand", 9),
        ("right_hand", 9),
        ("neck", 3),
        ("eyes", 3),
    ] {
        assert_eq!(model.group(group).unwrap().len(), n, "{group}");
    }
    let mut motors = model.neutral_motors();
    let set = |motors: &mut Vec<f64>, name: &str, deg: f64| {
        motors[model.motor_index(name).unwrap()] = deg.to_radians()
    };
    set(&mut motors, "r_hand_finger", 60.0);
    set(&mut motors, "r_thumb_distal", 100.0);
    set(&mut motors, "r_pinky", 270.0);
    set(&mut motors, "eyes_version", 10.0);
    set(&mut motors, "eyes_vergence", 20.0);
    let mut joints = vec![0.0; model.num_joints()];
    model.motors_to_joints(&motors, &mut joints).unwrap();
    let joint_deg = |name: &str| joints[model.joint_index(name).unwrap()].to_degrees();
    let close = |a: f64, b: f64| (a - b).abs() < 1e-9;
    assert!(close(joint_deg("r_hand_index_0_joint"), 0.0)); // 60/3 - 20
    assert!(close(joint_deg("r_hand_ring_0_joint"), 0.0)); // -60/3 + 20
    assert!(close(joint_deg("r_hand_thumb_2_joint"), 50.0));
    assert!(close(joint_deg("r_hand_thumb_3_joint"), 50.0));
    for j in ["ring", "little"] {
        for k in 1..=3 {
            assert!(close(joint_deg(&format!("r_hand_{j}_{k}_joint")), 90.0));
        }
    }
    assert!(close(joint_deg("r_hand_middle_0_joint"), 0.0));
    assert!(close(joint_deg("l_eye_pan_joint"), 20.0)); // version + vergence/2
    assert!(close(joint_deg("r_eye_pan_joint"), 0.0)); // version - vergence/2
    // Left hand untouched: hand_finger 0 spreads the fingers by ±20°.
    assert!(close(joint_deg("l_hand_index_0_joint"), -20.0));
    assert!(close(joint_deg("l_hand_little_0_joint"), 20.0));
}

#[test]
fn icub_motor_limits_keep_every_coupled_joint_within_its_urdf_limits() {
    let model = icub();
    let (lower, upper) = model.all_active().bounds();
    let mut joints = vec![0.0; model.num_joints()];
    // All corners of the box are too many; the couplings are separable, so the extremes of
    // each joint are reached at per-motor extremes: check lower, upper and both mixes.
    for corner in 0..4 {
        let motors: Vec<f64> = (0..lower.len())
            .map(|i| {
                if (corner >> (i % 2)) & 1 == 1 {
                    upper[i]
                } else {
                    lower[i]
                }
            })
            .collect();
        model.motors_to_joints(&motors, &mut joints).unwrap();
        for (j, v) in joints.iter().enumerate() {
            let l = model.joint(j).limits;
            assert!(
                *v >= l.lower - 1e-9 && *v <= l.upper + 1e-9,
                "{} = {v}",
                model.joint(j).name
            );
        }
    }
}

#[test]
fn locked_motors_stay_at_their_locked_values() {
    let model = icub();
    let home = model.posture("home").unwrap().to_vec();
    let arm = model.active_set(&["right_arm"], &home).unwrap();
    assert_eq!(arm.len(), 7);
    assert_eq!(arm.names().next(), Some("r_shoulder_pitch"));
    // Only the right arm's joints are computed per pass; the rest are folded into constants.
    assert_eq!(arm.num_distinct_joint_values(), 7);
    let q: Vec<f64> = arm.from_motors(&home).iter().map(|v| v + 0.1).collect();
    let (mut b1, mut b2) = (model.pose_buffer(), model.pose_buffer());
    arm.forward(&q, &mut b1).unwrap();
    model.forward_motors(&arm.to_motors(&q), &mut b2).unwrap();
    for (p, r) in b1.poses().iter().zip(b2.poses()) {
        assert!((p.translation.vector - r.translation.vector).norm() < 1e-14);
        assert!(p.rotation.angle_to(&r.rotation) < 1e-7);
    }
    let left_hand = model.frame_id("l_palm_center").unwrap();
    let mut b3 = model.pose_buffer();
    model.forward_motors(&home, &mut b3).unwrap();
    assert!(
        (b1.pose(left_hand).translation.vector - b3.pose(left_hand).translation.vector).norm()
            < 1e-14
    );
}

#[test]
fn all_motors_active_shares_one_angle_among_coupled_phalanges() {
    let model = icub();
    let all = model.all_active();
    // 63 joints; per hand thumb 2/3, index 2/3, middle 2/3 share, ring/little 1-3 share one
    // value and ring_0/little_0 another, middle_0 is constant.
    assert_eq!(
        all.num_distinct_joint_values(),
        63 - 2 * (1 + 1 + 1 + 5 + 1 + 1)
    );
}

/// A link's rigid ancestor and offset ([`trm_kinematics::Tree::rigid_ancestor`]) give its pose
/// in every configuration: the Panda's hand and fingers (fixed joints, VAMP's sphere model) hang
/// from `panda_link7` through `panda_link8`; a moving link is its own.
#[test]
fn a_link_rides_its_rigid_ancestor_at_a_fixed_offset() {
    let model = RobotModel::load(models().join("panda-mbm/panda_spherized.ron")).unwrap();
    let tree = model.tree();
    let link = |name: &str| tree.link_index(name).unwrap();
    let (hand, seven) = (link("panda_hand"), link("panda_link7"));
    assert_eq!(tree.rigid_ancestor(hand).0, seven);
    let (ancestor, offset) = tree.rigid_ancestor(seven);
    assert_eq!(ancestor, seven);
    assert!(offset.translation.vector.norm() == 0.0 && offset.rotation.angle() == 0.0);
    assert_eq!(tree.rigid_ancestor(0).0, 0);
    let mut buffer = model.pose_buffer();
    let active = model.all_active();
    let (lower, upper) = active.bounds();
    let mut moved = 0;
    for k in 0..20 {
        // spread over the limits, a different fraction per motor
        let q: Vec<f64> = (lower.iter().zip(&upper).enumerate())
            .map(|(m, (l, u))| l + (u - l) * ((k * 7 + m * 3) % 20) as f64 / 19.0)
            .collect();
        model
            .forward_motors(&active.to_motors(&q), &mut buffer)
            .unwrap();
        for l in 0..tree.links.len() {
            let (a, offset) = tree.rigid_ancestor(l);
            moved += usize::from(a != l);
            let expected = buffer.poses()[a] * offset;
            let got = buffer.poses()[l];
            assert!(
                (got.translation.vector - expected.translation.vector).norm() < 1e-12
                    && got.rotation.angle_to(&expected.rotation) < 1e-12,
                "{}",
                tree.links[l].name
            );
        }
    }
    assert!(moved > 0);
}

#[test]
fn named_frames_are_their_link_pose_times_the_offset() {
    let model = icub();
    let mut buffer = model.pose_buffer();
    model
        .forward_motors(model.posture("home").unwrap(), &mut buffer)
        .unwrap();
    assert!(!model.named_frames().is_empty());
    for frame in model.named_frames() {
        let expected = buffer.poses()[frame.link] * frame.local_offset;
        let got = buffer.pose(model.frame_id(&frame.name).unwrap());
        assert!(
            (got.translation.vector - expected.translation.vector).norm() < 1e-14,
            "{}",
            frame.name
        );
    }
    // The palm centre lies between the wrist and the finger bases, a few cm from each.
    let palm = buffer
        .pose(model.frame_id("r_palm_center").unwrap())
        .translation
        .vector;
    let wrist = buffer
        .pose(model.frame_id("r_hand").unwrap())
        .translation
        .vector;
    let index_base = buffer
        .pose(model.frame_id("r_hand_index_0").unwrap())
        .translation
        .vector;
    assert!((palm - wrist).norm() > 0.02 && (palm - wrist).norm() < 0.05);
    assert!(
        (palm - index_base).norm() < 0.05,
        "palm to index base {}",
        (palm - index_base).norm()
    );
}

#[test]
fn icub_home_posture_is_natural() {
    let model = icub();
    let mut buffer = model.pose_buffer();
    model
        .forward_motors(model.posture("home").unwrap(), &mut buffer)
        .unwrap();
    let p = |f: &str| buffer.pose(model.frame_id(f).unwrap()).translation.vector;
    let (left, right, head) = (p("l_palm_center"), p("r_palm_center"), p("head"));
    // Symmetric about the sagittal plane (y is lateral in the iCub root frame), hands below the head.
    assert!(
        (left.x - right.x).abs() < 2e-3
            && (left.z - right.z).abs() < 2e-3
            && (left.y + right.y).abs() < 2e-3
    );
    assert!(left.z < head.z && right.z < head.z);
    // The gaze frame looks forward (−x in the iCub root frame), level.
    let gaze = buffer.pose(model.frame_id("gaze").unwrap()).rotation * Vector3::z();
    assert!(gaze.x < -0.99, "gaze {gaze}");
}

#[test]
fn unknown_names_suggest_the_closest_ones() {
    let model = icub();
    let err = model.frame_id("r_plam_center").unwrap_err();
    let text = err.to_string();
    assert!(
        text.contains("unknown link or frame `r_plam_center`") && text.contains("r_palm_center"),
        "{text}"
    );
    let err = model
        .active_set(&["rigth_arm"], &model.neutral_motors())
        .unwrap_err();
    assert!(
        matches!(&err, KinematicsError::UnknownName { suggestions, .. } if suggestions.contains(&"right_arm".to_string())),
        "{err}"
    );
    assert!(
        model
            .motor_index("r_elbw")
            .unwrap_err()
            .to_string()
            .contains("r_elbow")
    );
    assert!(
        model
            .joint_index("r_hand_index_1")
            .unwrap_err()
            .to_string()
            .contains("r_hand_index_1_joint")
    );
}

#[test]
fn wrong_lengths_and_non_finite_values_are_errors() {
    let model = icub();
    let all = model.all_active();
    let mut buffer = model.pose_buffer();
    assert!(matches!(
        all.forward(&[0.0; 40], &mut buffer),
        Err(KinematicsError::WrongLength {
            expected: 41,
            got: 40,
            ..
        })
    ));
    let mut q = vec![0.0; 41];
    q[6] = f64::NAN;
    let err = all.forward(&q, &mut buffer).unwrap_err();
    assert!(
        err.to_string().contains("r_elbow") || err.to_string().contains("entry 6"),
        "{err}"
    );
    let mut wrong = planar().pose_buffer();
    assert!(all.forward(&[0.0; 41], &mut wrong).is_err());
}

#[test]
fn descriptions_built_in_code_work_like_files() {
    let urdf = std::fs::read_to_string(models().join("planar_arm.urdf")).unwrap();
    let description: ModelDescription = ModelDescription::from_ron(
        r#"(urdf: "planar_arm.urdf",
            motors: [(name: "curl", lower: -1.0, upper: 1.0)],
            couplings: [(joint: "joint2", motors: [("curl", 1.0)]), (joint: "joint3", motors: [("curl", 0.5)], offset: 0.25)],
            frames: [(name: "tip", link: "tool", xyz: (0.1, 0.0, 0.0)), (name: "tip2", link: "tip", xyz: (0.1, 0.0, 0.0))],
            postures: [(name: "bent", values: {"curl": 0.5})])"#,
        "<test>",
    )
    .unwrap();
    let model = RobotModel::from_parts(&urdf, "planar_arm.urdf", &description, None).unwrap();
    let names: Vec<&str> = model.motors().iter().map(|m| m.name.as_str()).collect();
    assert_eq!(names, ["joint1", "curl"]);
    let mut buffer = model.pose_buffer();
    model.forward_motors(&[0.0, 0.4], &mut buffer).unwrap();
    let (b, c): (f64, f64) = (0.4, 0.4 + 0.45);
    let tip = buffer
        .pose(model.frame_id("tip2").unwrap())
        .translation
        .vector;
    let expected = Vector3::new(
        1.0 + 0.8 * b.cos() + 0.7 * c.cos(),
        0.8 * b.sin() + 0.7 * c.sin(),
        0.1,
    );
    assert!((tip - expected).norm() < 1e-12, "{tip} vs {expected}");
    assert_eq!(model.posture("bent").unwrap(), &[0.0, 0.5]);
}

fn random_in_limits(model: &RobotModel, unit: &[f64]) -> Vec<f64> {
    (0..model.num_joints())
        .map(|j| {
            let l = model.joint(j).limits;
            let (lo, hi) = if l.lower.is_finite() {
                (l.lower, l.upper)
            } else {
                (-7.0, 7.0)
            };
            lo + (hi - lo) * unit[j % unit.len()]
        })
        .collect()
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    #[test]
    fn rotations_stay_orthonormal(unit in proptest::collection::vec(0.0f64..1.0, 63)) {
        for model in [icub(), branched()] {
            let q = random_in_limits(&model, &unit);
            let mut buffer = model.pose_buffer();
            model.forward_joints(&q, &mut buffer).unwrap();
            for pose in buffer.poses() {
                let r = pose.rotation.to_rotation_matrix().into_inner();
                prop_assert!((r.transpose() * r - nalgebra::Matrix3::identity()).norm() < 1e-12);
                prop_assert!((r.determinant() - 1.0).abs() < 1e-12);
                prop_assert!((pose.rotation.quaternion().norm() - 1.0).abs() < 1e-12);
            }
        }
    }

    #[test]
    fn fixed_joints_keep_their_urdf_offset(unit in proptest::collection::vec(0.0f64..1.0, 63)) {
        let model = icub();
        let q = random_in_limits(&model, &unit);
        let mut buffer = model.pose_buffer();
        model.forward_joints(&q, &mut buffer).unwrap();
        for joint in model.tree().joints.iter().filter(|j| !j.kind.is_movable()) {
            let relative: Isometry3<f64> = buffer.poses()[joint.parent].inverse() * buffer.poses()[joint.child];
            prop_assert!((relative.translation.vector - joint.local_origin.translation.vector).norm() < 1e-12);
            prop_assert!(relative.rotation.angle_to(&joint.local_origin.rotation) < 1e-7);
        }
    }

    #[test]
    fn links_rotate_about_their_joint_axis_by_the_joint_angle(unit in proptest::collection::vec(0.0f64..1.0, 63)) {
        let model = icub();
        let q = random_in_limits(&model, &unit);
        let mut buffer = model.pose_buffer();
        model.forward_joints(&q, &mut buffer).unwrap();
        for (j, &value) in q.iter().enumerate() {
            let joint = model.joint(j);
            let frame = buffer.poses()[joint.parent] * joint.local_origin;
            let relative = frame.inverse() * buffer.poses()[joint.child];
            prop_assert!(relative.translation.vector.norm() < 1e-12);
            let expected = nalgebra::UnitQuaternion::from_axis_angle(&joint.axis, value);
            prop_assert!(relative.rotation.angle_to(&expected) < 1e-7, "{}", joint.name);
        }
    }
}

#[test]
fn official_full_body_icub_arm_moves_with_the_legs_locked() {
    let model = RobotModel::load(models().join("icub-visuomanip/model.urdf")).unwrap();
    let mut locked = model.neutral_motors();
    locked[model.motor_index("l_knee").unwrap()] = -1.0;
    let arm = model
        .active_set(&["r_shoulder_pitch", "r_shoulder_roll", "r_elbow"], &locked)
        .unwrap();
    let mut buffer = model.pose_buffer();
    arm.forward(&[-0.5, 0.4, 1.0], &mut buffer).unwrap();
    let motors = arm.to_motors(&[-0.5, 0.4, 1.0]);
    assert_eq!(motors[model.motor_index("l_knee").unwrap()], -1.0);
    let mut reference = model.pose_buffer();
    model.forward_motors(&motors, &mut reference).unwrap();
    for name in ["r_hand", "l_foot", "head"] {
        let id = model.frame_id(name).unwrap();
        assert!(
            (buffer.pose(id).translation.vector - reference.pose(id).translation.vector).norm()
                < 1e-14,
            "{name}"
        );
    }
    assert_eq!(arm.num_distinct_joint_values(), 3);
}
