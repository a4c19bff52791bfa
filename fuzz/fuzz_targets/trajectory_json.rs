//! Trajectory JSON: a trajectory or a located error; one that reads is written back and reads
//! again unchanged, and is checked against the iCub.
#![no_main]
use libfuzzer_sys::fuzz_target;
use std::path::Path;

/// The iCub upper body, loaded once.
static ROBOT: std::sync::LazyLock<trm_kinematics::RobotModel> =
    std::sync::LazyLock::new(trm_models::icub_upper_body);

fuzz_target!(|text: &str| {
    let path = Path::new("fuzz.json");
    if let Ok(t) = trm_plan::Trajectory::from_json(text, path) {
        let written = t.to_json(path).expect("a trajectory that reads is written");
        let again = trm_plan::Trajectory::from_json(&written, path).expect("reads back");
        assert_eq!(t, again);
        let _ = t.check_robot(&ROBOT, path, |_| 0);
    }
});
