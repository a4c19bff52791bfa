//! MoveIt scenes and requests (MotionBenchMaker's Panda sample in tests/fixtures/mbm): every
//! file reads, scenes round-trip through the writer, malformed files are located errors, and
//! RRT-Connect solves every sample problem on MotionBenchMaker's own Panda with paths that an
//! independent certification proves free in continuous motion.

use std::path::{Path, PathBuf};

use trm_collision::{CollisionModel, Shape, World};
use trm_mbm::{LoadedProblem, Verdict, certify_path, find_problems, solve};
use trm_moveit::MoveItError;
use trm_moveit::{MotionPlanRequest, PlanningScene};
use trm_plan::rrt::RrtOptions;

fn fixtures() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/mbm")
}

/// Solves problem `p` for `robot` with certified paths, asserts it is valid, solved and its
/// path proved free in continuous motion by the independent check; its request and outcome.
fn solved_and_free(
    robot: &trm_kinematics::RobotModel,
    collision: &trm_collision::CollisionModel,
    p: &trm_mbm::Problem,
    options: &RrtOptions,
) -> (MotionPlanRequest, trm_mbm::Outcome) {
    let scene = PlanningScene::load(&p.scene).unwrap();
    let request = MotionPlanRequest::load(&p.request).unwrap();
    let certified = RrtOptions {
        certified: true,
        ..options.clone()
    };
    let outcome = solve(robot, collision, &scene, &request, &certified).unwrap();
    assert!(
        outcome.valid && outcome.solved,
        "{} {}: {}",
        p.family,
        p.index,
        outcome.note
    );
    assert!(
        certify_path(robot, collision, &scene, &request, &outcome.path).unwrap() == Verdict::Proved,
        "{} {}",
        p.family,
        p.index
    );
    (request, outcome)
}

#[test]
fn every_sample_scene_and_request_reads_and_scenes_round_trip() {
    let problems = find_problems(&fixtures()).unwrap();
    assert_eq!(problems.len(), 14);
    for p in &problems {
        let scene = PlanningScene::load(&p.scene).unwrap();
        let request = MotionPlanRequest::load(&p.request).unwrap();
        assert_eq!(request.goal.names.len(), 7, "{}", p.request.display());
        assert_eq!(request.group, "panda_arm");
        assert_eq!(request.planning_time, Some(60.0));
        assert_eq!(scene.robot_model_name, "panda");
        let world = scene.to_world().unwrap();
        let primitives: usize = scene.objects.iter().map(|o| o.primitives.len()).sum();
        assert!(primitives > 0 && world.objects().len() == primitives);
        let acm = scene.allowed_collisions.as_ref().unwrap();
        assert!(
            acm.allowed_pairs()
                .any(|(a, b)| a == "panda_hand" && b == "panda_leftfinger")
        );
        // the writer's output reads back to the same scene (poses to rounding)
        let again = PlanningScene::parse(&scene.to_yaml().unwrap(), &p.scene).unwrap();
        assert_eq!(again.objects.len(), scene.objects.len());
        assert_eq!(again.allowed_collisions, scene.allowed_collisions);
        assert_eq!(again.robot_state, scene.robot_state);
        for (a, b) in again.objects.iter().zip(&scene.objects) {
            assert_eq!(a.id, b.id);
            for (x, y) in a.primitives.iter().zip(&b.primitives) {
                assert_eq!(x.shape, y.shape);
                assert!((x.pose.translation.vector - y.pose.translation.vector).norm() < 1e-12);
                assert!(x.pose.rotation.angle_to(&y.pose.rotation) < 1e-9);
            }
        }
    }
}

fn scene_error(text: &str) -> String {
    match PlanningScene::parse(text, Path::new("s.yaml")).and_then(|s| s.to_world().map(|_| ())) {
        Err(e @ MoveItError::Invalid { .. }) => e.to_string(),
        other => panic!("{text:?}: {other:?}"),
    }
}

