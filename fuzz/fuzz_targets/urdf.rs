//! URDF text → robot model: any input gives a model or an error, never a panic or a hang.
#![no_main]
libfuzzer_sys::fuzz_target!(|data: &str| trm_fuzz_checks::urdf(data));
