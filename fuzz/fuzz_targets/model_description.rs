//! Model description (RON) over the iCub upper-body URDF: a model or a located error. The URDF
//! is parsed once; each input is applied to it (`RobotModel::with_description`).
#![no_main]
libfuzzer_sys::fuzz_target!(|data: &str| trm_fuzz_checks::model_description(data));
