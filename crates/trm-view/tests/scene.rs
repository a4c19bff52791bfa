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
    let newer = json.replace("\"version\":1", "\"version\":99");
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
