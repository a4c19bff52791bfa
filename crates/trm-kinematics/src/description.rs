//! The model description: a RON file beside a URDF that says what the URDF cannot — which motors
//! drive which joints (linear couplings), named frames, motor groups and named postures.
//!
//! The format is documented in `models/README.md`. A minimal description:
//!
//! ```ron
//! (
//!     urdf: "planar_arm.urdf",
//!     frames: [(name: "tool", link: "link3", xyz: (0.1, 0.0, 0.0))],
//!     groups: [(name: "arm", members: ["joint1", "joint2", "joint3"])],
//!     postures: [(name: "home", values: {"joint2": 0.5})],
//! )
//! ```

use std::collections::BTreeMap;
use std::path::PathBuf;

use serde::{Deserialize, Serialize};

/// Everything a model description file holds. All angles are radians, lengths metres.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ModelDescription {
    /// The URDF, relative to the description file.
    pub urdf: PathBuf,
    /// Directories searched for the URDF's `package://NAME/...` meshes, relative to the
    /// description file, before `ROS_PACKAGE_PATH` (e.g. `["../ros_ws/src"]`).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub package_paths: Vec<PathBuf>,
    /// Motors that drive coupled joints. A movable joint that no coupling names (and that has no
    /// `<mimic>`) is driven by a motor of its own, with the joint's name and limits.
    #[serde(default)]
    pub motors: Vec<MotorSpec>,
    /// Joints driven by a linear combination of motors.
    #[serde(default)]
    pub couplings: Vec<CouplingSpec>,
    /// Named frames: a link plus a fixed offset.
    #[serde(default)]
    pub frames: Vec<FrameSpec>,
    /// Named groups of motors, usable to select active motors.
    #[serde(default)]
    pub groups: Vec<GroupSpec>,
    /// Named postures in motor space.
    #[serde(default)]
    pub postures: Vec<PostureSpec>,
    /// Link pairs collision checking skips (as SRDF `<disable_collisions>`), usually written by
    /// `cargo xtask gen-acm`. Links joined by a joint are always skipped and need no entry.
    #[serde(default)]
    pub disabled_collisions: Vec<DisabledCollisionSpec>,
    /// Link pairs that are always checked, overriding every automatic or listed exclusion
    /// (adjacency included).
    #[serde(default)]
    pub enabled_collisions: Vec<(String, String)>,
    /// Sampling planners' settings for this robot where the ones sized by its lever arms do
    /// not suit it (e.g. `planning: (range: Some(0.5))`).
    #[serde(default, skip_serializing_if = "PlanningSpec::is_empty")]
    pub planning: PlanningSpec,
    /// Motion limits of motors, by motor name (as MoveIt's `joint_limits.yaml`): a velocity
    /// here replaces the URDF's; acceleration and jerk limits exist only here (e.g.
    /// `motion_limits: {"panda_joint1": (acceleration: Some(3.75))}`).
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub motion_limits: BTreeMap<String, MotionLimitSpec>,
}

/// A motor's motion limits (rad/s, rad/s², rad/s³; m/… for prismatic motors); each one absent
/// keeps what the URDF gives (velocity) or leaves the limit unknown.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MotionLimitSpec {
    /// Largest speed.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub velocity: Option<f64>,
    /// Largest acceleration.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub acceleration: Option<f64>,
    /// Largest jerk.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub jerk: Option<f64>,
}

/// A robot's own settings for sampling planners; each one absent is sized by the robot's
/// lever arms (`trm_plan::rrt::RrtOptions::for_robot`).
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PlanningSpec {
    /// RRT-Connect's longest step, rad (Euclidean in the planned motors' values).
    #[serde(default)]
    pub range: Option<f64>,
    /// Largest gap between checked points of an edge, rad.
    #[serde(default)]
    pub resolution: Option<f64>,
    /// First radius of RRT-Connect's dynamic domains, rad.
    #[serde(default)]
    pub domain_radius: Option<f64>,
}