#[test]
fn malformed_scenes_and_requests_are_located_errors() {
    let object = |body: &str| format!("world:\n  collision_objects:\n    - id: a\n{body}");
    let prim = "      primitives:\n        - type: box\n          dimensions: [1, 1, 1]\n      primitive_poses:\n        - position: [0, 0, 0]\n          orientation: [0, 0, 0, 1]\n";
    for (text, expected) in [
        ("world: [1, 2\n".to_string(), "s.yaml:2: not readable YAML"),
        ("- 1\n".into(), "s.yaml:1: the document is a sequence"),
        (object(&prim.replace("box", "cone")), "s.yaml:5: object `a`.primitives[0] is a `cone`"),
        (object(&prim.replace("[1, 1, 1]", "[1, -1, 1]")), "s.yaml:5: object `a`.primitives[0]: a box with dimensions"),
        (object(&prim.replace("[1, 1, 1]", "[1, 1]")), "s.yaml:5"),
        (object(&prim.replace("[0, 0, 0, 1]", "[0, 0, 0, 3]")), "orientation has norm 3.0000"),
        (object(&prim.replace("position: [0, 0, 0]", "position: [0, .nan, 0]")), "s.yaml:8: object `a`.primitive_poses[0].position[1] is `.nan`"),
        (object(&prim.replace("        - position: [0, 0, 0]\n          orientation: [0, 0, 0, 1]\n", "")), "s.yaml:8: object `a`.primitive_poses is a scalar, not a list"),
        (object(&format!("{prim}      planes: [{{}}]\n")), "s.yaml:3: object `a` has planes"),
        (object(&format!("{prim}      meshes: [{{}}]\n")), "s.yaml:3: object `a` has 1 meshes and 0 mesh_poses"),
        (format!("{}    - id: a\n{prim}", object(prim)), "s.yaml:10: object `a` is given twice (first at line 3)"),
        (object(prim).replace("id: a", "id: \"\""), "s.yaml:3: world.collision_objects[0] has an empty id"),
        ("allowed_collision_matrix:\n  entry_names: [a, b]\n  entry_values:\n    - [false, true]\n    - [false, false]\n".into(), "(b, a) is false one way and true the other"),
        ("allowed_collision_matrix:\n  entry_names: [a, b]\n  entry_values:\n    - [false, maybe]\n    - [true, false]\n".into(), "s.yaml:4: allowed_collision_matrix.entry_values[0]: `maybe`"),
        ("robot_state:\n  joint_state:\n    name: [j1, j2]\n    position: [0]\n".into(), "s.yaml:3: robot_state.joint_state names 2 joints and gives 1 positions"),
        ("a: 1\na: 2\n".into(), "s.yaml:2: not readable YAML: `a` is given twice"),
        (format!("world:\n  collision_objects:\n{}", "  ".to_string() + &"- ".repeat(100_000)), "nested more than 64 deep"),
    ] {
        let e = scene_error(&text);
        assert!(e.contains(expected) && e.contains("fix:"), "{text:?}:\n{e}\nexpected {expected:?}");
    }
    let request = std::fs::read_to_string(fixtures().join("box_panda/request0001.yaml")).unwrap();
    for (from, to, expected) in [
        (
            "position: 1.",
            "position: x1.",
            "r.yaml:17: goal_constraints[0].joint_constraints[1].position is `x1.",
        ),
        (
            "joint_name: panda_joint2",
            "joint_name: panda_joint1",
            "joint `panda_joint1` is constrained twice",
        ),
        (
            "allowed_planning_time: 60",
            "allowed_planning_time: -1",
            "allowed_planning_time is -1",
        ),
        (
            "goal_constraints:",
            "goals:",
            "the request has no `goal_constraints`",
        ),
    ] {
        assert!(request.contains(from), "{from}");
        let bad = request.replacen(from, to, 1);
        let e = MotionPlanRequest::parse(&bad, Path::new("r.yaml"))
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with("r.yaml:") && e.contains(expected),
            "{from} → {to}:\n{e}"
        );
    }
}

/// Both Panda models through the single-precision screen: mesh hulls (enclosed by spheres, the
/// lanes they leave uncertain checked pair by pair in `f64`) and VAMP's spheres; every path
/// then re-checked by the exact `f64` model.
#[test]
fn rrt_connect_solves_every_sample_problem_with_paths_free_at_half_the_resolution() {
    for (file, fast) in [("panda.ron", true), ("panda_spherized.ron", true)] {
        let model = Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../models/panda-mbm")
            .join(file);
        let robot = trm_kinematics::RobotModel::load(&model).unwrap();
        let collision = trm_collision::CollisionModel::new(&robot).unwrap();
        let objective = trm_tasks::Objective::new(
            robot.all_active(),
            collision.clone(),
            trm_collision::World::new(),
        );
        let world = trm_collision::World::new();
        assert_eq!(
            objective.world_checker(&world).unwrap().is_screened(),
            fast,
            "{file}"
        );
        let options = RrtOptions::default();
        for p in find_problems(&fixtures()).unwrap() {
            let (request, outcome) = solved_and_free(&robot, &collision, &p, &options);
            let path = &outcome.path;
            assert!(path.len() >= 2);
            assert!(
                path[0]
                    .iter()
                    .zip(&request.start.positions)
                    .all(|(a, b)| (a - b).abs() < 1e-12)
            );
            assert_eq!(path.last().unwrap(), &request.goal.positions);
            // the same seed finds the same path
            let scene = PlanningScene::load(&p.scene).unwrap();
            let certified = RrtOptions {
                certified: true,
                ..options.clone()
            };
            let again = solve(&robot, &collision, &scene, &request, &certified).unwrap();
            assert_eq!(again.path, outcome.path);
        }
    }
}

#[test]
fn the_writer_refuses_what_the_reader_refuses() {
    let scene = PlanningScene::load(fixtures().join("box_panda/scene0001.yaml")).unwrap();
    let refused = |mutate: &dyn Fn(&mut PlanningScene)| {
        let mut s = scene.clone();
        mutate(&mut s);
        s.to_yaml().unwrap_err().to_string()
    };
    let e = refused(&|s| {
        s.objects[0].primitives[0].shape = trm_collision::Shape::Capsule {
            radius: 0.1,
            length: 0.2,
        }
    });
    assert!(e.contains("not written") && e.contains("capsule"), "{e}");
    let e = refused(&|s| s.objects[0].primitives[0].pose.translation.vector.x = f64::NAN);
    assert!(e.contains("not finite"), "{e}");
    let e = refused(&|s| s.robot_state.as_mut().unwrap().positions[0] = f64::INFINITY);
    assert!(e.contains("one finite position per joint name"), "{e}");
    let e = refused(&|s| {
        s.allowed_collisions
            .as_mut()
            .unwrap()
            .allowed
            .pop()
            .map(drop)
            .unwrap()
    });
    assert!(e.contains("not square"), "{e}");
    let e = refused(&|s| {
        let twin = s.objects[0].clone();
        s.objects.push(twin)
    });
    assert!(
        e.contains("names an earlier object") || e.contains("already"),
        "{e}"
    );
}

