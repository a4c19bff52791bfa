//! World (RON): a world or a located error.
#![no_main]
libfuzzer_sys::fuzz_target!(|data: &str| trm_fuzz_checks::world(data));
