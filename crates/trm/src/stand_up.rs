//! `trm stand-up`: the safe trajectory optimisation of Modugno et al. on the iCub
//! standing up from a chair — Table II, Fig. 3 and Fig. 4 — and the optimised trajectory.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{Result, bail};
use plotters::style::{BLACK, Color, RGBColor};
use trm_wholebody::{Comparison, StandUpResult, WholeBody};

use crate::plot::{Panel, Series, lines, panels};

/// Arguments of `stand-up`.
#[derive(clap::Args)]
pub struct Args {
    /// The motion spec (default: the repository's specs/wholebody/standup.ron).
    spec: Option<PathBuf>,
    /// Seed of the optimiser (ChaCha).
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Override the spec's bootstrap budget (rollouts).
    #[arg(long, value_parser = clap::value_parser!(u64).range(0..=10_000_000))]
    bootstrap_rollouts: Option<u64>,
    /// Override the spec's constrained budget (rollouts).
    #[arg(long, value_parser = clap::value_parser!(u64).range(1..=10_000_000))]
    rollouts: Option<u64>,
    /// Also write a 3-D view of the optimised motion (`scene.html`, `scene.json` in --out).
    #[arg(long)]
    view: bool,
    /// Output directory (figures, trajectory, JSON).
    #[arg(long, default_value = "results/stand-up")]
    pub out: PathBuf,
}

/// The paper's Table II (hand-tuned, unconstrained, constrained): CoM error, effort, backward.
const PAPER: [(&str, f64, f64, f64); 3] = [
    ("hand-tuned", 1.0, 1.0, 0.186292),
    ("unconstrained", 0.806484, 0.945829, 0.962220),
    ("constrained", 0.580518, 0.646327, 0.844451),
];

/// Runs the command.
pub fn run(args: &Args) -> Result<()> {
    let spec_path = args
        .spec
        .clone()
        .unwrap_or_else(|| crate::models_dir().join("../specs/wholebody/standup.ron"));
    let problem = WholeBody::load_with_budgets(&spec_path, args.rollouts, args.bootstrap_rollouts)?;
    println!(
        "{}: {} motors, {:.1} kg, CoM from ({:.3}, {:.3}) to ({:.3}, {:.3}) m (x forward, z up), {} parameters, {} constraints",
        spec_path.display(),
        problem.model().motors().len(),
        problem.mass(),
        problem.com_waypoints().0.x,
        problem.com_waypoints().0.y,
        problem.com_waypoints().1.x,
        problem.com_waypoints().1.y,
        problem.num_params(),
        trm_wholebody::constraint_names(&problem).len()
    );
    let started = Instant::now();
    let budget = problem.spec().optimiser.rollouts;
    let mut progress = crate::progress::Progress::new("rollouts", budget);
    let result = trm_wholebody::optimize(&problem, args.seed, |n, best| {
        progress.set(n.min(budget), budget, &format!("best φ_co {best:.4}"));
    })?;
    progress.finish();
    let elapsed = started.elapsed().as_secs_f64();
    println!(
        "seed {}: {} rollouts ({} bootstrap) in {:.1} s ({:.1} ms per rollout); feasible: {}",
        args.seed,
        result.rollouts,
        result.bootstrap_rollouts,
        elapsed,
        1e3 * elapsed / result.rollouts.max(1) as f64,
        result.feasible
    );
    let is_stand_up = spec_path.file_stem().is_some_and(|s| s == "standup");
    print_table(&problem, &result, is_stand_up);
    std::fs::create_dir_all(&args.out)?;
    write_figures(&problem, &result, &args.out)?;
    let constrained = result.solutions.last().expect("constrained solution");
    write_trajectory(&problem, constrained, &args.out.join("trajectory.csv"))?;
    crate::write_json(
        &args.out.join("result.json"),
        &serde_json::to_value(&result)?,
    )?;
    if args.view {
        write_view(&problem, constrained, &args.out.join("scene.html"))?;
    }
    let check = problem.verify(&constrained.rollout);
    if result.feasible && !check.is_empty() {
        bail!(
            "the independent check finds violations the optimiser did not see: {}",
            check.join("; ")
        );
    }
    if !result.feasible {
        bail!(
            "no feasible trajectory found with seed {} in {} rollouts: raise optimiser.bootstrap_rollouts in {} or try another --seed",
            args.seed,
            result.rollouts,
            spec_path.display()
        );
    }
    Ok(())
}

