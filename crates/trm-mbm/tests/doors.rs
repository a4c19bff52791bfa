//! One planner, every door: a `trm_plan::Planner` made once for the robot, each MotionBenchMaker
//! scene set on it (world and allowed-collision matrix) and each request asked of it, answers
//! exactly as the benchmark's solve does; requests that do not fit the planner are named; the
//! MoveIt response a plan is written as reads back.

use std::path::{Path, PathBuf};

use trm_collision::CollisionModel;
use trm_kinematics::RobotModel;
use trm_mbm::{LoadedProblem, find_problems, solve_loaded};
use trm_moveit::{MotionPlanRequest, RequestGoal, load_scene, motion_plan_response_yaml};
use trm_plan::rrt::RrtOptions;
use trm_plan::{Planner, Source};

fn fixtures() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/mbm")
}

fn panda() -> (RobotModel, CollisionModel) {
    let model =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../models/panda-mbm/panda_spherized.ron");
    let robot = RobotModel::load(&model).unwrap();
    let collision = CollisionModel::new(&robot).unwrap();
    (robot, collision)
}

/// A planner for the first request's robot and motors.
fn planner_for(robot: &RobotModel, collision: &CollisionModel, request: &Path) -> Planner {
    let request = MotionPlanRequest::load(request).unwrap();
    let home = vec![0.0; robot.motors().len()];
    let active = request.active_set(robot, &home).unwrap();
    let objective = trm_tasks::Objective::new(active, collision.clone(), Default::default());
    Planner::new(&objective, &[]).unwrap()
}

/// A planner for problem `p`'s robot and motors, its scene set on it; the problem's start and
/// goal.
fn planner_in(
    robot: &RobotModel,
    collision: &CollisionModel,
    p: &trm_mbm::Problem,
) -> (Planner, Vec<f64>, Vec<f64>) {
    let mut planner = planner_for(robot, collision, &p.request);
    let scene = load_scene(&p.scene, collision).unwrap();
    planner.set_world(scene.world);
    planner.set_acm(scene.acm).unwrap();
    let (start, goal) = MotionPlanRequest::load(&p.request)
        .unwrap()
        .joint_query(planner.active())
        .unwrap();
    (planner, start, goal)
}

#[test]
fn one_planner_answers_every_problem_as_the_benchmark_does() {
    let (robot, collision) = panda();
    let problems = find_problems(&fixtures()).unwrap();
    let mut planner = planner_for(&robot, &collision, &problems[0].request);
    let options = RrtOptions::default();
    let mut matrices_set = 0;
    for p in &problems {
        let expected = solve_loaded(
            &robot,
            &LoadedProblem::load(&collision, p).unwrap(),
            &options,
        )
        .unwrap();
        let scene = load_scene(&p.scene, &collision).unwrap();
        planner.set_world(scene.world);
        matrices_set += usize::from(planner.set_acm(scene.acm).unwrap());
        let request = MotionPlanRequest::load(&p.request).unwrap();
        let (start, goal) = request.joint_query(planner.active()).unwrap();
        let found = planner.connect(&start, &goal, &options).unwrap();
        let what = format!("{} {}", p.family, p.index);
        assert!(expected.solved, "{what}: {}", expected.note);
        assert_eq!(found.path, expected.path, "{what}");
        assert_eq!(found.checks, expected.checks, "{what}");
        assert_eq!(
            found.source == Source::Straight,
            found.path.len() == 2,
            "{what}"
        );
    }
    // every sample scene carries a matrix, the model's own: nothing is compiled again
    assert_eq!(matrices_set, 0);
}

