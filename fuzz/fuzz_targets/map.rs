//! Roadmap file (JSON): a map or an error; a map that reads is written back and reads again
//! unchanged.
#![no_main]
libfuzzer_sys::fuzz_target!(|data: &str| trm_fuzz_checks::map(data));
