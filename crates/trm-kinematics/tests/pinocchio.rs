//! Forward kinematics agrees with Pinocchio (an independent rigid-body library) to 1e-9 on real
//! URDFs. The reference poses are committed fixtures made by `tests/fixtures/pinocchio_reference.py`.

use std::path::{Path, PathBuf};

use serde::Deserialize;
use trm_kinematics::RobotModel;

#[derive(Deserialize)]
struct Fixture {
    urdf: String,
    joint_names: Vec<String>,
    samples: Vec<Sample>,
}

#[derive(Deserialize)]
struct Sample {
    q: Vec<f64>,
    links: std::collections::BTreeMap<String, Pose>,
}

#[derive(Deserialize)]
struct Pose {
    p: [f64; 3],
    #[serde(rename = "R")]
    r: [[f64; 3]; 3],
}

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// Largest position and rotation-entry error over every link of every sample.
fn max_errors(fixture_name: &str) -> (f64, f64, usize) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fixtures")
        .join(fixture_name);
    let fixture: Fixture = serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
    let model = RobotModel::from_urdf_file(repo().join(&fixture.urdf)).unwrap();
    assert_eq!(
        fixture.joint_names.len(),
        model.num_joints(),
        "{}: movable joint count",
        fixture.urdf
    );
    let columns: Vec<usize> = fixture
        .joint_names
        .iter()
        .map(|n| model.joint_index(n).unwrap())
        .collect();
    let mut buffer = model.pose_buffer();
    let mut q = vec![0.0; model.num_joints()];
    let (mut ep, mut er, mut compared) = (0.0f64, 0.0f64, 0);
    for sample in &fixture.samples {
        for (&c, &v) in columns.iter().zip(&sample.q) {
            q[c] = v;
        }
        model.forward_joints(&q, &mut buffer).unwrap();
        assert_eq!(
            sample.links.len(),
            model.num_links(),
            "{}: every link has a reference pose",
            fixture.urdf
        );
        for (name, expected) in &sample.links {
            let pose = buffer.pose(model.frame_id(name).unwrap());
            let r = pose.rotation.to_rotation_matrix();
            for i in 0..3 {
                ep = ep.max((pose.translation.vector[i] - expected.p[i]).abs());
                for j in 0..3 {
                    er = er.max((r[(i, j)] - expected.r[i][j]).abs());
                }
            }
            compared += 1;
        }
    }
    (ep, er, compared)
}

fn check(fixture: &str) {
    let (ep, er, n) = max_errors(fixture);
    assert!(n > 0);
    eprintln!("{fixture}: max position error {ep:e} m, rotation entry error {er:e} over {n} poses");
    assert!(
        ep < 1e-9 && er < 1e-9,
        "{fixture}: max position error {ep:e} m, rotation entry error {er:e} over {n} poses"
    );
}

#[test]
fn shipped_icub_upper_body_matches_pinocchio() {
    check("icub_upper_body.pinocchio.json");
}

#[test]
fn official_icub_visuomanip_urdf_matches_pinocchio() {
    check("icub_visuomanip.pinocchio.json");
}

#[test]
fn official_icub_genova04_urdf_matches_pinocchio() {
    check("icub_genova04.pinocchio.json");
}

#[test]
fn branched_tree_with_prismatic_continuous_and_tilted_axes_matches_pinocchio() {
    check("branched_tree.pinocchio.json");
}

#[test]
fn planar_arm_matches_pinocchio() {
    check("planar_arm.pinocchio.json");
}
