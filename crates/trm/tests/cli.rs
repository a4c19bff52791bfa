//! The `trm` binary: its help lists every command, a command runs, bad flags are refused with
//! the flag's name and a failed command writes nothing.

use std::process::Command;

fn trm(args: &[&str], dir: &std::path::Path) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_trm"))
        .args(args)
        .current_dir(dir)
        .output()
        .expect("trm starts")
}

#[test]
fn help_lists_every_command_and_commands_run() {
    let dir = std::env::temp_dir();
    let help = trm(&["--help"], &dir);
    assert!(help.status.success());
    let help = String::from_utf8_lossy(&help.stdout);
    let listed = trm::command_list();
    let names: Vec<&str> = listed
        .lines()
        .filter_map(|l| l.split_whitespace().next())
        .collect();
    assert!(names.len() >= 19, "{listed}");
    for name in [
        "build-map",
        "plan",
        "benchmark-mbm",
        "solve",
        "view",
        "compare-optimisers",
    ] {
        assert!(names.contains(&name), "{name} missing from {listed}");
    }
    for name in &names {
        assert!(
            help.contains(name),
            "`trm --help` does not list {name}:\n{help}"
        );
    }
    let info = trm(&["model-info"], &dir);
    assert!(
        info.status.success(),
        "{}",
        String::from_utf8_lossy(&info.stderr)
    );
    assert!(String::from_utf8_lossy(&info.stdout).contains("41"));
}

