//! The JSON scene shows the right thing: counts, and link poses equal to the kinematics.

use trm_collision::{CollisionModel, World};
use trm_view::Scene;

fn icub_scene(frames: usize) -> (Scene, Vec<Vec<f64>>) {
    let model = trm_models::icub_upper_body();
    let collision = CollisionModel::new(&model).unwrap();
    let mut scene = Scene::new("test", &collision);
    let home = model.posture("home").unwrap().to_vec();
    let mut postures = Vec::new();
    for i in 0..frames {
        let mut q = home.clone();
        let s = i as f64 / frames.max(2) as f64;
        for (k, m) in model.motors().iter().enumerate() {
            q[k] =
                (q[k] + 0.3 * s * ((k as f64) * 1.7).sin()).clamp(m.limits.lower, m.limits.upper);
        }
        scene.add_frame(i as f64 * 0.1, &q).unwrap();
        postures.push(q);
    }
    (scene, postures)
}

#[test]
fn counts_match_the_model_the_world_and_the_map() {
    let (mut scene, postures) = icub_scene(5);
    let model = trm_models::icub_upper_body();
    let collision = CollisionModel::new(&model).unwrap();
    assert_eq!(scene.bodies.len(), collision.bodies().len());
    assert_eq!(scene.frames.len(), 5);
    assert!(
        scene
            .frames
            .iter()
            .all(|f| f.poses.len() == scene.links.len() && f.joints.len() == model.num_joints())
    );
    let world = World::load(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../specs/worlds/table.ron"
    ))
    .unwrap();
    scene.set_world(&world);
    assert_eq!(scene.world.len(), world.len());
    let points: Vec<[f64; 3]> = (0..5).map(|i| [i as f64, 0.0, 0.0]).collect();
    scene
        .set_map(points, vec![1.0; 5], &postures, vec![[0, 1], [1, 2]])
        .unwrap();
    let map = scene.map.as_ref().unwrap();
    assert_eq!(
        (map.points.len(), map.edges.len(), map.joints.len()),
        (5, 2, 5)
    );
    // bad maps are refused
    assert!(
        scene
            .set_map(vec![[0.0; 3]], vec![], &postures[..1], vec![])
            .is_err()
    );
    assert!(
        scene
            .set_map(vec![[0.0; 3]], vec![0.0], &postures[..1], vec![[0, 3]])
            .is_err()
    );
}

#[test]
fn link_poses_at_every_frame_equal_the_kinematics() {
    let (scene, postures) = icub_scene(4);
    let model = trm_models::icub_upper_body();
    let mut poses = model.pose_buffer();
    for (frame, q) in scene.frames.iter().zip(&postures) {
        model.all_active().forward(q, &mut poses).unwrap();
        for (slot, &l) in scene.link_index.iter().enumerate() {
            let want = poses.poses()[l];
            let got = frame.poses[slot];
            let t = want.translation.vector;
            assert!(
                (t.x - got[0]).abs() < 1e-6
                    && (t.y - got[1]).abs() < 1e-6
                    && (t.z - got[2]).abs() < 1e-6
            );
            let q = want.rotation.coords;
            let dot = q.x * got[3] + q.y * got[4] + q.z * got[5] + q.w * got[6];
            assert!(dot.abs() > 1.0 - 1e-6, "{} rotation", scene.links[slot]);
        }
    }
    // a body's name tells its link
    for b in &scene.bodies {
        assert!(b.name.starts_with(&scene.links[b.link]));
    }
}

#[test]
fn scenes_round_trip_and_name_their_format() {
    let (scene, _) = icub_scene(2);
    let json = scene.to_json().unwrap();
    let back = Scene::from_json(&json).unwrap();
    assert_eq!(back.frames, scene.frames);
    assert_eq!(back.bodies, scene.bodies);
    // version 1 (before visuals and held objects) still reads
    let old = json.replace("\"version\":2", "\"version\":1");
    assert_eq!(Scene::from_json(&old).unwrap().version, trm_view::VERSION);
    let newer = json.replace("\"version\":2", "\"version\":99");
    assert!(
        Scene::from_json(&newer)
            .unwrap_err()
            .to_string()
            .contains("version 99")
    );
    // a scene read back cannot add frames (it has no model) and says so
    let mut back = back;
    assert!(back.add_frame(0.0, &[0.0; 41]).is_err());
}

