//! SRDF text → a model description for the iCub upper body: a description or a located error,
//! never a panic, a hang or a stack overflow.
#![no_main]
libfuzzer_sys::fuzz_target!(|data: &str| trm_fuzz_checks::srdf(data));
