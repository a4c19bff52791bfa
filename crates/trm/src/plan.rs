//! `trm plan`: through maps (`--map FILE [--map FILE2 …] [--world WORLD] --from home|q.json
//! [--repair] --to "x,y,z"|q.json`), or without them for a robot (`--model MODEL --world
//! scene.yaml --request request.yaml`, or `--joints … --from q.json --to q.json`), writing the
//! trajectory with `--out traj.csv`.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use trm_moveit::RequestGoal;
use trm_plan::rrt::Budget;
use trm_plan::{ExactGoal, Goal, PlanOptions, Planner, Trajectory};
use trm_roadmap::{RepairOptions, Roadmap};
use trm_tasks::Problem;

/// Arguments of `plan`.
#[derive(clap::Args)]
pub struct Args {
    /// Map files (repeatable); they must share the first map's active motors. Without maps,
    /// `--model` plans by RRT-Connect (MoveIt's query: a start and a goal posture).
    #[arg(long = "map", conflicts_with_all = ["model", "joints", "request"])]
    maps: Vec<PathBuf>,
    /// Without maps: the robot (.urdf or .ron model description; the embedded iCub upper body
    /// when absent).
    #[arg(long)]
    model: Option<PathBuf>,
    #[command(flatten)]
    meshes: crate::MeshArgs,
    /// Without maps: the motors that move (comma-separated names, or a group's name; the
    /// request's goal joints with --request, else every motor).
    #[arg(long)]
    joints: Option<String>,
    /// Without maps: a MoveIt motion plan request (.yaml): its start state and joint goal, its
    /// allowed_planning_time as the budget (instead of --from and --to).
    #[arg(long, conflicts_with = "to")]
    request: Option<PathBuf>,
    /// Without maps' own spec: a map attached to the robot's planner (repeatable; built for
    /// the same moving motors, in any world, its nodes and edges checked in --world when the
    /// search wants them). RRT-Connect still answers what it answers in its first samples; the
    /// map is searched only after that (`trm_plan::Planner::connect`).
    #[arg(long = "with-map", value_name = "FILE", conflicts_with = "maps")]
    with_maps: Vec<PathBuf>,
    /// Without maps' own spec: an experience file (`trm-experience`). The paths it holds are
    /// tried first (checked in --world); a path RRT-Connect finds is kept in it (the file is
    /// written again, atomically; created when absent).
    #[arg(long, value_name = "FILE", conflicts_with = "maps")]
    experience: Option<PathBuf>,
    /// The current world (RON, or a MoveIt planning scene .yaml), replacing the one the maps
    /// were built in; a scene's allowed-collision matrix applies over the model's own and the
    /// robot holds its attached objects (with maps or without).
    #[arg(long)]
    world: Option<PathBuf>,
    /// Repair the maps for --world before planning: park what it blocks, bring back parked
    /// nodes it frees, grow points where coverage was lost (`repair-map` without its refill).
    #[arg(long, requires_all = ["world", "maps"])]
    repair: bool,
    /// Start: `home` (the spec's start posture; without maps the model's `home` posture, else
    /// 0 within the limits) or a JSON file with "motors": {name: value} (as `solve --out`
    /// writes) or "q": [active values].
    #[arg(long, default_value = "home")]
    from: String,
    /// Goal: a task-space point "x,y,z" (through a map node within --tolerance, then to the
    /// point itself) or a JSON posture file (the only goal without maps).
    #[arg(long, allow_hyphen_values = true, required_unless_present = "request")]
    to: Option<String>,
    /// Task-space tolerance for the map node a point goal's path goes through.
    #[arg(long, default_value_t = 0.03)]
    tolerance: f64,
    /// End a point goal's path at that map node: no exact finish (NGIK to the point and a
    /// collision-checked last segment).
    #[arg(long)]
    no_exact: bool,
    /// Task error the exact finish must reach (metres for positions).
    #[arg(long, default_value_t = 1e-3, value_parser = crate::parse::positive)]
    exact_tolerance: f64,
    /// Without maps: time budget, s (default: the request's allowed_planning_time, else none).
    #[arg(long, value_parser = crate::parse::positive)]
    max_seconds: Option<f64>,
    /// Without maps: sample budget of RRT-Connect.
    #[arg(long, default_value_t = 1_000_000, value_parser = crate::parse::count(1, 100_000_000))]
    max_samples: usize,
    /// Without maps: largest gap between checked points of an edge, rad (default: sized by the
    /// robot's lever arms; 1/32 rad on the Panda).
    #[arg(long, value_parser = crate::parse::positive)]
    resolution: Option<f64>,
    /// Without maps: RRT-Connect's longest step, rad (default: sized by the robot's lever
    /// arms; 1 rad on the Panda).
    #[arg(long, value_parser = crate::parse::positive)]
    range: Option<f64>,
    /// Without maps: rounds of corner cutting after shortcutting (VAMP's B-spline step; 0:
    /// the greedy shortcut only).
    #[arg(long, default_value_t = trm_plan::rrt::SMOOTHING_ROUNDS, value_parser = crate::parse::count(0, 1_000))]
    smoothing: usize,
    /// Without maps: prove the path free in continuous motion (f64, exact distances, lever-arm
    /// bounds), planning again with proved edges any segment that cannot be proved.
    #[arg(long)]
    certified: bool,
    /// Trajectory output (CSV; beside it a .json, a .ros.yaml ROS 2 JointTrajectory, a
    /// .response.yaml MoveIt MotionPlanResponse and, with maps, an .svg of the path over the
    /// first map).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Seed of the shortcutting (and of RRT-Connect's samples).
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Also write a 3-D view (maps, world, the motion and its task-space path) beside --out
    /// (`<stem>.scene.html`), or as target/plan.scene.html.
    #[arg(long)]
    view: bool,
    #[command(flatten)]
    timing: crate::support::timing::TimingArgs,
}

