//! Model description (RON) over the iCub upper-body URDF: a model or a located error.
#![no_main]
use libfuzzer_sys::fuzz_target;

static URDF: &str = include_str!("../../models/icub_upper_body.urdf");

fuzz_target!(|text: &str| {
    if let Ok(description) = trm_kinematics::ModelDescription::from_ron(text, "fuzz.ron") {
        let _ = trm_kinematics::RobotModel::from_parts(
            URDF,
            "icub_upper_body.urdf",
            &description,
            Some((text, "fuzz.ron")),
        );
    }
});
