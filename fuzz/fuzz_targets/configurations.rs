//! Configurations file (JSON) → iCub joint vectors: vectors or a located error.
#![no_main]
use libfuzzer_sys::fuzz_target;
use std::path::Path;

/// The iCub upper body, loaded once.
static ROBOT: std::sync::LazyLock<trm_kinematics::RobotModel> =
    std::sync::LazyLock::new(trm_models::icub_upper_body);

fuzz_target!(|text: &str| {
    let path = Path::new("fuzz.json");
    if let Ok(file) = trm_kinematics::ConfigurationsFile::from_json(text, path) {
        let _ = file.joint_vectors(&ROBOT, path);
    }
});
