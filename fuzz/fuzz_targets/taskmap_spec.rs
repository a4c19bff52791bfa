//! Task-map spec (RON): a spec or a located error.
#![no_main]
libfuzzer_sys::fuzz_target!(|data: &str| trm_fuzz_checks::taskmap_spec(data));
