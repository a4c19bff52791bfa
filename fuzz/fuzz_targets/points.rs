//! Point-cloud bytes (PLY or PCD; the first byte picks the format) → finite points or an error,
//! never a panic.
#![no_main]
libfuzzer_sys::fuzz_target!(|data: &[u8]| trm_fuzz_checks::points(data));
