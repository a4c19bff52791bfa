//! SRDF: MoveIt's format read into a model description (groups from joints, links, chains and
//! subgroups; group states; end effectors; disabled pairs), written back and read again
//! unchanged, and bad files refused with the file, the line and the closest names.

use std::collections::BTreeSet;

use trm_kinematics::srdf::Srdf;
use trm_kinematics::{ModelDescription, RobotModel};

fn models() -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../models")
}

/// An SRDF as MoveIt's setup assistant writes one, for the iCub upper body's URDF.
const ICUB_SRDF: &str = r#"<?xml version="1.0" encoding="UTF-8"?>
<!--This does not replace URDF, and is not an extension of URDF.-->
<robot name="icub_upper_body">
    <group name="right_arm">
        <chain base_link="chest" tip_link="r_hand"/>
    </group>
    <group name="head">
        <joint name="neck_pitch"/>
        <joint name="neck_roll"/>
        <joint name="neck_yaw"/>
    </group>
    <group name="right_forearm">
        <link name="r_forearm"/>
        <link name="r_wrist_1"/>
    </group>
    <group name="upper">
        <group name="right_arm"/>
        <group name="head"/>
    </group>
    <group_state name="ready" group="right_arm">
        <joint name="r_elbow" value="0.8"/>
        <joint name="r_shoulder_pitch" value="-0.5"/>
    </group_state>
    <end_effector name="right_palm" parent_link="r_hand" group="right_arm"/>
    <virtual_joint name="virtual_joint" type="floating" parent_frame="world" child_link="root_link"/>
    <disable_collisions link1="head" link2="neck_2" reason="Adjacent"/>
    <disable_collisions link1="r_hand" link2="r_forearm" reason="Never"/>
    <disable_collisions link1="chest" link2="l_shoulder_1" reason="Default"/>
    <link_sphere_approximation link="chest"/>
</robot>
"#;

fn urdf_model() -> RobotModel {
    RobotModel::load(models().join("icub_upper_body.urdf")).unwrap()
}

#[test]
fn moveit_srdf_becomes_groups_postures_frames_and_disabled_pairs() {
    let robot = urdf_model();
    let srdf = Srdf::parse(ICUB_SRDF, "icub.srdf").unwrap();
    let (description, report) = srdf
        .to_description(&robot, &ModelDescription::default())
        .unwrap();
    assert_eq!(report.counts, [4, 1, 1, 3], "{report}");
    assert!(
        report.notes.iter().any(|n| n.contains("floating")),
        "{report}"
    );
    let robot = robot.with_description(&description, None).unwrap();
    let names = |g: &str| -> Vec<String> {
        robot
            .group(g)
            .unwrap()
            .iter()
            .map(|&m| robot.motors()[m].name.clone())
            .collect()
    };
    // the chain chest → r_hand: the right arm's seven joints, in order
    assert_eq!(
        names("right_arm"),
        [
            "r_shoulder_pitch",
            "r_shoulder_roll",
            "r_shoulder_yaw",
            "r_elbow",
            "r_wrist_prosup",
            "r_wrist_pitch",
            "r_wrist_yaw"
        ]
    );
    assert_eq!(names("head"), ["neck_pitch", "neck_roll", "neck_yaw"]);
    // links: the joints above them
    assert_eq!(names("right_forearm"), ["r_wrist_prosup", "r_wrist_pitch"]);
    assert_eq!(names("upper").len(), 10);
    let ready = robot.posture("ready").unwrap();
    assert_eq!(ready[robot.motor_index("r_elbow").unwrap()], 0.8);
    assert_eq!(ready[robot.motor_index("r_shoulder_pitch").unwrap()], -0.5);
    let palm = robot.frame_id("right_palm").unwrap();
    assert_eq!(robot.tree().links[robot.frame_link(palm)].name, "r_hand");
    assert_eq!(robot.disabled_collisions().len(), 3);
}

