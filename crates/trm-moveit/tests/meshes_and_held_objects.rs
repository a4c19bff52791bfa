//! MoveIt scenes and requests with triangle meshes (inline and from files) and attached (held)
//! collision objects: read, turned into a world and held objects, written and read back the
//! same; malformed ones are errors naming the line.

use std::path::Path;

use trm_collision::Shape;
use trm_moveit::{MotionPlanRequest, PlanningScene};

const SCENE: &str = r#"name: kitchen
robot_state:
  joint_state:
    name: [panda_joint1]
    position: [0.1]
  attached_collision_objects:
    - link_name: panda_hand
      touch_links: [panda_leftfinger, panda_rightfinger]
      object:
        header: {frame_id: panda_hand}
        id: cup
        primitives:
          - type: cylinder
            dimensions: [0.1, 0.04]
        primitive_poses:
          - position: [0, 0, 0.1]
            orientation: [0, 0, 0, 1]
world:
  collision_objects:
    - id: bowl
      pose: {position: [0.5, 0, 0.3], orientation: [0, 0, 0, 1]}
      meshes:
        - vertices:
            - {x: 0, y: 0, z: 0}
            - {x: 0.2, y: 0, z: 0}
            - {x: 0, y: 0.2, z: 0}
            - {x: 0.1, y: 0.1, z: 0.1}
          triangles:
            - vertex_indices: [0, 1, 2]
            - vertex_indices: [0, 1, 3]
            - vertex_indices: [1, 2, 3]
      mesh_poses:
        - position: [0, 0, 0]
          orientation: [0, 0, 0, 1]
    - id: table
      primitives: [{type: box, dimensions: [1, 1, 0.05]}]
      primitive_poses: [{position: [0.5, 0, 0.2], orientation: [0, 0, 0, 1]}]
      meshes:
        - resource: fold.stl
          scale: [0.5, 0.5, 0.5]
      mesh_poses: [{position: [0, 0, 0.5], orientation: [0, 0, 0, 1]}]
"#;

fn fold_stl(dir: &Path) {
    let mut stl = String::from("solid t\n");
    for f in [[0, 1, 2], [0, 2, 3]] {
        let v = [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 1]];
        stl.push_str("facet normal 0 0 0\n outer loop\n");
        for i in f {
            stl.push_str(&format!(" vertex {} {} {}\n", v[i][0], v[i][1], v[i][2]));
        }
        stl.push_str(" endloop\nendfacet\n");
    }
    stl.push_str("endsolid t\n");
    std::fs::write(dir.join("fold.stl"), stl).unwrap();
}

#[test]
fn scenes_with_meshes_and_held_objects_read_and_round_trip() {
    let dir = std::env::temp_dir().join(format!("trm-moveit-meshes-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    fold_stl(&dir);
    let origin = dir.join("scene.yaml");
    let scene = PlanningScene::parse(SCENE, &origin).unwrap();
    let world = scene.to_world().unwrap();
    let names: Vec<&str> = world.objects().iter().map(|o| o.name()).collect();
    assert_eq!(names, ["bowl", "table/0", "table/1"]);
    let Shape::Mesh { triangles, .. } = world.object("bowl").unwrap().shape() else {
        panic!("the bowl is a mesh");
    };
    assert_eq!(triangles.len(), 3);
    let Shape::Mesh { vertices, .. } = world.object("table/1").unwrap().shape() else {
        panic!("the file's mesh");
    };
    assert!(vertices.contains(&[0.5, 0.5, 0.0]), "scaled: {vertices:?}");
    assert_eq!(world.object("table/1").unwrap().pose().translation.z, 0.5);
    let [cup] = scene.attached.as_slice() else {
        panic!("one held object: {:?}", scene.attached);
    };
    assert_eq!(
        (cup.name.as_str(), cup.link.as_str()),
        ("cup", "panda_hand")
    );
    assert_eq!(cup.touch_links, ["panda_leftfinger", "panda_rightfinger"]);
    assert_eq!(cup.shapes[0].1.translation.z, 0.1);
    // written and read back: the same scene (the file's mesh now inline)
    let again = PlanningScene::parse(&scene.to_yaml().unwrap(), &origin).unwrap();
    assert_eq!(again.attached, scene.attached);
    assert_eq!(again.objects.len(), scene.objects.len());
    for (a, b) in again.objects.iter().zip(&scene.objects) {
        assert_eq!(a.primitives, b.primitives, "{}", a.id);
    }
    // a request's start state holds objects too
    let request = format!(
        "start_state:\n  joint_state:\n    name: [panda_joint1]\n    position: [0.1]\n{}goal_constraints:\n  - joint_constraints:\n      - joint_name: panda_joint1\n        position: 0.5\n",
        &SCENE[SCENE.find("  attached_collision_objects").unwrap()..SCENE.find("world:").unwrap()]
    );
    let parsed = MotionPlanRequest::parse(&request, Path::new("request.yaml")).unwrap();
    assert_eq!(parsed.attached, scene.attached);
    let written = parsed.to_yaml().unwrap();
    let back = MotionPlanRequest::parse(&written, Path::new("request.yaml")).unwrap();
    assert_eq!(back.attached, scene.attached);
    // nothing is written that the reader refuses: a held object at a NaN pose, or a capsule
    let mut lost = scene.clone();
    lost.attached[0].shapes[0].1.translation.vector.z = f64::NAN;
    let e = lost.to_yaml().unwrap_err().to_string();
    assert!(e.contains("not written") && e.contains("not finite"), "{e}");
    let mut odd = parsed.clone();
    odd.attached[0].shapes[0].0 = Shape::Capsule {
        radius: 0.1,
        length: 0.1,
    };
    let e = odd.to_yaml().unwrap_err().to_string();
    assert!(e.contains("not written") && e.contains("capsule"), "{e}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn malformed_meshes_and_held_objects_name_the_line() {
    let dir = std::env::temp_dir().join(format!("trm-moveit-bad-meshes-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    fold_stl(&dir);
    let cases = [
        (
            "vertex_indices: [0, 1, 3]",
            "vertex_indices: [0, 1, 9]",
            "beyond the 4 vertices",
        ),
        (
            "vertex_indices: [1, 2, 3]",
            "vertex_indices: [1, 2]",
            "three vertex indices",
        ),
        (
            "frame_id: panda_hand",
            "frame_id: world",
            "give the held object's poses in the frame",
        ),
        (
            "resource: fold.stl",
            "resource: gone.stl",
            "gone.stl` is not found",
        ),
        (
            "      mesh_poses: [{position: [0, 0, 0.5], orientation: [0, 0, 0, 1]}]\n",
            "",
            "1 meshes and 0 mesh_poses",
        ),
        ("        id: cup", "        id: \"\"", "empty id"),
    ];
    for (from, to, says) in cases {
        let text = SCENE.replacen(from, to, 1);
        assert_ne!(text, SCENE, "{from}");
        let e = PlanningScene::parse(&text, &dir.join("scene.yaml"))
            .unwrap_err()
            .to_string();
        assert!(e.contains(says) && e.contains("scene.yaml:"), "{from}: {e}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}
