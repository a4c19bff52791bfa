//! `trm reach-grasp SPEC [--at "x,y,z[,yaw]"] [--world W.ron] [--exact] [--iterations N]
//! [--out traj.csv]`: a reaching motion of the right hand to the object of a task-map spec
//! (Gienger et al.: 12 attractors in the hand's position and grasp-axis task, iRprop− on the
//! analytic gradient), optimised with its task map (or, with `--exact`, to the map's grasp
//! nearest the object's centre), around the world's obstacles; the trajectory is written like
//! `plan` writes it.

use std::path::PathBuf;

use anyhow::{Context, Result};
use trm_collision::World;
use trm_plan::Trajectory;

use crate::support::taskmap::explore_spec;

/// Arguments of `reach-grasp`.
#[derive(clap::Args)]
pub struct Args {
    /// The task-map spec (the object and the hand).
    spec: PathBuf,
    /// Where the object stands in the robot's root frame: "x,y,z" or "x,y,z,yaw".
    #[arg(long, default_value = "-0.3,0.2,0.05", allow_hyphen_values = true)]
    at: String,
    /// Obstacles (RON world or MoveIt planning scene .yaml, root frame), e.g. specs/worlds/table.ron; none by default.
    #[arg(long)]
    world: Option<PathBuf>,
    /// Reach the single grasp nearest the object's centre instead of anywhere on the map.
    #[arg(long)]
    exact: bool,
    /// iRprop− iterations.
    #[arg(long, default_value_t = 30, value_parser = crate::parse::count(1, 100_000))]
    iterations: usize,
    /// Trajectory output (CSV; a .json and a .ros.yaml ROS 2 JointTrajectory beside it).
    #[arg(long)]
    pub out: Option<PathBuf>,
}

/// Optimises the reach and reports it.
pub fn run(args: &Args) -> Result<()> {
    crate::check_csv_out(args.out.as_deref())?;
    let e = explore_spec(&args.spec)?;
    let v = crate::numbers("--at", &args.at, "\"x,y,z\" or \"x,y,z,yaw\"")?;
    let at = trm_taskmap::placement(&v).with_context(|| format!("--at `{}`", args.at))?;
    let world = match &args.world {
        Some(w) => trm_moveit::load_world(w)?,
        None => World::new(),
    };
    let started = std::time::Instant::now();
    let reach = e.reach(&world, at, args.exact, args.iterations)?;
    let m = &reach.motion;
    println!(
        "{} goal, {} map grasps: cost {:.4} (from {:.4}), joint-limit cost {:.4}, closest approach {:.3} m ({} steps in contact), path {:.3} rad, end speed {:.3} m/s, end cost {:.5}; {:.2} s",
        if args.exact { "exact" } else { "task-map" },
        e.map.points.len(),
        m.cost,
        reach.trace[0].0,
        m.limits,
        m.min_distance,
        m.collisions,
        m.length,
        m.end_speed,
        m.end,
        started.elapsed().as_secs_f64()
    );
    println!("final hand pose in the object frame: {:.4?}", m.final_pose);
    if let Some(out) = &args.out {
        let trajectory = Trajectory::at_joint_speed(&reach.active, &m.trajectory, 1.0);
        let files = trm_moveit::trajectory_files(&trajectory, &e.model, None, out)?;
        for (path, text) in &files {
            crate::write_atomic(path, text.as_bytes())?;
        }
        println!("wrote {}", trm_moveit::describe_files(&files));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reach_grasp_writes_a_trajectory() {
        let dir = std::env::temp_dir().join(format!("trm-rg-{}", std::process::id()));
        let out = dir.join("traj.csv");
        run(&Args {
            spec: crate::models_dir().join("../specs/taskmaps/stick.ron"),
            at: "-0.3,0.2,0.05".into(),
            world: Some(crate::models_dir().join("../specs/worlds/table.ron")),
            exact: false,
            iterations: 2,
            out: Some(out.clone()),
        })
        .unwrap();
        let csv = std::fs::read_to_string(&out).unwrap();
        assert_eq!(csv.lines().count(), 1 + 61);
        assert!(csv.starts_with("time,"));
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
