//! SRDF text → a model description for the iCub upper body: a description or a located error,
//! never a panic, a hang or a stack overflow.
#![no_main]
use std::sync::OnceLock;

use libfuzzer_sys::fuzz_target;
use trm_kinematics::{ModelDescription, RobotModel};

fn robot() -> &'static RobotModel {
    static ROBOT: OnceLock<RobotModel> = OnceLock::new();
    ROBOT.get_or_init(|| {
        RobotModel::from_urdf_str(trm_models::ICUB_UPPER_BODY_URDF, "icub_upper_body.urdf")
            .expect("the embedded URDF loads")
    })
}

fuzz_target!(|text: &str| {
    if let Ok(srdf) = trm_kinematics::srdf::Srdf::parse(text, "fuzz.srdf") {
        if let Ok((description, _)) = srdf.to_description(robot(), &ModelDescription::default()) {
            let _ = robot().clone().with_description(&description, None);
        }
        // what it reads, it writes and reads back
        let again = trm_kinematics::srdf::Srdf::parse(&srdf.to_xml(), "again.srdf");
        assert!(again.is_ok(), "{again:?}");
    }
});
