//! MoveIt YAML (a planning scene and, from the same text, a motion plan request): a scene and
//! its world, a request, or a located error; never a panic, a hang or a stack overflow. A
//! scene that reads is written and read back to the same objects.
#![no_main]
use std::path::Path;

use libfuzzer_sys::fuzz_target;
use trm_plan::moveit::{MotionPlanRequest, PlanningScene};

fuzz_target!(|text: &str| {
    if let Ok(scene) = PlanningScene::parse(text, Path::new("fuzz.yaml")) {
        let _ = scene.to_world();
        let again = PlanningScene::parse(&scene.to_yaml().expect("a scene that reads is written"), Path::new("again.yaml"));
        let again = again.expect("what the writer writes, the reader reads");
        assert_eq!(again.objects.len(), scene.objects.len());
        assert_eq!(again.allowed_collisions, scene.allowed_collisions);
    }
    let _ = MotionPlanRequest::parse(text, Path::new("fuzz.yaml"));
});
