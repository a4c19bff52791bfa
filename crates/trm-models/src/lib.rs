//! The robot models shipped in `models/`, embedded in the binary so that every crate, test,
//! bench and command can load them from anywhere.
//!
//! ```
//! let icub = trm_models::icub_upper_body();
//! assert_eq!(icub.motors().len(), 41);
//! ```
//!
//! The iCub files are derived from robotology/icub-models (CC-BY-SA-4.0, © Istituto Italiano
//! di Tecnologia); see `models/icub-visuomanip/NOTICE.md`.

use std::path::Path;

use trm_kinematics::{KinematicsError, ModelDescription, RobotModel};

/// The names of the embedded models, as specs and [`by_name`] know them.
pub const NAMES: &[&str] = &[
    "icub_upper_body",
    "icub_sagittal",
    "icub_official",
    "icub_genova04",
    "planar_arm",
    "branched_tree",
];

/// The embedded model called `name` (one of [`NAMES`]).
pub fn by_name(name: &str) -> Option<RobotModel> {
    Some(match name {
        "icub_upper_body" => icub_upper_body(),
        "icub_sagittal" => icub_sagittal(),
        "icub_official" => icub_official(),
        "icub_genova04" => icub_genova04(),
        "planar_arm" => planar_arm(),
        "branched_tree" => branched_tree(),
        _ => return None,
    })
}

/// The one model loader of specs and commands: an embedded model by name ([`NAMES`]), else a
/// `.urdf` or `.ron` model file at `base.join(name)`. A name that is neither gets an error that
/// lists the embedded models closest to it.
///
/// ```
/// let arm = trm_models::load("planar_arm", ".".as_ref())?;
/// assert_eq!(arm.motors().len(), 3);
/// assert!(trm_models::load("icub_uper_body", ".".as_ref()).unwrap_err().to_string().contains("icub_upper_body"));
/// # Ok::<(), trm_kinematics::KinematicsError>(())
/// ```
pub fn load(name: &str, base: &Path) -> Result<RobotModel, KinematicsError> {
    if let Some(model) = by_name(name) {
        return Ok(model);
    }
    let path = base.join(name);
    if path.is_file() {
        return RobotModel::load(&path);
    }
    Err(KinematicsError::UnknownModel {
        name: name.to_string(),
        looked_for: path,
        suggestions: trm_io::closest_names(name, NAMES.iter().copied()),
    })
}

/// models/icub_upper_body.urdf: the iCub upper body with primitive collision proxies.
pub const ICUB_UPPER_BODY_URDF: &str = include_str!("../models/icub_upper_body.urdf");
/// models/icub_upper_body.ron: its 41 motors, couplings, frames, groups and postures.
pub const ICUB_UPPER_BODY_RON: &str = include_str!("../models/icub_upper_body.ron");
/// models/icub_full_body.urdf: the whole iCub (legs included) with primitive collision proxies.
pub const ICUB_FULL_BODY_URDF: &str = include_str!("../models/icub_full_body.urdf");
/// models/icub_sagittal.ron: the whole iCub reduced to 8 symmetric sagittal motors.
pub const ICUB_SAGITTAL_RON: &str = include_str!("../models/icub_sagittal.ron");
/// The official iCubGazeboV2_5_visuomanip URDF (75 revolute joints), unchanged.
pub const ICUB_OFFICIAL_URDF: &str = include_str!("../models/icub-visuomanip/model.urdf");
/// The official iCubGenova04 URDF (32 revolute joints), unchanged.
pub const ICUB_GENOVA04_URDF: &str = include_str!("../models/icub-genova04/model.urdf");
/// models/planar_arm.urdf: a three-link planar arm.
pub const PLANAR_ARM_URDF: &str = include_str!("../models/planar_arm.urdf");
/// models/branched_tree.urdf: a small tree with continuous, prismatic, mimic and fixed joints.
pub const BRANCHED_TREE_URDF: &str = include_str!("../models/branched_tree.urdf");

/// `load()`'s model, parsed once per process (models are immutable and share their data, so a
/// clone is cheap).
fn once(cell: &'static std::sync::OnceLock<RobotModel>, load: fn() -> RobotModel) -> RobotModel {
    cell.get_or_init(load).clone()
}

