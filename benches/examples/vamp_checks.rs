//! FK + self-collision per configuration, trm beside VAMP on the same random configurations,
//! interleaved (trm's pass, VAMP's pass, … in one process pair), and the verdicts compared with
//! trm's exact model:
//!
//! ```sh
//! benches/peers/vamp/build.sh VAMP_DIR PDQSORT_DIR
//! cargo run --release -p trm-benches --example vamp_checks -- \
//!     models/panda-mbm/panda_spherized.ron models/panda-mbm/panda.ron target/peers/vamp-mbm 100000
//! ```
//!
//! Arguments: the model timed (VAMP's spheres), the exact model (mesh hulls) whose verdicts
//! are the reference, VAMP's program, the number of configurations (seed 0, uniform within
//! the joint limits), and optionally the rounds (default 7) and the joints moved (a group or
//! comma-separated motors of both models, the others held at their neutral values: VAMP's
//! joints, e.g. `arm` for the project's fitted Panda, whose fingers are a motor). Both sides check blocks of
//! configurations (trm [`trm_kinematics::LANES`], VAMP its float lanes), stopping a block at
//! its first collision, in an empty world.

use std::io::Write;
use std::time::Instant;

use trm_benches::{median, positive, random_configurations};
use trm_collision::fast::{FAST_LANES, FastChecker};
use trm_collision::{CollisionModel, World};
use trm_kinematics::{LANES, RobotModel};
use trm_tasks::Objective;

/// The model at `path`, moving `joints` (a group or comma-separated motors; the others held at
/// their neutral values) or every motor.
fn objective(path: &str, joints: Option<&str>) -> Result<Objective, String> {
    let robot = RobotModel::load(path).map_err(|e| e.to_string())?;
    let collision = CollisionModel::new(&robot).map_err(|e| e.to_string())?;
    let active = match joints {
        Some(list) => {
            let names: Vec<&str> = list.split(',').collect();
            robot
                .active_set(&names, &robot.neutral_motors())
                .map_err(|e| format!("{path}: {e}"))?
        }
        None => robot.all_active(),
    };
    Ok(Objective::new(active, collision, World::new()))
}

/// trm's `f64` batch, trm's single-precision screen of the timed model and of the exact model
/// (each when it screens), VAMP's times per configuration (one per round) and VAMP's verdicts.
type Exchanged = (Vec<f64>, Vec<f64>, Vec<f64>, Vec<f64>, Vec<bool>);

fn main() {
    trm_benches::exit_on_error(run);
}

fn run() -> Result<(), String> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.len() < 4 {
        return Err(
            "usage: vamp_checks TIMED_MODEL EXACT_MODEL VAMP_PROGRAM COUNT [ROUNDS [JOINTS]]"
                .into(),
        );
    }
    let joints = args.get(5).map(String::as_str);
    let (timed, exact) = (objective(&args[0], joints)?, objective(&args[1], joints)?);
    let n = positive(&args[3], "COUNT")?;
    let rounds = args.get(4).map_or(Ok(7), |r| positive(r, "ROUNDS"))?;
    if timed.dim() != exact.dim() {
        return Err(format!(
            "{} moves {} motors, {} moves {}: give two models of one robot",
            args[0],
            timed.dim(),
            args[1],
            exact.dim()
        ));
    }
    let qs = random_configurations(timed.active(), n, 0);
    let world = World::new();
    // VAMP's verdicts on every configuration, and the times on all of them (blocks mostly end
    // at their first collision) and on the free ones only (every pair looked at)
    let (mut ours, mut screened, mut screened_exact, mut theirs, vamp_free) =
        exchange(&args[2], &qs, rounds, &timed, &exact, &world)?;
    let mut scratch = timed.scratch();
    let free: Vec<Vec<f64>> = qs
        .iter()
        .filter(|q| timed.is_collision_free_in(q, &world, &mut scratch))
        .cloned()
        .collect();
    let mut exact_scratch = exact.scratch();
    let (mut missed, mut false_positive, mut agree_spheres, mut colliding) = (0, 0, 0, 0);
    for (q, &v) in qs.iter().zip(&vamp_free) {
        let truth = exact.is_collision_free_in(q, &world, &mut exact_scratch);
        let spheres = timed.is_collision_free_in(q, &world, &mut scratch);
        colliding += usize::from(!truth);
        missed += usize::from(!truth && v);
        false_positive += usize::from(truth && !v);
        agree_spheres += usize::from(spheres == v);
    }
    let free_times = if free.is_empty() {
        None
    } else {
        Some(exchange(&args[2], &free, rounds, &timed, &exact, &world)?)
    };

    let (a, b) = (median(&mut ours), median(&mut theirs));
    println!(
        "{n} configurations of {} (seed 0), FK + self-collision in blocks, median of {rounds} interleaved rounds:",
        timed.active().model().name()
    );
    println!(
        "  trm, f64 batches of {LANES} ({}): {a:.1} ns per configuration ({:.2}× VAMP)",
        args[0],
        a / b
    );
    if !screened.is_empty() {
        let c = median(&mut screened);
        println!(
            "  trm, f32 sphere screen, blocks of {FAST_LANES} (exact answers): {c:.1} ns per configuration ({:.2}× VAMP)",
            c / b
        );
    }
    if !screened_exact.is_empty() {
        let c = median(&mut screened_exact);
        println!(
            "  trm, f32 screen of {} (its spheres, then its own shapes pair by pair where they touch; exact answers): {c:.1} ns per configuration ({:.2}× VAMP)",
            args[1],
            c / b
        );
    }
    println!("  VAMP ({}): {b:.1} ns per configuration", args[2]);
    if let Some((mut ours, mut screened, mut screened_exact, mut theirs, _)) = free_times {
        let b = median(&mut theirs);
        let ratio = |v: &mut Vec<f64>| {
            let c = median(v);
            format!("{c:.1} ns ({:.2}× VAMP)", c / b)
        };
        println!(
            "the {} free configurations alone (every pair looked at): trm f64 batches {}, f32 sphere screen {}, f32 screen of the exact model {}, VAMP {b:.1} ns",
            free.len(),
            ratio(&mut ours),
            if screened.is_empty() {
                "—".into()
            } else {
                ratio(&mut screened)
            },
            if screened_exact.is_empty() {
                "—".into()
            } else {
                ratio(&mut screened_exact)
            },
        );
    }
    println!(
        "verdicts against the exact model ({}, {colliding} of {n} colliding): VAMP missed {missed} collisions, refused {false_positive} free configurations; VAMP and trm's copy of its spheres agree on {agree_spheres} of {n}",
        args[1]
    );
    Ok(())
}

