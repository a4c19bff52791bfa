//! NGIK on a task spec: the 41-DOF iCub reaches a point with its right palm over a table,
//! collision-free, close to home; prints the cost breakdown.
//!
//! `cargo run -p trm-tasks --example solve_posture [-- SPEC.ron]`

use trm_tasks::{Problem, solve};

const SPEC: &str = r#"(
    model: "icub_upper_body",
    active: ["torso", "right_arm"],
    world: (objects: [(name: "table", shape: Box(size: (0.5, 0.8, 0.04)), xyz: (-0.4, 0.0, -0.14))]),
    costs: [
        (weight: 0.1, cost: HomePosture()),
        (weight: 10.0, cost: Collision()),
        (weight: 20.0, cost: Position(part: "r_palm_center", target: Point((-0.3, 0.15, 0.0)))),
    ],
    solver: (max_evaluations: 6000, seed: 1),
)"#;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let problem = match std::env::args().nth(1) {
        Some(path) => Problem::load(path)?,
        None => Problem::from_ron(SPEC, "<example>", std::path::Path::new("."))?,
    };
    let s = solve(&problem.objective, &problem.start, &problem.spec.solver)?;
    println!(
        "cost {:.5} after {} evaluations (best at {}), collision-free: {}",
        s.cost, s.evaluations, s.best_at, s.collision_free
    );
    for t in &s.breakdown {
        println!("  {:<36} {:>7.3} × {:.6}", t.label, t.weight, t.value);
    }
    Ok(())
}
