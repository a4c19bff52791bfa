//! Roadmap file (JSON): a map or an error; a map that reads is written back and reads again
//! unchanged.
#![no_main]
use libfuzzer_sys::fuzz_target;
use std::path::Path;

fuzz_target!(|text: &str| {
    let path = Path::new("fuzz.map.json");
    if let Ok(map) = trm_roadmap::Roadmap::from_json(text, path) {
        let _ = map.summary();
        let written = map.to_json(path).expect("a map that reads is written");
        let again = trm_roadmap::Roadmap::from_json(&written, path).expect("and reads back");
        assert_eq!(map, again);
    }
});