#[test]
fn problem_sets_open_from_folders_and_archives_and_summarise() {
    use trm_mbm::{Outcome, ProblemSet, Summary, quantile};
    assert_eq!(ProblemSet::open(&fixtures()).unwrap().problems.len(), 14);
    let archive =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../benches/mbm/panda_problems.tar.bz2");
    let set = ProblemSet::open(&archive).unwrap();
    assert_eq!(set.problems.len(), 700);
    let first = set.problems[0].scene.clone();
    assert!(first.is_file());
    drop(set);
    assert!(!first.exists(), "the unpacked set is removed with it");
    let not_tar = fixtures().join("NOTICE.md");
    let e = ProblemSet::open(&not_tar).err().unwrap().to_string();
    assert!(
        e.starts_with(&not_tar.display().to_string()) && e.contains("fix:"),
        "{e}"
    );
    let e = ProblemSet::open(Path::new("no/such/set"))
        .err()
        .unwrap()
        .to_string();
    assert!(e.contains("no/such/set"), "{e}");
    // the field's report: quantiles by nearest rank, nothing where nothing was solved
    assert_eq!(quantile(&[3.0, 1.0, 2.0, 4.0], 0.5), Some(2.0));
    assert_eq!(quantile(&[3.0, 1.0, 2.0, 4.0], 0.95), Some(4.0));
    assert_eq!(quantile(&[], 0.5), None);
    let unsolved = Outcome {
        valid: true,
        ..Default::default()
    };
    let s = Summary::of([&unsolved]);
    assert_eq!((s.problems, s.valid, s.solved, s.time), (1, 1, 0, None));
}

/// The second MotionBenchMaker robot, from its files only (URDF, SRDF naming links the URDF
/// lacks, STL meshes): its sample problems read, their ±π states are taken within
/// `LIMIT_SLACK`, and RRT-Connect solves them with paths proved free.
#[test]
fn the_fetch_runs_from_its_files_only() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let robot =
        trm_kinematics::RobotModel::load(root.join("../../models/fetch-mbm/fetch.ron")).unwrap();
    assert_eq!(robot.motors().len(), 8);
    let collision = trm_collision::CollisionModel::new(&robot).unwrap();
    let options = RrtOptions::default();
    let problems = find_problems(&root.join("tests/fixtures/mbm-fetch")).unwrap();
    assert_eq!(problems.len(), 2);
    for p in problems {
        solved_and_free(&robot, &collision, &p, &options);
    }
}

/// Problems as peers read them, and their answers read back: every problem and primitive
/// written, numbers exact; malformed answers are errors naming the line.
#[test]
fn peer_problems_are_written_and_peer_results_read() {
    let problems = find_problems(&fixtures()).unwrap();
    let text = trm_mbm::peer_problems("panda", &problems, None).unwrap();
    let mut lines = text.lines();
    assert_eq!(lines.next(), Some("trm-mbm-problems 1"));
    assert_eq!(lines.next(), Some("robot panda"));
    assert!(lines.next().unwrap().starts_with("joints 7 panda_joint1 "));
    assert_eq!(lines.next(), Some("problems 14"));
    for p in &problems {
        let scene = PlanningScene::load(&p.scene).unwrap();
        let request = MotionPlanRequest::load(&p.request).unwrap();
        assert_eq!(
            lines.next().unwrap(),
            format!("problem {} {}", p.family, p.index)
        );
        let start: Vec<f64> = lines
            .next()
            .unwrap()
            .split(' ')
            .skip(1)
            .map(|v| v.parse().unwrap())
            .collect();
        assert_eq!(start, request.start.positions[..7]);
        let goal: Vec<f64> = lines
            .next()
            .unwrap()
            .split(' ')
            .skip(1)
            .map(|v| v.parse().unwrap())
            .collect();
        assert_eq!(goal, request.goal.positions);
        let n: usize = lines
            .next()
            .unwrap()
            .strip_prefix("objects ")
            .unwrap()
            .parse()
            .unwrap();
        let primitives: Vec<_> = scene.objects.iter().flat_map(|o| &o.primitives).collect();
        assert_eq!(n, primitives.len());
        for primitive in primitives {
            let words: Vec<&str> = lines.next().unwrap().split(' ').collect();
            let x: f64 = words[1].parse().unwrap();
            assert_eq!(x, primitive.pose.translation.vector.x);
        }
    }
    assert_eq!(lines.next(), None);

    let answer = "result box_panda 1 1 1 150000 50000 4.5 4.0 12 2\npath 0 0\npath 1 1\n\nresult box_panda 2 0 0 0 0 0 0 0 0\n";
    let results = trm_mbm::parse_peer_results(answer).unwrap();
    assert_eq!(results.len(), 2);
    let (family, index, first) = &results[0];
    assert_eq!((family.as_str(), *index), ("box_panda", 1));
    assert!(first.valid && first.solved);
    assert!((first.seconds - 2e-4).abs() < 1e-15);
    assert_eq!((first.length, first.waypoints), (4.0, 2));
    assert_eq!(first.path, vec![vec![0.0, 0.0], vec![1.0, 1.0]]);
    assert!(!results[1].2.valid && !results[1].2.solved);
    for (bad, says) in [
        (
            "result box_panda 1 1 1 NaN 0 0 0 0 0",
            "line 1: not a finite number",
        ),
        (
            "result box_panda 1 1 1 0 0 0 0 0",
            "line 1: a result has 10 or 11 fields",
        ),
        ("path 0 0", "line 1: a path line before any result"),
        (
            "result box_panda x 1 1 0 0 0 0 0 0",
            "line 1: not a problem number",
        ),
        (
            "result box_panda 1 1 1 0 0 0 0 0 0\nsolved",
            "line 2: neither",
        ),
    ] {
        let e = trm_mbm::parse_peer_results(bad).unwrap_err();
        assert!(e.contains(says), "{bad}: {e}");
    }
}

/// `--world` files: a MoveIt scene (.yaml) or trm's RON world, one call.
#[test]
fn worlds_load_from_moveit_scenes_and_ron() {
    let scene = fixtures().join("box_panda/scene0001.yaml");
    let world = trm_moveit::load_world(&scene).unwrap();
    assert_eq!(
        world.len(),
        PlanningScene::load(&scene)
            .unwrap()
            .to_world()
            .unwrap()
            .len()
    );
    let ron = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../specs/worlds/table.ron");
    assert!(!trm_moveit::load_world(&ron).unwrap().is_empty());
    let e = trm_moveit::load_world(fixtures().join("box_panda/request0001.yaml")).unwrap_err();
    assert!(e.to_string().contains("request0001.yaml"), "{e}");
}

