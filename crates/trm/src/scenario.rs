//! `trm scenario SPEC --map MAP [--out-dir DIR] [--repair-ms MS | --repair-evaluations N]`:
//! a map in a moving world (`trm_plan::run_scenario`), step by step.

use std::fmt::Write as _;
use std::path::PathBuf;

use anyhow::{Context, Result};
use trm_plan::{Action, Scenario, ScenarioOptions, ScenarioRun, run_scenario};
use trm_roadmap::Roadmap;

/// Arguments of `scenario`.
#[derive(clap::Args)]
pub struct Args {
    /// The scenario (RON: moving objects and task goals; see specs/scenarios/).
    spec: PathBuf,
    /// The map (build-map's output for the scenario's task).
    #[arg(long)]
    map: PathBuf,
    /// Where the step table (steps.csv, steps.md), the robot's motion (motion.csv, its .json
    /// and .ros.yaml) and the viewer page (scenario.scene.html) go.
    #[arg(long, default_value = "target/scenario")]
    pub out_dir: PathBuf,
    /// Repair budget per step, milliseconds (repairs then depend on the machine's speed).
    #[arg(long, default_value_t = 40.0, value_parser = crate::parse::positive, conflicts_with = "repair_evaluations")]
    repair_ms: f64,
    /// Repair budget per step in cost evaluations instead of time: a reproducible run.
    #[arg(long, value_parser = crate::parse::count(1, usize::MAX))]
    repair_evaluations: Option<usize>,
    /// At every step without a path, build the map anew in that step's world (same size,
    /// seed and settings; seconds each) and plan there: whether a full rebuild could have
    /// reached the goal.
    #[arg(long)]
    check_rebuild: bool,
    /// Worker threads.
    #[arg(long, value_parser = crate::parse::count(1, 4096))]
    threads: Option<usize>,
}

/// Runs the scenario, prints and writes its steps, motion and view.
pub fn run(args: &Args) -> Result<()> {
    let scenario = Scenario::load(&args.spec)?;
    let map = Roadmap::load(&args.map)?;
    let problem = map
        .problem_with(&trm_taskmap::loaders())
        .with_context(|| format!("{}: the spec stored in the map", args.map.display()))?;
    let options = match args.repair_evaluations {
        Some(n) => ScenarioOptions {
            repair_seconds: None,
            repair_evaluations: Some(n as u64),
            ..Default::default()
        },
        None => ScenarioOptions {
            repair_seconds: Some(args.repair_ms / 1e3),
            ..Default::default()
        },
    };
    let pool = crate::thread_pool(args.threads)?;
    let run = pool.install(|| run_scenario(&map, &problem, &scenario, &options))?;
    if !scenario.description.is_empty() {
        println!("{}", scenario.description);
    }
    let table = step_table(&run);
    print!("{table}");
    println!("{}", summary(&run, options.reached));
    if args.check_rebuild {
        pool.install(|| check_rebuilds(&map, &run, &options))?;
    }
    std::fs::create_dir_all(&args.out_dir)
        .with_context(|| format!("creating {}", args.out_dir.display()))?;
    let dir = &args.out_dir;
    crate::write_atomic(&dir.join("steps.md"), table.as_bytes())?;
    crate::write_atomic(&dir.join("steps.csv"), steps_csv(&run).as_bytes())?;
    let csv = dir.join("motion.csv");
    crate::write_atomic(&csv, run.motion.to_csv(&csv)?.as_bytes())?;
    let json = dir.join("motion.json");
    crate::write_atomic(&json, run.motion.to_json(&json)?.as_bytes())?;
    let ros = dir.join("motion.ros.yaml");
    crate::write_atomic(
        &ros,
        run.motion.to_ros_yaml(&problem.robot, &ros)?.as_bytes(),
    )?;
    let scene = crate::support::scene::scenario_scene(&problem, &run)?;
    crate::support::scene::write_scene(&scene, &dir.join("scenario.scene.html"))?;
    println!(
        "wrote steps.md, steps.csv, motion.csv (+ .json, .ros.yaml) in {}",
        dir.display()
    );
    Ok(())
}

