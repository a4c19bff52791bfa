//! What the `trm` tool and Python share through this crate: a scene and a request applied to a
//! planner (held objects by name), the timing's scaling resolved as MoveIt resolves it, and a
//! planned motion's files.

use std::path::Path;

use trm_collision::{AttachedObject, CollisionModel, Shape};
use trm_kinematics::nalgebra::Isometry3;
use trm_moveit::{
    JointLimitsFile, MotionPlanRequest, Scene, TimingSettings, check_trajectory_out,
    describe_files, trajectory_files,
};
use trm_plan::{Planner, Trajectory};

fn panda() -> trm_kinematics::RobotModel {
    let models = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../models");
    trm_models::load("panda-mbm/panda_spherized.ron", &models).unwrap()
}

fn held(name: &str, radius: f64) -> AttachedObject {
    AttachedObject {
        name: name.into(),
        link: "panda_hand".into(),
        shapes: vec![(Shape::Sphere { radius }, Isometry3::identity())],
        touch_links: vec!["panda_leftfinger".into(), "panda_rightfinger".into()],
    }
}

fn request(extra: &str) -> MotionPlanRequest {
    let text = format!(
        "start_state:\n  joint_state:\n    name: [panda_joint1]\n    position: [0.1]\n{extra}goal_constraints:\n  - joint_constraints:\n      - joint_name: panda_joint1\n        position: 0.5\n"
    );
    MotionPlanRequest::parse(&text, Path::new("request.yaml")).unwrap()
}

#[test]
fn a_scene_and_a_request_set_what_the_robot_holds_by_name() {
    let robot = panda();
    let collision = CollisionModel::new(&robot).unwrap();
    let active = robot
        .active_set(&["panda_arm"], &robot.home_motors())
        .unwrap();
    let objective = trm_tasks::Objective::new(active, collision.clone(), Default::default());
    let mut planner = Planner::new(&objective, &[]).unwrap();
    let scene = Scene {
        world: Default::default(),
        acm: collision.acm().clone(),
        notes: vec!["a note".into()],
        attached: vec![held("cup", 0.03), held("spoon", 0.01)],
    };
    assert_eq!(scene.apply_to(&mut planner).unwrap(), ["a note"]);
    let names = |p: &Planner| {
        p.attached()
            .iter()
            .map(|o| o.name.clone())
            .collect::<Vec<_>>()
    };
    assert_eq!(names(&planner), ["cup", "spoon"]);
    // the request's start state holds a bigger cup: it replaces the scene's, the spoon stays
    let mut r = request("");
    r.attached = vec![held("cup", 0.05)];
    r.hold_on(&mut planner).unwrap();
    assert_eq!(names(&planner), ["spoon", "cup"]);
    assert_eq!(planner.attached()[1], held("cup", 0.05));
    // a request holding nothing changes nothing
    request("").hold_on(&mut planner).unwrap();
    assert_eq!(names(&planner), ["spoon", "cup"]);
}

#[test]
fn scaling_resolves_as_moveit_resolves_it() {
    let file = JointLimitsFile::parse(
        "default_velocity_scaling_factor: 0.5\ndefault_acceleration_scaling_factor: 0.25\njoint_limits: {}\n",
        Path::new("joint_limits.yaml"),
    )
    .unwrap();
    let asks = request("max_velocity_scaling_factor: 0.3\n");
    let mut settings = TimingSettings::default();
    // nothing given: full speed
    assert_eq!(settings.timing(Some(&asks)).acceleration_scaling, 1.0);
    assert_eq!(settings.timing(Some(&asks)).velocity_scaling, 0.3);
    // the file's defaults under the request's
    settings.joint_limits = Some(file);
    let t = settings.timing(Some(&asks));
    assert_eq!((t.velocity_scaling, t.acceleration_scaling), (0.3, 0.25));
    let t = settings.timing(None);
    assert_eq!((t.velocity_scaling, t.acceleration_scaling), (0.5, 0.25));
    // the user's over both
    settings.velocity_scaling = Some(0.9);
    assert_eq!(settings.timing(Some(&asks)).velocity_scaling, 0.9);
}

#[test]
fn a_motion_is_written_as_trm_plan_writes_it() {
    let robot = panda();
    let active = robot
        .active_set(&["panda_arm"], &robot.home_motors())
        .unwrap();
    let start = active.from_motors(&robot.home_motors());
    let mut goal = start.clone();
    goal[0] += 0.5;
    let trajectory = Trajectory::at_joint_speed(&active, &[start, goal], 1.0);
    assert_eq!(trajectory.times, [0.0, 0.5]);
    let out = Path::new("dir/motion.csv");
    let files = trajectory_files(&trajectory, &robot, Some(("panda_arm", 0.25)), out).unwrap();
    let names: Vec<_> = files.iter().map(|(p, _)| p.display().to_string()).collect();
    assert_eq!(
        names,
        [
            "dir/motion.csv",
            "dir/motion.json",
            "dir/motion.ros.yaml",
            "dir/motion.response.yaml"
        ]
    );
    assert!(files[0].1.starts_with("time,panda_joint1,"));
    assert!(files[3].1.contains("group_name: \"panda_arm\""));
    assert!(files[3].1.contains("planning_time: 0.25"));
    assert_eq!(
        describe_files(&files),
        "dir/motion.csv, dir/motion.json, dir/motion.ros.yaml (ROS 2 JointTrajectory), dir/motion.response.yaml (MoveIt MotionPlanResponse)"
    );
    // without a group and a planning time, no response
    assert_eq!(
        trajectory_files(&trajectory, &robot, None, out)
            .unwrap()
            .len(),
        3
    );
    // a CSV path its own JSON would overwrite is refused, naming the setting and the fix
    let e = check_trajectory_out("--out", Path::new("motion.json"))
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("--out motion.json") && e.contains("fix: give a .csv path"),
        "{e}"
    );
    assert!(check_trajectory_out("--out", out).is_ok());
    // an empty path, and a directory or a symlink where a file goes: refused before planning,
    // each naming the path
    let e = check_trajectory_out("out", Path::new(""))
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("is empty") && e.contains("fix: give a .csv path"),
        "{e}"
    );
    let dir = std::env::temp_dir().join(format!("trm-moveit-out-{}", std::process::id()));
    std::fs::create_dir_all(dir.join("motion.ros.yaml")).unwrap();
    let e = check_trajectory_out("--out", &dir.join("motion.csv"))
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("motion.ros.yaml") && e.contains("directory"),
        "{e}"
    );
    #[cfg(unix)]
    {
        std::os::unix::fs::symlink(dir.join("elsewhere"), dir.join("linked.csv")).unwrap();
        let e = check_trajectory_out("--out", &dir.join("linked.csv"))
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("linked.csv") && e.contains("symbolic link"),
            "{e}"
        );
    }
    std::fs::remove_dir_all(&dir).unwrap();
}
