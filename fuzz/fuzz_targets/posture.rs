//! Posture file (JSON) → iCub motor vector: a posture or a located error; one that reads is
//! written back and reads again unchanged.
#![no_main]
use libfuzzer_sys::fuzz_target;
use std::path::Path;

/// The iCub upper body, loaded once.
static ROBOT: std::sync::LazyLock<trm_kinematics::RobotModel> =
    std::sync::LazyLock::new(trm_models::icub_upper_body);

fuzz_target!(|text: &str| {
    let path = Path::new("fuzz.json");
    let Ok(file) = trm_kinematics::PostureFile::from_json(text, path) else {
        return;
    };
    let robot = &*ROBOT;
    let start = vec![0.0; robot.motors().len()];
    let active = robot.all_active();
    if file.to_motors(&robot, Some(&active), &start, path).is_ok() {
        let written = file.to_json(path).expect("a posture that reads is written");
        let again = trm_kinematics::PostureFile::from_json(&written, path).expect("reads back");
        assert_eq!(file.motors, again.motors);
        assert_eq!(file.q, again.q);
    }
});
