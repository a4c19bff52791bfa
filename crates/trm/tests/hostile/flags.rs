//! Flag values out of range, damaged checkpoints and maps, MotionBenchMaker sets and peers,
//! budgets and package paths.

use std::path::Path;

use crate::harness::*;

/// The cases, with the valid files in `dir`.
pub fn cases(dir: &Path) -> Vec<Case> {
    let root = root();
    let at = |p: &str| root.join(p);
    let spec = at("specs/reach.ron").to_string_lossy().to_string();
    let spec = spec.as_str();
    let mut cases = Vec::new();
    // flag values
    let counts = ["0", "-1", "x", "1e3", "18446744073709551616"];
    cases.extend(flag_cases(&["build-map", spec], "--points", &counts));
    cases.extend(flag_cases(&["build-map", spec], "--points", &["100000000"]));
    cases.extend(flag_cases(
        &["build-map", spec],
        "--searches",
        &["0", "5000", "-2"],
    ));
    cases.extend(flag_cases(
        &["build-map", spec],
        "--threads",
        &["0", "-1", "x"],
    ));
    cases.extend(flag_cases(
        &["build-map", spec],
        "--seed",
        &["-1", "x", "1.5"],
    ));
    cases.extend(flag_cases(
        &["build-map", spec],
        "--edge-resolution",
        &["0", "-0.1", "NaN", "inf", "1e-300", "x"],
    ));
    // checkpoints: damaged, foreign, missing; flags that do not go with --resume
    let checkpoint = std::fs::read(dir.join("ck.map.checkpoint")).unwrap();
    let n = checkpoint.len();
    let mut damaged: Vec<(String, Vec<u8>)> = vec![("empty".into(), vec![])];
    for cut in [1, 10, n / 2, n - 1] {
        damaged.push((format!("cut at byte {cut}"), checkpoint[..cut].to_vec()));
    }
    for at in [0, 20, n / 3, 2 * n / 3, n - 1] {
        let mut bytes = checkpoint.clone();
        bytes[at] ^= 0x40;
        damaged.push((format!("byte {at} changed"), bytes));
    }
    damaged.push((
        "a map file".into(),
        std::fs::read(dir.join("map.json")).unwrap(),
    ));
    for (k, (what, bytes)) in damaged.into_iter().enumerate() {
        let name = format!("bad_{k}.checkpoint");
        std::fs::write(dir.join(&name), bytes).unwrap();
        cases.push(Case {
            what: format!("checkpoint: {what}"),
            args: ["build-map", "--resume", &name, "--out", "o.json"]
                .map(String::from)
                .to_vec(),
            names: name,
        });
    }
    cases.extend(file_flag_cases(
        &["build-map", "--out", "o.json"],
        "--resume",
        &["no_such.checkpoint", "."],
    ));
    cases.extend(flag_cases(
        &["build-map", spec],
        "--checkpoint-every",
        &["0", "-1", "x", "100000000"],
    ));
    let resume = [
        "build-map",
        "--resume",
        "ck.map.checkpoint",
        "--out",
        "o.json",
    ];
    cases.extend(flag_cases(&resume, "--seed", &["3"]));
    // the checkpoint holds 2 points (of 4): a resumed build does not shrink the map
    cases.push(Case {
        what: "build-map --resume with --points below the checkpoint's".into(),
        args: [
            "build-map",
            "--resume",
            "ck.map.checkpoint",
            "--points",
            "1",
            "--out",
            "o.json",
        ]
        .map(String::from)
        .to_vec(),
        names: "--points".into(),
    });
    cases.extend(flag_cases(&resume, "--searches", &["2"]));
    cases.push(Case {
        what: "build-map with a spec and --resume".into(),
        args: ["build-map", spec, "--resume", "ck.map.checkpoint"]
            .map(String::from)
            .to_vec(),
        names: "--resume".into(),
    });
    cases.push(Case {
        what: "build-map --mpi from an xtask built without MPI".into(),
        args: ["build-map", spec, "--points", "2", "--mpi"]
            .map(String::from)
            .to_vec(),
        names: "--features mpi".into(),
    });
    cases.push(Case {
        what: "build-map --checkpoint without an interval".into(),
        args: ["build-map", spec, "--checkpoint", "c.checkpoint"]
            .map(String::from)
            .to_vec(),
        names: "--checkpoint-every".into(),
    });
    // maps whose edge step or recorded world does not hold
    let map: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("map.json")).unwrap()).unwrap();
    let bad_maps = [
        ("edge_resolution", serde_json::json!(0.0)),
        ("edge_resolution", serde_json::json!(1e-300)),
        ("edge_resolution", serde_json::json!(-0.05)),
        (
            "world",
            serde_json::json!({"objects": [{"name": "ball", "shape": {"Sphere": {"radius": -1.0}}}]}),
        ),
        (
            "world",
            serde_json::json!({"objects": [
                {"name": "ball", "shape": {"Sphere": {"radius": 0.1}}},
                {"name": "ball", "shape": {"Sphere": {"radius": 0.1}}}]}),
        ),
        ("world", serde_json::json!("table")),
        (
            "parked",
            serde_json::json!({"points": [{"q": [0.0], "t": [0.0, 0.0, 0.0], "cost": 0.0}], "edges": []}),
        ),
        (
            "parked",
            serde_json::json!({"points": [], "edges": [[0, 99, 1.0]]}),
        ),
        (
            "parked",
            serde_json::json!({"points": [map["points"][0]], "edges": [[4, 4, 1.0]]}),
        ),
        ("parked", {
            // a parked point whose task vector is not its posture's
            let mut p = map["points"][0].clone();
            p["t"][0] = serde_json::json!(5.0);
            serde_json::json!({"points": [p], "edges": []})
        }),
        ("parked", serde_json::json!({"points": []})),
        ("edges", serde_json::json!([[0, 1, -0.5]])),
        ("settings", {
            let mut settings = map["settings"].clone();
            settings["spacing"] = serde_json::json!(-0.025);
            settings
        }),
        ("settings", {
            let mut settings = map["settings"].clone();
            settings["edge_neighbours"] = serde_json::json!(0);
            settings
        }),
    ];
    for (k, (key, value)) in bad_maps.into_iter().enumerate() {
        let mut bad = map.clone();
        bad[key] = value.clone();
        let name = format!("bad_map_{k}.map.json");
        std::fs::write(dir.join(&name), serde_json::to_string(&bad).unwrap()).unwrap();
        for command in [
            vec!["map-info", name.as_str()],
            vec![
                "repair-map",
                name.as_str(),
                "--world",
                "world.ron",
                "--out",
                "r.json",
            ],
        ] {
            cases.push(Case {
                what: format!("{} with {key} = {value}", command[0]),
                args: command.iter().map(|a| a.to_string()).collect(),
                names: name.clone(),
            });
        }
    }
    let sliding = at("specs/scenarios/sliding_box.ron");
    let sliding = sliding.to_str().unwrap();
    let run_scenario = ["scenario", sliding, "--map", "map.json", "--out-dir", "sc"];
    cases.extend(flag_cases(
        &run_scenario,
        "--repair-ms",
        &["0", "-1", "NaN", "inf", "x"],
    ));
    cases.extend(flag_cases(
        &run_scenario,
        "--repair-evaluations",
        &["0", "-1", "x"],
    ));
    cases.extend(flag_cases(&run_scenario, "--threads", &["0", "x"]));
    // MotionBenchMaker sets: missing, empty, not an archive, an unknown family, a broken scene
    let mbm = at("crates/trm-mbm/tests/fixtures/mbm")
        .to_string_lossy()
        .to_string();
    let panda = at("models/panda-mbm/panda.ron")
        .to_string_lossy()
        .to_string();
    let bench = |set: &str| -> Vec<String> {
        [
            "benchmark-mbm",
            set,
            "--model",
            panda.as_str(),
            "--out-dir",
            "mbm-out",
        ]
        .map(String::from)
        .to_vec()
    };
    std::fs::create_dir_all(dir.join("empty_set/family")).unwrap();
    std::fs::create_dir_all(dir.join("broken_set/box")).unwrap();
    std::fs::write(dir.join("broken_set/box/scene0001.yaml"), "world:\n  collision_objects:\n    - id: a\n      primitives: [{type: cone, dimensions: [1, 1]}]\n      primitive_poses: [{position: [0, 0, 0]}]\n").unwrap();
    std::fs::copy(
        at("crates/trm-mbm/tests/fixtures/mbm/box_panda/request0001.yaml"),
        dir.join("broken_set/box/request0001.yaml"),
    )
    .unwrap();
    std::fs::create_dir_all(dir.join("lonely_set/box")).unwrap();
    std::fs::write(dir.join("lonely_set/box/scene0001.yaml"), "{}\n").unwrap();
    for (set, names) in [
        ("no_such_set", "no_such_set"),
        ("empty_set", "empty_set"),
        ("map.json", "map.json"),
        ("broken_set", "scene0001.yaml:4"),
        ("lonely_set", "request0001.yaml"),
    ] {
        cases.push(Case {
            what: format!("benchmark-mbm {set}"),
            args: bench(set),
            names: names.into(),
        });
    }
    for (flag, values) in [
        ("--per-family", &["0", "-1", "x"][..]),
        ("--max-seconds", &["0", "-1", "NaN", "inf"][..]),
        ("--resolution", &["0", "-0.1", "NaN", "1e-300"][..]),
        ("--max-iterations", &["0", "1e12"][..]),
        ("--seed", &["-1", "1.5"][..]),
        ("--ompl", &["0", "-1", "NaN"][..]),
        ("--sampler", &["sobol", ""][..]),
    ] {
        let names = if flag == "--resolution" {
            "resolution"
        } else {
            flag
        };
        for v in values {
            let mut args = bench(&mbm);
            args.extend([flag.to_string(), v.to_string()]);
            cases.push(Case {
                what: format!("benchmark-mbm {flag} {v}"),
                args,
                names: names.into(),
            });
        }
    }
    for out in ["map.json", "link_to_dir"] {
        let mut args = bench(&mbm);
        args.truncate(4);
        args.extend(["--out-dir".into(), out.into()]);
        cases.push(Case {
            what: format!("benchmark-mbm --out-dir {out}"),
            args,
            names: out.into(),
        });
    }
    let _ = std::os::unix::fs::symlink(dir.join("map.json"), dir.join("link_to_dir"));
    let mut both = bench(&mbm);
    both.extend(["--families".into(), "box_panda".into()]);
    cases.push(Case {
        what: "benchmark-mbm --ompl with --families".into(),
        args: both
            .into_iter()
            .chain(["--ompl".into(), "1".into()])
            .collect(),
        names: "--ompl".into(),
    });
    // VAMP beside trm: a program that is not there, not a program, or prints nonsense
    let fake = dir.join("fake_vamp.sh");
    std::fs::write(
        &fake,
        "#!/bin/sh\ncat > /dev/null\necho 'result box_panda 1 1 1 NaN 0 0 0 0 0'\n",
    )
    .unwrap();
    std::fs::set_permissions(&fake, std::os::unix::fs::PermissionsExt::from_mode(0o755)).unwrap();
    // a harness that stops without reading its input (VAMP's, for a robot it does not have)
    let refusing = dir.join("refusing_vamp.sh");
    std::fs::write(
        &refusing,
        "#!/bin/sh\necho 'vamp-mbm: VAMP has no robot `x` here' >&2\nexit 2\n",
    )
    .unwrap();
    std::fs::set_permissions(
        &refusing,
        std::os::unix::fs::PermissionsExt::from_mode(0o755),
    )
    .unwrap();
    for program in [
        "no/such/program",
        "map.json",
        "fake_vamp.sh",
        "refusing_vamp.sh",
    ] {
        let mut args = bench(&mbm);
        args.extend(["--per-family", "1", "--vamp", program].map(String::from));
        cases.push(Case {
            what: format!("benchmark-mbm --vamp {program}"),
            args,
            names: "--vamp".into(),
        });
    }
    let mut robot_alone = bench(&mbm);
    robot_alone.extend(["--vamp-robot".into(), "ur5".into()]);
    cases.push(Case {
        what: "benchmark-mbm --vamp-robot without --vamp".into(),
        args: robot_alone,
        names: "--vamp".into(),
    });
    // task-space goals: an unknown link, tolerances without --task-space, with experience
    for (extra, names) in [
        (vec!["--task-space", "panda_hnd"], "panda_hand"),
        (vec!["--position-tolerance", "0.02"], "--task-space"),
        (
            vec!["--task-space", "panda_hand", "--experience"],
            "--experience",
        ),
        (
            vec!["--task-space", "panda_hand", "--orientation-tolerance", "0"],
            "--orientation-tolerance",
        ),
        // a switch given a value
        (
            vec!["--ignore-scene-matrices=yes"],
            "--ignore-scene-matrices",
        ),
    ] {
        let mut args = bench(&mbm);
        args.extend(extra.iter().map(|s| s.to_string()));
        cases.push(Case {
            what: format!("benchmark-mbm {}", extra.join(" ")),
            args,
            names: names.into(),
        });
    }
    // maps attached: missing, not a map, a map of other motors (the iCub's)
    let bench_args = bench(&mbm);
    let bench_refs: Vec<&str> = bench_args.iter().map(String::as_str).collect();
    cases.extend(file_flag_cases(
        &bench_refs,
        "--map",
        &["no_such.json", "posture.json", "map.json"],
    ));
    // corner-cutting rounds: negative, not a number, beyond the bound
    cases.extend(flag_cases(
        &bench_refs,
        "--smoothing",
        &["-1", "x", "NaN", "1001", "18446744073709551616"],
    ));
    // point clouds: no samples, not a number, beyond the bound, with --vamp-obstacles
    cases.extend(flag_cases(
        &bench_refs,
        "--cloud",
        &["0", "-1", "x", "1000001"],
    ));
    let mut both = bench_args.clone();
    both.push("--vamp-obstacles".into());
    cases.push(Case {
        what: "benchmark-mbm --cloud with --vamp-obstacles".into(),
        args: both
            .into_iter()
            .chain(["--cloud".into(), "100".into()])
            .collect(),
        names: "--cloud".into(),
    });
    let request = at("crates/trm-mbm/tests/fixtures/mbm/box_panda/request0001.yaml")
        .to_string_lossy()
        .to_string();
    let plan_request = [
        "plan",
        "--model",
        panda.as_str(),
        "--request",
        request.as_str(),
    ];
    cases.extend(file_flag_cases(
        &plan_request,
        "--with-map",
        &["no_such.json", "posture.json", "map.json"],
    ));
    cases.extend(file_flag_cases(
        &plan_request,
        "--experience",
        &["posture.json", "map.json"],
    ));
    // timing: limits and factors out of range, joint-limit files that are none or wrong
    for (flag, values) in [
        ("--velocity-scaling", &["0", "1.5", "NaN"][..]),
        ("--acceleration-scaling", &["-1", "2"][..]),
        ("--max-deviation", &["-0.1", "inf"][..]),
        ("--sample-period", &["0", "NaN"][..]),
        ("--acceleration", &["0", "-2"][..]),
        ("--jerk", &["0", "NaN"][..]),
    ] {
        cases.extend(flag_cases(&plan_request, flag, values));
    }
    cases.extend(file_flag_cases(
        &plan_request,
        "--joint-limits",
        &["no_such.yaml", "posture.json", "bad_limits.yaml"],
    ));
    let mut families = bench(&mbm);
    families.extend(["--families".into(), "box_pand".into()]);
    cases.push(Case {
        what: "benchmark-mbm with an unknown family".into(),
        args: families,
        names: "box_panda".into(),
    });
    // gen-mbm: settings out of range, a spec that does not reach, outputs that are files
    let gen_spec = at("specs/mbm/icub_reach.ron").to_string_lossy().to_string();
    let gen_mbm = [
        "gen-mbm",
        gen_spec.as_str(),
        "--out",
        "gen-out",
        "--per-family",
        "1",
    ];
    for (flag, values) in [
        ("--per-family", &["0", "-1"][..]),
        ("--center", &["1,2", "1,2,NaN"][..]),
        ("--facing", &["0,0", "1"][..]),
        ("--tolerance", &["0", "-1", "NaN"][..]),
        ("--tries", &["0"][..]),
    ] {
        cases.extend(flag_cases(&gen_mbm, flag, values));
    }
    cases.push(Case {
        what: "gen-mbm with an unknown family".into(),
        args: gen_mbm
            .iter()
            .map(|s| s.to_string())
            .chain(["--families".into(), "kitchen".into()])
            .collect(),
        names: "kitchen".into(),
    });
    cases.push(Case {
        what: "gen-mbm with scenes out of reach".into(),
        args: gen_mbm
            .iter()
            .map(|s| s.to_string())
            .chain(["--center=-5,0,0".into(), "--tries".into(), "1".into()])
            .collect(),
        names: "center".into(),
    });
    cases.extend(file_flag_cases(
        &["gen-mbm", gen_spec.as_str(), "--per-family", "1"],
        "--out",
        &["map.json"],
    ));
    cases.push(Case {
        what: "gen-mbm with a spec that is not there".into(),
        args: ["gen-mbm", "no_such_spec.ron", "--out", "gen-out"]
            .map(String::from)
            .to_vec(),
        names: "no_such_spec.ron".into(),
    });
    // one budget or the other, not both
    let both: Vec<&str> = run_scenario
        .iter()
        .copied()
        .chain(["--repair-ms", "10"])
        .collect();
    cases.extend(flag_cases(&both, "--repair-evaluations", &["100"]));
    // a package path that is not there
    cases.extend(file_flag_cases(
        &["model-info", "icub_upper_body.urdf"],
        "--package-path",
        &["no/such/dir", "map.json"],
    ));
    cases.extend(file_flag_cases(
        &["scenario", sliding, "--out-dir", "sc"],
        "--map",
        &["no_such.json", ".", "posture.json", "world.ron"],
    ));
    cases.extend(file_flag_cases(
        &["scenario", sliding, "--map", "map.json"],
        "--out-dir",
        &["posture.json"],
    ));
    for bad in ["no_such.ron", ".", "map.json", "world.ron"] {
        cases.push(Case {
            what: format!("scenario {bad}"),
            args: ["scenario", bad, "--map", "map.json", "--out-dir", "sc"]
                .map(String::from)
                .to_vec(),
            names: bad.into(),
        });
    }
    cases
}
