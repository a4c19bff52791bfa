//! Bad input gets an error that names the file, the element and the fix; never a panic.

use trm_kinematics::{KinematicsError, ModelDescription, RobotModel};

const ORIGIN: &str = "robot.urdf";

fn urdf(body: &str) -> String {
    format!("<?xml version=\"1.0\"?>\n<robot name=\"r\">\n{body}\n</robot>\n")
}

fn revolute(name: &str, parent: &str, child: &str, extra: &str) -> String {
    format!(
        "<joint name=\"{name}\" type=\"revolute\">\n  <parent link=\"{parent}\"/>\n  <child link=\"{child}\"/>\n  <axis xyz=\"0 0 1\"/>\n  <limit lower=\"-1\" upper=\"1\" effort=\"1\" velocity=\"1\"/>{extra}\n</joint>"
    )
}

/// Loads and returns the error text, checking it names the file and offers a fix.
fn error_of(text: &str) -> String {
    let err = RobotModel::from_urdf_str(text, ORIGIN).expect_err("must be rejected");
    let message = err.to_string();
    assert!(message.contains(ORIGIN), "no file name in: {message}");
    assert!(message.contains("fix:"), "no fix in: {message}");
    message
}

#[test]
fn malformed_xml_is_reported_with_the_file() {
    let message = error_of("<robot name=\"r\"><link name=\"a\"></robot>");
    assert!(message.contains("malformed URDF"), "{message}");
    let message = error_of("not xml at all");
    assert!(message.contains("malformed URDF"), "{message}");
}

#[test]
fn nesting_a_hundred_thousand_deep_is_an_error_not_a_stack_overflow() {
    let n = 100_000;
    let body = format!(
        "<link name=\"a\">\n{}{}</link>",
        "<visual>".repeat(n),
        "</visual>".repeat(n)
    );
    let message = error_of(&urdf(&body));
    assert!(
        message.contains("line 4") && message.contains("nested more than 256 deep"),
        "{message}"
    );
}

#[test]
fn missing_child_link_names_the_joint_line_and_the_closest_link() {
    let text = urdf(&format!(
        "<link name=\"base\"/>\n<link name=\"upper_arm\"/>\n{}",
        revolute("shoulder", "base", "uper_arm", "")
    ));
    let message = error_of(&text);
    assert!(message.contains("<joint name=\"shoulder\">"), "{message}");
    assert!(
        message.contains("child link `uper_arm` is not defined"),
        "{message}"
    );
    assert!(message.contains("upper_arm"), "{message}");
    assert!(
        message.contains("robot.urdf:5:"),
        "line of the joint element: {message}"
    );
}

#[test]
fn missing_parent_link_is_an_error() {
    let text = urdf(&format!(
        "<link name=\"a\"/>\n{}",
        revolute("j", "ghost", "a", "")
    ));
    assert!(error_of(&text).contains("parent link `ghost` is not defined"));
}

#[test]
fn two_roots_are_an_error_listing_them() {
    let text = urdf("<link name=\"a\"/>\n<link name=\"b\"/>");
    let message = error_of(&text);
    assert!(message.contains("2 root links (a, b)"), "{message}");
}

#[test]
fn a_cycle_is_an_error() {
    let body = format!(
        "<link name=\"root\"/><link name=\"a\"/><link name=\"b\"/>\n{}\n{}\n{}",
        revolute("j0", "root", "a", ""),
        revolute("j1", "a", "b", ""),
        revolute("j2", "b", "a", "")
    );
    let message = error_of(&urdf(&body));
    assert!(
        message.contains("already has parent joint") || message.contains("cycle"),
        "{message}"
    );
    // A pure cycle without a root.
    let body = format!(
        "<link name=\"a\"/><link name=\"b\"/>\n{}\n{}",
        revolute("j1", "a", "b", ""),
        revolute("j2", "b", "a", "")
    );
    assert!(error_of(&urdf(&body)).contains("cycle"));
}

#[test]
fn duplicate_names_are_errors() {
    assert!(error_of(&urdf("<link name=\"a\"/><link name=\"a\"/>")).contains("defined twice"));
    let body = format!(
        "<link name=\"a\"/><link name=\"b\"/><link name=\"c\"/>\n{}\n{}",
        revolute("j", "a", "b", ""),
        revolute("j", "a", "c", "")
    );
    assert!(error_of(&urdf(&body)).contains("defined twice"));
}

#[test]
fn lower_above_upper_is_an_error_that_says_to_swap() {
    let body = "<link name=\"a\"/><link name=\"b\"/>\n<joint name=\"j\" type=\"revolute\"><parent link=\"a\"/><child link=\"b\"/><limit lower=\"1\" upper=\"-1\" effort=\"1\" velocity=\"1\"/></joint>";
    let message = error_of(&urdf(body));
    assert!(
        message.contains("lower is above upper") && message.contains("swap"),
        "{message}"
    );
}