fn posture(path: &Path, problem: &Problem) -> Result<Vec<f64>> {
    let active = problem.objective.active();
    let motors = crate::support::scene::posture_motors(
        path,
        &problem.robot,
        Some(active),
        &active.to_motors(&problem.start),
    )?;
    Ok(active.from_motors(&motors))
}

/// Plans and reports.
pub fn run(args: &Args) -> Result<()> {
    crate::check_csv_out(args.out.as_deref())?;
    anyhow::ensure!(
        args.tolerance.is_finite() && args.tolerance > 0.0,
        "--tolerance {}: give a finite positive task-space distance",
        args.tolerance
    );
    if args.maps.is_empty() {
        return run_without_maps(args);
    }
    let to = args.to.as_deref().unwrap_or_default();
    let mut maps = load_maps(args)?;
    let problem = maps[0]
        .problem_with(&trm_taskmap::loaders())
        .with_context(|| format!("the spec stored in {}", args.maps[0].display()))?;
    // the world as the map-free path reads it: a scene's objects, its allowed collisions and
    // what the robot holds in it
    let scene = match &args.world {
        Some(path) => Some(trm_moveit::load_scene(path, problem.objective.collision())?),
        None => None,
    };
    if let (true, Some(scene)) = (args.repair, &scene) {
        repair_maps(args, &mut maps, &scene.world)?;
    }
    let first = &maps[0];
    let refs: Vec<&Roadmap> = maps.iter().collect();
    let mut planner = Planner::new(&problem.objective, &refs)?;
    if let (Some(scene), Some(path)) = (scene, &args.world) {
        let notes = scene
            .apply_to(&mut planner)
            .context("the objects the robot holds (attached_collision_objects)")?;
        for note in &notes {
            eprintln!("{}: {note}", path.display());
        }
    }
    let start = if args.from == "home" {
        problem.start.clone()
    } else {
        posture(Path::new(&args.from), &problem)?
    };
    let goal = map_goal(args, to, first, &problem)?;
    let goal_configuration = match &goal {
        Goal::Configuration(q) => Some(q),
        _ => None,
    };
    check_free(&mut planner, args, &start, goal_configuration)?;
    let options = PlanOptions {
        seed: args.seed,
        timing: args.timing.settings()?.timing(None),
        exact_goal: !args.no_exact,
        exact_tolerance: args.exact_tolerance,
        ..Default::default()
    };
    let plan = planner.plan(&start, &goal, &options)?;
    let s = &plan.stats;
    println!(
        "{} maps, {} nodes, {} edges; world: {} objects",
        maps.len(),
        planner.num_nodes(),
        planner.num_edges(),
        planner.world().len()
    );
    println!(
        "path: {} map nodes → {} waypoints after shortcutting, joint-space length {:.3} rad, duration {:.2} s",
        s.path_nodes,
        plan.trajectory.times.len(),
        s.length,
        plan.trajectory.times.last().copied().unwrap_or(0.0)
    );
    println!(
        "planning: {:.2} ms, {} A* searches, {} edges checked ({} blocked), {} nodes found colliding",
        s.seconds * 1e3,
        s.searches,
        s.edges_checked,
        s.edges_invalid,
        s.nodes_invalid
    );
    if let Some(last) = plan.trajectory.task_path.last() {
        println!("reached task point {last:?}");
    }
    match (&s.exact, s.goal_error) {
        (
            ExactGoal::Reached {
                evaluations,
                detour,
                ..
            },
            Some(e),
        ) => {
            let how = if *detour > 0 {
                format!(
                    "; the straight last segment was blocked: {detour} waypoints through the map instead"
                )
            } else {
                String::new()
            };
            println!(
                "exact goal: reached, task error {e:.2e} ({evaluations} NGIK evaluations){how}"
            )
        }
        (ExactGoal::Fallback { reason }, Some(e)) => println!(
            "exact goal: not used ({reason}); the path ends at the map node, task error {e:.3}"
        ),
        (_, Some(e)) => println!("task error at the end: {e:.3} (exact finish off)"),
        _ => {}
    }
    if let Some(out) = &args.out {
        let group = problem
            .objective
            .active()
            .names()
            .collect::<Vec<_>>()
            .join(",");
        let written = write_trajectory(&plan.trajectory, &problem.robot, (&group, s.seconds), out)?;
        let svg = out.with_extension("svg");
        crate::write_atomic(
            &svg,
            crate::plot::map_scatter(first, Some(&plan.trajectory.task_path))?.as_bytes(),
        )?;
        println!("wrote {written} and {}", svg.display());
    }
    if args.view {
        let mut scene = trm_view::Scene::of_problem(&problem, "planned motion")?;
        scene.frames.clear();
        for (t, q) in plan.trajectory.times.iter().zip(&plan.trajectory.positions) {
            scene.add_frame(*t, q)?;
        }
        scene.set_path(
            plan.trajectory
                .task_path
                .iter()
                .map(|p| trm_view::point3(p))
                .collect(),
        );
        scene.add_roadmap(first, problem.objective.active())?;
        write_view(scene, planner.world(), args.out.as_deref())?;
    }
    Ok(())
}

