//! Trajectory JSON: a trajectory or a located error; one that reads is written back and reads
//! again unchanged, and is checked against the iCub.
#![no_main]
libfuzzer_sys::fuzz_target!(|data: &str| trm_fuzz_checks::trajectory_json(data));
