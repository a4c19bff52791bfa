//! `cargo xtask task-map-studies`: the two studies of Gienger et al. (IROS 2008) on the iCub,
//! set as the paper set them — (a) Fig. 7: a cylinder standing on a table, reached once with
//! the cylinder's centre as the exact target and once with its task map (the joint-limit cost
//! over the iterations, where along the cylinder the grasp ends); (b) Fig. 9: a basket on the
//! table at three locations, reached with the handle's task map (where on the handle the grasp
//! ends). Each run writes its trajectory and a world file for `cargo xtask view`.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use trm_collision::{Shape, World};
use trm_kinematics::nalgebra::Isometry3;
use trm_plan::Trajectory;
use trm_taskmap::{Motion, MotionGoal};

use trm_taskmap::{Explored, TaskMapSpec};

/// Arguments of `task-map-studies`.
#[derive(clap::Args)]
pub struct Args {
    /// iRprop− iterations per optimisation.
    #[arg(long, default_value_t = 30, value_parser = trm::parse::count(1, 100_000))]
    iterations: usize,
    /// Output directory (table.md, joint_limits.svg, paths.svg, one CSV and world per run).
    #[arg(long, default_value = "target/taskmap-studies")]
    pub out_dir: PathBuf,
}

/// The table of both studies: 50 × 80 cm, its top 20 cm below the iCub's root (8 cm lower than
/// specs/worlds/table.ron's, so that the idle left hand clears it when the torso bends).
const TABLE_TOP: f64 = -0.2;

/// Where the cylinder stands (its centre; 30 cm tall, on the table, near the far end of the
/// right hand's reach).
const CYLINDER: [f64; 3] = [-0.45, 0.2, TABLE_TOP + 0.17];

/// The basket's three locations on the table (handle origin x, y), from the robot's right to
/// its left.
const BASKET: [(&str, [f64; 2]); 3] = [
    ("right", [-0.3, 0.2]),
    ("centre", [-0.3, 0.05]),
    ("left", [-0.3, -0.1]),
];

/// The basket's body under its handle: 22 × 14 × 10 cm, its top at the handle's origin, which
/// stands 10 cm above the table.
const BASKET_HEIGHT: f64 = 0.10;

fn table() -> Result<World> {
    let mut w = World::new();
    w.add(
        "table",
        Shape::Box {
            size: [0.5, 0.8, 0.04],
        },
        Isometry3::translation(-0.4, 0.0, TABLE_TOP - 0.02),
    )?;
    Ok(w)
}

/// The world `cargo xtask view` shows: the obstacles and the object's parts at `at`.
fn scene(obstacles: &World, e: &Explored, at: &Isometry3<f64>) -> Result<World> {
    let mut w = obstacles.clone();
    for o in e.object.objects() {
        w.add(o.name(), o.shape().clone(), at * o.pose())?;
    }
    Ok(w)
}

/// One optimised reach.
struct Run {
    name: String,
    motion: Motion,
    trace: Vec<(f64, f64)>,
    seconds: f64,
}

impl Run {
    /// The first iteration whose best cost is within 1 % of the final one.
    fn converged(&self) -> usize {
        let last = self.trace.last().map_or(0.0, |t| t.0);
        self.trace
            .iter()
            .position(|t| t.0 <= last + 0.01 * last.abs())
            .unwrap_or(0)
    }
}

#[allow(clippy::too_many_arguments)]
fn reach(
    name: &str,
    e: &Explored,
    obstacles: &World,
    at: Isometry3<f64>,
    goal: MotionGoal<'_>,
    iterations: usize,
    out_dir: &Path,
) -> Result<Run> {
    let active = e.reaching_set()?;
    let problem = e.reach_problem(&active, obstacles, at, goal)?;
    let started = std::time::Instant::now();
    let (motion, trace) = problem.optimize(iterations);
    let seconds = started.elapsed().as_secs_f64();
    let csv = out_dir.join(format!("{name}.csv"));
    let trajectory = Trajectory::at_joint_speed(&active, &motion.trajectory, 1.0);
    trm::write_atomic(&csv, trajectory.to_csv(&csv)?.as_bytes())?;
    let world = scene(obstacles, e, &at)?;
    let ron = ron::ser::to_string_pretty(&world.to_spec(), Default::default())?;
    trm::write_atomic(&out_dir.join(format!("{name}.world.ron")), ron.as_bytes())?;
    Ok(Run {
        name: name.into(),
        motion,
        trace,
        seconds,
    })
}