fn print_table(problem: &WholeBody, result: &StandUpResult, paper_column: bool) {
    println!(
        "\nTable II (CoM error and effort normalised by the hand-tuned trajectory, backward by b_max):"
    );
    println!(
        "| solution | duration | CoM error | effort | backward | φ_co | violations (samples) | independent check | fallen |{}",
        if paper_column {
            " paper: CoM error / effort / backward |"
        } else {
            ""
        }
    );
    println!(
        "|---|---|---|---|---|---|---|---|---|{}",
        if paper_column { "---|" } else { "" }
    );
    for s in &result.solutions {
        let check = problem.verify(&s.rollout);
        let paper = if paper_column {
            PAPER
                .iter()
                .find(|p| p.0 == s.name)
                .map(|p| format!(" {:.3} / {:.3} / {:.3} |", p.1, p.2, p.3))
                .unwrap_or_else(|| " |".into())
        } else {
            String::new()
        };
        println!(
            "| {} | {:.2} s (1st phase {:.2} s) | {:.3} | {:.3} | {:.3} | {:.3} | {} | {} | {} |{}",
            s.name,
            s.ends.last().copied().unwrap_or(0.0),
            s.ends.first().copied().unwrap_or(0.0),
            s.normalised.com_error,
            s.normalised.effort,
            s.normalised.backward,
            s.phi_co,
            s.rollout.violations(),
            if check.is_empty() {
                "feasible".to_string()
            } else {
                format!("{} violated", check.len())
            },
            if s.rollout.fallen { "yes" } else { "no" },
            paper
        );
    }
    for s in &result.solutions {
        let check = problem.verify(&s.rollout);
        if !check.is_empty() {
            println!("\n{} violates:", s.name);
            for c in check {
                println!("  {c}");
            }
        }
    }
}

const COLORS: [RGBColor; 3] = [
    RGBColor(30, 150, 60),
    RGBColor(230, 120, 20),
    RGBColor(20, 90, 200),
];

fn series(
    result: &StandUpResult,
    label: impl Fn(&Comparison) -> String,
    points: impl Fn(&Comparison) -> Vec<(f64, f64)>,
) -> Vec<Series> {
    result
        .solutions
        .iter()
        .enumerate()
        .map(|(i, s)| Series {
            label: label(s),
            points: points(s),
            color: Some(COLORS[i % COLORS.len()].to_rgba()),
        })
        .collect()
}

fn range(values: impl Iterator<Item = f64>, pad: f64) -> std::ops::Range<f64> {
    let (lo, hi) = values.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
        (lo.min(v), hi.max(v))
    });
    if lo.is_finite() {
        (lo - pad)..(hi + pad)
    } else {
        0.0..1.0
    }
}

fn write_figures(problem: &WholeBody, result: &StandUpResult, out: &Path) -> Result<()> {
    let duration = result
        .solutions
        .iter()
        .filter_map(|s| s.ends.last().copied())
        .fold(0.0, f64::max);
    // Fig. 3 C: the CoM on the sagittal plane (actual and desired)
    let mut com = series(
        result,
        |s| format!("{} (actual)", s.name),
        |s| s.rollout.com.iter().map(|c| (c[0], c[2])).collect(),
    );
    com.push(Series {
        label: "constrained (desired)".into(),
        points: result
            .solutions
            .last()
            .map(|s| s.rollout.com_desired.iter().map(|c| (c[0], c[1])).collect())
            .unwrap_or_default(),
        color: Some(BLACK.mix(0.5)),
    });
    let all = || result.solutions.iter().flat_map(|s| s.rollout.com.iter());
    let com_svg = lines(
        "Centre of mass on the sagittal plane (Fig. 3 C)",
        ("x (m, forward)", "z (m, up)"),
        range(all().map(|c| c[0]), 0.02),
        range(all().map(|c| c[2]), 0.02),
        com,
    )?;
    // Fig. 3 D: ZMP x over time with the conservative support polygon
    let mut zmp = series(
        result,
        |s| s.name.clone(),
        |s| {
            s.rollout
                .times
                .iter()
                .zip(&s.rollout.zmp)
                .map(|(t, z)| (*t, z[0]))
                .collect()
        },
    );
    for (i, s) in result.solutions.iter().enumerate() {
        for (bound, label) in [(0, "support polygon, back"), (1, "support polygon, front")] {
            zmp.push(Series {
                label: format!("{} {label}", s.name),
                points: s
                    .rollout
                    .times
                    .iter()
                    .zip(&s.rollout.support)
                    .map(|(t, b)| (*t, b[bound]))
                    .collect(),
                color: Some(COLORS[i % COLORS.len()].mix(0.35)),
            });
        }
    }
    let zmp_svg = lines(
        "ZMP (x) and the conservative support polygon (Fig. 3 D)",
        ("time (s)", "x (m)"),
        0.0..duration,
        range(
            result.solutions.iter().flat_map(|s| {
                let zmp = s.rollout.zmp.iter().map(|z| z[0].clamp(-0.5, 0.5));
                let front = s.rollout.support.iter().map(|b| b[1]);
                zmp.chain(front)
            }),
            0.02,
        ),
        zmp,
    )?;
    // Fig. 3 B: joint positions, one panel per solution
    let names: Vec<String> = problem.model().motor_names();
    let joints_svg = per_motor_panels(
        result,
        &names,
        ("Joint positions", "Fig. 3 B", "degrees"),
        (0.0..duration, -180.0..180.0),
        |r| &r.q,
        f64::to_degrees,
    )?;
    // Fig. 3 A: torques, one panel per solution
    let torque_range = range(
        result
            .solutions
            .iter()
            .flat_map(|s| s.rollout.torque.iter().flatten().copied()),
        1.0,
    );
    let torques_svg = per_motor_panels(
        result,
        &names,
        ("Static joint torques", "Fig. 3 A", "N m per joint"),
        (0.0..duration, torque_range),
        |r| &r.torque,
        |v| v,
    )?;
    // Fig. 4: best φ_co over the constrained rollouts
    let fitness_svg = lines(
        "Best φ_co over the constrained rollouts (Fig. 4)",
        ("rollout", "φ_co (lower is better)"),
        0.0..(result.trace.last().map_or(1.0, |t| t.0 as f64)),
        range(result.trace.iter().map(|t| t.1), 0.02),
        vec![Series {
            label: "(1+1)-CMA-ES with CCA".into(),
            points: result.trace.iter().map(|&(e, f)| (e as f64, f)).collect(),
            color: None,
        }],
    )?;
    for (name, svg) in [
        ("com.svg", com_svg),
        ("zmp.svg", zmp_svg),
        ("joints.svg", joints_svg),
        ("torques.svg", torques_svg),
        ("fitness.svg", fitness_svg),
    ] {
        crate::write_atomic(&out.join(name), svg.as_bytes())?;
        eprintln!("wrote {}", out.join(name).display());
    }
    Ok(())
}