#[test]
fn nan_and_infinite_numbers_are_errors() {
    for bad in [
        "<origin xyz=\"0 nan 0\"/>",
        "<origin rpy=\"inf 0 0\"/>",
        "<axis xyz=\"NaN 0 1\"/>",
    ] {
        let body = format!(
            "<link name=\"a\"/><link name=\"b\"/>\n<joint name=\"j\" type=\"revolute\"><parent link=\"a\"/><child link=\"b\"/>{bad}<limit lower=\"-1\" upper=\"1\" effort=\"1\" velocity=\"1\"/></joint>"
        );
        let message = error_of(&urdf(&body));
        assert!(message.contains("not finite"), "{bad}: {message}");
    }
    let body = "<link name=\"a\"/><link name=\"b\"/>\n<joint name=\"j\" type=\"revolute\"><parent link=\"a\"/><child link=\"b\"/><limit lower=\"nan\" upper=\"1\" effort=\"1\" velocity=\"1\"/></joint>";
    assert!(error_of(&urdf(body)).contains("not finite"));
}

#[test]
fn zero_axis_and_unsupported_joint_types_are_errors() {
    let body = "<link name=\"a\"/><link name=\"b\"/>\n<joint name=\"j\" type=\"revolute\"><parent link=\"a\"/><child link=\"b\"/><axis xyz=\"0 0 0\"/><limit lower=\"-1\" upper=\"1\" effort=\"1\" velocity=\"1\"/></joint>";
    assert!(error_of(&urdf(body)).contains("zero <axis>"));
    let body = "<link name=\"a\"/><link name=\"b\"/>\n<joint name=\"j\" type=\"floating\"><parent link=\"a\"/><child link=\"b\"/></joint>";
    assert!(error_of(&urdf(body)).contains("does not support"));
}

#[test]
fn mimic_of_an_unknown_joint_suggests_the_right_one() {
    let body = format!(
        "<link name=\"a\"/><link name=\"b\"/><link name=\"c\"/>\n{}\n{}",
        revolute("finger_a", "a", "b", ""),
        revolute(
            "finger_b",
            "a",
            "c",
            "<mimic joint=\"finger_aa\" multiplier=\"-1\"/>"
        )
    );
    let message = error_of(&urdf(&body));
    assert!(
        message.contains("<mimic joint=\"finger_aa\"> names no joint")
            && message.contains("finger_a"),
        "{message}"
    );
}

fn description_error(ron: &str) -> String {
    let urdf = urdf(&format!(
        "<link name=\"a\"/><link name=\"b\"/><link name=\"c\"/>\n{}\n{}",
        revolute("j1", "a", "b", ""),
        revolute("j2", "b", "c", "")
    ));
    let err = ModelDescription::from_ron(ron, "model.ron")
        .and_then(|d| RobotModel::from_parts(&urdf, ORIGIN, &d, Some((ron, "model.ron"))))
        .expect_err("must be rejected");
    let message = err.to_string();
    assert!(message.contains("model.ron"), "no file name in: {message}");
    assert!(message.contains("fix:"), "no fix in: {message}");
    message
}

#[test]
fn malformed_description_names_line_and_column() {
    let message =
        description_error("(urdf: \"x.urdf\",\n  motors: [(name: \"m\", lower: 0.0)],\n)");
    assert!(message.contains("model.ron:2:"), "{message}");
    let message = description_error("(urdf: \"x.urdf\", colour: 3)");
    assert!(message.contains("colour"), "{message}");
}

#[test]
fn coupling_of_an_unknown_joint_or_motor_is_an_error() {
    let message = description_error("(urdf: \"x\",\n couplings: [(joint: \"j2x\", motors: [])])");
    assert!(
        message.contains("names no joint") && message.contains("`j2`"),
        "{message}"
    );
    let message = description_error(
        "(urdf: \"x\",\n couplings: [(joint: \"j2\", motors: [(\"curl\", 1.0)])])",
    );
    assert!(
        message.contains("motor `curl`") && message.contains("model.ron:2"),
        "{message}"
    );
}

#[test]
fn coupling_that_leaves_the_joint_limits_is_an_error() {
    let message = description_error(
        "(urdf: \"x\", motors: [(name: \"m\", lower: 0.0, upper: 3.0)], couplings: [(joint: \"j2\", motors: [(\"m\", 1.0)])])",
    );
    assert!(message.contains("outside its URDF limits"), "{message}");
}

