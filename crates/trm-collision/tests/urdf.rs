//! Collision models from URDF text: primitives, meshes through package paths, the
//! allowed-collision matrix, and clear errors for bad input.

use std::path::PathBuf;

use trm_collision::{
    AcmOptions, CollisionError, CollisionModel, CollisionOptions, DisableReason, Shape,
    generate_acm,
};
use trm_kinematics::{ModelDescription, RobotModel};

fn fixtures() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/meshes")
}

/// base → upper (revolute) → mid (fixed, no geometry) → tool; `geometry` is the tool's.
fn arm(tool_geometry: &str) -> String {
    format!(
        r#"<robot name="arm">
  <link name="base"><collision><geometry><box size="0.2 0.2 0.1"/></geometry></collision></link>
  <link name="upper"><collision><origin xyz="0 0 0.25"/><geometry><cylinder radius="0.03" length="0.5"/></geometry></collision></link>
  <link name="mid"/>
  <link name="tool">
    <collision><origin xyz="0 0 0.5"/><geometry>{tool_geometry}</geometry></collision>
  </link>
  <joint name="j1" type="revolute"><parent link="base"/><child link="upper"/><origin xyz="0 0 0.05"/>
    <axis xyz="0 1 0"/><limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
  <joint name="j2" type="fixed"><parent link="upper"/><child link="mid"/><origin xyz="0 0 0.5"/></joint>
  <joint name="j3" type="revolute"><parent link="mid"/><child link="tool"/>
    <axis xyz="0 1 0"/><limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
</robot>"#
    )
}

fn model(urdf: &str) -> RobotModel {
    RobotModel::from_urdf_str(urdf, "arm.urdf").unwrap()
}