impl PlanningSpec {
    /// Whether no setting is given.
    pub fn is_empty(&self) -> bool {
        self.range.is_none() && self.resolution.is_none() && self.domain_radius.is_none()
    }
}

/// Why a link pair is left out of collision checking (the reasons of MoveIt's setup assistant).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum DisableReason {
    /// The links are joined by a joint (directly, or through links without geometry).
    Adjacent,
    /// The pair collides at the model's default posture.
    Default,
    /// The pair collided in (almost) every random sample.
    Always,
    /// The pair collided in none of the random samples.
    Never,
    /// Disabled by hand.
    User,
}

impl DisableReason {
    /// The lower-case name used in files.
    pub fn as_str(self) -> &'static str {
        match self {
            DisableReason::Adjacent => "adjacent",
            DisableReason::Default => "default",
            DisableReason::Always => "always",
            DisableReason::Never => "never",
            DisableReason::User => "user",
        }
    }
}

/// A link pair excluded from collision checking.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DisabledCollisionSpec {
    /// First link.
    pub a: String,
    /// Second link.
    pub b: String,
    /// Why the pair is excluded.
    pub reason: DisableReason,
}

impl DisabledCollisionSpec {
    /// `entries` as the lines of a RON list, one `(a: "…", b: "…", reason: …)` per line, each
    /// indented by `indent` — serialised by ron, read back by [`ModelDescription::from_ron`].
    pub fn list_to_ron(entries: &[DisabledCollisionSpec], indent: &str) -> String {
        let compact = ron::ser::PrettyConfig::new().compact_structs(true);
        entries
            .iter()
            .map(|e| {
                let line = ron::ser::to_string_pretty(e, compact.clone())
                    .expect("names and a reason serialise");
                format!("{indent}{line},\n")
            })
            .collect()
    }
}

/// A motor declared for couplings.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MotorSpec {
    /// Unique motor name.
    pub name: String,
    /// Lowest motor position.
    pub lower: f64,
    /// Highest motor position.
    pub upper: f64,
    /// Largest motor speed; unlimited when absent.
    #[serde(default)]
    pub velocity: Option<f64>,
}

/// `joint = Σ factor · motor + offset`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CouplingSpec {
    /// URDF name of the driven joint.
    pub joint: String,
    /// `(motor name, factor)` terms; empty for a joint held at `offset`.
    pub motors: Vec<(String, f64)>,
    /// Constant term.
    #[serde(default)]
    pub offset: f64,
}

/// A named frame rigidly attached to a link.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FrameSpec {
    /// Unique name, distinct from every link name.
    pub name: String,
    /// The link (or an earlier named frame) it is attached to.
    pub link: String,
    /// Offset translation, in the link frame.
    #[serde(default)]
    pub xyz: [f64; 3],
    /// Offset rotation as URDF roll-pitch-yaw.
    #[serde(default)]
    pub rpy: [f64; 3],
}

/// A named list of motors (or of other, earlier groups).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GroupSpec {
    /// Unique group name.
    pub name: String,
    /// Motor names or earlier group names.
    pub members: Vec<String>,
}

/// A named posture: motor values by name. Motors left out take 0 clamped into their limits.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PostureSpec {
    /// Unique posture name.
    pub name: String,
    /// Motor values by motor name.
    #[serde(deserialize_with = "crate::unique_names")]
    pub values: BTreeMap<String, f64>,
}

impl ModelDescription {
    /// Parses RON text; `origin` names the file in errors.
    pub fn from_ron(text: &str, origin: &str) -> crate::Result<Self> {
        ron::from_str(text).map_err(|e| {
            let p = crate::explain_ron_error(&e);
            crate::KinematicsError::MalformedDescription {
                origin: origin.to_string(),
                line: p.line,
                column: p.column,
                message: p.message(),
            }
        })
    }
}