/// The `--map`s.
fn load_maps(args: &Args) -> Result<Vec<Roadmap>> {
    args.maps
        .iter()
        .map(|p| Roadmap::load(p).with_context(|| format!("loading {}", p.display())))
        .collect()
}

/// Each map repaired for `world` (`--repair`).
fn repair_maps(args: &Args, maps: &mut [Roadmap], world: &trm_collision::World) -> Result<()> {
    for (map, path) in maps.iter_mut().zip(&args.maps) {
        let problem = map
            .problem_with(&trm_taskmap::loaders())
            .with_context(|| format!("the spec stored in {}", path.display()))?;
        let options = RepairOptions {
            refill: false,
            ..Default::default()
        };
        let started = std::time::Instant::now();
        let (repaired, report) = trm_roadmap::repair(map, &problem, world, &options)?;
        print!(
            "{}: repaired in {:.2} s; ",
            path.display(),
            started.elapsed().as_secs_f64()
        );
        println!("{report}");
        *map = repaired;
    }
    Ok(())
}

/// The goal `to` names for a map (`first`, of `problem`): a posture file, else a task point
/// of the map's task space within `--tolerance`.
fn map_goal(args: &Args, to: &str, first: &Roadmap, problem: &Problem) -> Result<Goal> {
    Ok(if Path::new(to).is_file() {
        Goal::Configuration(posture(Path::new(to), problem)?)
    } else {
        let t = crate::numbers("--to", to, "\"x,y,z\" or a posture file")?;
        let dim = first.points.first().map_or(t.len(), |p| p.t.len());
        if t.len() != dim {
            anyhow::bail!(
                "--to `{}`: {} values for the map's {dim}-dimensional task space",
                to,
                t.len()
            );
        }
        Goal::TaskPoint {
            t,
            tolerance: args.tolerance,
        }
    })
}

/// Writes the 3-D view of a plan, `scene` in `world`, beside `out` (or as
/// target/plan.scene.html).
fn write_view(
    mut scene: trm_view::Scene,
    world: &trm_collision::World,
    out: Option<&Path>,
) -> Result<()> {
    scene.set_world(world);
    let out = out.map_or_else(|| PathBuf::from("target/plan.csv"), Path::to_path_buf);
    crate::support::scene::write_scene(&scene, &crate::support::scene::scene_path(&out))
}