#[test]
fn a_task_space_request_is_answered_as_the_benchmark_answers_it() {
    let (robot, collision) = panda();
    let problems = find_problems(&fixtures()).unwrap();
    let goals = trm_mbm::TaskSpaceGoals {
        link: "panda_hand".into(),
        position_tolerance: 0.01,
        orientation_tolerance: 0.05,
    };
    let options = RrtOptions::default();
    for p in problems.iter().step_by(3) {
        let (mut planner, _, _) = planner_in(&robot, &collision, p);
        let posed = LoadedProblem::load(&collision, p)
            .unwrap()
            .with_task_space(&robot, &goals)
            .unwrap();
        let expected = solve_loaded(&robot, &posed, &options).unwrap();
        let (start, goal) = posed.request.query(planner.active()).unwrap();
        let RequestGoal::Pose(pose) = goal else {
            panic!("{}: a joint goal", p.request.display())
        };
        let what = format!("{} {}", p.family, p.index);
        let found = planner.connect_to_pose(&start, &pose, &options).unwrap();
        assert!(expected.solved, "{what}: {}", expected.note);
        assert_eq!(found.path, expected.path, "{what}");
        // the path ends where the goal holds, collision-free
        let end = found.path.last().unwrap();
        let mut poses = robot.pose_buffer();
        planner.active().forward(end, &mut poses).unwrap();
        assert!(pose.met(&robot, &poses).unwrap(), "{what}");
        assert!(planner.is_free(end), "{what}");
    }
    // a goal given in another frame is refused by name
    let mut posed = LoadedProblem::load(&collision, &problems[0])
        .unwrap()
        .with_task_space(&robot, &goals)
        .unwrap();
    posed.request.pose_goal.positions[0].frame = "panda_link3".into();
    let (mut planner, start, _) = planner_in(&robot, &collision, &problems[0]);
    let e = planner
        .connect_to_pose(&start, &posed.request.pose_goal, &options)
        .unwrap_err()
        .to_string();
    assert!(e.contains("panda_link3") && e.contains("root frame"), "{e}");
}

#[test]
fn experience_kept_on_the_planner_answers_a_repeated_query() {
    let (robot, collision) = panda();
    let problems = find_problems(&fixtures()).unwrap();
    let p = problems
        .iter()
        .find(|p| p.family == "cage_panda")
        .expect("a cage problem");
    let (mut planner, start, goal) = planner_in(&robot, &collision, p);
    let options = RrtOptions::default();
    let first = planner.connect(&start, &goal, &options).unwrap();
    assert_eq!(first.source, Source::Sampled);
    assert!(planner.add_path(&first.path).unwrap() > 0);
    let again = planner.connect(&start, &goal, &options).unwrap();
    assert_eq!(again.source, Source::Retrieved);
    assert_eq!(again.iterations, 0);
    assert!(
        again.checks < first.checks,
        "{} {}",
        again.checks,
        first.checks
    );
    // timed within the motors' limits, sampled, from the start to the goal
    let timing = trm_plan::Timing::default();
    let trajectory = planner.trajectory(&again.path, &timing).unwrap();
    assert!(trajectory.positions.len() > again.path.len());
    assert!(trajectory.times.windows(2).all(|w| w[1] > w[0]));
    let active = planner.active().clone();
    let first = active.from_motors(&trajectory.positions[0]);
    let last = active.from_motors(trajectory.positions.last().unwrap());
    assert_eq!(&first, again.path.first().unwrap());
    assert!(trm_collision::edge::distance(&last, again.path.last().unwrap()) < 1e-9);
}

/// An edit of a request's text.
type Edit = dyn Fn(&str) -> String;

/// The first sample request with `edit` applied to its text, asked of a planner moving
/// `joints` (the request's when empty) with the other motors held at `held`.
fn request_error(edit: &Edit, joints: &[&str], held: f64) -> String {
    let (robot, collision) = panda();
    let path = find_problems(&fixtures()).unwrap()[0].request.clone();
    let planner = if joints.is_empty() {
        planner_for(&robot, &collision, &path)
    } else {
        let active = robot
            .active_set(joints, &vec![held; robot.motors().len()])
            .unwrap();
        let objective = trm_tasks::Objective::new(active, collision, Default::default());
        Planner::new(&objective, &[]).unwrap()
    };
    let text = edit(&std::fs::read_to_string(&path).unwrap());
    let request = MotionPlanRequest::parse(&text, &path).unwrap();
    request
        .joint_query(planner.active())
        .err()
        .unwrap_or_else(|| panic!("not refused: {text}"))
        .to_string()
}