#[test]
fn bad_flags_name_the_flag_and_failed_commands_write_nothing() {
    let dir = std::env::temp_dir().join(format!("trm-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let bad = trm(&["optimise", "--runs", "0"], &dir);
    assert_eq!(bad.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&bad.stderr).contains("--runs"));
    std::fs::write(dir.join("spec.ron"), "(robot: \"nope\")").unwrap();
    let failed = trm(&["solve", "spec.ron", "--out", "posture.json"], &dir);
    assert_eq!(failed.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&failed.stderr).contains("spec.ron"));
    assert!(!dir.join("posture.json").exists());
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Builds a reach map of `points` points as `dir/map.json`.
fn reach_map(dir: &std::path::Path, points: usize) {
    let spec = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../specs/reach.ron");
    let points = points.to_string();
    let built = trm(
        &[
            "build-map",
            spec.to_str().unwrap(),
            "--points",
            &points,
            "--out",
            "map.json",
        ],
        dir,
    );
    assert!(
        built.status.success(),
        "{}",
        String::from_utf8_lossy(&built.stderr)
    );
}

/// A MotionBenchMaker sample problem's scene and request (crates/trm-mbm's fixtures) and the
/// Panda they were made for.
fn panda_problem() -> [std::path::PathBuf; 3] {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let family = root.join("crates/trm-mbm/tests/fixtures/mbm/box_panda");
    [
        root.join("models/panda-mbm/panda_spherized.ron"),
        family.join("scene0001.yaml"),
        family.join("request0001.yaml"),
    ]
}

/// `trm plan` for the Panda in `scene` asked `request` (paths as given, relative to `dir`), with
/// `extra` arguments: its output, the command having succeeded.
fn plan_panda(
    dir: &std::path::Path,
    scene: &std::path::Path,
    request: &std::path::Path,
    extra: &[&str],
) -> String {
    let [model, _, _] = panda_problem();
    let mut args = vec![
        "plan",
        "--model",
        model.to_str().unwrap(),
        "--world",
        scene.to_str().unwrap(),
        "--request",
        request.to_str().unwrap(),
    ];
    args.extend(extra);
    let out = trm(&args, dir);
    let stdout = String::from_utf8_lossy(&out.stdout).to_string();
    assert!(
        out.status.success(),
        "{stdout}{}",
        String::from_utf8_lossy(&out.stderr)
    );
    stdout
}

#[test]
fn plan_without_maps_answers_a_moveit_request_and_writes_every_format() {
    let dir = std::env::temp_dir().join(format!("trm-cli-plan-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let [_, scene, request] = panda_problem();
    let stdout = plan_panda(&dir, &scene, &request, &["--out", "traj.csv"]);
    assert!(stdout.contains("7 of 7 motors move"), "{stdout}");
    for file in [
        "traj.csv",
        "traj.json",
        "traj.ros.yaml",
        "traj.response.yaml",
    ] {
        assert!(dir.join(file).is_file(), "{file} not written: {stdout}");
    }
    let response = std::fs::read_to_string(dir.join("traj.response.yaml")).unwrap();
    assert!(response.contains("group_name: \"panda_arm\"") && response.contains("val: 1"));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn plan_without_maps_refuses_what_does_not_fit_and_writes_nothing() {
    let dir = std::env::temp_dir().join(format!("trm-cli-plan-bad-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let [model, scene, request] = panda_problem();
    let (model, scene, request) = (
        model.to_str().unwrap(),
        scene.to_str().unwrap(),
        request.to_str().unwrap(),
    );
    // flags that do not go together are clap's errors, naming them
    let both = trm(
        &[
            "plan", "--map", "m.json", "--model", model, "--to", "g.json",
        ],
        &dir,
    );
    assert_eq!(both.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&both.stderr).contains("--model"));
    let no_goal = trm(&["plan", "--model", model], &dir);
    assert_eq!(no_goal.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&no_goal.stderr).contains("--to"));
    for (args, expected) in [
        (
            vec!["--joints", "panda_joint1,nope", "--request", request],
            "nope",
        ),
        (vec!["--request", "missing.yaml"], "missing.yaml"),
        (
            vec!["--world", "missing.yaml", "--request", request],
            "missing.yaml",
        ),
        (
            vec![
                "--joints",
                "panda_joint1,panda_joint2",
                "--request",
                request,
            ],
            "the goal constrains `panda_joint3`, which the planner does not move",
        ),
        (
            vec![
                "--world",
                scene,
                "--from",
                "start.json",
                "--to",
                "start.json",
            ],
            "start.json",
        ),
        // the model's zero posture folds the arm onto itself: the pair is named
        (
            vec!["--joints", "panda_arm", "--to", "home"],
            "the start collides: links `panda_link5` and `panda_hand`",
        ),
        (
            vec!["--request", request, "--max-samples", "0"],
            "--max-samples",
        ),
        (
            vec!["--request", request, "--resolution", "NaN"],
            "--resolution",
        ),
        (
            vec!["--request", request, "--max-seconds", "-1"],
            "--max-seconds",
        ),
        (vec!["--request", request, "--range", "0"], "--range"),
        (
            vec!["--request", request, "--smoothing", "-1"],
            "--smoothing",
        ),
        (
            vec!["--request", request, "--smoothing", "1001"],
            "--smoothing",
        ),
    ] {
        let mut full = vec!["plan", "--model", model, "--out", "traj.csv"];
        full.extend(args);
        let failed = trm(&full, &dir);
        let stderr = String::from_utf8_lossy(&failed.stderr);
        // a flag's value out of range is clap's error (2), the rest trm's (1)
        let code = if expected.starts_with("--") { 2 } else { 1 };
        assert_eq!(failed.status.code(), Some(code), "{full:?}: {stderr}");
        assert!(stderr.contains(expected), "{full:?}: {stderr}");
        assert!(!dir.join("traj.csv").exists(), "{full:?}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn plan_and_view_draw_the_robot_with_what_it_holds() {
    let dir = std::env::temp_dir().join(format!("trm-cli-plan-held-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let [_, scene, request] = panda_problem();
    // the sample scene with a small box held inside the hand (clear of the can it reaches for)
    let mut held = trm_moveit::PlanningScene::load(&scene).unwrap();
    held.attached.push(trm_collision::AttachedObject {
        name: "box".into(),
        link: "panda_hand".into(),
        shapes: vec![(
            trm_collision::Shape::Box {
                size: [0.02, 0.02, 0.02],
            },
            trm_kinematics::nalgebra::Isometry3::translation(0.0, 0.0, 0.03),
        )],
        touch_links: vec!["panda_leftfinger".into(), "panda_rightfinger".into()],
    });
    let held_scene = dir.join("held.yaml");
    std::fs::write(&held_scene, held.to_yaml().unwrap()).unwrap();
    plan_panda(
        &dir,
        &held_scene,
        &request,
        &["--out", "traj.csv", "--view"],
    );
    let page = std::fs::read_dir(&dir)
        .unwrap()
        .filter_map(|e| e.ok().map(|e| e.path()))
        .find(|p| p.to_string_lossy().ends_with(".scene.json"))
        .expect("--view wrote a scene");
    // `trm view` of the scene holds it too
    let [model, _, _] = panda_problem();
    let out = trm(
        &[
            "view",
            model.to_str().unwrap(),
            "--world",
            held_scene.to_str().unwrap(),
            "--out",
            "view.html",
        ],
        &dir,
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    for page in [page, dir.join("view.json")] {
        let view = trm_view::Scene::load(&page).unwrap();
        let box_ = view
            .bodies
            .iter()
            .find(|b| b.held.as_deref() == Some("box"));
        assert_eq!(
            view.links[box_.expect("the held box is drawn").link],
            "panda_hand"
        );
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn plan_keeps_experience_in_a_file_and_retrieves_it() {
    let dir = std::env::temp_dir().join(format!("trm-cli-experience-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let family = root.join("crates/trm-mbm/tests/fixtures/mbm/cage_panda");
    let plan = |number: &str| {
        let scene = family.join(format!("scene{number}.yaml"));
        let request = family.join(format!("request{number}.yaml"));
        plan_panda(
            &dir,
            &scene,
            &request,
            &["--experience", "cage.experience.json"],
        )
    };
    // a cage needs RRT-Connect: its path is kept, and the same query again retrieves it
    let first = plan("0001");
    assert!(
        first.contains("(sampled)") && first.contains("kept the path"),
        "{first}"
    );
    let again = plan("0001");
    assert!(
        again.contains("1 kept paths") && again.contains("(retrieved)"),
        "{again}"
    );
    let other = plan("0002");
    assert!(other.contains("1 kept paths"), "{other}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn plan_answers_a_task_space_request() {
    let dir = std::env::temp_dir().join(format!("trm-cli-pose-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let [model, scene, request] = panda_problem();
    let robot = trm_kinematics::RobotModel::load(&model).unwrap();
    let posed = trm_moveit::MotionPlanRequest::load(&request)
        .unwrap()
        .to_task_space(&robot, "panda_hand", 0.01, 0.05)
        .unwrap();
    std::fs::write(dir.join("pose.yaml"), posed.to_yaml().unwrap()).unwrap();
    let pose = std::path::Path::new("pose.yaml");
    let stdout = plan_panda(&dir, &scene, pose, &["--out", "pose.csv"]);
    assert!(stdout.contains("7 of 7 motors move") && dir.join("pose.csv").is_file());
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A world that swallows the robot at the map's start: the repair runs and says which object
/// covers the start (issue 49's round 4: it used to pass without a word).
#[test]
fn a_repair_world_covering_the_start_is_named() {
    let dir = std::env::temp_dir().join(format!("trm-cli-repair-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    reach_map(&dir, 4);
    std::fs::write(
        dir.join("swallow.ron"),
        "(objects: [(name: \"blob\", shape: Sphere(radius: 0.6), xyz: (0.0, 0.0, 0.0))])",
    )
    .unwrap();
    let repaired = trm(
        &[
            "repair-map",
            "map.json",
            "--world",
            "swallow.ron",
            "--out",
            "r.map.json",
        ],
        &dir,
    );
    let out = String::from_utf8_lossy(&repaired.stdout);
    assert!(
        repaired.status.success(),
        "{}",
        String::from_utf8_lossy(&repaired.stderr)
    );
    assert!(
        out.contains("swallow.ron: `blob` collides with the robot"),
        "{out}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// `trm plan` through a map in a MoveIt scene reads the scene as the map-free path does: the
/// objects the robot holds in it are held (here a plank in the right hand that runs through the
/// body at the start), not dropped.
#[test]
fn plan_through_a_map_holds_what_the_scene_holds() {
    let dir = std::env::temp_dir().join(format!("trm-cli-held-map-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    reach_map(&dir, 20);
    // a scene whose robot state holds `held` (attached collision objects)
    let scene = |held: &str| {
        format!(
            "name: kitchen\nrobot_state:\n  attached_collision_objects: {held}\nworld:\n  collision_objects:\n    - id: far_box\n      primitives: [{{type: box, dimensions: [0.1, 0.1, 0.1]}}]\n      primitive_poses: [{{position: [3, 3, 3], orientation: [0, 0, 0, 1]}}]\n"
        )
    };
    let plank = "\n    - link_name: r_hand\n      object:\n        header: {frame_id: r_hand}\n        id: plank\n        primitives: [{type: box, dimensions: [1.0, 1.0, 1.0]}]\n        primitive_poses: [{position: [0, 0, 0], orientation: [0, 0, 0, 1]}]";
    std::fs::write(dir.join("holding.yaml"), scene(plank)).unwrap();
    std::fs::write(dir.join("empty.yaml"), scene("[]")).unwrap();
    let plan = |world: &str| {
        trm(
            // (a goal any node of the small map meets)
            &[
                "plan",
                "--map",
                "map.json",
                "--world",
                world,
                "--to",
                "0.25,-0.15,0.1",
                "--tolerance",
                "2",
            ],
            &dir,
        )
    };
    let free = plan("empty.yaml");
    assert!(
        free.status.success(),
        "{}",
        String::from_utf8_lossy(&free.stderr)
    );
    let held = plan("holding.yaml");
    let stderr = String::from_utf8_lossy(&held.stderr);
    assert!(
        !held.status.success(),
        "{}",
        String::from_utf8_lossy(&held.stdout)
    );
    assert!(stderr.contains("plank"), "{stderr}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn model_info_shows_the_planner_settings_sized_or_given() {
    let dir = std::env::temp_dir().join(format!("trm-cli-planning-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let models = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../models/panda");
    let text = std::fs::read_to_string(models.join("panda.ron")).unwrap();
    let urdf = models.join("panda_fitted.urdf");
    let text = text.replace(
        "urdf: \"panda_fitted.urdf\"",
        &format!("urdf: {:?}", urdf.display().to_string()),
    );
    let end = text.rfind(')').unwrap();
    let given = format!("{}    planning: (range: Some(1.25)),\n)\n", &text[..end]);
    std::fs::write(dir.join("panda.ron"), given).unwrap();
    let info = trm(&["model-info", "panda.ron"], &dir);
    assert!(
        info.status.success(),
        "{}",
        String::from_utf8_lossy(&info.stderr)
    );
    let out = String::from_utf8_lossy(&info.stdout);
    // the range given, the rest sized as the planner sizes it for the group
    let robot = trm_kinematics::RobotModel::load(dir.join("panda.ron")).unwrap();
    let collision = trm_collision::CollisionModel::new(&robot).unwrap();
    let arm = robot.active_set(&["arm"], &robot.neutral_motors()).unwrap();
    let sized = trm_plan::rrt::RrtOptions::for_robot(&collision, &arm).unwrap();
    assert_eq!(sized.range, 1.25);
    let planning = &out[out.find("\nplanning (").expect("a planning section")..];
    let line = planning
        .lines()
        .find(|l| l.trim_start().starts_with("arm "))
        .unwrap_or_else(|| panic!("no line for the arm group:\n{out}"));
    assert!(
        line.contains("range 1.250 rad")
            && line.contains(&format!("resolution 1/{:.1} rad", 1.0 / sized.resolution))
            && line.contains(&format!("domains {:.2} rad", sized.domain_radius)),
        "{line}"
    );
    assert!(out.contains("(the model description sets range)"), "{out}");
    assert!(out.contains("sized by the lever arms"), "{out}");
    std::fs::remove_dir_all(&dir).unwrap();
}