#[test]
fn other_description_mistakes_are_errors() {
    for (ron, needle) in [
        (
            "(urdf: \"x\", motors: [(name: \"m\", lower: 1.0, upper: 0.0)])",
            "above upper",
        ),
        (
            "(urdf: \"x\", motors: [(name: \"m\", lower: 0.0, upper: 1.0)])",
            "drives no joint",
        ),
        (
            "(urdf: \"x\", frames: [(name: \"f\", link: \"bb\")])",
            "no link or earlier frame",
        ),
        (
            "(urdf: \"x\", frames: [(name: \"b\", link: \"a\")])",
            "name of a link",
        ),
        (
            "(urdf: \"x\", groups: [(name: \"g\", members: [\"j3\"])])",
            "no motor or earlier group",
        ),
        (
            "(urdf: \"x\", postures: [(name: \"p\", values: {\"j1\": 5.0})])",
            "outside its limits",
        ),
        (
            "(urdf: \"x\", postures: [(name: \"p\", values: {\"j9\": 0.0})])",
            "which is no motor",
        ),
        (
            "(urdf: \"x\",\n planning: (range: Some(-0.5)))",
            "-0.5 is not a positive finite number of radians",
        ),
        (
            "(urdf: \"x\",\n planning: (resolution: Some(0.0)))",
            "planning.resolution",
        ),
        (
            "(urdf: \"x\",\n planning: (domain_radius: Some(-2.0)))",
            "planning.domain_radius",
        ),
        ("(urdf: \"x\", planning: (step: Some(1.0)))", "step"),
        (
            "(urdf: \"x\", motion_limits: {\"j3\": (acceleration: Some(1.0))})",
            "which is no motor",
        ),
        (
            "(urdf: \"x\", motion_limits: {\"j1\": (acceleration: Some(-1.0))})",
            "acceleration limit of -1",
        ),
        (
            "(urdf: \"x\", motion_limits: {\"j1\": (jerk: Some(inf))})",
            "jerk limit",
        ),
        (
            "(urdf: \"x\", motion_limits: {\"j1\": (accel: Some(1.0))})",
            "accel",
        ),
    ] {
        let message = description_error(ron);
        assert!(message.contains(needle), "{ron}: {message}");
    }
}

#[test]
fn a_missing_file_is_an_io_error_naming_it() {
    let err = RobotModel::load("/nonexistent/robot.urdf").unwrap_err();
    assert!(matches!(err, KinematicsError::Io { .. }));
    assert!(err.to_string().contains("/nonexistent/robot.urdf"));
}

#[test]
fn official_icub_urdf_loads_without_its_meshes() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../models/icub-visuomanip/model.urdf");
    let model = RobotModel::load(path).unwrap();
    assert_eq!(model.num_joints(), 75);
    assert_eq!(model.num_links(), 102);
    assert_eq!(model.motors().len(), 75);
}

#[test]
fn description_errors_point_at_their_entry_not_the_first_line_naming_it() {
    // `m` is named in a coupling on line 2 before its (wrong) declaration on line 3
    let message = description_error(
        "(urdf: \"x\",\n couplings: [(joint: \"j2\", motors: [(\"m\", 1.0)])],\n motors: [(name: \"m\", lower: 1.0, upper: 0.0)])",
    );
    assert!(
        message.contains("model.ron:3: motors[0] (\"m\"): lower 1 is above upper 0"),
        "{message}"
    );
    // the second disabled pair is the bad one; its links appear on line 2 already
    let message = description_error(
        "(urdf: \"x\",\n disabled_collisions: [(a: \"a\", b: \"b\", reason: user),\n   (a: \"b\", b: \"b\", reason: user)])",
    );
    assert!(
        message.contains("model.ron:3: disabled_collisions[1]"),
        "{message}"
    );
}

#[test]
fn a_namespace_the_xml_layer_chokes_on_is_an_error_not_a_panic() {
    // found by fuzzing (fuzz/artifacts/urdf/crash-693f…): urdf-rs's XML layer panicked with "No
    // namespace prefix bound"
    let text = String::from_utf8_lossy(include_bytes!("fixtures/fuzz_urdf_namespace.urdf"));
    let e = RobotModel::from_urdf_str(&text, "fuzz.urdf").unwrap_err();
    assert!(matches!(e, KinematicsError::MalformedUrdf { .. }), "{e}");
    let message = e.to_string();
    assert!(
        message.starts_with("fuzz.urdf") && message.contains("namespace"),
        "{message}"
    );
    // and the model loads as before afterwards
    assert!(RobotModel::from_urdf_str(&urdf(r#"<link name="a"/>"#), "ok.urdf").is_ok());
}

#[test]
fn a_bad_planning_setting_is_located() {
    let message = description_error("(urdf: \"x\",\n planning: (range: Some(-0.5)))");
    assert!(message.contains("model.ron:2"), "{message}");
}

#[test]
fn motion_limits_replace_the_urdf_s_and_add_accelerations() {
    let urdf = urdf(&format!(
        "<link name=\"a\"/><link name=\"b\"/>\n{}",
        revolute("j1", "a", "b", "")
    ));
    let ron = "(urdf: \"x\", motion_limits: {\"j1\": (velocity: Some(0.5), acceleration: Some(2.0), jerk: Some(40.0))})";
    let d = ModelDescription::from_ron(ron, "model.ron").unwrap();
    let robot = RobotModel::from_parts(&urdf, ORIGIN, &d, Some((ron, "model.ron"))).unwrap();
    let limits = &robot.motors()[0].limits;
    assert_eq!(
        (limits.velocity, limits.acceleration, limits.jerk),
        (0.5, 2.0, 40.0)
    );
    let plain = RobotModel::from_urdf_str(&urdf, ORIGIN).unwrap();
    assert!(plain.motors()[0].limits.acceleration.is_infinite());
}
