//! Trajectory CSV of the iCub: a trajectory or a located error; one that reads is written back
//! and reads again unchanged.
#![no_main]
use libfuzzer_sys::fuzz_target;
use std::path::Path;

/// The iCub upper body, loaded once.
static ROBOT: std::sync::LazyLock<trm_kinematics::RobotModel> =
    std::sync::LazyLock::new(trm_models::icub_upper_body);

fuzz_target!(|text: &str| {
    let robot = &*ROBOT;
    let path = Path::new("fuzz.csv");
    if let Ok(t) = trm_plan::Trajectory::from_csv(text, path, robot) {
        let written = t.to_csv(path).expect("a trajectory that reads is written");
        let again = trm_plan::Trajectory::from_csv(&written, path, robot).expect("reads back");
        assert_eq!((t.names, t.times, t.positions), (again.names, again.times, again.positions));
    }
});