/// Experience: one planner per family keeps what RRT-Connect finds; the second pass over the
/// sample answers from it, every path proved free (certified planning), and the whole run repeats
/// exactly for its seed.
#[test]
fn experience_answers_the_second_pass() {
    let model = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../models/panda-mbm/panda.ron");
    let robot = trm_kinematics::RobotModel::load(&model).unwrap();
    let collision = trm_collision::CollisionModel::new(&robot).unwrap();
    let problems = find_problems(&fixtures()).unwrap();
    // certified: kept paths are proved, and so is what the second pass retrieves
    let options = RrtOptions {
        certified: true,
        ..Default::default()
    };
    let loaded = LoadedProblem::load_all(&collision, &problems).unwrap();
    let mut calls = 0;
    let passes =
        trm_mbm::solve_with_experience(&robot, &loaded, &options, 2, |_, _| calls += 1).unwrap();
    assert_eq!(calls, 2 * problems.len());
    for (pass, outcomes) in passes.iter().enumerate() {
        for (p, o) in problems.iter().zip(outcomes) {
            assert!(
                o.valid && o.solved,
                "pass {pass}, {} {}: {}",
                p.family,
                p.index,
                o.note
            );
            let scene = PlanningScene::load(&p.scene).unwrap();
            let request = MotionPlanRequest::load(&p.request).unwrap();
            assert!(
                certify_path(&robot, &collision, &scene, &request, &o.path).unwrap()
                    == Verdict::Proved
            );
            assert_eq!(o.path.first().unwrap(), &request.start.positions[..7]);
            assert_eq!(o.path.last().unwrap(), &request.goal.positions);
        }
    }
    // the first problem of each family has no experience yet
    assert!(
        passes[0]
            .iter()
            .zip(&problems)
            .filter(|(_, p)| p.index == 1)
            .all(|(o, _)| o.note != "experience" && o.note != "retrieved")
    );
    let from_experience = passes[1]
        .iter()
        .filter(|o| o.note == "experience" || o.note == "retrieved")
        .count();
    assert!(
        from_experience * 2 >= problems.len(),
        "{from_experience} of {} from experience",
        problems.len()
    );
    let again = trm_mbm::solve_with_experience(&robot, &loaded, &options, 2, |_, _| {}).unwrap();
    for (a, b) in passes.iter().flatten().zip(again.iter().flatten()) {
        assert_eq!(a.path, b.path);
    }
}

/// Plain RRT-Connect (no dynamic domain, alternating trees) solves the sample too; the dynamic
/// domain skips samples without checking them, so it needs fewer checks on the cage problems.
#[test]
fn plain_and_dynamic_domain_rrt_connect_both_solve() {
    let model = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../models/panda-mbm/panda.ron");
    let robot = trm_kinematics::RobotModel::load(&model).unwrap();
    let collision = trm_collision::CollisionModel::new(&robot).unwrap();
    let plain = RrtOptions {
        dynamic_domain: false,
        balance: false,
        ..Default::default()
    };
    let (mut checks_plain, mut checks_domain) = (0, 0);
    for p in find_problems(&fixtures()).unwrap() {
        let scene = PlanningScene::load(&p.scene).unwrap();
        let request = MotionPlanRequest::load(&p.request).unwrap();
        for (options, checks) in [
            (&plain, &mut checks_plain),
            (&RrtOptions::default(), &mut checks_domain),
        ] {
            let outcome = solve(&robot, &collision, &scene, &request, options).unwrap();
            assert!(outcome.solved, "{} {}: {}", p.family, p.index, outcome.note);
            if p.family.starts_with("cage") {
                *checks += outcome.checks;
            }
        }
    }
    assert!(
        checks_domain < checks_plain,
        "{checks_domain} checks with the dynamic domain, {checks_plain} without"
    );
}

/// Random shortcuts cut corners close to obstacles: with certified paths, every path they
/// return is proved free in continuous motion (checked only at points, 12 of MotionBenchMaker's
/// 699 Panda paths with 50 shortcuts once collided between them).
#[test]
fn randomly_shortcut_certified_paths_are_proved_free() {
    let model =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../models/panda-mbm/panda_spherized.ron");
    let robot = trm_kinematics::RobotModel::load(&model).unwrap();
    let collision = trm_collision::CollisionModel::new(&robot).unwrap();
    let mut solved = 0;
    for p in find_problems(&fixtures()).unwrap() {
        let scene = PlanningScene::load(&p.scene).unwrap();
        let request = MotionPlanRequest::load(&p.request).unwrap();
        for seed in 0..6 {
            let options = RrtOptions {
                shortcuts: 50,
                seed,
                certified: true,
                ..Default::default()
            };
            let outcome = solve(&robot, &collision, &scene, &request, &options).unwrap();
            if outcome.solved {
                solved += 1;
                assert!(
                    certify_path(&robot, &collision, &scene, &request, &outcome.path).unwrap()
                        == Verdict::Proved,
                    "{} {} seed {seed}",
                    p.family,
                    p.index
                );
            }
        }
    }
    assert!(solved >= 70, "{solved} of 84 solved");
}

/// The Halton sampler solves every sample problem too (paths proved free), the
/// same path for the same seed twice and another path for another seed (its shift).
#[test]
fn halton_samples_solve_reproducibly_and_seeds_shift_them() {
    let model = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../models/panda-mbm/panda.ron");
    let robot = trm_kinematics::RobotModel::load(&model).unwrap();
    let collision = trm_collision::CollisionModel::new(&robot).unwrap();
    let halton = |seed| RrtOptions {
        sampler: trm_plan::rrt::Sampler::Halton,
        seed,
        ..Default::default()
    };
    let mut differ = 0;
    for p in find_problems(&fixtures()).unwrap() {
        // each run solved and its path proved free
        let run = |seed| solved_and_free(&robot, &collision, &p, &halton(seed)).1;
        let (first, again, other) = (run(0), run(0), run(1));
        assert_eq!(first.path, again.path, "{} {}", p.family, p.index);
        differ += usize::from(first.path != other.path);
    }
    assert!(differ > 0, "seeds 0 and 1 gave the same paths everywhere");
}

