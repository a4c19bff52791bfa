//! Whole-body motion spec (RON), checked against the iCub's names: a spec or a located error.
#![no_main]
use libfuzzer_sys::fuzz_target;

/// The iCub upper body, loaded once.
static ROBOT: std::sync::LazyLock<trm_kinematics::RobotModel> =
    std::sync::LazyLock::new(trm_models::icub_upper_body);

fuzz_target!(|text: &str| {
    if let Ok(spec) = trm_wholebody::MotionSpec::from_ron(text, "fuzz.ron") {
        let _ = spec.check_names(&ROBOT, "fuzz.ron", text);
    }
});
