//! Task-map spec (RON): a spec or a located error.
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|text: &str| {
    let _ = trm_taskmap::TaskMapSpec::from_ron(text, "fuzz.ron", std::path::Path::new("."));
});
