//! Mesh bytes (STL, OBJ, COLLADA through mesh-loader; the first byte picks the format) → the
//! vertices of a convex hull or an error, never a panic, a hang or a stack overflow.
#![no_main]
libfuzzer_sys::fuzz_target!(|data: &[u8]| trm_fuzz_checks::mesh(data));