/// The 41-motor iCub upper body (the default model of trm).
pub fn icub_upper_body() -> RobotModel {
    static MODEL: std::sync::OnceLock<RobotModel> = std::sync::OnceLock::new();
    once(&MODEL, || {
        let description =
            ModelDescription::from_ron(ICUB_UPPER_BODY_RON, "models/icub_upper_body.ron")
                .expect("the shipped description parses (checked by tests)");
        RobotModel::from_parts(
            ICUB_UPPER_BODY_URDF,
            "models/icub_upper_body.urdf",
            &description,
            Some((ICUB_UPPER_BODY_RON, "models/icub_upper_body.ron")),
        )
        .expect("the shipped model is valid (checked by tests)")
    })
}

/// The whole iCub moving symmetrically in its sagittal plane: 8 motors (hip pitch, knee, ankle
/// pitch, torso pitch, shoulder pitch/roll/yaw, elbow), each driving the left and right joint
/// alike; every other joint held at 0. The model of `cargo xtask stand-up`.
pub fn icub_sagittal() -> RobotModel {
    static MODEL: std::sync::OnceLock<RobotModel> = std::sync::OnceLock::new();
    once(&MODEL, || {
        let description = ModelDescription::from_ron(ICUB_SAGITTAL_RON, "models/icub_sagittal.ron")
            .expect("the shipped description parses (checked by tests)");
        RobotModel::from_parts(
            ICUB_FULL_BODY_URDF,
            "models/icub_full_body.urdf",
            &description,
            Some((ICUB_SAGITTAL_RON, "models/icub_sagittal.ron")),
        )
        .expect("the shipped model is valid (checked by tests)")
    })
}

/// The official 75-joint iCub URDF, every joint its own motor.
pub fn icub_official() -> RobotModel {
    static MODEL: std::sync::OnceLock<RobotModel> = std::sync::OnceLock::new();
    once(&MODEL, || {
        RobotModel::from_urdf_str(ICUB_OFFICIAL_URDF, "models/icub-visuomanip/model.urdf")
            .expect("the official URDF loads")
    })
}

/// The official iCubGenova04 URDF.
pub fn icub_genova04() -> RobotModel {
    RobotModel::from_urdf_str(ICUB_GENOVA04_URDF, "models/icub-genova04/model.urdf")
        .expect("the official URDF loads")
}

/// The three-link planar arm.
pub fn planar_arm() -> RobotModel {
    RobotModel::from_urdf_str(PLANAR_ARM_URDF, "models/planar_arm.urdf")
        .expect("the planar arm loads")
}

/// The small branched tree.
pub fn branched_tree() -> RobotModel {
    RobotModel::from_urdf_str(BRANCHED_TREE_URDF, "models/branched_tree.urdf")
        .expect("the branched tree loads")
}

#[cfg(test)]
mod tests {
    #[test]
    fn a_description_applied_to_a_loaded_urdf_gives_the_same_model() {
        use trm_kinematics::{ModelDescription, RobotModel};
        let bare = RobotModel::from_urdf_str(super::ICUB_UPPER_BODY_URDF, "u.urdf").unwrap();
        let description = ModelDescription::from_ron(super::ICUB_UPPER_BODY_RON, "d.ron").unwrap();
        let described = bare.with_description(&description, None).unwrap();
        let shipped = super::icub_upper_body();
        let names = |m: &RobotModel| m.motor_names();
        assert_eq!(names(&described), names(&shipped));
        assert_eq!(
            described.frame_names().count(),
            shipped.frame_names().count()
        );
        assert_eq!(bare.motors().len(), bare.num_joints());
        // errors still point into the description's text
        let bad = super::ICUB_UPPER_BODY_RON.replacen("\"r_elbow\"", "\"r_elbw\"", 1);
        let e = ModelDescription::from_ron(&bad, "d.ron")
            .and_then(|d| bare.with_description(&d, Some((&bad, "d.ron"))))
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("d.ron:") && e.contains("r_elbow"), "{e}");
    }

    #[test]
    fn every_embedded_model_loads() {
        assert_eq!(super::icub_upper_body().num_joints(), 63);
        assert_eq!(super::icub_official().num_joints(), 75);
        assert_eq!(super::icub_sagittal().num_joints(), 75);
        assert_eq!(super::icub_sagittal().motors().len(), 8);
        assert_eq!(super::icub_genova04().num_joints(), 32);
        assert_eq!(super::planar_arm().num_joints(), 3);
        assert_eq!(super::branched_tree().num_joints(), 6);
        for name in super::NAMES {
            assert!(super::by_name(name).is_some(), "{name}");
        }
    }
}
