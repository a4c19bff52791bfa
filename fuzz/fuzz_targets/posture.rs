//! Posture file (JSON) → iCub motor vector: a posture or a located error; one that reads is
//! written back and reads again unchanged.
#![no_main]
libfuzzer_sys::fuzz_target!(|data: &str| trm_fuzz_checks::posture(data));
