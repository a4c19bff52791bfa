//! `cargo xtask plan --map FILE [--map FILE2 …] [--world WORLD.ron] --from home|q.json
//! [--repair] --to "x,y,z"|q.json [--out traj.csv]`.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use trm_plan::{ExactGoal, Goal, PlanOptions, Planner};
use trm_roadmap::{RepairOptions, Roadmap};
use trm_tasks::Problem;

/// Arguments of `plan`.
#[derive(clap::Args)]
pub struct Args {
    /// Map files (repeatable); they must share the first map's active motors.
    #[arg(long = "map", required = true)]
    maps: Vec<PathBuf>,
    /// The current world (RON, or a MoveIt planning scene .yaml), replacing the one the maps were built in.
    #[arg(long)]
    world: Option<PathBuf>,
    /// Repair the maps for --world before planning: park what it blocks, bring back parked
    /// nodes it frees, grow points where coverage was lost (`repair-map` without its refill).
    #[arg(long, requires = "world")]
    repair: bool,
    /// Start: `home` (the spec's start posture) or a JSON file with "motors": {name: value}
    /// (as `solve --out` writes) or "q": [active values].
    #[arg(long, default_value = "home")]
    from: String,
    /// Goal: a task-space point "x,y,z" (through a map node within --tolerance, then to the
    /// point itself) or a JSON posture file.
    #[arg(long, allow_hyphen_values = true)]
    to: String,
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
    /// Trajectory output (CSV; beside it a .json with the task-space path, a .ros.yaml ROS 2
    /// JointTrajectory and an .svg of the path over the map).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Seed of the shortcutting.
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Also write a 3-D view (maps, world, the motion and its task-space path) beside --out
    /// (`<stem>.scene.html`), or as target/plan.scene.html.
    #[arg(long)]
    view: bool,
    /// Joint speed where the model has no limit, rad/s.
    #[arg(long, default_value_t = 1.0)]
    velocity: f64,
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
        args.velocity.is_finite() && args.velocity > 0.0,
        "--velocity {}: give a finite positive joint speed (rad/s)",
        args.velocity
    );
    anyhow::ensure!(
        args.tolerance.is_finite() && args.tolerance > 0.0,
        "--tolerance {}: give a finite positive task-space distance",
        args.tolerance
    );
    let mut maps: Vec<Roadmap> = args
        .maps
        .iter()
        .map(|p| Roadmap::load(p).with_context(|| format!("loading {}", p.display())))
        .collect::<Result<_>>()?;
    let world = args
        .world
        .as_ref()
        .map(trm_moveit::load_world)
        .transpose()?;
    if let (true, Some(world)) = (args.repair, &world) {
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
    }
    let first = &maps[0];
    let problem = first
        .problem_with(&trm_taskmap::loaders())
        .with_context(|| format!("the spec stored in {}", args.maps[0].display()))?;
    let refs: Vec<&Roadmap> = maps.iter().collect();
    let mut planner = Planner::new(&problem.objective, &refs)?;
    if let Some(world) = world {
        planner.set_world(world);
    }
    let start = if args.from == "home" {
        problem.start.clone()
    } else {
        posture(Path::new(&args.from), &problem)?
    };
    let goal = if Path::new(&args.to).is_file() {
        Goal::Configuration(posture(Path::new(&args.to), &problem)?)
    } else {
        let t = crate::numbers("--to", &args.to, "\"x,y,z\" or a posture file")?;
        let dim = first.points.first().map_or(t.len(), |p| p.t.len());
        if t.len() != dim {
            anyhow::bail!(
                "--to `{}`: {} values for the map's {dim}-dimensional task space",
                args.to,
                t.len()
            );
        }
        Goal::TaskPoint {
            t,
            tolerance: args.tolerance,
        }
    };
    let options = PlanOptions {
        seed: args.seed,
        default_velocity: args.velocity,
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
        crate::write_atomic(out, plan.trajectory.to_csv(out)?.as_bytes())?;
        let json = out.with_extension("json");
        crate::write_atomic(&json, plan.trajectory.to_json(&json)?.as_bytes())?;
        let ros = out.with_extension("ros.yaml");
        let yaml = plan.trajectory.to_ros_yaml(&problem.robot, &ros)?;
        crate::write_atomic(&ros, yaml.as_bytes())?;
        let svg = out.with_extension("svg");
        crate::write_atomic(
            &svg,
            crate::plot::map_scatter(first, Some(&plan.trajectory.task_path))?.as_bytes(),
        )?;
        println!(
            "wrote {}, {}, {} (ROS 2 JointTrajectory) and {}",
            out.display(),
            json.display(),
            ros.display(),
            svg.display()
        );
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
        scene.set_world(planner.world());
        scene.add_roadmap(first, problem.objective.active())?;
        let out = args
            .out
            .clone()
            .unwrap_or_else(|| PathBuf::from("target/plan.csv"));
        crate::support::scene::write_scene(&scene, &crate::support::scene::scene_path(&out))?;
    }
    Ok(())
}