/// For every step without a path: a map built from scratch in that step's world, and a plan
/// from the robot's posture then; prints whether it reaches the goal.
fn check_rebuilds(map: &Roadmap, run: &ScenarioRun, options: &ScenarioOptions) -> Result<()> {
    let failed: Vec<usize> = (0..run.steps.len())
        .filter(|&k| matches!(run.steps[k].action, Action::Failed(_)))
        .collect();
    let (mut could, mut total) = (0, 0);
    for k in failed {
        let mut problem = map.problem_with(&trm_taskmap::loaders())?;
        problem.objective.set_world(run.worlds[k].clone());
        let like = trm_roadmap::BuildOptions::like(map);
        let rebuilt = trm_roadmap::Builder::new(&problem, &like)
            .connected()
            .run(|_| {})?;
        let active = problem.objective.active();
        let q = active.from_motors(&run.motion.positions[k]);
        let Some(goal) = run.steps[k].goal.clone() else {
            continue;
        };
        let mut planner = trm_plan::Planner::new(&problem.objective, &[&rebuilt])?;
        let outcome = planner.plan(
            &q,
            &trm_plan::Goal::TaskPoint {
                t: goal,
                tolerance: options.tolerance,
            },
            &options.plan,
        );
        total += 1;
        let verdict = match outcome {
            Ok(p) => {
                could += 1;
                format!(
                    "the rebuilt map reaches it (task error {:.1} mm)",
                    p.stats.goal_error.unwrap_or(f64::NAN) * 1e3
                )
            }
            Err(e) => format!("the rebuilt map has no path either ({e})"),
        };
        println!("t = {:.1} s, no path: {verdict}", run.steps[k].t);
    }
    println!(
        "steps without a path: {total}; a full rebuild in that world reaches the goal in {could}"
    );
    Ok(())
}

/// A step's action in one word (the CSV's column).
fn action_name(action: &Action) -> &'static str {
    match action {
        Action::Kept => "kept",
        Action::Replanned(_) => "replanned",
        Action::Failed(_) => "failed",
    }
}

/// The per-step table (Markdown).
fn step_table(run: &ScenarioRun) -> String {
    let mut s = String::from(
        "| t (s) | blocked | restored | parked | grown | invalidate (ms) | repair (ms) | plan (ms) | total (ms) | action | goal error (mm) |\n|---|---|---|---|---|---|---|---|---|---|---|\n",
    );
    for step in &run.steps {
        let [inv, rep, plan] = step.seconds.map(|s| s * 1e3);
        let action = match &step.action {
            Action::Kept => action_name(&step.action).to_string(),
            Action::Replanned(why) => format!("replanned ({why})"),
            Action::Failed(why) => format!("no path ({})", why.split(';').next().unwrap_or(why)),
        };
        let hit = if step.hit {
            " — hit by an object"
        } else {
            ""
        };
        let error = step
            .goal_error
            .map_or("–".into(), |e| format!("{:.1}", e * 1e3));
        let _ = writeln!(
            s,
            "| {:.1} | {} | {} | {} | {} | {inv:.2} | {rep:.1} | {plan:.1} | {:.1} | {action}{hit} | {error} |",
            step.t,
            step.blocked,
            step.restored,
            step.parked_nodes.len(),
            step.added,
            inv + rep + plan
        );
    }
    s
}

/// The steps as CSV.
fn steps_csv(run: &ScenarioRun) -> String {
    let mut s = String::from(
        "t,blocked,restored,parked,grown,invalidate_ms,repair_ms,plan_ms,action,goal_error_m,hit\n",
    );
    for step in &run.steps {
        let [inv, rep, plan] = step.seconds.map(|s| s * 1e3);
        let action = action_name(&step.action);
        let _ = writeln!(
            s,
            "{},{},{},{},{},{inv},{rep},{plan},{action},{},{}",
            step.t,
            step.blocked,
            step.restored,
            step.parked_nodes.len(),
            step.added,
            step.goal_error.map_or(String::new(), |e| e.to_string()),
            step.hit
        );
    }
    s
}

/// Medians and worst step times, and how the goals went.
fn summary(run: &ScenarioRun, reached: f64) -> String {
    let totals: Vec<f64> = run
        .steps
        .iter()
        .map(|s| s.seconds.iter().sum::<f64>() * 1e3)
        .collect();
    let mut sorted = totals.clone();
    sorted.sort_by(f64::total_cmp);
    let median = sorted.get(sorted.len() / 2).copied().unwrap_or(0.0);
    let worst = sorted.last().copied().unwrap_or(0.0);
    let over = totals.iter().filter(|&&t| t > 100.0).count();
    let replans = run
        .steps
        .iter()
        .filter(|s| matches!(s.action, Action::Replanned(_)))
        .count();
    let failed = run
        .steps
        .iter()
        .filter(|s| matches!(s.action, Action::Failed(_)))
        .count();
    let at_goal = run
        .steps
        .iter()
        .filter(|s| s.goal_error.is_some_and(|e| e <= reached))
        .count();
    let hits = run.steps.iter().filter(|s| s.hit).count();
    format!(
        "{} steps: median {median:.1} ms, worst {worst:.1} ms per step ({over} over 100 ms); {replans} replans, {failed} steps without a path, {hits} with the robot hit; at the goal (≤ {:.0} mm) in {at_goal} steps",
        run.steps.len(),
        reached * 1e3
    )
}