/// Runs both studies and writes the tables, the plots, the trajectories and the worlds.
pub fn run(args: &Args) -> Result<()> {
    let specs = crate::repo_dir().join("specs/taskmaps");
    let started = std::time::Instant::now();
    let out = &args.out_dir;
    let stick = TaskMapSpec::load(specs.join("stick.ron"))?.explore()?;
    let tabletop = table()?;
    let place = Isometry3::translation(CYLINDER[0], CYLINDER[1], CYLINDER[2]);
    // the exact target: the map's grasp nearest the cylinder's centre
    let centre = stick
        .map
        .center_grasp()
        .context("the cylinder's task map is empty")?;
    let runs = [
        reach(
            "cylinder_exact",
            &stick,
            &tabletop,
            place,
            MotionGoal::Target(centre),
            args.iterations,
            out,
        )?,
        reach(
            "cylinder_map",
            &stick,
            &tabletop,
            place,
            MotionGoal::Map(&stick.map),
            args.iterations,
            out,
        )?,
    ];
    let mut md = format!(
        "## (a) Cylinder on a table ({} feasible grasps), {} iRprop− iterations\n\n| goal | total cost | joint-limit cost | closest approach (m) | end cost | converged at iteration | grasp height on the cylinder (m) | time (s) |\n|---|---|---|---|---|---|---|---|\n",
        stick.map.points.len(),
        args.iterations
    );
    for (label, r) in ["exact target at the centre", "task map"].iter().zip(&runs) {
        let m = &r.motion;
        let _ = writeln!(
            md,
            "| {label} | {:.4} | {:.4} | {:.3} | {:.5} | {} | {:+.3} | {:.2} |",
            m.cost,
            m.limits,
            m.min_distance,
            m.end,
            r.converged(),
            m.final_pose[2],
            r.seconds
        );
    }
    // what the analytic gradient saves: one backward pass against 2 × 60 simulations
    let active = stick.reaching_set()?;
    let problem = stick.reach_problem(&active, &tabletop, place, MotionGoal::Map(&stick.map))?;
    let x0 = problem.initial_attractors();
    let timed = |f: &dyn Fn()| {
        let mut times: Vec<f64> = (0..5)
            .map(|_| {
                let t = std::time::Instant::now();
                f();
                t.elapsed().as_secs_f64() * 1e3
            })
            .collect();
        times.sort_by(f64::total_cmp);
        times[2]
    };
    let analytic = timed(&|| drop(problem.gradient(&x0)));
    let numeric = timed(&|| drop(problem.numerical_gradient(&x0, 1e-5)));
    let _ = writeln!(
        md,
        "\nOne gradient over the {} attractor coordinates (median of 5): analytic {analytic:.2} ms, central differences {numeric:.1} ms ({:.0}× slower).",
        x0.len(),
        numeric / analytic
    );
    let handle = TaskMapSpec::load(specs.join("handle.ron"))?.explore()?;
    let _ = write!(
        md,
        "\n## (b) Basket on the table ({} feasible grasps on the handle, {} clusters), three locations\n\n| basket | handle origin (x, y) m | total cost | joint-limit cost | closest approach (m) | end cost | grasp angle on the handle (°; 90 = top, below 90 towards the robot) | time (s) |\n|---|---|---|---|---|---|---|---|\n",
        handle.map.points.len(),
        handle.map.clusters()
    );
    let mut basket_runs = Vec::new();
    for (name, [x, y]) in BASKET {
        let z = TABLE_TOP + BASKET_HEIGHT;
        let at = Isometry3::translation(x, y, z);
        let mut obstacles = table()?;
        obstacles.add(
            "basket",
            Shape::Box {
                size: [0.22, 0.14, BASKET_HEIGHT],
            },
            Isometry3::translation(x, y, z - BASKET_HEIGHT / 2.0),
        )?;
        let r = reach(
            &format!("basket_{name}"),
            &handle,
            &obstacles,
            at,
            MotionGoal::Map(&handle.map),
            args.iterations,
            out,
        )?;
        let m = &r.motion;
        let angle = m.final_pose[2].atan2(m.final_pose[0]).to_degrees();
        let _ = writeln!(
            md,
            "| {name} | ({x:+.2}, {y:+.2}) | {:.4} | {:.4} | {:.3} | {:.5} | {angle:.0} | {:.2} |",
            m.cost, m.limits, m.min_distance, m.end, r.seconds
        );
        basket_runs.push(r);
    }
    let _ = writeln!(md, "\nWall time {:.1} s.", started.elapsed().as_secs_f64());
    trm::write_atomic(&out.join("table.md"), md.as_bytes())?;
    write_plots(args, &runs, &basket_runs)?;
    println!("{md}");
    println!(
        "wrote {}/{{table.md, joint_limits.svg, paths.svg}} and per run NAME.csv + NAME.world.ron (cargo xtask view --traj {0}/cylinder_map.csv --world {0}/cylinder_map.world.ron)",
        out.display()
    );
    Ok(())
}

