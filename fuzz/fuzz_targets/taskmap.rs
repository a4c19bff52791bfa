//! Task-map file (JSON): a task map or an error; one that reads is written back and reads again.
#![no_main]
use libfuzzer_sys::fuzz_target;
use std::path::Path;

fuzz_target!(|text: &str| {
    let path = Path::new("fuzz.taskmap.json");
    if let Ok(map) = trm_taskmap::TaskMap::from_json(text, path) {
        let written = map.to_json(path).expect("a task map that reads is written");
        let again = trm_taskmap::TaskMap::from_json(&written, path).expect("and reads back");
        assert_eq!(map.points, again.points);
    }
});
