//! Trajectory CSV of the iCub: a trajectory or a located error; one that reads is written back
//! and reads again unchanged.
#![no_main]
libfuzzer_sys::fuzz_target!(|data: &str| trm_fuzz_checks::trajectory_csv(data));