/// One line per run.
fn series<'a>(
    runs: impl IntoIterator<Item = &'a Run>,
    points: impl Fn(&Run) -> Vec<(f64, f64)>,
) -> Vec<trm::plot::Series> {
    runs.into_iter()
        .map(|r| trm::plot::Series {
            label: r.name.replace('_', " "),
            points: points(r),
            color: None,
        })
        .collect()
}

/// joint_limits.svg (Fig. 7, bottom) and paths.svg (the hand's path, seen from the side and
/// from above).
fn write_plots(args: &Args, cylinder: &[Run], basket: &[Run]) -> Result<()> {
    let hi = cylinder
        .iter()
        .flat_map(|r| r.trace.iter().map(|t| t.1))
        .fold(0.0f64, f64::max)
        * 1.1;
    let svg = trm::plot::lines(
        "Cylinder: joint-limit cost of the best motion so far",
        (
            "iRprop− iteration",
            "joint-limit cost (mean over the motion)",
        ),
        0.0..args.iterations as f64,
        0.0..hi.max(1e-3),
        series(cylinder, |r| {
            r.trace
                .iter()
                .enumerate()
                .map(|(k, t)| (k as f64, t.1))
                .collect()
        }),
    )?;
    trm::write_atomic(&args.out_dir.join("joint_limits.svg"), svg.as_bytes())?;
    let all = || cylinder.iter().chain(basket);
    let range = |i: usize| {
        let (lo, hi) = all()
            .flat_map(|r| r.motion.task_path.iter().map(move |x| x[i]))
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
                (a.min(v), b.max(v))
            });
        (lo - 0.03)..(hi + 0.03)
    };
    let path = |a: usize, b: usize| {
        series(all(), move |r: &Run| {
            r.motion.task_path.iter().map(|x| (x[a], x[b])).collect()
        })
    };
    let panels = [
        trm::plot::Panel {
            title: "Hand path from the side (x back, z up)".into(),
            axes: ("x (m)".into(), "z (m)".into()),
            x: range(0),
            y: range(2),
            series: path(0, 2),
        },
        trm::plot::Panel {
            title: "Hand path from above (x back, y right)".into(),
            axes: ("x (m)".into(), "y (m)".into()),
            x: range(0),
            y: range(1),
            series: path(0, 1),
        },
    ];
    let svg = trm::plot::panels((640, 420), &panels)?;
    trm::write_atomic(&args.out_dir.join("paths.svg"), svg.as_bytes())?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_studies_write_their_tables_plots_and_runs() {
        let dir = std::env::temp_dir().join(format!("trm-tms-{}", std::process::id()));
        run(&Args {
            iterations: 2,
            out_dir: dir.clone(),
        })
        .unwrap();
        let table = std::fs::read_to_string(dir.join("table.md")).unwrap();
        assert!(table.contains("| task map |") && table.contains("| exact target at the centre |"));
        for name in ["right", "centre", "left"] {
            assert!(table.contains(&format!("\n| {name} |")), "{table}");
            let world =
                World::load(dir.join(format!("basket_{name}.world.ron"))).expect("a world file");
            assert!(world.index("basket").is_ok() && world.index("handle_3").is_ok());
        }
        for svg in ["joint_limits.svg", "paths.svg"] {
            assert!(
                std::fs::read_to_string(dir.join(svg))
                    .unwrap()
                    .starts_with("<svg")
            );
        }
        let csv = std::fs::read_to_string(dir.join("cylinder_map.csv")).unwrap();
        assert_eq!(csv.lines().count(), 1 + 61);
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
