//! `trm solve SPEC [--algo A] [--seed S] [--out posture.json]`: NGIK on a task spec.

use std::path::PathBuf;

use anyhow::{Context, Result};
use serde_json::json;
use trm_tasks::{Problem, solve};

/// Arguments of `solve`.
#[derive(clap::Args)]
pub struct Args {
    /// The task spec (RON; format: crates/trm-tasks/docs/task-spec.md).
    spec: PathBuf,
    /// Optimiser, overriding the spec's solver.algo.
    #[arg(long)]
    algo: Option<String>,
    /// Seed, overriding the spec's solver.seed.
    #[arg(long)]
    seed: Option<u64>,
    /// Evaluation budget, overriding the spec's solver.max_evaluations.
    #[arg(long, value_parser = clap::value_parser!(u64).range(1..=1_000_000_000))]
    max_evals: Option<u64>,
    /// Write the posture (motor values by name, active values, cost breakdown, frame poses).
    #[arg(long)]
    pub out: Option<PathBuf>,
}

/// Solves and reports.
pub fn run(args: &Args) -> Result<()> {
    let problem = Problem::load_with(&args.spec, &trm_taskmap::loaders())?;
    let solver = (problem.spec.solver)
        .overridden(args.algo.as_deref(), args.seed, args.max_evals)
        .context("--algo")?;
    let objective = &problem.objective;
    let mut scratch = objective.scratch();
    let start_cost = objective.eval(&problem.start, &mut scratch);
    let s = solve(objective, &problem.start, &solver)?;
    println!(
        "{}: {} active motors, {} cost terms, algo {} seed {}",
        problem.origin,
        objective.dim(),
        objective.num_terms(),
        solver.algo,
        solver.seed
    );
    println!(
        "cost {:.6} (start {:.6}); best found at evaluation {} of {}; {:.2} s; stop {:?}",
        s.cost,
        start_cost,
        s.best_at,
        s.evaluations,
        s.wall_time.as_secs_f64(),
        s.reasons
    );
    for t in &s.breakdown {
        println!(
            "  {:<32} weight {:>8.3} × {:>10.6} = {:>10.6}",
            t.label,
            t.weight,
            t.value,
            t.weight * t.value
        );
    }
    if !s.task.is_empty() {
        println!("task vector: {:?}", s.task);
    }
    if problem.spec.noise.is_some() {
        let plain: f64 = s.breakdown.iter().map(|t| t.weight * t.value).sum();
        println!(
            "cost without the noise: {plain:.6} (the search minimised its mean over the noise samples)"
        );
    }
    println!("{}", clearance(objective, &s.q));
    if s.collision_free {
        println!("collision-free: yes");
    } else {
        println!("collision-free: NO — the posture does not meet the hard constraint");
    }
    if let Some(out) = &args.out {
        let robot = &problem.robot;
        let poses = objective.poses(&s.q, &mut scratch);
        let frames: serde_json::Map<String, serde_json::Value> = robot
            .frame_names()
            .enumerate()
            .map(|(i, n)| {
                let p = &poses.poses()[i];
                let (r, pi, y) = p.rotation.euler_angles();
                (
                    n.to_string(),
                    json!({"xyz": [p.translation.x, p.translation.y, p.translation.z], "rpy": [r, pi, y]}),
                )
            })
            .collect();
        let file = trm_kinematics::PostureFile::from_motors(robot, &s.motors)?
            .with("spec", problem.origin.as_str())
            .with("algo", solver.algo.as_str())
            .with("seed", solver.seed)
            .with("cost", s.cost)
            .with("collision_free", s.collision_free)
            .with("evaluations", s.evaluations)
            .with("best_at_evaluation", s.best_at)
            .with("wall_time_s", s.wall_time.as_secs_f64())
            .with(
                "active",
                objective
                    .active()
                    .names()
                    .zip(&s.q)
                    .map(|(n, v)| (n.to_string(), json!(v)))
                    .collect::<serde_json::Map<_, _>>(),
            )
            .with(
                "breakdown",
                s.breakdown
                    .iter()
                    .map(|t| json!({"term": t.label, "weight": t.weight, "value": t.value}))
                    .collect::<Vec<_>>(),
            )
            .with("task", s.task.clone())
            .with("frames", frames);
        crate::write_atomic(out, file.to_json(out)?.as_bytes())?;
        eprintln!("wrote {}", out.display());
    }
    Ok(())
}

/// The posture's clearance: the closest checked body pair and the closest body to a world
/// object (signed distances; negative = penetration).
fn clearance(objective: &trm_tasks::Objective, q: &[f64]) -> String {
    let bodies = objective.collision().bodies();
    let world = objective.world();
    let c = objective.clearance_in(q, world, &mut objective.scratch());
    let mut line = String::from("clearance:");
    if let Some((d, a, b)) = c.own {
        line += &format!(
            " {:.1} mm between checked bodies ({} – {})",
            d * 1e3,
            bodies[a].name,
            bodies[b].name
        );
    }
    if let Some((d, b, o)) = c.world {
        line += &format!(
            ", {:.1} mm to the world ({} – {})",
            d * 1e3,
            bodies[b].name,
            world.objects()[o].name()
        );
    }
    line
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn solve_writes_the_posture_with_its_breakdown() {
        let dir = std::env::temp_dir().join(format!("trm-solve-{}", std::process::id()));
        let out = dir.join("posture.json");
        run(&Args {
            spec: crate::models_dir().join("../specs/reach_point.ron"),
            algo: None,
            seed: Some(2),
            max_evals: Some(2_000),
            out: Some(out.clone()),
        })
        .unwrap();
        let v: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(&out).unwrap()).unwrap();
        assert_eq!(v["motors"].as_object().unwrap().len(), 41);
        assert_eq!(v["active"].as_object().unwrap().len(), 10);
        assert_eq!(v["breakdown"].as_array().unwrap().len(), 6);
        assert!(v["frames"]["r_palm_center"]["xyz"].is_array());
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
