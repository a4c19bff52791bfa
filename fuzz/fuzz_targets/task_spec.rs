//! Task spec (RON) → problem (model, costs, task, world, solver): a problem or a located error.
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|text: &str| {
    let base = std::path::Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../specs"));
    let _ = trm_tasks::Problem::from_ron(text, "fuzz.ron", base);
});