#[test]
fn requests_that_do_not_fit_the_planner_are_named() {
    let six = [
        "panda_joint1",
        "panda_joint2",
        "panda_joint3",
        "panda_joint4",
        "panda_joint5",
        "panda_joint6",
    ];
    let without_joint7 = |t: &str| {
        t.replace(
            "      - joint_name: panda_joint7\n        position: 1.06196398075046\n",
            "",
        )
    };
    let cases: [(&Edit, &[&str], &str); 5] = [
        (
            &|t| {
                t.replacen(
                    "joint_name: panda_joint1",
                    "joint_name: panda_finger_joint1",
                    1,
                )
            },
            &[],
            "the goal constrains `panda_finger_joint1`, which the planner does not move",
        ),
        (
            &|t| t.replace("panda_joint7, panda_finger", "panda_jointX, panda_finger"),
            &[],
            "the start state does not give `panda_joint7`, which the planner moves",
        ),
        (
            &without_joint7,
            &six,
            "the start state puts `panda_joint7` at 0.785; the planner holds it at 0.5",
        ),
        (
            &|t| t.replace("[0, -0.785, 0, -2.356", "[9, -0.785, 0, -2.356"),
            &[],
            "the start puts `panda_joint1` at 9, outside its limits",
        ),
        (
            &|t| t.to_string(),
            &six,
            "the goal constrains `panda_joint7`, which the planner does not move",
        ),
    ];
    for (edit, joints, expected) in cases {
        let message = request_error(edit, joints, 0.5);
        assert!(message.contains(expected), "{message}");
        assert!(
            message.contains("request0001.yaml") && message.contains("fix:"),
            "{message}"
        );
    }
}

#[test]
fn a_scene_matrix_that_allows_a_colliding_pair_frees_the_configuration() {
    let (robot, collision) = panda();
    let path = &find_problems(&fixtures()).unwrap()[0].request;
    let mut planner = planner_for(&robot, &collision, path);
    // a self-colliding configuration, drawn with a fixed seed
    let mut rng = <rand_chacha::ChaCha8Rng as rand::SeedableRng>::seed_from_u64(7);
    let active = planner.active().clone();
    let colliding = (0..10_000)
        .map(|_| active.random(&mut rng))
        .find(|q| !planner.is_free(q))
        .expect("a self-colliding configuration");
    let own = collision.acm().clone();
    let mut everything = own.clone();
    let links = robot.tree().links.len();
    for a in 0..links {
        for b in a + 1..links {
            everything.disable(a, b, trm_kinematics::DisableReason::User);
        }
    }
    assert!(planner.set_acm(everything.clone()).unwrap());
    assert!(planner.is_free(&colliding));
    assert!(
        !planner.set_acm(everything).unwrap(),
        "the same matrix again"
    );
    assert!(planner.set_acm(own).unwrap());
    assert!(!planner.is_free(&colliding));
}

#[test]
fn a_plan_written_as_a_moveit_response_reads_back() {
    let (robot, collision) = panda();
    let p = &find_problems(&fixtures()).unwrap()[0];
    let (mut planner, start, goal) = planner_in(&robot, &collision, p);
    let found = planner
        .connect(&start, &goal, &RrtOptions::default())
        .unwrap();
    let trajectory = planner
        .trajectory(&found.path, &trm_plan::Timing::default())
        .unwrap();
    let out = Path::new("plan.response.yaml");
    let text = motion_plan_response_yaml(&trajectory, &robot, "panda_arm", 0.25, out).unwrap();
    let doc = trm_moveit::yaml::parse(&text).unwrap();
    assert_eq!(doc.get("group_name").unwrap().scalar(), Some("panda_arm"));
    assert_eq!(doc.get("planning_time").unwrap().scalar(), Some("0.25"));
    let code = doc.get("error_code").unwrap().get("val").unwrap();
    assert_eq!(code.scalar(), Some("1"));
    let points = doc
        .get("trajectory")
        .and_then(|t| t.get("joint_trajectory"))
        .and_then(|t| t.get("points"))
        .and_then(|p| p.items())
        .unwrap();
    assert_eq!(points.len(), trajectory.times.len());
    // every point carries velocities and accelerations, the last at rest
    for key in ["velocities", "accelerations"] {
        let values = points[points.len() - 1]
            .get(key)
            .and_then(|p| p.items())
            .unwrap();
        assert!(!values.is_empty(), "{key}");
    }
    let last: Vec<f64> = points[points.len() - 1]
        .get("positions")
        .and_then(|p| p.items())
        .unwrap()
        .iter()
        .map(|v| v.scalar().unwrap().parse().unwrap())
        .collect();
    // the arm's 7 joints end at the goal (the fingers are not in the trajectory's motors)
    for (k, g) in goal.iter().enumerate() {
        assert!((last[k] - g).abs() < 1e-9, "joint {k}: {} vs {g}", last[k]);
    }
    let start_state = doc
        .get("trajectory_start")
        .unwrap()
        .get("joint_state")
        .unwrap();
    assert_eq!(
        start_state.get("name").unwrap().items().unwrap().len(),
        last.len()
    );
}

