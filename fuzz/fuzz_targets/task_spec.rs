//! Task spec (RON) → problem (model, costs, task, world, solver): a problem or a located error.
#![no_main]
libfuzzer_sys::fuzz_target!(|data: &str| trm_fuzz_checks::task_spec(data));