/// Requests round-trip through the writer (every field the reader reads), and the writer
/// refuses a goal or start that is not one finite value per name.
#[test]
fn requests_round_trip_and_bad_ones_are_not_written() {
    for p in find_problems(&fixtures()).unwrap() {
        let request = MotionPlanRequest::load(&p.request).unwrap();
        let again = MotionPlanRequest::parse(&request.to_yaml().unwrap(), &p.request).unwrap();
        assert_eq!(again, request, "{}", p.request.display());
    }
    let good = MotionPlanRequest::load(fixtures().join("box_panda/request0001.yaml")).unwrap();
    let mut nan = good.clone();
    nan.goal.positions[0] = f64::NAN;
    let mut short = good.clone();
    short.start.positions.pop();
    let mut tolerance = good.clone();
    tolerance.goal.tolerances[0].1 = -1.0;
    for bad in [nan, short, tolerance] {
        let e = bad.to_yaml().unwrap_err().to_string();
        assert!(
            e.contains("not written") && e.contains("request0001.yaml"),
            "{e}"
        );
    }
}

/// A task-space goal: the Panda's hand where the sample problem's joint goal puts it (a 1 cm
/// box, orientation within 0.05 rad), written as MoveIt constraints, read back, solved (IK for
/// a collision-free goal, then RRT-Connect) and checked at the end of the path.
#[test]
fn task_space_goals_are_read_written_and_solved() {
    use trm_collision::Shape;
    use trm_kinematics::nalgebra::{Isometry3, Translation3};
    use trm_plan::pose_goal::{OrientationConstraint, PoseGoal, PositionConstraint};
    let model = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../models/panda-mbm/panda.ron");
    let robot = trm_kinematics::RobotModel::load(&model).unwrap();
    let collision = trm_collision::CollisionModel::new(&robot).unwrap();
    let dir = fixtures().join("box_panda");
    let scene = PlanningScene::load(dir.join("scene0001.yaml")).unwrap();
    let joints = MotionPlanRequest::load(dir.join("request0001.yaml")).unwrap();
    // the hand's pose at the joint goal
    let base: Vec<f64> = robot.neutral_motors();
    let (start, _) = trm_moveit::motors_from_state(&robot, &joints.start, &base);
    let mut goal_motors = start.clone();
    for (name, v) in joints.goal.names.iter().zip(&joints.goal.positions) {
        goal_motors[robot.motor_index(name).unwrap()] = *v;
    }
    let mut poses = robot.pose_buffer();
    robot.forward_motors(&goal_motors, &mut poses).unwrap();
    let hand = *poses.pose(robot.frame_id("panda_hand").unwrap());
    let goal = PoseGoal {
        positions: vec![PositionConstraint {
            link: "panda_hand".into(),
            frame: "panda_link0".into(),
            offset: Default::default(),
            regions: vec![(
                Shape::Box {
                    size: [0.01, 0.01, 0.01],
                },
                Isometry3::from_parts(
                    Translation3::from(hand.translation.vector),
                    Default::default(),
                ),
            )],
        }],
        orientations: vec![OrientationConstraint {
            link: "panda_hand".into(),
            frame: String::new(),
            orientation: hand.rotation,
            tolerance: [0.05; 3],
        }],
    };
    let mut request = joints.clone();
    request.goal = Default::default();
    request.pose_goal = goal.clone();
    let text = request.to_yaml().unwrap();
    let back = MotionPlanRequest::parse(&text, Path::new("pose.yaml")).unwrap();
    // read back as written (the quaternion renormalised on reading: equal to 1e-12 rad)
    assert_eq!(back.pose_goal.positions, goal.positions, "{text}");
    let (a, b) = (&back.pose_goal.orientations[0], &goal.orientations[0]);
    assert!(a.orientation.angle_to(&b.orientation) < 1e-12 && a.tolerance == b.tolerance);
    assert!(back.goal.names.is_empty() && back.group == "panda_arm");
    let certified = RrtOptions {
        certified: true,
        ..Default::default()
    };
    let outcome = solve(&robot, &collision, &scene, &back, &certified).unwrap();
    assert!(outcome.valid && outcome.solved, "{}", outcome.note);
    // the path ends where the goal holds, and is proved free
    let active = robot.group("panda_arm").unwrap();
    let mut end = start.clone();
    for (&i, v) in active.iter().zip(outcome.path.last().unwrap()) {
        end[i] = *v;
    }
    robot.forward_motors(&end, &mut poses).unwrap();
    assert!(goal.met(&robot, &poses).unwrap());
    assert!(
        certify_path(&robot, &collision, &scene, &back, &outcome.path).unwrap() == Verdict::Proved
    );

    // bad task-space goals: another frame, no group, joints and a pose at once
    let mut foreign = back.clone();
    foreign.pose_goal.positions[0].frame = "world".into();
    let e = solve(&robot, &collision, &scene, &foreign, &RrtOptions::default())
        .unwrap_err()
        .to_string();
    assert!(e.contains("`world`") && e.contains("panda_link0"), "{e}");
    let no_group = text.replace("group_name: \"panda_arm\"\n", "");
    let e = solve(
        &robot,
        &collision,
        &scene,
        &MotionPlanRequest::parse(&no_group, Path::new("g.yaml")).unwrap(),
        &RrtOptions::default(),
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("group_name"), "{e}");
    let both = text.replace(
        "goal_constraints:\n",
        "goal_constraints:\n  - joint_constraints:\n      - {joint_name: panda_joint1, position: 0.0}\n    ",
    );
    let e = MotionPlanRequest::parse(&both, Path::new("b.yaml"))
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("either joint constraints or a task-space goal"),
        "{e}\n{both}"
    );
}

