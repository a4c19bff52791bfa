//! A MoveIt planning scene and motion plan request read from YAML (MotionBenchMaker's layout),
//! the scene turned into a trm world, both written back and read again, and a malformed scene
//! refused with its file and line.
//!
//! ```sh
//! cargo run -p trm-moveit --example scene_and_request
//! ```

use std::path::Path;

use trm_moveit::{MotionPlanRequest, PlanningScene};

const SCENE: &str = "\
name: shelf
world:
  collision_objects:
    - id: shelf
      primitives:
        - type: box
          dimensions: [0.6, 1.0, 0.04]
      primitive_poses:
        - position: [0.6, 0.0, 0.4]
          orientation: [0, 0, 0, 1]
    - id: can
      primitives:
        - type: cylinder
          dimensions: [0.12, 0.03]
      primitive_poses:
        - position: {x: 0.55, y: 0.1, z: 0.48}
          orientation: {x: 0, y: 0, z: 0, w: 1}
";

const REQUEST: &str = "\
group_name: panda_arm
allowed_planning_time: 1.0
start_state:
  joint_state:
    name: [panda_joint1, panda_joint2]
    position: [0.0, -0.5]
goal_constraints:
  - joint_constraints:
      - joint_name: panda_joint1
        position: 0.8
        tolerance_above: 0.001
        tolerance_below: 0.001
      - joint_name: panda_joint2
        position: 0.2
        tolerance_above: 0.001
        tolerance_below: 0.001
";

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let scene = PlanningScene::parse(SCENE, Path::new("scene.yaml"))?;
    let world = scene.to_world()?;
    for object in world.objects() {
        println!("{}: {:?}", object.name(), object.shape());
    }
    let request = MotionPlanRequest::parse(REQUEST, Path::new("request.yaml"))?;
    println!(
        "request for `{}`: {:?} → {:?}",
        request.group, request.goal.names, request.goal.positions
    );
    // what a writer emits, its reader takes back
    let again = PlanningScene::parse(&scene.to_yaml()?, Path::new("again.yaml"))?;
    assert_eq!(again.objects.len(), scene.objects.len());
    let again = MotionPlanRequest::parse(&request.to_yaml()?, Path::new("again.yaml"))?;
    assert_eq!(again.goal.positions, request.goal.positions);
    // a mistake is named with its file and line
    let bad = SCENE.replace("type: box", "type: torus");
    match PlanningScene::parse(&bad, Path::new("scene.yaml")).and_then(|s| s.to_world()) {
        Ok(_) => unreachable!("a torus is no MoveIt primitive"),
        Err(e) => println!("{e}"),
    }
    Ok(())
}
