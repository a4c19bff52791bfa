//! URDF text → robot model: any input gives a model or an error, never a panic or a hang.
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|text: &str| {
    if let Ok(model) = trm_kinematics::RobotModel::from_urdf_str(text, "fuzz.urdf") {
        // a model that loads can be evaluated at its start posture
        let motors: Vec<f64> = model
            .motors()
            .iter()
            .map(|m| 0.5 * (m.limits.lower.max(-1e3) + m.limits.upper.min(1e3)))
            .collect();
        let _ = model.forward_motors(&motors, &mut model.pose_buffer());
    }
});
