//! Model description (RON) over the iCub upper-body URDF: a model or a located error. The URDF
//! is parsed once; each input is applied to it (`RobotModel::with_description`).
#![no_main]
use libfuzzer_sys::fuzz_target;

/// The iCub upper-body URDF without a description, parsed once.
static URDF: std::sync::LazyLock<trm_kinematics::RobotModel> = std::sync::LazyLock::new(|| {
    trm_kinematics::RobotModel::from_urdf_str(
        include_str!("../../models/icub_upper_body.urdf"),
        "icub_upper_body.urdf",
    )
    .expect("the shipped URDF loads")
});

fuzz_target!(|text: &str| {
    if let Ok(description) = trm_kinematics::ModelDescription::from_ron(text, "fuzz.ron") {
        let _ = URDF.with_description(&description, Some((text, "fuzz.ron")));
    }
});