#[test]
fn a_colliding_start_or_goal_names_its_pairs_and_the_matrix_that_checks_them() {
    let (robot, collision) = panda();
    let p = &find_problems(&fixtures()).unwrap()[0];
    let mut planner = planner_for(&robot, &collision, &p.request);
    let (start, goal) = MotionPlanRequest::load(&p.request)
        .unwrap()
        .joint_query(planner.active())
        .unwrap();
    // a box around the robot's base: the start collides with it
    let mut world = trm_collision::World::new();
    world
        .add(
            "crate",
            trm_collision::Shape::Box {
                size: [0.4, 0.4, 0.4],
            },
            trm_kinematics::nalgebra::Isometry3::identity(),
        )
        .unwrap();
    planner.set_world(world);
    let message = planner
        .connect(&start, &goal, &RrtOptions::default())
        .unwrap_err()
        .to_string();
    assert!(
        message.contains("collides: link `panda_link0` and object `crate`"),
        "{message}"
    );
    planner.set_world(trm_collision::World::new());
    // every pair checked, the adjacent ones the model disables included: the goal's named
    // pairs say which matrix checks them
    let links = robot.tree().links.len();
    assert!(
        planner
            .set_acm(trm_collision::AllowedCollisionMatrix::all_checked(links))
            .unwrap()
    );
    let pairs = planner.collisions(&goal);
    assert!(!pairs.is_empty());
    assert!(
        pairs.iter().all(|p| p.contains(
            "checked by the matrix set on the planner (a scene's); the model's own disables it ("
        )),
        "{pairs:?}"
    );
    let message = planner
        .connect(&start, &goal, &RrtOptions::default())
        .unwrap_err()
        .to_string();
    assert!(message.contains("collides: links `"), "{message}");
    // the benchmark's note says the same
    let mut loaded = LoadedProblem::load(&collision, p).unwrap();
    loaded.collision = collision
        .with_acm(trm_collision::AllowedCollisionMatrix::all_checked(links))
        .unwrap();
    let outcome = solve_loaded(&robot, &loaded, &RrtOptions::default()).unwrap();
    assert!(!outcome.valid);
    assert!(
        outcome.note.starts_with("the start collides: links `"),
        "{}",
        outcome.note
    );
    assert!(
        outcome
            .note
            .contains("the model's own disables it (adjacent)"),
        "{}",
        outcome.note
    );
}

#[test]
fn a_joint_given_twice_is_refused_where_it_is_given() {
    let (robot, _) = panda();
    let path = find_problems(&fixtures()).unwrap()[0].request.clone();
    let text = std::fs::read_to_string(&path)
        .unwrap()
        .replace("joint_name: panda_joint2", "joint_name: panda_joint1");
    let message = MotionPlanRequest::parse(&text, &path)
        .unwrap_err()
        .to_string();
    assert!(
        message.contains("request0001.yaml:14: joint `panda_joint1` is constrained twice"),
        "{message}"
    );
    // and an active set of motor indices that repeats one
    let home = vec![0.0; robot.motors().len()];
    let message = trm_kinematics::ActiveSet::new(robot.clone(), vec![0, 1, 0], &home)
        .unwrap_err()
        .to_string();
    assert!(
        message.contains("`panda_joint1` is given twice"),
        "{message}"
    );
}
