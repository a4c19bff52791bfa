//! Jacobians, centre of mass and gravity torques against Pinocchio (fixtures from
//! tests/fixtures/pinocchio_derivatives.py) and against finite differences on the coupled iCub.

use nalgebra::{Matrix3xX, Matrix6xX, Point3};
use serde_json::Value;
use trm_kinematics::{GRAVITY, RobotModel};

fn fixture(name: &str) -> Value {
    let path = format!("{}/tests/fixtures/{name}", env!("CARGO_MANIFEST_DIR"));
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

fn rows(v: &Value) -> Vec<Vec<f64>> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|r| {
            r.as_array()
                .unwrap()
                .iter()
                .map(|x| x.as_f64().unwrap())
                .collect()
        })
        .collect()
}

/// Compares trm's motor-space derivatives with Pinocchio's joint-space ones mapped through the
/// couplings (C: joints × motors), at poses computed from the fixture's joint values.
fn compare(file: &str) {
    let doc = fixture(file);
    let root = format!("{}/../..", env!("CARGO_MANIFEST_DIR"));
    let model =
        RobotModel::from_urdf_file(format!("{root}/{}", doc["urdf"].as_str().unwrap())).unwrap();
    let active = model.all_active();
    let names: Vec<&str> = doc["joint_names"]
        .as_array()
        .unwrap()
        .iter()
        .map(|n| n.as_str().unwrap())
        .collect();
    let coordinate: Vec<usize> = names
        .iter()
        .map(|n| model.joint_index(n).unwrap())
        .collect();
    let motors = model.motors().len();
    // C[j][m]: ∂joint/∂motor, joint in fixture order
    let mut c = vec![vec![0.0; motors]; names.len()];
    for (col, &j) in coordinate.iter().enumerate() {
        for &(m, f) in &model.couplings()[j].terms {
            c[col][m] += f;
        }
    }
    let map = |pin_rows: &[Vec<f64>]| -> Vec<Vec<f64>> {
        pin_rows
            .iter()
            .map(|row| {
                (0..motors)
                    .map(|m| (0..names.len()).map(|j| row[j] * c[j][m]).sum())
                    .collect()
            })
            .collect()
    };
    let mut poses = model.pose_buffer();
    let mut worst = 0.0f64;
    let mut worst_by = [0.0f64; 4];
    let mut jac = Matrix6xX::zeros(0);
    let mut jcom = Matrix3xX::zeros(0);
    let mut g = vec![0.0; motors];
    for sample in doc["samples"].as_array().unwrap() {
        let q: Vec<f64> = sample["q"]
            .as_array()
            .unwrap()
            .iter()
            .map(|x| x.as_f64().unwrap())
            .collect();
        let mut joints = vec![0.0; model.num_joints()];
        for (col, &j) in coordinate.iter().enumerate() {
            joints[j] = q[col];
        }
        model.forward_joints(&joints, &mut poses).unwrap();
        for (frame, expected) in sample["jacobians"].as_object().unwrap() {
            active.jacobian(&poses, model.frame_id(frame).unwrap(), &mut jac);
            let want = map(&rows(expected));
            for r in 0..6 {
                for m in 0..motors {
                    worst = worst.max((jac[(r, m)] - want[r][m]).abs());
                    worst_by[0] = worst_by[0].max((jac[(r, m)] - want[r][m]).abs());
                }
            }
        }
        let (mass, com) = active.center_of_mass(&poses);
        assert!((mass - doc["mass"].as_f64().unwrap()).abs() < 1e-9);
        let want_com: Vec<f64> = sample["com"]
            .as_array()
            .unwrap()
            .iter()
            .map(|x| x.as_f64().unwrap())
            .collect();
        for i in 0..3 {
            worst = worst.max((com[i] - want_com[i]).abs());
            worst_by[1] = worst_by[1].max((com[i] - want_com[i]).abs());
        }
        active.com_jacobian(&poses, &mut jcom);
        let want = map(&rows(&sample["com_jacobian"]));
        for r in 0..3 {
            for m in 0..motors {
                worst = worst.max((jcom[(r, m)] - want[r][m]).abs());
                worst_by[2] = worst_by[2].max((jcom[(r, m)] - want[r][m]).abs());
            }
        }
        active.gravity_torques(&poses, &GRAVITY, &mut g);
        let pin_g: Vec<f64> = sample["gravity"]
            .as_array()
            .unwrap()
            .iter()
            .map(|x| x.as_f64().unwrap())
            .collect();
        for m in 0..motors {
            let want: f64 = (0..names.len()).map(|j| c[j][m] * pin_g[j]).sum();
            worst = worst.max((g[m] - want).abs() / want.abs().max(1.0));
            worst_by[3] = worst_by[3].max((g[m] - want).abs() / want.abs().max(1.0));
        }
    }
    assert!(
        worst < 1e-9,
        "{file}: worst difference {worst:e} (jacobian, com, com jacobian, gravity: {worst_by:?})"
    );
}

#[test]
fn derivatives_match_pinocchio_on_the_official_icub() {
    compare("icub_visuomanip.derivatives.json");
}

#[test]
fn derivatives_match_pinocchio_on_the_upper_body_urdf() {
    compare("icub_upper_body.derivatives.json");
}

#[test]
fn derivatives_match_pinocchio_with_prismatic_continuous_and_mimic_joints() {
    compare("branched_tree.derivatives.json");
}

