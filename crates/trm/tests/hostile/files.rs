//! Malformed input files: RON specs, worlds and models, URDF, JSON and CSV, each through a
//! command that reads it.

use std::path::Path;

use crate::harness::*;

/// The cases, with the valid files in `dir`.
pub fn cases(dir: &Path) -> Vec<Case> {
    let root = root();
    let read = |p: &Path| std::fs::read_to_string(p).unwrap();
    let at = |p: &str| root.join(p);
    let non_finite = ["NaN", "inf", "-inf"];
    let mut cases = Vec::new();
    // RON files, each through a command that reads it
    let stick_spec = at("specs/taskmaps/stick.ron").to_string_lossy().to_string();
    for (source, args) in [
        (
            at("specs/reach.ron"),
            vec!["solve", "{}", "--out", "o.json"],
        ),
        (at("specs/fig6/c_bimanual_grab.ron"), vec!["solve", "{}"]),
        (at("specs/table_iii/posture1.ron"), vec!["solve", "{}"]),
        (
            dir.join("world.ron"),
            vec!["collide", "--configs", "configs.json", "--world", "{}"],
        ),
        (
            at("specs/wholebody/standup.ron"),
            vec!["stand-up", "{}", "--out", "standup"],
        ),
        (
            at("specs/taskmaps/stick.ron"),
            vec!["explore-task-map", "{}", "--out", "o.taskmap.json"],
        ),
        (
            dir.join("world.ron"),
            vec![
                "reach-grasp",
                stick_spec.as_str(),
                "--iterations",
                "1",
                "--world",
                "{}",
            ],
        ),
        (
            at("specs/scenarios/sliding_box.ron"),
            vec!["scenario", "{}", "--map", "map.json", "--out-dir", "sc"],
        ),
    ] {
        let text = read(&source);
        cases.extend(file_cases(
            dir,
            &source,
            mutations(&text, false, 12, &non_finite),
            &args,
        ));
    }
    // values that parse but make no sense: zero or huge counts, inverted or degenerate ranges,
    // duplicated names
    let solve = ["solve", "{}"];
    let stand = ["stand-up", "{}", "--out", "su"];
    let collide = ["collide", "--configs", "configs.json", "--world", "{}"];
    let explore = ["explore-task-map", "{}"];
    let scenario = ["scenario", "{}", "--map", "map.json", "--out-dir", "sc"];
    let sliding = "specs/scenarios/sliding_box.ron";
    for (source, from, to, args) in [
        (
            "specs/reach.ron",
            "max_points: 400",
            "max_points: 0",
            &solve[..],
        ),
        (
            "specs/reach.ron",
            "max_points: 400",
            "max_points: 99999999999",
            &solve[..],
        ),
        ("specs/reach.ron", "searches: 4", "searches: 0", &solve[..]),
        (
            "specs/reach.ron",
            "(150, 0.15)",
            "(10000000000000, 0.15)",
            &solve[..],
        ),
        ("specs/reach.ron", "(30, 0.03)", "(30, -0.03)", &solve[..]),
        (
            "specs/reach.ron",
            "seed: 0)",
            "seed: 0, population: Some(10000000000000))",
            &solve[..],
        ),
        (
            "specs/reach.ron",
            "seed: 0)",
            "seed: 0, max_evaluations: 0)",
            &solve[..],
        ),
        ("specs/reach.ron", "weight: 5.0", "weight: -5.0", &solve[..]),
        (
            "specs/reach.ron",
            "radius: 0.05",
            "radius: -0.05",
            &solve[..],
        ),
        (
            "specs/reach.ron",
            "axis: (0, 1, 0)",
            "axis: (0, 0, 0)",
            &solve[..],
        ),
        (
            "specs/reach.ron",
            "\"l_palm_center\"",
            "\"l_palm_centre\"",
            &solve[..],
        ),
        ("specs/reach.ron", "\"xnes\"", "\"xnse\"", &solve[..]),
        (
            "specs/reach.ron",
            "\"torso\": 3.0",
            "\"torso\": 3.0, \"torso\": 1.0",
            &solve[..],
        ),
        (
            "specs/reach.ron",
            "size: (0.5, 0.8, 0.04)",
            "size: (0.5, 0.0, 0.04)",
            &solve[..],
        ),
        (
            "specs/worlds/reach_with_box.ron",
            "\"new_box\"",
            "\"table\"",
            &collide[..],
        ),
        (
            "specs/wholebody/standup.ron",
            "dt: 0.01",
            "dt: 1e-300",
            &stand[..],
        ),
        (
            "specs/wholebody/standup.ron",
            "dt: 0.01",
            "dt: 0.00001",
            &stand[..],
        ),
        (
            "specs/wholebody/standup.ron",
            "rbfs: 5",
            "rbfs: 0",
            &stand[..],
        ),
        (
            "specs/worlds/reach_with_box.ron",
            "\"new_box\"",
            "\"\"",
            &collide[..],
        ),
        (
            "specs/worlds/reach_with_box.ron",
            "\"new_box\"",
            "\"  \"",
            &collide[..],
        ),
        (
            "specs/wholebody/standup.ron",
            "rbfs: 5",
            "rbfs: 100000000",
            &stand[..],
        ),
        (
            "specs/wholebody/standup.ron",
            "\"standing\"",
            "\"seated\"",
            &stand[..],
        ),
        (
            "specs/wholebody/standup.ron",
            "end: 4.5",
            "end: 1.0",
            &stand[..],
        ),
        (
            "specs/taskmaps/stick.ron",
            "samples: 5000",
            "samples: 0",
            &explore[..],
        ),
        (sliding, "duration: 6.0", "duration: 0.0", &scenario[..]),
        (sliding, "rate: 10.0", "rate: 1e9", &scenario[..]),
        (sliding, "rate: 10.0", "rate: -10.0", &scenario[..]),
        (
            sliding,
            "to: [-0.3, 0.15, 0.1]",
            "to: [-0.3, 0.15]",
            &scenario[..],
        ),
        (sliding, "to: [-0.3, 0.15, 0.1]", "to: []", &scenario[..]),
        (sliding, "(t: 1.5, to:", "(t: -1.5, to:", &scenario[..]),
        (sliding, "(t: 2.5, xyz:", "(t: 7.5, xyz:", &scenario[..]),
        (sliding, "name: \"can\"", "name: \"table\"", &scenario[..]),
        (
            sliding,
            "name: \"can\"",
            "name: \"sliding_box\"",
            &scenario[..],
        ),
        (
            sliding,
            "appear: 2.0",
            "appear: 2.0, vanish: Some(1.0)",
            &scenario[..],
        ),
        (sliding, "radius: 0.03", "radius: 0.0", &scenario[..]),
        (sliding, "goals: [", "goals: [], goal: [", &scenario[..]),
        (sliding, "duration: 6.0,", "", &scenario[..]),
    ] {
        let text = read(&at(source));
        assert!(text.contains(from), "{source} has no `{from}`");
        cases.extend(file_cases(
            dir,
            &at(source),
            vec![(format!("`{from}` → `{to}`"), text.replacen(from, to, 1))],
            args,
        ));
    }

    // the model description (next to its URDF) and the URDF
    let text = read(&dir.join("icub_upper_body.ron"));
    cases.extend(file_cases(
        dir,
        &dir.join("icub_upper_body.ron"),
        mutations(&text, false, 10, &non_finite),
        &["model-info", "{}"],
    ));
    let urdf = read(&dir.join("icub_upper_body.urdf"));
    let mut bad_urdf: Vec<(String, String)> = spread(&attribute_numbers(&urdf), 30)
        .into_iter()
        .map(|(s, e)| {
            (
                format!("{} → nan at byte {s}", &urdf[s..e]),
                format!("{}nan{}", &urdf[..s], &urdf[e..]),
            )
        })
        .collect();
    for k in [1, 5, 9] {
        let cut = urdf.len() * k / 10;
        bad_urdf.push((format!("truncated at byte {cut}"), urdf[..cut].to_string()));
    }
    bad_urdf.push((
        "a joint named twice".into(),
        urdf.replacen("name=\"r_elbow\"", "name=\"r_shoulder_pitch\"", 1),
    ));
    bad_urdf.push((
        "a parent link that does not exist".into(),
        urdf.replacen("<parent link=\"", "<parent link=\"no_such_", 1),
    ));
    // found by fuzzing: urdf-rs's XML layer panics on this one
    bad_urdf.push((
        "an unbound namespace".into(),
        String::from_utf8_lossy(include_bytes!(
            "../../../trm-kinematics/tests/fixtures/fuzz_urdf_namespace.urdf"
        ))
        .into_owned(),
    ));
    cases.extend(file_cases(
        dir,
        &dir.join("icub_upper_body.urdf"),
        bad_urdf,
        &["model-info", "{}"],
    ));

    // JSON and CSV files
    let huge = ["1e999", "null", "\"x\""];
    let to = read(&dir.join("to.txt"));
    let to = to.as_str();
    for (name, args, values, per_value) in [
        ("map.json", vec!["map-info", "{}"], &huge[..], 12),
        (
            "map.json",
            vec!["plan", "--map", "{}", "--to", "0,0,0", "--tolerance", "9"],
            &["1e999", "99"][..],
            12,
        ),
        (
            "posture.json",
            vec!["plan", "--map", "map.json", "--from", "{}", "--to", to],
            &["1e999", "99", "\"x\""][..],
            12,
        ),
        (
            "configs.json",
            vec!["fk", "--configs", "{}"],
            &["1e999", "99"][..],
            12,
        ),
        ("traj.json", vec!["view", "--traj", "{}"], &huge[..], 12),
    ] {
        let source = dir.join(name);
        let text = read(&source);
        let mut file = file_cases(
            dir,
            &source,
            mutations(&text, true, per_value, values)
                .into_iter()
                // a posture file's other keys are its free-form metadata (documented)
                .filter(|(what, _)| !(name == "posture.json" && what == "an unknown field"))
                .collect(),
            &args,
        );
        cases.append(&mut file);
    }
    let csv = read(&dir.join("traj.csv"));
    let row = csv.lines().nth(1).unwrap();
    let mut bad_csv = vec![
        ("no header".to_string(), String::new()),
        (
            "a NaN".into(),
            csv.replacen(row, &row.replacen(",", ",NaN,", 1), 1),
        ),
        ("a value outside its limits".into(), {
            let mut fields: Vec<&str> = row.split(',').collect();
            fields[1] = "99";
            csv.replacen(row, &fields.join(","), 1)
        }),
        ("a row too short".into(), csv.replacen(row, "0", 1)),
        (
            "a header and no rows".into(),
            csv.lines().next().unwrap().to_string() + "\n",
        ),
        (
            "a negative time".into(),
            csv.replacen(row, &format!("-1{}", &row[1..]), 1),
        ),
        (
            "an unknown column".into(),
            csv.replacen("time,", "time,r_elbw,", 1),
        ),
    ];
    for k in [1, 5] {
        let cut = csv.len() * k / 10;
        bad_csv.push((format!("truncated at byte {cut}"), csv[..cut].to_string()));
    }
    cases.extend(file_cases(
        dir,
        &dir.join("traj.csv"),
        bad_csv,
        &["view", "--traj", "{}"],
    ));

    cases
}
