//! World (RON): a world or a located error.
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|text: &str| {
    let _ = trm_collision::World::from_ron(text, "fuzz.ron");
});