/// trm's passes over `qs` and VAMP's (`program`), interleaved `rounds` times, then VAMP's
/// verdict on each configuration.
fn exchange(
    program: &str,
    qs: &[Vec<f64>],
    rounds: usize,
    timed: &Objective,
    exact: &Objective,
    world: &World,
) -> Result<Exchanged, String> {
    let n = qs.len();
    let mut input = format!(
        "trm-mbm-problems 1\nrobot {}\nconfigurations {n}\n",
        timed.active().model().name()
    );
    for q in qs {
        let values: Vec<String> = q.iter().map(|v| format!("{v}")).collect();
        input.push_str(&values.join(" "));
        input.push('\n');
    }
    input.push_str(&format!("{rounds}\n"));
    let (mut vamp, mut to_vamp, mut from_vamp) = trm_benches::start_vamp(program)?;
    let lost = |e: std::io::Error| format!("{program}: {e}");
    let flat: Vec<f64> = qs.iter().flatten().copied().collect();
    let d = timed.dim();
    let mut scratch = timed.scratch();
    let mut fast = FastChecker::new(timed.collision(), timed.active().clone()).ok();
    let fast_world = fast.as_ref().map(|f| f.model().world(world));
    let mut fast_exact = FastChecker::new(exact.collision(), exact.active().clone())
        .ok()
        .map(|checker| {
            let fast_world = checker.model().world(world);
            (checker, fast_world)
        });
    let mut run = || -> Result<Exchanged, String> {
        to_vamp.write_all(input.as_bytes()).map_err(lost)?;
        to_vamp.flush().map_err(lost)?;
        let (mut ours, mut screened, mut screened_exact, mut theirs) =
            (Vec::new(), Vec::new(), Vec::new(), Vec::new());
        for round in 0..rounds {
            let began = Instant::now();
            let mut free_blocks = 0;
            for block in flat.chunks(LANES * d) {
                free_blocks += usize::from(timed.all_collision_free_in(block, world, &mut scratch));
            }
            ours.push(began.elapsed().as_nanos() as f64 / n as f64);
            if let (Some(fast), Some(fast_world)) = (&mut fast, &fast_world) {
                let began = Instant::now();
                for block in flat.chunks(FAST_LANES * d) {
                    free_blocks += usize::from(fast.all_free_unchecked(block, world, fast_world));
                }
                screened.push(began.elapsed().as_nanos() as f64 / n as f64);
            }
            if let Some((fast, fast_world)) = &mut fast_exact {
                let began = Instant::now();
                for block in flat.chunks(FAST_LANES * d) {
                    free_blocks += usize::from(fast.all_free_unchecked(block, world, fast_world));
                }
                screened_exact.push(began.elapsed().as_nanos() as f64 / n as f64);
            }
            std::hint::black_box(free_blocks);
            let line = from_vamp
                .next()
                .ok_or_else(|| format!("{program} stopped answering"))?
                .map_err(lost)?;
            let ns: f64 = line
                .split_whitespace()
                .nth(1)
                .and_then(|v| v.parse().ok())
                .ok_or_else(|| format!("{program} said `{line}`, not `time NS VALID`"))?;
            theirs.push(ns);
            if round + 1 < rounds {
                to_vamp.write_all(b"next\n").map_err(lost)?;
                to_vamp.flush().map_err(lost)?;
            }
        }
        let mut free = Vec::with_capacity(n);
        for _ in 0..n {
            let line = from_vamp
                .next()
                .ok_or_else(|| format!("{program} gave too few verdicts"))?
                .map_err(lost)?;
            free.push(line == "valid 1");
        }
        Ok((ours, screened, screened_exact, theirs, free))
    };
    let result = run();
    let _ = vamp.kill();
    let _ = vamp.wait();
    result
}
