//! Robot models for trm: URDF link trees, motors with linear couplings, active-joint selection,
//! named frames and allocation-free forward kinematics.
//!
//! Start with [`RobotModel::load`] (a `.urdf`, or a `.ron` [model description](ModelDescription)
//! that adds couplings, frames, groups and postures to a URDF), choose the variables with
//! [`RobotModel::active_set`], and pose the robot with [`ActiveSet::forward`] into a reusable
//! [`PoseBuffer`]:
//!
//! ```
//! use trm_kinematics::RobotModel;
//!
//! let urdf = r#"<robot name="arm">
//!   <link name="base"/><link name="upper"/><link name="tool"/>
//!   <joint name="shoulder" type="revolute"><parent link="base"/><child link="upper"/>
//!     <axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
//!   <joint name="tip" type="fixed"><origin xyz="1 0 0"/><parent link="upper"/><child link="tool"/></joint>
//! </robot>"#;
//! let model = RobotModel::from_urdf_str(urdf, "<example>")?;
//! let active = model.all_active();
//! let mut poses = model.pose_buffer();
//! active.forward(&[std::f64::consts::FRAC_PI_2], &mut poses)?;
//! let tool = poses.pose(model.frame_id("tool")?);
//! assert!((tool.translation.y - 1.0).abs() < 1e-12);
//! # Ok::<(), trm_kinematics::KinematicsError>(())
//! ```
//!
//! Derivatives come from the same pose buffer: [`ActiveSet::jacobian`] (geometric, world axes),
//! [`ActiveSet::point_jacobian`], [`ActiveSet::center_of_mass`], [`ActiveSet::com_jacobian`] and
//! [`ActiveSet::gravity_torques`], all with respect to the active motors (couplings included;
//! checked against Pinocchio and finite differences).
//!
//! World frame = the URDF root link. Joint, motor and active vectors are explained on
//! [`RobotModel`]. Mesh files are never opened: kinematics needs none.

mod active;
mod batch;
mod derivatives;
mod description;
mod error;
mod fk;
pub mod ik;
mod model;
mod posture;
mod resolve;
pub mod ros;
pub mod srdf;
mod tree;

pub use active::ActiveSet;
pub use batch::{
    BLOCK_LANES, LANES, Lanes, PoseBatch, PoseBlock, PoseLanes, PoseLanes32, lane_pose, sin_cos,
};
pub use derivatives::GRAVITY;
pub use description::{
    CouplingSpec, DisableReason, DisabledCollisionSpec, FrameSpec, GroupSpec, ModelDescription,
    MotionLimitSpec, MotorSpec, PlanningSpec, PostureSpec,
};
pub use error::{KinematicsError, NameKind, Result};
// The file plumbing lives in trm-io; re-exported here for the crates built on this one.
pub use fk::{FrameId, PoseBuffer};
pub use model::{Coupling, DisabledCollision, Motor, NamedFrame, RobotModel, quietly};
pub use nalgebra;
pub use posture::{ConfigurationSample, ConfigurationsFile, PostureFile};
pub use tree::{
    Inertial, Joint, JointKind, LIMIT_TOLERANCE, Limits, Link, Mimic, Tree, pose_from_xyz_rpy,
};
pub use trm_io::{
    FileError, MAX_INPUT_BYTES, StagedFile, binary_bytes, check_output, check_unique_keys,
    json_text, load_versioned, parse_binary_versioned, parse_versioned, read_file, read_file_bytes,
    read_input, read_input_bytes, save_json, unique_names, write_atomic, write_file,
    write_file_bytes,
};
pub use trm_io::{
    RonProblem, SpecError, TooDeep, XML_NESTING_LIMIT, check_xml_nesting, closest_names,
    explain_ron_error, locate_ron_field, locate_ron_path,
};
pub use urdf_rs;

/// The file formats this crate reads and writes.
pub mod formats {
    #[doc = include_str!("../docs/model-description.md")]
    pub mod model_description {}
}
