//! Configurations file (JSON) → iCub joint vectors: vectors or a located error.
#![no_main]
libfuzzer_sys::fuzz_target!(|data: &str| trm_fuzz_checks::configurations(data));
