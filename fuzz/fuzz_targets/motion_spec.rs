//! Whole-body motion spec (RON), checked against the iCub's names: a spec or a located error.
#![no_main]
libfuzzer_sys::fuzz_target!(|data: &str| trm_fuzz_checks::motion_spec(data));
