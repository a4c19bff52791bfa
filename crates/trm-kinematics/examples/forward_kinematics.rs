//! Forward kinematics of a URDF given on the command line (or a two-link arm): every link's
//! world position at the home posture, or at all motors zero.
//!
//! `cargo run -p trm-kinematics --example forward_kinematics [-- MODEL.urdf|MODEL.ron]`

use trm_kinematics::{KinematicsError, RobotModel};

const ARM: &str = r#"<robot name="arm">
  <link name="base"/><link name="upper"/><link name="fore"/><link name="tool"/>
  <joint name="shoulder" type="revolute"><parent link="base"/><child link="upper"/>
    <axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
  <joint name="elbow" type="revolute"><origin xyz="0.3 0 0"/><parent link="upper"/><child link="fore"/>
    <axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
  <joint name="tip" type="fixed"><origin xyz="0.25 0 0"/><parent link="fore"/><child link="tool"/></joint>
</robot>"#;

fn main() -> Result<(), KinematicsError> {
    let model = match std::env::args().nth(1) {
        Some(path) => RobotModel::load(path)?,
        None => RobotModel::from_urdf_str(ARM, "<two-link arm>")?,
    };
    let motors = model.home_motors();
    let mut poses = model.pose_buffer();
    model.forward_motors(&motors, &mut poses)?;
    println!(
        "{}: {} motors, {} joints, {} links",
        model.name(),
        model.motors().len(),
        model.num_joints(),
        model.num_links()
    );
    for (i, name) in model.frame_names().enumerate() {
        let p = poses.poses()[i].translation;
        println!("{name:<28} {:>8.4} {:>8.4} {:>8.4}", p.x, p.y, p.z);
    }
    Ok(())
}
