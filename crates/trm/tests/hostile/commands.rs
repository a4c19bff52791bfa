//! SRDF files, command-specific flags and files, and outputs in the way: symlinks, devices,
//! directories and paths under regular files.

use std::path::Path;

use crate::harness::*;

/// The cases, with the valid files in `dir`.
pub fn cases(dir: &Path) -> Vec<Case> {
    let root = root();
    let read = |p: &Path| std::fs::read_to_string(p).unwrap();
    let at = |p: &str| root.join(p);
    let spec = at("specs/reach.ron").to_string_lossy().to_string();
    let spec = spec.as_str();
    let mut cases = Vec::new();
    // SRDF files: malformed, unknown names, missing attributes, wrong values
    for (k, (what, text, names)) in [
        ("truncated XML", "<robot name=\"r\">\n  <group name=\"a\">", "srdf_0.srdf"),
        ("an unknown joint", "<robot name=\"icub_upper_body\">\n<group name=\"a\"><joint name=\"r_elbw\"/></group>\n</robot>", "r_elbow"),
        ("an unknown link in a group", "<robot name=\"icub_upper_body\">\n<group name=\"a\"><link name=\"r_hnd\"/></group>\n</robot>", "r_hand"),
        ("a missing attribute", "<robot name=\"icub_upper_body\">\n<end_effector name=\"e\" group=\"a\"/>\n</robot>", "parent_link"),
        ("a non-number", "<robot name=\"icub_upper_body\"><group name=\"a\"><joint name=\"r_elbow\"/></group><group_state name=\"s\" group=\"a\"><joint name=\"r_elbow\" value=\"x\"/></group_state></robot>", "srdf_4.srdf"),
        ("another root", "<urdf/>", "srdf_5.srdf"),
        ("a reversed chain", "<robot name=\"icub_upper_body\"><group name=\"a\"><chain base_link=\"r_hand\" tip_link=\"chest\"/></group></robot>", "srdf_6.srdf"),
        ("binary", "\u{0}\u{1}\u{2}", "srdf_7.srdf"),
        ("several values for a URDF joint", "<robot name=\"icub_upper_body\"><group name=\"a\"><joint name=\"r_elbow\"/></group><group_state name=\"s\" group=\"a\"><joint name=\"r_elbow\" value=\"0.1 0.2\"/></group_state></robot>", "r_elbow"),
        ("a NaN among a floating base's values", "<robot name=\"icub_upper_body\"><group name=\"a\"><joint name=\"r_elbow\"/></group><group_state name=\"s\" group=\"a\"><joint name=\"root_joint\" value=\"0 0 NaN 0 0 0 1\"/></group_state></robot>", "srdf_9.srdf"),
        ("a robot name other than the URDF's", "<robot name=\"panda\">\n</robot>", "icub_upper_body"),
        ("a group defined twice", "<robot name=\"icub_upper_body\">\n<group name=\"a\"><joint name=\"r_elbow\"/></group>\n<group name=\"a\"><joint name=\"l_elbow\"/></group>\n</robot>", "srdf_11.srdf:3"),
        ("a group state setting a joint outside its group", "<robot name=\"icub_upper_body\"><group name=\"a\"><joint name=\"r_elbow\"/></group>\n<group_state name=\"s\" group=\"a\"><joint name=\"l_elbow\" value=\"0.1\"/></group_state></robot>", "srdf_12.srdf:2"),
        ("groups nested 100 000 deep", "DEEP", "srdf_13.srdf:2"),
    ]
    .into_iter()
    .enumerate()
    {
        let name = format!("srdf_{k}.srdf");
        let deep = format!(
            "<robot name=\"icub_upper_body\">\n{}{}</robot>",
            "<group name=\"g\">".repeat(100_000),
            "</group>".repeat(100_000)
        );
        std::fs::write(dir.join(&name), if text == "DEEP" { &deep } else { text }).unwrap();
        cases.push(Case {
            what: format!("model-info --srdf with {what}"),
            args: ["model-info", "icub_upper_body.urdf", "--srdf", name.as_str()]
                .map(String::from)
                .to_vec(),
            names: names.into(),
        });
    }
    cases.extend(file_flag_cases(
        &["model-info"],
        "--srdf",
        &["no_such.srdf", ".", "map.json"],
    ));
    cases.extend(file_flag_cases(
        &["model-info"],
        "--write-srdf",
        &[".", "map.json/x.srdf"],
    ));
    cases.push(Case {
        what: "model-info --write-description without --srdf".into(),
        args: [
            "model-info",
            "icub_upper_body.urdf",
            "--write-description",
            "d.ron",
        ]
        .map(String::from)
        .to_vec(),
        names: "--srdf".into(),
    });
    std::fs::write(
        dir.join("empty.srdf"),
        "<robot name=\"icub_upper_body\"></robot>",
    )
    .unwrap();
    cases.push(Case {
        what: "model-info --write-description of a .ron model".into(),
        args: [
            "model-info",
            "icub_upper_body.ron",
            "--srdf",
            "empty.srdf",
            "--write-description",
            "d.ron",
        ]
        .map(String::from)
        .to_vec(),
        names: "--write-description".into(),
    });
    for out in [".", "beside.ros.yaml", "linked.ros.yaml"] {
        for command in [
            vec!["fit-proxies", "icub_upper_body.urdf", "--out"],
            vec![
                "model-info",
                "icub_upper_body.urdf",
                "--srdf",
                "empty.srdf",
                "--write-description",
            ],
            vec!["model-info", "--write-srdf"],
        ] {
            cases.push(Case {
                what: format!("{} into {out}", command.join(" ")),
                args: command
                    .iter()
                    .map(|s| s.to_string())
                    .chain([out.to_string()])
                    .collect(),
                names: out.into(),
            });
        }
    }
    cases.push(Case {
        what: "fit-proxies of a model without meshes".into(),
        args: ["fit-proxies", "icub_upper_body.urdf"]
            .map(String::from)
            .to_vec(),
        names: "icub_upper_body.urdf".into(),
    });
    for (extra, names) in [
        (vec!["--spheres", "0"], "--spheres"),
        (vec!["--spheres", "x"], "--spheres"),
        (vec!["--spheres", "4"], "icub_upper_body.urdf"),
    ] {
        cases.push(Case {
            what: format!("fit-proxies {}", extra.join(" ")),
            args: ["fit-proxies", "icub_upper_body.urdf"]
                .into_iter()
                .chain(extra.iter().copied())
                .map(String::from)
                .collect(),
            names: names.into(),
        });
    }
    for bad in ["no_such.urdf", ".", "map.json", "world.ron"] {
        cases.push(Case {
            what: format!("fit-proxies {bad}"),
            args: ["fit-proxies", bad].map(String::from).to_vec(),
            names: bad.into(),
        });
    }
    cases.push(Case {
        what: "plan --repair without --world".into(),
        args: [
            "plan",
            "--map",
            "map.json",
            "--to",
            "0.1,0.2,0.3",
            "--repair",
        ]
        .map(String::from)
        .to_vec(),
        names: "--world".into(),
    });
    cases.push(Case {
        what: "model-info --ros-postures of a model without named postures".into(),
        args: [
            "model-info",
            "icub_upper_body.urdf",
            "--ros-postures",
            "p.ros.yaml",
        ]
        .map(String::from)
        .to_vec(),
        names: "named postures".into(),
    });
    cases.extend(file_flag_cases(
        &["repair-map", "map.json", "--out", "r.json"],
        "--world",
        &["no_such.ron", ".", "map.json", "posture.json"],
    ));
    for bad in ["no_such.json", ".", "posture.json", "world.ron"] {
        cases.push(Case {
            what: format!("repair-map {bad}"),
            args: ["repair-map", bad, "--world", "world.ron", "--out", "r.json"]
                .map(String::from)
                .to_vec(),
            names: bad.into(),
        });
    }
    cases.extend(flag_cases(
        &[
            "repair-map",
            "map.json",
            "--world",
            "world.ron",
            "--out",
            "r.json",
        ],
        "--threads",
        &["0", "-1", "x"],
    ));
    cases.extend(flag_cases(
        &["model-info", "--ros-postures", "p.ros.yaml"],
        "--posture-seconds",
        &["0", "-1", "NaN", "inf", "x"],
    ));
    cases.extend(file_flag_cases(
        &["map-info", "map.json"],
        "--world",
        &["no_such.ron", ".", "map.json", "posture.json"],
    ));
    let plan = ["plan", "--map", "map.json"];
    cases.extend(flag_cases(
        &plan,
        "--to",
        &[
            "nan,0,0",
            "1,2",
            "a,b,c",
            "1,2,3,4",
            "inf,0,0",
            "no_such.json",
        ],
    ));
    let plan_to = ["plan", "--map", "map.json", "--to", "0.1,0.2,0.3"];
    cases.extend(flag_cases(
        &plan_to,
        "--tolerance",
        &["-1", "NaN", "inf", "0"],
    ));
    cases.extend(flag_cases(
        &plan_to,
        "--velocity",
        &["0", "-1", "NaN", "inf"],
    ));
    cases.extend(flag_cases(
        &plan_to,
        "--exact-tolerance",
        &["0", "-1", "NaN", "inf", "x"],
    ));
    cases.extend(flag_cases(&plan_to, "--seed", &["-5", "x"]));
    cases.extend(flag_cases(&plan_to, "--out", &["t.json"]));
    cases.extend(file_flag_cases(
        &plan_to,
        "--from",
        &["no_such.json", "map.json"],
    ));
    cases.extend(file_flag_cases(
        &plan_to,
        "--world",
        &["no_such.ron", "map.json"],
    ));
    cases.extend(file_flag_cases(
        &["plan", "--to", "0,0,0"],
        "--map",
        &[
            "no_such.json",
            "posture.json",
            "world.ron",
            "/dev/zero",
            ".",
        ],
    ));
    let compare = ["compare-optimisers", "--spec", spec, "--out-dir", "cmp"];
    cases.extend(flag_cases(
        &compare,
        "--runs",
        &["0", "-1", "18446744073709551616"],
    ));
    cases.extend(flag_cases(&compare, "--runs", &["100000000"]));
    cases.extend(flag_cases(
        &compare,
        "--algos",
        &["", "xnes,nope", "xnes,xnes"],
    ));
    cases.extend(flag_cases(&compare, "--max-evals", &["0", "-1"]));
    cases.extend(flag_cases(&compare, "--seed", &["18446744073709551615"]));
    let optimise = ["optimise"];
    cases.extend(flag_cases(&optimise, "--algo", &["nope", ""]));
    cases.extend(flag_cases(
        &optimise,
        "--function",
        &["nope", "rotated-nope"],
    ));
    cases.extend(flag_cases(&optimise, "--dim", &["0", "-1", "100000000"]));
    cases.extend(flag_cases(&optimise, "--target", &["NaN", "x"]));
    cases.extend(flag_cases(
        &optimise,
        "--runs",
        &["0", "18446744073709551615"],
    ));
    cases.extend(flag_cases(
        &["optimise", "--runs", "3"],
        "--seed",
        &["18446744073709551615"],
    ));
    let map_json = read(&dir.join("map.json"));
    cases.extend(file_cases(
        dir,
        &dir.join("map.json"),
        vec![(
            "a version written as a string".into(),
            map_json.replacen("\"version\":1", "\"version\":\"1\"", 1),
        )],
        &["map-info", "{}"],
    ));
    cases.extend(flag_cases(
        &optimise,
        "--max-evals",
        &["0", "18446744073709551615"],
    ));
    cases.extend(flag_cases(&optimise, "--sigma", &["0", "-1", "NaN", "inf"]));
    cases.extend(flag_cases(
        &optimise,
        "--population",
        &["0", "1", "10000000000000"],
    ));
    let stand = ["stand-up", "--out", "su"];
    cases.extend(flag_cases(
        &stand,
        "--rollouts",
        &["0", "-1", "18446744073709551615"],
    ));
    cases.extend(flag_cases(
        &stand,
        "--bootstrap-rollouts",
        &["18446744073709551615"],
    ));
    let solve = ["solve", spec];
    cases.extend(flag_cases(&solve, "--algo", &["nope", "XNES2"]));
    cases.extend(flag_cases(
        &solve,
        "--max-evals",
        &["0", "-1", "18446744073709551615"],
    ));
    let stick = at("specs/taskmaps/stick.ron").to_string_lossy().to_string();
    let grasp = ["reach-grasp", stick.as_str()];
    cases.extend(flag_cases(&grasp, "--at", &["1,2", "nan,0,0", "0,0,0,0,0"]));
    cases.extend(flag_cases(
        &grasp,
        "--iterations",
        &["0", "-1", "18446744073709551615"],
    ));
    cases.extend(file_flag_cases(
        &grasp,
        "--world",
        &["no_such.ron", "map.json", "/dev/zero", "."],
    ));
    let acm = ["gen-acm"];
    cases.extend(flag_cases(
        &acm,
        "--samples",
        &["0", "-1", "18446744073709551615"],
    ));
    cases.extend(flag_cases(
        &acm,
        "--always-fraction",
        &["-0.1", "1.5", "NaN"],
    ));
    cases.extend(flag_cases(
        &["gen-acm", "--samples", "10"],
        "--posture",
        &["hom", "no_such_posture"],
    ));
    // --write-description needs a .ron description and a place beside it
    let description = at("models/panda/panda.ron").to_string_lossy().to_string();
    for (what, args, names) in [
        (
            "gen-acm --write-description of a URDF model",
            vec![
                "gen-acm",
                "icub_upper_body.urdf",
                "--samples",
                "10",
                "--write-description",
                "o.ron",
            ],
            "--write-description",
        ),
        (
            "gen-acm --write-description away from the description",
            vec![
                "gen-acm",
                description.as_str(),
                "--samples",
                "10",
                "--write-description",
                "elsewhere.ron",
            ],
            "elsewhere.ron",
        ),
    ] {
        cases.push(Case {
            what: what.into(),
            args: args.iter().map(|s| s.to_string()).collect(),
            names: names.into(),
        });
    }
    cases.extend(file_flag_cases(
        &["view", "--out", "v.html"],
        "--posture",
        &["no_such.json", "map.json", "/dev/zero"],
    ));
    cases.extend(file_flag_cases(
        &["view", "--out", "v.html"],
        "--map",
        &["posture.json"],
    ));
    cases.extend(file_flag_cases(
        &["view", "--out", "v.html"],
        "--world",
        &["map.json", "/dev/zero"],
    ));
    cases.extend(file_flag_cases(
        &["fk"],
        "--configs",
        &["map.json", "no_such.json", "."],
    ));

    // output paths: a symlink, a device, a directory, a path under a regular file
    std::os::unix::fs::symlink("/etc/hostname", dir.join("link.json")).unwrap();
    std::fs::create_dir_all(dir.join("a_directory")).unwrap();
    for out in [
        "link.json",
        "/dev/null",
        "a_directory",
        "posture.json/x.json",
    ] {
        let commands = [
            vec!["solve", spec, "--out"],
            vec!["build-map", spec, "--points", "2", "--out"],
            vec![
                "build-map",
                spec,
                "--points",
                "2",
                "--checkpoint-every",
                "1",
                "--checkpoint",
            ],
            vec!["plan", "--map", "map.json", "--to", "0.1,0.2,0.3", "--out"],
            vec!["fk", "--configs", "configs.json", "--out"],
            vec!["collide", "--configs", "configs.json", "--out"],
            vec!["gen-acm", "--samples", "10", "--out"],
            vec!["view", "--out"],
            vec!["explore-task-map", stick.as_str(), "--out"],
            vec!["model-info", "--ros-postures"],
            vec!["repair-map", "map.json", "--world", "world.ron", "--out"],
        ];
        cases.extend(output_cases(&commands, out));
    }
    cases.extend(output_cases(
        &[
            vec![
                "compare-optimisers",
                "--spec",
                spec,
                "--runs",
                "1",
                "--out-dir",
            ],
            vec!["stand-up", "--rollouts", "1", "--out"],
        ],
        "posture.json",
    ));

    // files written beside --out (the ROS 2 trajectory) that are a directory or a symlink
    std::fs::create_dir_all(dir.join("beside.ros.yaml")).unwrap();
    std::os::unix::fs::symlink("/etc/hostname", dir.join("linked.ros.yaml")).unwrap();
    std::fs::create_dir_all(dir.join("stand_up_out/trajectory.ros.yaml")).unwrap();
    for (command, names) in [
        (
            vec![
                "plan",
                "--map",
                "map.json",
                "--to",
                "0.1,0.2,0.3",
                "--out",
                "beside.csv",
            ],
            "beside.ros.yaml",
        ),
        (
            vec![
                "plan",
                "--map",
                "map.json",
                "--to",
                "0.1,0.2,0.3",
                "--out",
                "linked.csv",
            ],
            "linked.ros.yaml",
        ),
        (
            vec!["reach-grasp", stick.as_str(), "--out", "beside.csv"],
            "beside.ros.yaml",
        ),
        (
            vec!["stand-up", "--rollouts", "1", "--out", "stand_up_out"],
            "trajectory.ros.yaml",
        ),
    ] {
        cases.push(Case {
            what: format!("{} with {names} in the way", command[0]),
            args: command.iter().map(|s| s.to_string()).collect(),
            names: names.into(),
        });
    }
    cases
}
