//! Viewer scene (JSON): a scene or an error; one that reads is written back and reads again.
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|text: &str| {
    if let Ok(scene) = trm_view::Scene::from_json(text) {
        let written = scene.to_json().expect("a scene that reads is written");
        trm_view::Scene::from_json(&written).expect("and reads back");
    }
});