/// One panel per solution with one line per motor of `values(rollout)[sample][motor]`, mapped
/// by `scale`; `what` = (quantity, figure, unit).
fn per_motor_panels(
    result: &StandUpResult,
    names: &[String],
    what: (&str, &str, &str),
    ranges: (std::ops::Range<f64>, std::ops::Range<f64>),
    values: impl Fn(&trm_wholebody::Rollout) -> &Vec<Vec<f64>>,
    scale: impl Fn(f64) -> f64,
) -> Result<String> {
    let all: Vec<Panel> = result
        .solutions
        .iter()
        .map(|s| Panel {
            title: format!("{}, {} ({})", what.0, s.name, what.1),
            axes: ("time (s)".into(), what.2.into()),
            x: ranges.0.clone(),
            y: ranges.1.clone(),
            series: names
                .iter()
                .enumerate()
                .map(|(k, n)| Series {
                    label: n.clone(),
                    points: s
                        .rollout
                        .times
                        .iter()
                        .zip(values(&s.rollout))
                        .map(|(t, v)| (*t, scale(v[k])))
                        .collect(),
                    color: None,
                })
                .collect(),
        })
        .collect();
    panels((720, 380), &all)
}

/// The motion in the ground frame (feet flat), with its world and the CoM path.
fn write_view(problem: &WholeBody, s: &Comparison, path: &Path) -> Result<()> {
    let title = format!(
        "{} solution ({:.2} s)",
        s.name,
        s.ends.last().copied().unwrap_or(0.0)
    );
    let mut scene = trm_view::Scene::new(&title, problem.collision());
    scene.set_world(problem.ground_world());
    let r = &s.rollout;
    // every 5th control step (20 frames per second) keeps the page light
    for i in (0..r.times.len()).step_by(5) {
        scene.add_frame_at(r.times[i], &r.q[i], &problem.root_pose(&r.q[i]))?;
    }
    scene.set_path(r.com.clone());
    crate::support::scene::write_scene(&scene, path)
}

/// The optimised motion as CSV ([`trm_wholebody::Rollout::to_csv`]) and, beside it, as a ROS 2
/// JointTrajectory (`.ros.yaml`, [`trm_wholebody::Rollout::to_ros_yaml`]).
fn write_trajectory(problem: &WholeBody, s: &Comparison, path: &Path) -> Result<()> {
    crate::write_atomic(path, s.rollout.to_csv(problem.model())?.as_bytes())?;
    let ros = path.with_extension("ros.yaml");
    crate::write_atomic(&ros, s.rollout.to_ros_yaml(problem.model())?.as_bytes())?;
    eprintln!("wrote {} and {}", path.display(), ros.display());
    Ok(())
}