#[test]
fn meshes_resolve_through_package_paths_and_become_scaled_convex_hulls() {
    let urdf = arm(r#"<mesh filename="package://demo_pkg/meshes/cube.stl" scale="0.1 0.2 0.3"/>"#);
    let robot = model(&urdf);
    let options = CollisionOptions {
        package_paths: vec![fixtures()],
        ..Default::default()
    };
    let collision = CollisionModel::with_options(&robot, &options).unwrap();
    let tool = &collision.bodies()[collision.body_index("tool").unwrap()];
    let Shape::Convex { points } = &tool.shape else {
        panic!("{:?}", tool.shape)
    };
    assert_eq!(points.len(), 8);
    let max = points.iter().fold([0.0f64; 3], |m, p| {
        [m[0].max(p[0]), m[1].max(p[1]), m[2].max(p[2])]
    });
    assert_eq!(max, [0.1, 0.2, 0.3]);
    // the tool folded back onto the base collides with it; upright it does not
    let mut poses = robot.pose_buffer();
    let mut placed = collision.placed_bodies();
    robot.forward_joints(&[0.0, 0.0], &mut poses).unwrap();
    collision.place(&poses, &mut placed);
    assert_eq!(collision.count_self(&placed), 0);
    robot.forward_joints(&[0.0, 3.0], &mut poses).unwrap();
    collision.place(&poses, &mut placed);
    assert_eq!(collision.count_self(&placed), 1);
}

#[test]
fn relative_mesh_paths_start_at_the_urdf_directory() {
    let dir = std::env::temp_dir().join(format!("trm-collision-rel-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::copy(
        fixtures().join("demo_pkg/meshes/cube.stl"),
        dir.join("cube.stl"),
    )
    .unwrap();
    std::fs::write(dir.join("arm.urdf"), arm(r#"<mesh filename="cube.stl"/>"#)).unwrap();
    let robot = RobotModel::from_urdf_file(dir.join("arm.urdf")).unwrap();
    let collision = CollisionModel::new(&robot).unwrap();
    assert_eq!(collision.bodies().len(), 3);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn links_are_adjacent_through_links_without_geometry() {
    let robot = model(&arm(r#"<sphere radius="0.05"/>"#));
    let c = CollisionModel::new(&robot).unwrap();
    let link = |n: &str| robot.tree().link_index(n).unwrap();
    assert_eq!(
        c.acm().reason(link("upper"), link("tool")),
        Some(DisableReason::Adjacent)
    );
    assert_eq!(
        c.acm().reason(link("base"), link("upper")),
        Some(DisableReason::Adjacent)
    );
    assert!(c.acm().is_checked(link("base"), link("tool")));
    assert_eq!(c.num_checked_link_pairs(), 1);
}

#[test]
fn generated_matrices_are_reproducible_and_respect_forced_pairs() {
    let urdf = arm(r#"<sphere radius="0.05"/>"#);
    let robot = model(&urdf);
    let c = CollisionModel::new(&robot).unwrap();
    let settings = AcmOptions {
        samples: 10_000,
        seed: 7,
        ..Default::default()
    };
    let on = |threads: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| generate_acm(&c, &settings).unwrap())
    };
    let (a, b) = (on(1), on(2));
    assert_eq!(a.acm, b.acm);
    assert_eq!(a.collision_counts, b.collision_counts);
    // base/tool do meet when the arm folds back: the pair stays checked
    let (base, tool) = (
        robot.tree().link_index("base").unwrap(),
        robot.tree().link_index("tool").unwrap(),
    );
    assert!(a.acm.is_checked(base, tool));
    assert!(
        a.collision_counts
            .iter()
            .any(|(p, n)| *p == [base, tool] && *n > 0)
    );
    // a forced pair stays checked even if it is adjacent
    let description = ModelDescription::from_ron(
        r#"(urdf: "arm.urdf", enabled_collisions: [("upper", "tool")],
            disabled_collisions: [(a: "base", b: "tool", reason: user)])"#,
        "arm.ron",
    )
    .unwrap();
    let robot = RobotModel::from_parts(&urdf, "arm.urdf", &description, None).unwrap();
    let c = CollisionModel::new(&robot).unwrap();
    let upper = robot.tree().link_index("upper").unwrap();
    assert!(c.acm().is_checked(upper, tool));
    assert_eq!(c.acm().reason(base, tool), Some(DisableReason::User));
    let g = generate_acm(&c, &settings).unwrap();
    assert!(g.acm.is_checked(upper, tool));
    assert_eq!(g.acm.reason(base, tool), Some(DisableReason::User));
}

#[test]
fn a_missing_mesh_names_the_file_the_element_and_every_path_tried() {
    let urdf = arm(r#"<mesh filename="package://demo_pkg/meshes/nope.stl"/>"#);
    let options = CollisionOptions {
        package_paths: vec![fixtures()],
        ..Default::default()
    };
    let e = CollisionModel::with_options(&model(&urdf), &options).unwrap_err();
    assert!(matches!(e, CollisionError::MeshNotFound { .. }));
    let text = e.to_string();
    assert!(
        text.starts_with("arm.urdf:5: <collision> of <link name=\"tool\">"),
        "{text}"
    );
    assert!(
        text.contains("demo_pkg/meshes/nope.stl") && text.contains("package paths"),
        "{text}"
    );
}

#[test]
fn an_unreadable_mesh_is_a_clear_error() {
    let urdf = arm(r#"<mesh filename="package://demo_pkg/meshes/garbage.stl"/>"#);
    let options = CollisionOptions {
        package_paths: vec![fixtures()],
        ..Default::default()
    };
    let e = CollisionModel::with_options(&model(&urdf), &options).unwrap_err();
    assert!(matches!(e, CollisionError::MeshUnreadable { .. }), "{e}");
    assert!(e.to_string().contains("garbage.stl"), "{e}");
}

#[test]
fn degenerate_shapes_name_the_file_line_and_link() {
    for (geometry, says) in [
        (r#"<sphere radius="0"/>"#, "sphere radius 0"),
        (r#"<box size="0.1 -0.1 0.1"/>"#, "box size -0.1"),
        (
            r#"<capsule radius="0.1" length="-1"/>"#,
            "capsule length -1",
        ),
    ] {
        let e = CollisionModel::new(&model(&arm(geometry)))
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with("arm.urdf:5: <collision> of <link name=\"tool\">: ") && e.contains(says),
            "{e}"
        );
    }
}

#[test]
fn unknown_links_in_the_collision_lists_are_named_with_suggestions() {
    let urdf = arm(r#"<sphere radius="0.05"/>"#);
    let description = ModelDescription::from_ron(
        "(urdf: \"arm.urdf\",\n disabled_collisions: [(a: \"base\", b: \"tol\", reason: never)])",
        "arm.ron",
    )
    .unwrap();
    let e = RobotModel::from_parts(&urdf, "arm.urdf", &description, Some(("(urdf: \"arm.urdf\",\n disabled_collisions: [(a: \"base\", b: \"tol\", reason: never)])", "arm.ron")))
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("arm.ron:2") && e.contains("did you mean `tool`"),
        "{e}"
    );
}

/// A model description's `package_paths` (relative to the description) reach the mesh loader
/// of every user of the model, `CollisionModel::new` included; without them the mesh is not
/// found and the error says where to add it.
#[test]
fn package_paths_of_a_description_reach_the_mesh_loader() {
    let dir = std::env::temp_dir().join(format!("trm-collision-pkg-{}", std::process::id()));
    std::fs::create_dir_all(dir.join("robot")).unwrap();
    let urdf = arm(r#"<mesh filename="package://demo_pkg/meshes/cube.stl"/>"#);
    std::fs::write(dir.join("robot/arm.urdf"), &urdf).unwrap();
    let fixtures = fixtures().display().to_string();
    std::fs::write(
        dir.join("robot/arm.ron"),
        format!("(urdf: \"arm.urdf\", package_paths: [\"{fixtures}\"])"),
    )
    .unwrap();
    let robot = RobotModel::load(dir.join("robot/arm.ron")).unwrap();
    assert_eq!(robot.package_paths().len(), 1);
    let collision = CollisionModel::new(&robot).unwrap();
    assert!(matches!(
        collision.bodies()[collision.body_index("tool").unwrap()].shape,
        Shape::Convex { .. }
    ));
    // relative to the description
    std::fs::create_dir_all(dir.join("pkgs")).unwrap();
    std::fs::write(
        dir.join("robot/relative.ron"),
        "(urdf: \"arm.urdf\", package_paths: [\"../pkgs\"])",
    )
    .unwrap();
    let relative = RobotModel::load(dir.join("robot/relative.ron")).unwrap();
    assert_eq!(relative.package_paths(), &[dir.join("robot/../pkgs")]);
    let e = CollisionModel::new(&relative).unwrap_err().to_string();
    assert!(e.contains("package paths"), "{e}");
    let _ = std::fs::remove_dir_all(&dir);
}
