//! Plans through a map file (`cargo xtask build-map specs/reach.ron` writes one) to a task-space
//! point, then again after a box appears in the way; writes the trajectory as CSV.
//!
//! `cargo run -p trm-plan --example plan_in_a_map -- MAP.json [x,y,z]`

use trm_collision::{Shape, World};
use trm_kinematics::nalgebra::Isometry3;
use trm_plan::{Goal, PlanOptions, Planner};
use trm_roadmap::Roadmap;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let path = args
        .next()
        .ok_or("give a map file (cargo xtask build-map specs/reach.ron)")?;
    let map = Roadmap::load(&path)?;
    let problem = map.problem()?;
    let t: Vec<f64> = match args.next() {
        Some(text) => text.split(',').map(str::parse).collect::<Result<_, _>>()?,
        None => map.points[map.points.len() / 2].t.clone(),
    };
    let goal = Goal::TaskPoint { t, tolerance: 0.03 };
    let mut planner = Planner::new(&problem.objective, &[&map])?;
    let plan = planner.plan(&problem.start, &goal, &PlanOptions::default())?;
    println!(
        "{} waypoints, {:.2} s",
        plan.trajectory.positions.len(),
        plan.trajectory.times.last().unwrap_or(&0.0)
    );
    let mut world: World = problem.objective.world().clone();
    let middle = &plan.trajectory.task_path[plan.trajectory.task_path.len() / 2];
    world.add(
        "box",
        Shape::Box {
            size: [0.05, 0.05, 0.05],
        },
        Isometry3::translation(middle[0], middle[1], middle[2]),
    )?;
    planner.set_world(world);
    match planner.plan(&problem.start, &goal, &PlanOptions::default()) {
        Ok(p) => println!(
            "with a box on the old path: {} waypoints, {} edges found blocked",
            p.trajectory.positions.len(),
            p.stats.edges_invalid
        ),
        Err(e) => println!("with a box on the old path: {e}"),
    }
    let out = std::path::Path::new("target/plan_in_a_map.csv");
    trm_io::write_atomic(out, plan.trajectory.to_csv(out)?.as_bytes())?;
    Ok(())
}
