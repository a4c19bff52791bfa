//! MoveIt YAML (a planning scene and, from the same text, a motion plan request): a scene and
//! its world, a request, or a located error; never a panic, a hang or a stack overflow. A
//! scene that reads is written and read back to the same objects.
#![no_main]
libfuzzer_sys::fuzz_target!(|data: &str| trm_fuzz_checks::moveit(data));