#[test]
fn a_model_written_as_srdf_reads_back_the_same() {
    // the embedded description: coupled hands, groups, postures
    let described = RobotModel::load(models().join("icub_upper_body.ron")).unwrap();
    let disabled: Vec<_> = described
        .disabled_collisions()
        .iter()
        .map(|d| trm_kinematics::DisabledCollisionSpec {
            a: described.tree().links[d.links[0]].name.clone(),
            b: described.tree().links[d.links[1]].name.clone(),
            reason: d.reason,
        })
        .collect();
    let xml = Srdf::from_model(&described, &disabled).to_xml();
    let srdf = Srdf::parse(&xml, "written.srdf").unwrap();
    assert_eq!(
        Srdf::parse(&srdf.to_xml(), "again.srdf").unwrap().groups,
        srdf.groups
    );
    // read into the plain URDF (every joint a motor): a group holds the joints its motors drove
    let plain = urdf_model();
    let (description, _) = srdf
        .to_description(&plain, &ModelDescription::default())
        .unwrap();
    let plain = plain.with_description(&description, None).unwrap();
    for (name, motors) in described.groups() {
        let want: BTreeSet<String> = (0..described.num_joints())
            .filter(|&j| {
                described.couplings()[j]
                    .terms
                    .iter()
                    .any(|(m, _)| motors.contains(m))
            })
            .map(|j| described.joint(j).name.clone())
            .collect();
        let got: BTreeSet<String> = plain
            .group(name)
            .unwrap()
            .iter()
            .map(|&m| plain.motors()[m].name.clone())
            .collect();
        assert_eq!(got, want, "group {name}");
    }
    // postures: the same joint values
    let mut joints = vec![0.0; described.num_joints()];
    for name in described.posture_names() {
        described
            .motors_to_joints(described.posture(name).unwrap(), &mut joints)
            .unwrap();
        let mut plain_joints = vec![0.0; plain.num_joints()];
        plain
            .motors_to_joints(plain.posture(name).unwrap(), &mut plain_joints)
            .unwrap();
        for (a, b) in joints.iter().zip(&plain_joints) {
            assert!((a - b).abs() < 1e-12, "posture {name}");
        }
    }
    let pairs = |m: &RobotModel| -> BTreeSet<(usize, usize)> {
        m.disabled_collisions()
            .iter()
            .map(|d| (d.links[0].min(d.links[1]), d.links[0].max(d.links[1])))
            .collect()
    };
    assert_eq!(pairs(&plain), pairs(&described));
}