/// The scene's allowed-collision matrix overrides the model's on the robot's link pairs, as
/// MoveIt's planning-scene matrix overrides the SRDF's; entries that are not links are noted.
#[test]
fn the_scenes_allowed_collision_matrix_is_applied_to_link_pairs() {
    let model = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../models/panda-mbm/panda.ron");
    let robot = trm_kinematics::RobotModel::load(&model).unwrap();
    let collision = trm_collision::CollisionModel::new(&robot).unwrap();
    let scene = PlanningScene::load(fixtures().join("box_panda/scene0001.yaml")).unwrap();
    let acm = scene.allowed_collisions.clone().unwrap();
    let tree = robot.tree();
    let id = |n: &str| tree.link_index(n).unwrap();
    // pick a pair the model checks and allow it, and one the model skips and forbid it
    let mut m = acm.clone();
    let (a, b) = (
        m.names.iter().position(|n| n == "panda_hand").unwrap(),
        m.names.iter().position(|n| n == "panda_link2").unwrap(),
    );
    m.allowed[a][b] = true;
    m.allowed[b][a] = true;
    // and check two adjacent links: a fact of the model's geometry, the pair stays disabled
    let (c, d) = (
        m.names.iter().position(|n| n == "panda_link1").unwrap(),
        m.names.iter().position(|n| n == "panda_link2").unwrap(),
    );
    m.allowed[c][d] = false;
    m.allowed[d][c] = false;
    m.names.push("table".into());
    for row in &mut m.allowed {
        row.push(true);
    }
    m.allowed.push(vec![true; m.names.len()]);
    assert!(
        collision
            .acm()
            .is_checked(id("panda_hand"), id("panda_link2"))
    );
    let (applied, notes) = m.apply(&collision).unwrap();
    let applied = applied.expect("the matrix changes the model's");
    assert!(
        !applied
            .acm()
            .is_checked(id("panda_hand"), id("panda_link2"))
    );
    assert_eq!(notes.len(), 2);
    assert!(notes[0].contains("`table`"), "{notes:?}");
    assert!(
        notes[1].contains("1 pair it checks stays disabled")
            && notes[1].contains("`panda_link1`–`panda_link2` (adjacent)"),
        "{notes:?}"
    );
    // every pair the scene lists ends as the scene says, but for the pairs the model's own
    // geometry disables
    for (i, row) in m.allowed.iter().enumerate() {
        for (j, &allowed) in row.iter().enumerate() {
            if let (Some(x), Some(y)) = (tree.link_index(&m.names[i]), tree.link_index(&m.names[j]))
            {
                let geometric = collision.acm().reason(x, y).is_some_and(|r| {
                    use trm_kinematics::DisableReason::{Adjacent, Always, Default, Never};
                    matches!(r, Adjacent | Always | Default | Never)
                });
                if x != y {
                    assert_eq!(
                        applied.acm().is_checked(x, y),
                        !allowed && !geometric,
                        "{} {}",
                        m.names[i],
                        m.names[j]
                    );
                }
            }
        }
    }
}