/// A configuration spread inside the limits (30–70 % of each range, unbounded ranges cut to
/// ±3), the same for every run.
fn interior(active: &trm_kinematics::ActiveSet) -> Vec<f64> {
    let (lower, upper) = active.bounds();
    lower
        .iter()
        .zip(&upper)
        .enumerate()
        .map(|(i, (l, u))| {
            let (l, u) = (l.max(-3.0), u.min(3.0));
            l + (u - l) * (0.3 + 0.4 * ((i * 7 % 11) as f64 / 11.0))
        })
        .collect()
}

/// Central differences on the 41-motor iCub (couplings included) for a named frame's Jacobian,
/// the centre-of-mass Jacobian and gravity torques as the gradient of the potential energy.
#[test]
fn derivatives_match_finite_differences_through_the_couplings() {
    let model = trm_kinematics::RobotModel::load(format!(
        "{}/../../models/icub_upper_body.ron",
        env!("CARGO_MANIFEST_DIR")
    ))
    .unwrap();
    let active = model.all_active();
    let q = interior(&active);
    let frame = model.frame_id("r_index_fingertip").unwrap();
    let mut poses = model.pose_buffer();
    active.forward(&q, &mut poses).unwrap();
    let mut jac = Matrix6xX::zeros(0);
    active.jacobian(&poses, frame, &mut jac);
    let mut jcom = Matrix3xX::zeros(0);
    active.com_jacobian(&poses, &mut jcom);
    let mut g = vec![0.0; active.len()];
    active.gravity_torques(&poses, &GRAVITY, &mut g);
    let h = 1e-6;
    let mut plus = model.pose_buffer();
    let mut minus = model.pose_buffer();
    for k in 0..active.len() {
        let (mut qp, mut qm) = (q.clone(), q.clone());
        qp[k] += h;
        qm[k] -= h;
        active.forward(&qp, &mut plus).unwrap();
        active.forward(&qm, &mut minus).unwrap();
        let dp = (plus.pose(frame).translation.vector - minus.pose(frame).translation.vector)
            / (2.0 * h);
        // angular velocity from the rotation difference
        let dr = (plus.pose(frame).rotation * minus.pose(frame).rotation.inverse()).scaled_axis()
            / (2.0 * h);
        for i in 0..3 {
            assert!((jac[(i, k)] - dp[i]).abs() < 1e-6, "linear {i} motor {k}");
            assert!(
                (jac[(i + 3, k)] - dr[i]).abs() < 1e-6,
                "angular {i} motor {k}"
            );
        }
        let (m, cp) = active.center_of_mass(&plus);
        let (_, cm) = active.center_of_mass(&minus);
        let dc = (cp - cm) / (2.0 * h);
        for i in 0..3 {
            assert!((jcom[(i, k)] - dc[i]).abs() < 1e-7, "com {i} motor {k}");
        }
        // V = −m gᵀ c, g(q) = ∂V/∂q
        let v = |c: Point3<f64>| -m * GRAVITY.dot(&c.coords);
        let dv = (v(cp) - v(cm)) / (2.0 * h);
        assert!(
            (g[k] - dv).abs() < 1e-6 * dv.abs().max(1.0),
            "gravity motor {k}: {} vs {dv}",
            g[k]
        );
    }
}

#[test]
fn negative_or_non_finite_inertials_are_errors() {
    let urdf = |mass: &str| {
        format!(
            r#"<robot name="r"><link name="a"><inertial><mass value="{mass}"/>
            <inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link></robot>"#
        )
    };
    let e = RobotModel::from_urdf_str(&urdf("-1"), "m.urdf")
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("m.urdf:1") && e.contains("mass -1 is negative"),
        "{e}"
    );
    let e = RobotModel::from_urdf_str(&urdf("NaN"), "m.urdf")
        .unwrap_err()
        .to_string();
    assert!(e.contains("not finite"), "{e}");
}

/// ∂J/∂q_k against central differences of the Jacobian: on the coupled 41-motor iCub (a
/// fingertip deep in the tree) and on a branched tree with prismatic, continuous and mimic
/// joints (a link beyond the prismatic joint).
#[test]
fn jacobian_derivatives_match_finite_differences() {
    let root = format!("{}/../..", env!("CARGO_MANIFEST_DIR"));
    let icub = RobotModel::load(format!("{root}/models/icub_upper_body.ron")).unwrap();
    let tree = RobotModel::from_urdf_file(format!("{root}/models/branched_tree.urdf")).unwrap();
    for (model, frames) in [
        (&icub, vec!["r_index_fingertip", "r_hand"]),
        (&tree, vec!["left_slider", "right_finger_b"]),
    ] {
        let active = model.all_active();
        let q = interior(&active);
        let mut poses = model.pose_buffer();
        let (mut jp, mut jm) = (Matrix6xX::zeros(0), Matrix6xX::zeros(0));
        let mut derivatives = Vec::new();
        let h = 1e-6;
        for name in frames {
            let frame = model.frame_id(name).unwrap();
            active.forward(&q, &mut poses).unwrap();
            active.jacobian_derivatives(&poses, frame, &mut derivatives);
            assert_eq!(derivatives.len(), active.len());
            let mut largest = 0.0f64;
            for k in 0..active.len() {
                let (mut qp, mut qm) = (q.clone(), q.clone());
                qp[k] += h;
                qm[k] -= h;
                active.forward(&qp, &mut poses).unwrap();
                active.jacobian(&poses, frame, &mut jp);
                active.forward(&qm, &mut poses).unwrap();
                active.jacobian(&poses, frame, &mut jm);
                let numeric = (&jp - &jm) / (2.0 * h);
                largest = largest.max(numeric.amax());
                let error = (&derivatives[k] - &numeric).amax();
                assert!(error < 1e-6, "{name}, motor {k}: error {error}");
            }
            assert!(largest > 0.1, "{name}: a test that cannot fail");
        }
    }
}