#[test]
fn scenes_whose_parts_do_not_fit_are_neither_written_nor_read() {
    let (scene, _) = icub_scene(2);
    let json = scene.to_json().unwrap();
    let mut broken = Vec::new();
    let mut s = scene.clone();
    s.bodies[0].link = s.links.len();
    broken.push((s, "bodies[0]"));
    let mut s = scene.clone();
    s.frames[1].poses.pop();
    broken.push((s, "frames[1]"));
    let mut s = scene.clone();
    s.frames[0].joints[3] = f64::NAN;
    broken.push((s, "frames[0]"));
    let mut s = scene.clone();
    s.set_path(vec![[0.0, f64::INFINITY, 0.0]]);
    broken.push((s, "path"));
    for (s, what) in broken {
        let e = s.to_json().unwrap_err().to_string();
        assert!(e.starts_with(what), "{e}");
    }
    // the reader refuses the same, naming the file
    let dir = std::env::temp_dir().join(format!("trm-scene-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("s.scene.json");
    let first_body = json.find("\"link\":").unwrap();
    let end = first_body + json[first_body..].find(',').unwrap();
    std::fs::write(
        &path,
        format!("{}\"link\":9999{}", &json[..first_body], &json[end..]),
    )
    .unwrap();
    let e = Scene::load(&path).unwrap_err().to_string();
    assert!(e.contains("s.scene.json: bodies[0]"), "{e}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn the_page_inlines_the_bundle_or_falls_back_to_the_pinned_cdn() {
    let (scene, _) = icub_scene(1);
    let offline = scene
        .to_html(Some("/* bundle */ console.log('</script>')"))
        .unwrap();
    assert!(offline.contains("/* bundle */") && !offline.contains("cdn.jsdelivr.net"));
    assert_eq!(
        offline.matches("</script>").count(),
        2,
        "the bundle cannot close its tag"
    );
    let online = scene.to_html(None).unwrap();
    assert!(online.contains(&format!("three@{}", trm_view::THREE_VERSION)));
    assert!(online.contains("import * as THREE from 'three'"));
    // the pinned version is the one viewer/package.json installs
    let package = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../viewer/package.json"
    ))
    .unwrap();
    assert!(package.contains(&format!("\"three\": \"{}\"", trm_view::THREE_VERSION)));
}

/// A robot whose links look like something: a box in a colour named at robot level, a mesh
/// whose material library gives two colours, a mesh whose file is missing and one that is
/// malformed.
fn looks_robot(dir: &std::path::Path) -> trm_kinematics::RobotModel {
    std::fs::create_dir_all(dir.join("meshes")).unwrap();
    std::fs::write(
        dir.join("meshes/part.obj"),
        "mtllib part.mtl\nv 0 0 0\nv 0.1 0 0\nv 0 0.1 0\nv 0 0 0.1\nusemtl red\nf 1 3 2\nf 1 2 4\nusemtl blue\nf 1 4 3\nf 2 3 4\n",
    )
    .unwrap();
    std::fs::write(
        dir.join("meshes/broken.dae"),
        "<COLLADA><library_geometries>",
    )
    .unwrap();
    std::fs::write(
        dir.join("meshes/part.mtl"),
        "newmtl red\nKd 1 0 0\nnewmtl blue\nKd 0 0 1\n",
    )
    .unwrap();
    let urdf = r#"<robot name="looks">
  <material name="orange"><color rgba="1 0.5 0 1"/></material>
  <link name="base">
    <visual><geometry><box size="0.2 0.2 0.1"/></geometry><material name="orange"/></visual>
    <visual><geometry><sphere radius="0.05"/></geometry><material name="bytes"><color rgba="255 128 0 1"/></material></visual>
    <collision><geometry><box size="0.2 0.2 0.1"/></geometry></collision>
  </link>
  <link name="arm">
    <visual><origin xyz="0 0 0.05"/><geometry><mesh filename="meshes/part.obj" scale="2 2 2"/></geometry></visual>
    <visual><geometry><mesh filename="meshes/gone.stl"/></geometry></visual>
    <visual><geometry><mesh filename="meshes/broken.dae"/></geometry></visual>
  </link>
  <joint name="j" type="revolute"><parent link="base"/><child link="arm"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
</robot>"#;
    let path = dir.join("looks.urdf");
    std::fs::write(&path, urdf).unwrap();
    trm_kinematics::RobotModel::from_urdf_file(&path).unwrap()
}

#[test]
fn the_robot_looks_as_its_urdf_visuals_say() {
    let dir = std::env::temp_dir().join(format!("trm-view-looks-{}", std::process::id()));
    let model = looks_robot(&dir);
    let collision = CollisionModel::new(&model).unwrap();
    let mut scene = Scene::new("looks", &collision);
    scene.add_frame(0.0, &[0.5]).unwrap();
    // the arm has no collision body but a visual: it is a link of the scene, posed per frame
    assert_eq!(scene.links, ["base", "arm"]);
    assert_eq!(scene.frames[0].poses.len(), 2);
    // the box in the robot-level colour; the mesh in its material library's two colours,
    // scaled, each part with its own vertices
    assert_eq!(scene.visuals.len(), 4, "{:?}", scene.visuals);
    assert_eq!(scene.visuals[0].color, [1.0, 0.5, 0.0, 1.0]);
    // a colour written in 0..=255 is drawn saturated, not refused
    assert_eq!(scene.visuals[1].color, [1.0, 1.0, 0.0, 1.0]);
    let colors: Vec<[f32; 4]> = scene.visuals[2..].iter().map(|v| v.color).collect();
    assert!(colors.contains(&[1.0, 0.0, 0.0, 1.0]) && colors.contains(&[0.0, 0.0, 1.0, 1.0]));
    for v in &scene.visuals[2..] {
        assert_eq!(v.link, 1);
        assert_eq!(v.local[2], 0.05);
        let trm_collision::Shape::Mesh {
            vertices,
            triangles,
        } = &v.shape
        else {
            panic!("{:?}", v.shape)
        };
        assert_eq!(triangles.len(), 2);
        assert!(vertices.len() <= 4);
        assert!(vertices.iter().flatten().any(|&c| c == 0.2));
    }
    // the missing file is named with where it was looked for, the malformed one with the
    // reader's complaint: listed, not an error
    assert_eq!(
        scene.missing_visuals.len(),
        2,
        "{:?}",
        scene.missing_visuals
    );
    assert!(
        scene.missing_visuals[0].contains("gone.stl") && scene.missing_visuals[0].contains("arm"),
        "{:?}",
        scene.missing_visuals
    );
    assert!(scene.missing_visuals[1].contains("broken.dae"));
    // and it all round-trips
    let back = Scene::from_json(&scene.to_json().unwrap()).unwrap();
    assert_eq!(back.visuals, scene.visuals);
    assert_eq!(back.missing_visuals, scene.missing_visuals);
    // a visual with a colour out of range or a broken mesh is neither written nor read
    let mut bad = scene.clone();
    bad.visuals[0].color[0] = 2.0;
    assert!(
        bad.to_json()
            .unwrap_err()
            .to_string()
            .contains("visuals[0]")
    );
    let mut bad = scene.clone();
    if let trm_collision::Shape::Mesh { triangles, .. } = &mut bad.visuals[2].shape {
        triangles[0][0] = 99;
    }
    let e = bad.to_json().unwrap_err().to_string();
    assert!(
        e.contains("visuals[2].shape") && e.contains("beyond"),
        "{e}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn held_objects_are_marked_and_drawn_with_the_robot() {
    let model = trm_models::icub_upper_body();
    let collision = CollisionModel::new(&model).unwrap();
    let held = collision
        .with_attached(trm_collision::AttachedObject {
            name: "cup".into(),
            link: "r_hand".into(),
            shapes: vec![(
                trm_collision::Shape::Cylinder {
                    radius: 0.03,
                    length: 0.1,
                },
                trm_kinematics::nalgebra::Isometry3::translation(0.0, 0.0, -0.05),
            )],
            touch_links: vec![],
        })
        .unwrap();
    let scene = Scene::new("holding", &held);
    let cup: Vec<_> = scene.bodies.iter().filter(|b| b.held.is_some()).collect();
    assert_eq!(cup.len(), 1);
    assert_eq!(cup[0].name, "cup");
    assert_eq!(scene.links[cup[0].link], "r_hand");
    assert_eq!(scene.bodies.len(), collision.bodies().len() + 1);
}

/// The official iCub (iCubGenova04, its visuals icub-models' STL meshes) looks as its
/// URDF says: every visual loads, on the link it belongs to. Runs where `TRM_ICUB_MESHES`
/// holds icub-models' `share` directory (`.ci/run` installs it); elsewhere the missing meshes
/// are listed, not an error.
#[test]
fn the_official_icub_looks_as_its_visuals_say() {
    let robot = trm_models::icub_genova04();
    let Some(dir) = std::env::var_os("TRM_ICUB_MESHES") else {
        let collision = CollisionModel::from_bodies(
            &robot,
            Vec::new(),
            trm_collision::AllowedCollisionMatrix::all_checked(robot.num_links()),
        )
        .unwrap();
        let scene = Scene::new("iCub", &collision);
        assert!(scene.visuals.is_empty());
        assert!(scene.missing_visuals[0].contains("package://iCub/meshes"));
        eprintln!("TRM_ICUB_MESHES is not set: checked only that the missing meshes are listed");
        return;
    };
    let options = trm_collision::CollisionOptions {
        package_paths: vec![dir.into()],
        ..Default::default()
    };
    let collision = CollisionModel::with_options(&robot, &options).unwrap();
    let mut scene = Scene::new("iCub", &collision);
    assert!(
        scene.missing_visuals.is_empty(),
        "{:?}",
        scene.missing_visuals
    );
    let with_visuals = robot
        .tree()
        .links
        .iter()
        .filter(|l| !l.visuals.is_empty())
        .count();
    let drawn: std::collections::HashSet<usize> = scene.visuals.iter().map(|v| v.link).collect();
    assert_eq!(drawn.len(), with_visuals);
    let elements: usize = robot.tree().links.iter().map(|l| l.visuals.len()).sum();
    assert!(elements >= 39 && scene.visuals.len() >= elements);
    scene.add_frame(0.0, &robot.neutral_motors()).unwrap();
    let back = Scene::from_json(&scene.to_json().unwrap()).unwrap();
    assert_eq!(back.visuals.len(), scene.visuals.len());
}
