//! `cargo xtask task-map-studies`: the two studies of Gienger et al. on the iCub — (a) reaching
//! a stick with an exact target at its centre versus with its task map (joint-limit cost over the
//! optimisation, where along the stick the grasp ends; the paper's Fig. 7) and (b) a basket
//! handle at three placements (where along the handle the grasp ends; the paper's Fig. 9).

use std::fmt::Write as _;
use std::path::PathBuf;

use anyhow::Result;
use trm_collision::World;
use trm_kinematics::nalgebra::{Isometry3, Vector3};
use trm_taskmap::{MotionGoal, MotionOptions, ReachProblem};

use crate::explore_task_map::{Explored, explore_spec};

/// Arguments of `task-map-studies`.
#[derive(clap::Args)]
pub struct Args {
    /// RPROP iterations per optimisation.
    #[arg(long, default_value_t = 30, value_parser = crate::parse::count(1, 100_000))]
    iterations: usize,
    /// Output directory (table.md, joint_limits.svg).
    #[arg(long, default_value = "target/taskmap-studies")]
    pub out_dir: PathBuf,
}

fn reach<'a>(
    e: &'a Explored,
    active: &'a trm_kinematics::ActiveSet,
    world: &'a World,
    object: Isometry3<f64>,
    goal: MotionGoal<'a>,
) -> ReachProblem<'a> {
    let home = e
        .model
        .posture("home")
        .expect("the iCub has a home posture");
    ReachProblem {
        active,
        collision: &e.collision,
        world,
        hand: e.model.frame_id("r_hand").expect("iCub right hand"),
        object,
        start: active.from_motors(home),
        goal,
        settings: MotionOptions::default(),
    }
}

/// Runs both studies and writes the table and the plot.
pub fn run(args: &Args) -> Result<()> {
    let specs = crate::models_dir().join("../specs/taskmaps");
    let started = std::time::Instant::now();
    let stick = explore_spec(&specs.join("stick.ron"))?;
    let active = stick
        .model
        .active_set(&["torso", "right_arm"], stick.model.posture("home")?)?;
    let world = World::new();
    let place = Isometry3::new(Vector3::new(-0.3, 0.2, 0.05), Vector3::zeros());
    // the exact target: the map's grasp nearest the stick's centre
    let centre = stick.map.center_grasp().expect("a non-empty map");
    let (exact, exact_trace) = reach(&stick, &active, &world, place, MotionGoal::Target(centre))
        .optimize(args.iterations, 1e-3);
    let (mapped, map_trace) = reach(&stick, &active, &world, place, MotionGoal::Map(&stick.map))
        .optimize(args.iterations, 1e-3);
    let mut md = format!(
        "## (a) Stick ({} feasible grasps), {} RPROP iterations\n\n| goal | total cost | joint-limit proximity | end cost | path length (rad) | grasp position along the stick (m) |\n|---|---|---|---|---|---|\n",
        stick.map.points.len(),
        args.iterations
    );
    for (name, m) in [
        ("exact target at the centre", &exact),
        ("task map", &mapped),
    ] {
        let _ = writeln!(
            md,
            "| {name} | {:.4} | {:.4} | {:.5} | {:.3} | {:+.3} |",
            m.cost, m.limits, m.end, m.length, m.final_pose[2]
        );
    }
    let handle = explore_spec(&specs.join("handle.ron"))?;
    let _ = write!(
        md,
        "\n## (b) Basket handle ({} feasible grasps in {} clusters) at (−0.30, 0.20, −0.05) m, turned about the vertical\n\n| basket yaw (°) | total cost | end cost | grasp angle on the arc (°) |\n|---|---|---|---|\n",
        handle.map.points.len(),
        handle.map.clusters()
    );
    for yaw in [-0.6f64, 0.0, 0.6] {
        let at = Isometry3::new(Vector3::new(-0.3, 0.2, -0.05), Vector3::z() * yaw);
        let (m, _) = reach(&handle, &active, &world, at, MotionGoal::Map(&handle.map))
            .optimize(args.iterations, 1e-3);
        let angle = m.final_pose[2].atan2(m.final_pose[0]).to_degrees();
        let _ = writeln!(
            md,
            "| {:.0} | {:.4} | {:.5} | {angle:.0} |",
            yaw.to_degrees(),
            m.cost,
            m.end
        );
    }
    let _ = writeln!(md, "\nWall time {:.1} s.", started.elapsed().as_secs_f64());
    std::fs::create_dir_all(&args.out_dir)?;
    crate::write_atomic(&args.out_dir.join("table.md"), md.as_bytes())?;
    let hi = exact_trace
        .iter()
        .chain(&map_trace)
        .map(|t| t.1)
        .fold(0.0f64, f64::max)
        * 1.1;
    let series: Vec<crate::plot::Series> =
        [("exact target", &exact_trace), ("task map", &map_trace)]
            .into_iter()
            .map(|(name, trace)| crate::plot::Series {
                label: name.into(),
                points: trace
                    .iter()
                    .enumerate()
                    .map(|(k, t)| (k as f64, t.1))
                    .collect(),
                color: None,
            })
            .collect();
    let svg = crate::plot::lines(
        "Stick: joint-limit proximity of the best motion",
        ("RPROP iteration", "joint-limit cost"),
        0.0..args.iterations as f64,
        0.0..hi.max(1e-3),
        series,
    )?;
    crate::write_atomic(&args.out_dir.join("joint_limits.svg"), svg.as_bytes())?;
    println!("{md}");
    println!(
        "wrote {}/{{table.md, joint_limits.svg}}",
        args.out_dir.display()
    );
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_studies_write_their_table_and_plot() {
        let dir = std::env::temp_dir().join(format!("trm-tms-{}", std::process::id()));
        run(&Args {
            iterations: 3,
            out_dir: dir.clone(),
        })
        .unwrap();
        let table = std::fs::read_to_string(dir.join("table.md")).unwrap();
        assert!(table.contains("| task map |") && table.contains("| exact target at the centre |"));
        assert_eq!(
            table.matches("\n| -34 |").count()
                + table.matches("\n| 0 |").count()
                + table.matches("\n| 34 |").count(),
            3
        );
        assert!(
            std::fs::read_to_string(dir.join("joint_limits.svg"))
                .unwrap()
                .starts_with("<svg")
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