#[test]
fn bad_srdf_names_the_file_the_line_and_the_closest_names() {
    let robot = urdf_model();
    let apply = |text: &str| -> String {
        match Srdf::parse(text, "bad.srdf") {
            Err(e) => e.to_string(),
            Ok(s) => s
                .to_description(&robot, &ModelDescription::default())
                .unwrap_err()
                .to_string(),
        }
    };
    let e = apply(
        "<robot name=\"icub_upper_body\">\n  <group name=\"a\">\n    <joint name=\"r_elbw\"/>\n  </group>\n</robot>",
    );
    assert!(e.contains("bad.srdf:2") && e.contains("`r_elbow`"), "{e}");
    let e = apply("<robot name=\"icub_upper_body\">\n  <group name=\"a\">\n");
    assert!(e.contains("bad.srdf:") && e.contains("XML"), "{e}");
    let e =
        apply("<robot name=\"icub_upper_body\">\n<disable_collisions link1=\"chest\"/>\n</robot>");
    assert!(e.contains("bad.srdf:2") && e.contains("link2"), "{e}");

    let e = apply(
        "<robot name=\"icub_upper_body\"><group name=\"a\"><chain base_link=\"r_hand\" tip_link=\"torso_2\"/></group></robot>",
    );
    assert!(e.contains("not above"), "{e}");
    let e = apply(
        "<robot name=\"icub_upper_body\"><group name=\"a\"><joint name=\"r_elbow\"/></group><group_state name=\"s\" group=\"b\"><joint name=\"r_elbow\" value=\"1\"/></group_state></robot>",
    );
    assert!(e.contains("group `b`"), "{e}");
    let e = apply(
        "<robot name=\"icub_upper_body\"><group name=\"a\"><joint name=\"r_elbow\"/></group><group_state name=\"s\" group=\"a\"><joint name=\"r_elbow\" value=\"nan\"/></group_state></robot>",
    );
    assert!(e.contains("finite"), "{e}");
    // a group may include one defined later (as MoveIt reads it), not one defined nowhere or
    // one that includes it in turn
    let later = Srdf::parse(
        "<robot name=\"icub_upper_body\"><group name=\"u\"><group name=\"later\"/></group><group name=\"later\"><joint name=\"r_elbow\"/></group></robot>",
        "later.srdf",
    )
    .unwrap();
    let (d, _) = later
        .to_description(&robot, &ModelDescription::default())
        .unwrap();
    assert_eq!(d.groups.len(), 2);
    let e = apply(
        "<robot name=\"icub_upper_body\"><group name=\"u\"><group name=\"nowhere\"/></group></robot>",
    );
    assert!(e.contains("`nowhere`, which is not defined"), "{e}");
    let e = apply(
        "<robot name=\"icub_upper_body\"><group name=\"u\"><group name=\"v\"/></group><group name=\"v\"><group name=\"u\"/></group></robot>",
    );
    assert!(e.contains("includes it in turn"), "{e}");
    let e = apply(
        "<robot name=\"icub_upper_body\"><virtual_joint name=\"v\" type=\"fixed\" parent_frame=\"w\" child_link=\"chest\"/></robot>",
    );
    assert!(e.contains("root link"), "{e}");
    let e = apply("<model/>");
    assert!(e.contains("root element"), "{e}");
    // MoveIt's rules: the URDF's robot, each group and group state once, a state sets only
    // joints of its group
    let e = apply("<robot name=\"panda\">\n</robot>");
    assert!(
        e.contains("bad.srdf:1") && e.contains("`panda`") && e.contains("`icub_upper_body`"),
        "{e}"
    );
    let e = apply("<robot>\n</robot>");
    assert!(e.contains("bad.srdf:1") && e.contains("`name`"), "{e}");
    let e = apply(
        "<robot name=\"icub_upper_body\">\n<group name=\"a\"><joint name=\"r_elbow\"/></group>\n<group name=\"a\"><joint name=\"l_elbow\"/></group></robot>",
    );
    assert!(
        e.contains("bad.srdf:3") && e.contains("defined twice (first at line 2)"),
        "{e}"
    );
    let e = apply(
        "<robot name=\"icub_upper_body\"><group name=\"a\"><joint name=\"r_elbow\"/></group>\n<group_state name=\"s\" group=\"a\"><joint name=\"r_elbow\" value=\"1\"/></group_state>\n<group_state name=\"s\" group=\"a\"><joint name=\"r_elbow\" value=\"0\"/></group_state></robot>",
    );
    assert!(
        e.contains("bad.srdf:3") && e.contains("defined twice"),
        "{e}"
    );
    let e = apply(
        "<robot name=\"icub_upper_body\"><group name=\"a\"><joint name=\"r_elbow\"/><joint name=\"r_wrist_prosup\"/></group>\n<group name=\"b\"><group name=\"a\"/></group>\n<group_state name=\"s\" group=\"b\"><joint name=\"r_shoulder_roll\" value=\"1\"/></group_state></robot>",
    );
    assert!(
        e.contains("bad.srdf:3") && e.contains("not in group `b`"),
        "{e}"
    );
    // a state of a group that includes the other's joints through a subgroup is fine; as
    // MoveIt does, a pair naming a link the URDF lacks and an unknown group member are skipped
    // with a note
    let srdf = Srdf::parse(
        "<robot name=\"icub_upper_body\"><group name=\"a\"><joint name=\"r_elbow\"/><passive_joint name=\"r_wrist_yaw\"/></group>\n<group name=\"b\"><group name=\"a\"/></group>\n<group_state name=\"s\" group=\"b\"><joint name=\"r_elbow\" value=\"1\"/></group_state>\n<disable_collisions link1=\"chest\" link2=\"r_hnd\"/></robot>",
        "ok.srdf",
    )
    .unwrap();
    let (_, report) = srdf
        .to_description(&robot, &ModelDescription::default())
        .unwrap();
    let notes = report.to_string();
    assert!(
        notes.contains("line 4: disabled pair (chest, r_hnd) skipped")
            && notes.contains("`r_hand`")
            && notes.contains("line 1: <passive_joint> in group `a` skipped"),
        "{notes}"
    );
    // nesting a hundred thousand deep is refused before any parser recurses
    let deep = format!(
        "<robot name=\"icub_upper_body\">\n{}{}</robot>",
        "<group name=\"g\">".repeat(100_000),
        "</group>".repeat(100_000)
    );
    let e = apply(&deep);
    assert!(
        e.contains("bad.srdf:2") && e.contains("nested more than 256 deep"),
        "{e}"
    );
}
