//! FK + self-collision per configuration for any model: trm's `f64` batches beside its
//! single-precision screen, on the same random configurations (interleaved rounds), and the
//! screen's verdicts compared with the exact model's one configuration at a time:
//!
//! ```sh
//! cargo run --release -p trm-benches --example screen_checks -- models/icub_upper_body.ron 100000
//! ```
//!
//! Arguments: the model, the number of configurations (seed 0, uniform within the joint limits)
//! and optionally the rounds (default 7). Both sides check blocks (the batches
//! [`trm_kinematics::LANES`] configurations, the screen [`FAST_LANES`]), stopping a block at
//! its first collision, in an empty world; the same is then timed on the configurations that
//! are free, where every pair is looked at.

use std::time::Instant;

use trm_benches::{median, positive, random_configurations};
use trm_collision::fast::{FAST_LANES, FastChecker};
use trm_collision::{CollisionModel, World};
use trm_kinematics::{LANES, RobotModel};
use trm_tasks::Objective;

fn main() {
    trm_benches::exit_on_error(run);
}

fn run() -> Result<(), String> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.len() < 2 {
        return Err("usage: screen_checks MODEL COUNT [ROUNDS]".into());
    }
    let n = positive(&args[1], "COUNT")?;
    let rounds = args.get(2).map_or(Ok(7), |r| positive(r, "ROUNDS"))?;
    let robot = RobotModel::load(&args[0]).map_err(|e| e.to_string())?;
    let collision = CollisionModel::new(&robot).map_err(|e| e.to_string())?;
    let world = World::new();
    let objective = Objective::new(robot.all_active(), collision, world.clone());
    let mut fast = FastChecker::new(objective.collision(), objective.active().clone())
        .map_err(|e| e.to_string())?;
    let fast_world = fast.model().world(&world);
    let mut scratch = objective.scratch();
    let qs = random_configurations(objective.active(), n, 0);

    // verdicts: the screen against the exact model, one configuration and one block at a time
    let truth: Vec<bool> = qs
        .iter()
        .map(|q| objective.is_collision_free_in(q, &world, &mut scratch))
        .collect();
    let mut wrong = 0;
    for (q, &t) in qs.iter().zip(&truth) {
        wrong += usize::from(fast.all_free_unchecked(q, &world, &fast_world) != t);
    }
    for (block, t) in qs.chunks(FAST_LANES).zip(truth.chunks(FAST_LANES)) {
        let flat: Vec<f64> = block.iter().flatten().copied().collect();
        let expected = t.iter().all(|&f| f);
        wrong += usize::from(fast.all_free_unchecked(&flat, &world, &fast_world) != expected);
    }
    let free: Vec<&Vec<f64>> = qs
        .iter()
        .zip(&truth)
        .filter(|(_, t)| **t)
        .map(|(q, _)| q)
        .collect();
    println!(
        "{} ({} motors, {} spheres screened): {n} random configurations (seed 0), {} free",
        args[0],
        objective.dim(),
        fast.model().num_spheres(),
        free.len()
    );
    println!(
        "verdicts: the screen and the exact model differ on {wrong} of {} configurations and blocks",
        n + n.div_ceil(FAST_LANES)
    );

    let d = objective.dim();
    for (label, set) in [
        ("random", qs.iter().collect::<Vec<_>>()),
        ("free only", free),
    ] {
        if set.is_empty() {
            continue;
        }
        let flat: Vec<f64> = set.iter().flat_map(|q| q.iter().copied()).collect();
        let (mut batches, mut screened) = (Vec::new(), Vec::new());
        fast.uncertain = 0;
        for _ in 0..rounds {
            let began = Instant::now();
            let mut free_blocks = 0;
            for block in flat.chunks(LANES * d) {
                free_blocks +=
                    usize::from(objective.all_collision_free_in(block, &world, &mut scratch));
            }
            batches.push(began.elapsed().as_nanos() as f64 / set.len() as f64);
            let began = Instant::now();
            for block in flat.chunks(FAST_LANES * d) {
                free_blocks += usize::from(fast.all_free_unchecked(block, &world, &fast_world));
            }
            screened.push(began.elapsed().as_nanos() as f64 / set.len() as f64);
            std::hint::black_box(free_blocks);
        }
        let (a, b) = (median(&mut batches), median(&mut screened));
        println!(
            "{label} ({} configurations), median of {rounds} interleaved rounds: f64 batches of {LANES} {a:.1} ns per configuration, f32 screen in blocks of {FAST_LANES} {b:.1} ns ({:.2}×; {:.2} % of lanes left uncertain and checked exactly)",
            set.len(),
            b / a,
            100.0 * fast.uncertain as f64 / (rounds * set.len()) as f64
        );
    }
    Ok(())
}