/// Writes `trajectory` as [`trm_moveit::trajectory_files`] (with a MoveIt response for the
/// group, planned in the seconds of `response`), each file whole or not at all. Returns the
/// files' names, for the report.
fn write_trajectory(
    trajectory: &Trajectory,
    robot: &trm_kinematics::RobotModel,
    response: (&str, f64),
    out: &Path,
) -> Result<String> {
    let files = trm_moveit::trajectory_files(trajectory, robot, Some(response), out)?;
    for (path, text) in &files {
        crate::write_atomic(path, text.as_bytes())?;
    }
    Ok(trm_moveit::describe_files(&files))
}

/// `plan` without maps: one planner for the robot, the world (and a scene's matrix) set on it,
/// a start and a goal posture (or a MoveIt request's), RRT-Connect.
fn run_without_maps(args: &Args) -> Result<()> {
    let robot = crate::load_model(args.model.as_deref())?;
    let collision = args.meshes.collision_model(&robot)?;
    let request = args
        .request
        .as_ref()
        .map(trm_moveit::MotionPlanRequest::load)
        .transpose()?;
    let home = robot.home_motors();
    let active = active_motors(args, &robot, request.as_ref(), home)?;
    // the motors that do not move, where the planner holds them
    let fixed = active.to_motors(&vec![0.0; active.len()]);
    let names: Vec<String> = active.names().map(str::to_string).collect();
    let mut planner = planner_in_world(args, &collision, &active, request.as_ref())?;
    let configuration = |text: &str, what: &str| -> Result<Vec<f64>> {
        if text == "home" {
            return Ok(active.from_motors(&fixed));
        }
        let motors =
            crate::support::scene::posture_motors(Path::new(text), &robot, Some(&active), &fixed)
                .with_context(|| format!("{what} {text}: give `home` or a posture file"))?;
        Ok(active.from_motors(&motors))
    };
    let (start, goal) = match &request {
        Some(r) => r.query(&active)?,
        None => (
            configuration(&args.from, "--from")?,
            RequestGoal::Joints(configuration(
                args.to.as_deref().unwrap_or_default(),
                "--to",
            )?),
        ),
    };
    let options = planner.rrt_options_within(&Budget {
        seed: args.seed,
        max_seconds: args
            .max_seconds
            .or(request.as_ref().and_then(|r| r.planning_time)),
        max_samples: args.max_samples,
        resolution: args.resolution,
        range: args.range,
        certified: args.certified,
        smoothing: args.smoothing,
    })?;
    let goal_configuration = match &goal {
        RequestGoal::Joints(q) => Some(q),
        RequestGoal::Pose(_) => None,
    };
    check_free(&mut planner, args, &start, goal_configuration)?;
    let found = match goal.connect(&mut planner, &start, &options) {
        Ok(found) => found,
        Err(e @ trm_plan::PlanError::Unreachable { .. }) => anyhow::bail!(
            "{e}\n  fix: a larger budget (--max-samples {}, --max-seconds), or a goal the robot can reach in this world",
            args.max_samples
        ),
        Err(e) => return Err(e.into()),
    };
    let timing = args.timing.settings()?.timing(request.as_ref());
    let trajectory = planner.trajectory(&found.path, &timing)?;
    let timed = describe_motion(&mut planner, &found.path, &timing, &trajectory)?;
    println!(
        "{}: {} of {} motors move; world: {} objects",
        robot.name(),
        active.len(),
        robot.motors().len(),
        planner.world().len()
    );
    println!(
        "path: {} waypoints ({}), joint-space length {:.3} rad; motion: {timed}",
        found.path.len(),
        found.source.name(),
        trm_plan::rrt::path_length(&found.path),
    );
    println!(
        "planning: {:.2} ms, {} samples, {} configurations checked",
        found.seconds * 1e3,
        found.iterations,
        found.checks
    );
    if let Some(out) = &args.out {
        let group = request
            .as_ref()
            .map_or_else(|| names.join(","), |r| r.group.clone());
        println!(
            "wrote {}",
            write_trajectory(&trajectory, &robot, (&group, found.seconds), out)?
        );
    }
    if args.view {
        // the robot with what it holds, as the planner checked it
        let collision = planner.objective().collision();
        let mut scene = trm_view::Scene::new("planned motion", collision);
        for (t, q) in trajectory.times.iter().zip(&trajectory.positions) {
            scene.add_frame(*t, q)?;
        }
        write_view(scene, planner.world(), args.out.as_deref())?;
    }
    // last: the experience file changes only once every output is written
    if let (Some(file), trm_plan::Source::Sampled) = (&args.experience, found.source) {
        planner.add_path(&found.path)?;
        planner.save_experience(file)?;
        println!("kept the path in {}", file.display());
    }
    Ok(())
}