/// Experience runs plan each problem with its own scene's allowed-collision matrix, as single
/// runs do: a scene that forbids a pair the model skips (links 1 and 2, which touch; disabled
/// by hand here, as a scene cannot enable a pair the model disables as adjacent) makes its
/// problem invalid in both, and the family's other problems are still solved.
#[test]
fn experience_runs_apply_each_scenes_allowed_collision_matrix() {
    let model = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../models/panda-mbm/panda.ron");
    let robot = trm_kinematics::RobotModel::load(&model).unwrap();
    let collision = trm_collision::CollisionModel::new(&robot).unwrap();
    let tree = robot.tree();
    let (l1, l2) = (
        tree.link_index("panda_link1").unwrap(),
        tree.link_index("panda_link2").unwrap(),
    );
    let mut own = collision.acm().clone();
    own.enable(l1, l2);
    own.disable(l1, l2, trm_kinematics::DisableReason::User);
    let collision = collision.with_acm(own).unwrap();
    let dir = std::env::temp_dir().join(format!("trm-acm-experience-{}", std::process::id()));
    let family = dir.join("box_panda");
    std::fs::create_dir_all(&family).unwrap();
    for entry in std::fs::read_dir(fixtures().join("box_panda")).unwrap() {
        let path = entry.unwrap().path();
        std::fs::copy(&path, family.join(path.file_name().unwrap())).unwrap();
    }
    let problems = find_problems(&dir).unwrap();
    let strict = &problems[1];
    let mut scene = PlanningScene::load(&strict.scene).unwrap();
    let m = scene.allowed_collisions.as_mut().unwrap();
    let a = m.names.iter().position(|n| n == "panda_link1").unwrap();
    let b = m.names.iter().position(|n| n == "panda_link2").unwrap();
    m.allowed[a][b] = false;
    m.allowed[b][a] = false;
    std::fs::write(&strict.scene, scene.to_yaml().unwrap()).unwrap();
    let options = RrtOptions::default();
    let request = MotionPlanRequest::load(&strict.request).unwrap();
    let single = solve(&robot, &collision, &scene, &request, &options).unwrap();
    assert!(!single.valid, "{}", single.note);
    let loaded = LoadedProblem::load_all(&collision, &problems).unwrap();
    let passes = trm_mbm::solve_with_experience(&robot, &loaded, &options, 1, |_, _| {}).unwrap();
    for (p, o) in problems.iter().zip(&passes[0]) {
        assert_eq!(
            o.valid,
            p.index != strict.index,
            "{} {}: {}",
            p.family,
            p.index,
            o.note
        );
        assert_eq!(o.solved, o.valid, "{} {}: {}", p.family, p.index, o.note);
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A kept solver (one planner, each problem's scene set on it) answers every problem as a
/// planner made for that problem alone does, in either order and in both modes: the
/// benchmark's outcomes do not depend on the problems before.
#[test]
fn a_kept_planner_answers_as_a_fresh_one() {
    let model = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../models/panda-mbm/panda.ron");
    let robot = trm_kinematics::RobotModel::load(&model).unwrap();
    let collision = CollisionModel::new(&robot).unwrap();
    let problems = find_problems(&fixtures()).unwrap();
    let loaded = LoadedProblem::load_all(&collision, &problems).unwrap();
    assert!(loaded.len() >= 3, "{} problems", loaded.len());
    for certified in [false, true] {
        let options = RrtOptions {
            certified,
            ..RrtOptions::default()
        };
        let fresh: Vec<_> = (loaded.iter())
            .map(|p| trm_mbm::solve_loaded(&robot, p, &options).unwrap())
            .collect();
        for order in [false, true] {
            let mut solver = trm_mbm::Solver::new(&robot, &[]);
            let mut ks: Vec<usize> = (0..loaded.len()).collect();
            if order {
                ks.reverse();
            }
            for k in ks {
                let kept = solver.solve(&loaded[k], &options).unwrap();
                let (a, b) = (&kept, &fresh[k]);
                assert!(a.solved, "problem {k}: {}", a.note);
                assert_eq!(
                    (a.solved, &a.path, a.checks, &a.note),
                    (b.solved, &b.path, b.checks, &b.note),
                    "problem {k}, certified {certified}"
                );
            }
        }
    }
}

/// Leave-one-out experience: each problem planned through the other problems' paths (of its
/// family, or of the set) never retrieves its own, even when the paths given include it at its
/// own index; a path given for itself alone is retrieved. Times split into planning and
/// simplification.
#[test]
fn leave_one_out_experience_never_sees_the_problem_s_own_path() {
    let model = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../models/panda-mbm/panda.ron");
    let robot = trm_kinematics::RobotModel::load(&model).unwrap();
    let collision = trm_collision::CollisionModel::new(&robot).unwrap();
    let problems = find_problems(&fixtures()).unwrap();
    let loaded = LoadedProblem::load_all(&collision, &problems).unwrap();
    let options = RrtOptions::default();
    let plain: Vec<trm_mbm::Outcome> = loaded
        .iter()
        .map(|p| trm_mbm::solve_loaded(&robot, p, &options).unwrap())
        .collect();
    for o in &plain {
        assert!(o.solved && o.simplify_seconds >= 0.0 && o.simplify_seconds <= o.seconds);
    }
    let paths: Vec<Vec<Vec<f64>>> = plain.iter().map(|o| o.path.clone()).collect();
    for scope in [trm_mbm::Scope::Family, trm_mbm::Scope::Set] {
        let mut calls = 0;
        let outcomes =
            trm_mbm::solve_leave_one_out(&robot, &loaded, &paths, scope, &options, |_| calls += 1)
                .unwrap();
        assert_eq!(calls, problems.len());
        for (k, (p, o)) in problems.iter().zip(&outcomes.outcomes).enumerate() {
            assert!(o.solved, "{scope:?} {} {}: {}", p.family, p.index, o.note);
            assert_ne!(o.note, "retrieved", "{scope:?} {} {}", p.family, p.index);
            // beside it, the problem afresh: the plain run's answer
            let fresh = &outcomes.fresh[k];
            assert_eq!(
                (&fresh.path, fresh.checks),
                (&plain[k].path, plain[k].checks)
            );
        }
    }
    // the control: a problem's own path, given under another problem's index, is retrieved
    let only_first: Vec<Vec<Vec<f64>>> = paths
        .iter()
        .enumerate()
        .map(|(k, p)| if k == 0 { p.clone() } else { Vec::new() })
        .collect();
    let mut swapped = loaded.clone();
    swapped.swap(0, 1);
    let (a, b) = (&swapped[0].problem, &swapped[1].problem);
    if a.family == b.family {
        // the first problem's path, given at index 0, is left out of the planner of the problem
        // now at index 0 (the second), and given to the problem now at index 1 (the first),
        // which retrieves it: what leave-one-out would do with a problem's own path
        let outcomes = trm_mbm::solve_leave_one_out(
            &robot,
            &swapped,
            &only_first,
            trm_mbm::Scope::Family,
            &options,
            |_| {},
        )
        .unwrap();
        let notes = &outcomes.outcomes;
        assert_eq!(notes[1].note, "retrieved", "{}", notes[1].note);
        assert_ne!(notes[0].note, "retrieved");
    }
    let e = trm_mbm::solve_leave_one_out(
        &robot,
        &loaded,
        &paths[1..],
        trm_mbm::Scope::Family,
        &options,
        |_| {},
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("paths for"), "{e}");
}

/// A set as point clouds: every problem's world is one cloud thinned to the spacing, trm
/// plans among it, and the peers get the very points (`cloud N RADIUS` and a line per point),
/// their build times read back from an 11th field.
#[test]
fn scenes_as_point_clouds_are_planned_in_and_handed_to_peers() {
    let robot = trm_kinematics::RobotModel::load(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../models/panda-mbm/panda_spherized.ron"),
    )
    .unwrap();
    let collision = CollisionModel::new(&robot).unwrap();
    let problems: Vec<_> = find_problems(&fixtures())
        .unwrap()
        .into_iter()
        .take(3)
        .collect();
    let options = trm_mbm::BenchmarkOptions {
        obstacles: trm_mbm::Obstacles::Cloud { per_object: 2000 },
        ..Default::default()
    };
    let bench =
        trm_mbm::benchmark(&robot, &collision, &problems, &options, |_, _, _, _| {}).unwrap();
    for (p, run) in bench.problems.iter().zip(&bench.runs) {
        let build = p.cloud.expect("a cloud");
        assert!(build.kept > 100 && build.kept < build.sampled, "{build:?}");
        let [cloud] = p.world.objects() else {
            panic!("one cloud object");
        };
        let Shape::Points { points, radius } = cloud.shape() else {
            panic!("points");
        };
        assert_eq!(
            (points.len(), *radius),
            (build.kept, trm_mbm::CLOUD_POINT_RADIUS)
        );
        assert!(run.outcome.build_seconds > 0.0);
        assert!(run.outcome.solved, "{}", run.outcome.note);
    }
    let clouds: Vec<World> = bench.problems.iter().map(|p| p.world.clone()).collect();
    let text = trm_mbm::peer_problems("panda", &problems, Some(&clouds)).unwrap();
    let first = &bench.problems[0].world.objects()[0];
    let Shape::Points { points, .. } = first.shape() else {
        panic!("points");
    };
    let header = format!("cloud {} {}", points.len(), trm_mbm::CLOUD_POINT_RADIUS);
    let at = text.find(&header).expect("the cloud's header");
    let line = text[at..].lines().nth(1).unwrap();
    assert_eq!(
        line,
        format!("{} {} {}", points[0][0], points[0][1], points[0][2])
    );
    let parsed =
        trm_mbm::parse_peer_results("result box 1 1 1 1000 500 3.0 2.5 10 4 2500000\n").unwrap();
    assert_eq!(parsed[0].2.build_seconds, 2.5e-3);
    assert!(trm_mbm::parse_peer_results("result box 1 1 1 1000 500 3.0 2.5 10 4 2 3\n").is_err());
}

/// A committed MotionBenchMaker set (`panda` or `fetch`) and its robot's sphere model.
fn committed_set(
    robot: &str,
) -> (
    trm_mbm::ProblemSet,
    trm_kinematics::RobotModel,
    CollisionModel,
) {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let set =
        trm_mbm::ProblemSet::open(&root.join(format!("benches/mbm/{robot}_problems.tar.bz2")))
            .unwrap();
    let model = root.join(format!("models/{robot}-mbm/{robot}_spherized.ron"));
    let robot = trm_kinematics::RobotModel::load(&model).unwrap();
    let collision = CollisionModel::new(&robot).unwrap();
    (set, robot, collision)
}

/// Random shortcuts may cut a corner that grazes an obstacle between its checked points at
/// every resolution the search refines to: the problem is still solved, by the search's own
/// path through the greedy pass (with 30 shortcuts, six of MotionBenchMaker's 699 Panda
/// problems, these among them, were once reported unreachable).
#[test]
fn randomly_shortcut_paths_never_turn_a_solved_problem_unsolved() {
    let (set, robot, collision) = committed_set("panda");
    let options = RrtOptions {
        shortcuts: 30,
        ..trm_mbm::rrt_options_for(&robot, &collision, &set.problems).unwrap()
    };
    let grazing = [
        ("table_pick_panda", 6),
        ("table_pick_panda", 7),
        ("bookshelf_tall_panda", 58),
    ];
    let mut tried = 0;
    for p in (set.problems.iter()).filter(|p| grazing.contains(&(p.family.as_str(), p.index))) {
        tried += 1;
        let scene = PlanningScene::load(&p.scene).unwrap();
        let request = MotionPlanRequest::load(&p.request).unwrap();
        let outcome = solve(&robot, &collision, &scene, &request, &options).unwrap();
        let what = format!("{} {}: {}", p.family, p.index, outcome.note);
        assert!(outcome.valid && outcome.solved, "{what}");
    }
    assert_eq!(tried, grazing.len());
}

/// A scene's matrix written for the Fetch's meshes checks a pair its SRDF disables as never
/// colliding, which VAMP's spheres overlap at bookshelf_small 32's goal: the pair stays
/// disabled (a note names it) and the problem is solved. Were the pair disabled by hand, the
/// scene's matrix would check it and the goal collide; with the scenes' matrices ignored (the
/// model's own only, as VAMP checks) it is solved again.
#[test]
fn a_pair_never_colliding_stays_disabled_and_scene_matrices_can_be_ignored() {
    let (set, robot, collision) = committed_set("fetch");
    let problems: Vec<_> = (set.problems.iter())
        .filter(|p| p.family == "bookshelf_small_fetch" && p.index == 32)
        .cloned()
        .collect();
    assert_eq!(problems.len(), 1);
    let run = |collision: &CollisionModel, ignore_scene_matrices| {
        let options = trm_mbm::BenchmarkOptions {
            // the benchmark's budget
            rrt: RrtOptions {
                max_iterations: 1_000_000,
                ..trm_mbm::rrt_options_for(&robot, collision, &problems).unwrap()
            },
            ignore_scene_matrices,
            ..Default::default()
        };
        let bench = trm_mbm::benchmark(&robot, collision, &problems, &options, |_, _, _, _| {});
        bench.unwrap().runs.remove(0).outcome
    };
    let applied = run(&collision, false);
    assert!(applied.valid && applied.solved, "{}", applied.note);
    let kept = "1 pair it checks stays disabled, as this model disables it for a fact of \
                geometry: `shoulder_lift_link`–`torso_lift_link` (never)";
    assert!(applied.note.contains(kept), "{}", applied.note);
    let tree = robot.tree();
    let (a, b) = (
        tree.link_index("torso_lift_link").unwrap(),
        tree.link_index("shoulder_lift_link").unwrap(),
    );
    let mut by_hand = collision.acm().clone();
    by_hand.enable(a, b);
    by_hand.disable(a, b, trm_kinematics::DisableReason::User);
    let by_hand = collision.with_acm(by_hand).unwrap();
    let checked = run(&by_hand, false);
    assert!(!checked.valid, "{}", checked.note);
    assert!(checked.note.contains("a scene's"), "{}", checked.note);
    let ignored = run(&by_hand, true);
    assert!(ignored.valid && ignored.solved, "{}", ignored.note);
}
