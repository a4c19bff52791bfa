//! Viewer scene (JSON): a scene or an error; one that reads is written back and reads again.
#![no_main]
libfuzzer_sys::fuzz_target!(|data: &str| trm_fuzz_checks::scene(data));