/// The motors that move: `--joints` (names or a group), else the request's goal joints, else
/// every motor; the others stay where the request's start (else `home`) puts them.
fn active_motors(
    args: &Args,
    robot: &trm_kinematics::RobotModel,
    request: Option<&trm_moveit::MotionPlanRequest>,
    home: Vec<f64>,
) -> Result<trm_kinematics::ActiveSet> {
    Ok(match (&args.joints, request) {
        // the request's goal joints move, the other motors stay where its start puts them
        (None, Some(r)) => r.active_set(robot, &home)?,
        (joints, _) => {
            // motor names or groups' names
            let names: Vec<&str> = match joints {
                Some(j) => j.split(',').map(str::trim).collect(),
                None => robot.motors().iter().map(|m| m.name.as_str()).collect(),
            };
            let fixed = match request {
                Some(r) => trm_moveit::motors_from_state(robot, &r.start, &home).0,
                None => home,
            };
            robot
                .active_set(&names, &fixed)
                .context("--joints: give motor names of the model, or a group's name")?
        }
    })
}

/// A planner for `active` in `--world` (with its allowed collisions), holding what the scene
/// and the request's start state hold, with `--experience` and the `--with-map`s loaded.
fn planner_in_world(
    args: &Args,
    collision: &trm_collision::CollisionModel,
    active: &trm_kinematics::ActiveSet,
    request: Option<&trm_moveit::MotionPlanRequest>,
) -> Result<Planner> {
    let mut planner = Planner::new(
        &trm_tasks::Objective::new(active.clone(), collision.clone(), Default::default()),
        &[],
    )?;
    // what the robot holds: the scene's, then the request's start state's (by name, over them)
    if let Some(world) = &args.world {
        let scene = trm_moveit::load_scene(world, collision)?;
        let notes = scene
            .apply_to(&mut planner)
            .context("the objects the robot holds (attached_collision_objects)")?;
        for note in &notes {
            eprintln!("{}: {note}", world.display());
        }
    }
    if let Some(r) = request {
        r.hold_on(&mut planner)
            .context("the objects the robot holds (attached_collision_objects)")?;
    }
    if let Some(file) = args.experience.as_ref().filter(|f| f.exists()) {
        let paths = planner.load_experience(file)?;
        println!("{}: {paths} kept paths", file.display());
    }
    for path in &args.with_maps {
        let map = Roadmap::load(path).with_context(|| format!("--with-map {}", path.display()))?;
        planner
            .add_map(&map)
            .with_context(|| format!("--with-map {}", path.display()))?;
    }
    Ok(planner)
}

/// An error naming the contacts when the start or the goal collides.
fn check_free(
    planner: &mut Planner,
    args: &Args,
    start: &[f64],
    goal: Option<&Vec<f64>>,
) -> Result<()> {
    for (what, q) in std::iter::once(("start", start)).chain(goal.map(|q| ("goal", q.as_slice()))) {
        if !planner.is_free(q) {
            anyhow::bail!(
                "the {what} collides{}: {}\n  fix: give a collision-free {what}",
                args.world
                    .as_ref()
                    .map_or(String::new(), |w| format!(" in {}", w.display())),
                planner
                    .collisions(q)
                    .into_iter()
                    .take(5)
                    .collect::<Vec<_>>()
                    .join("; ")
            );
        }
    }
    Ok(())
}

/// How long the motion takes, for the report (jerk-limited: with the time-optimal duration).
fn describe_motion(
    planner: &mut Planner,
    path: &[Vec<f64>],
    timing: &trm_plan::Timing,
    trajectory: &trm_plan::Trajectory,
) -> Result<String> {
    let duration = |t: &trm_plan::Trajectory| t.times.last().copied().unwrap_or(0.0);
    Ok(if timing.jerk_limited {
        let optimal = trm_plan::Timing {
            jerk_limited: false,
            ..timing.clone()
        };
        format!(
            "{:.2} s jerk-limited, stopping at each waypoint ({:.2} s time-optimal without a jerk limit)",
            duration(trajectory),
            duration(&planner.trajectory(path, &optimal)?)
        )
    } else {
        format!(
            "{:.2} s time-optimal within velocity and acceleration limits",
            duration(trajectory)
        )
    })
}
