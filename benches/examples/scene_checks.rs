//! The check of free configurations in MotionBenchMaker's scenes, where the world part costs:
//! random configurations of each problem's scene (seed = the problem's place in the set) kept
//! where the exact model finds them free, checked by the single-precision screen in blocks of
//! [`FAST_LANES`] (interleaved rounds, median of the rounds):
//!
//! ```sh
//! cargo run --release -p trm-benches --example scene_checks -- \
//!     benches/mbm/fetch_problems.tar.bz2 models/fetch-mbm/fetch_spherized.ron 10
//! ```
//!
//! Arguments: the problem set, the model, the problems per family (default 10) and the rounds
//! (default 7). Prints the time per free configuration per family and over the set, and
//! whether the screen agreed with the exact model on every configuration.

use std::path::Path;
use std::time::Instant;

use trm_benches::{median, positive, random_configurations};
use trm_collision::CollisionModel;
use trm_collision::fast::{FAST_LANES, FastChecker};
use trm_kinematics::RobotModel;
use trm_mbm::{LoadedProblem, ProblemSet};
use trm_tasks::Objective;

fn main() {
    trm_benches::exit_on_error(run);
}

fn run() -> Result<(), String> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.len() < 2 {
        return Err("usage: scene_checks PROBLEMS MODEL [PER_FAMILY] [ROUNDS]".into());
    }
    let per_family = args.get(2).map_or(Ok(10), |r| positive(r, "PER_FAMILY"))?;
    let rounds = args.get(3).map_or(Ok(7), |r| positive(r, "ROUNDS"))?;
    let robot = RobotModel::load(&args[1]).map_err(|e| e.to_string())?;
    let collision = CollisionModel::new(&robot).map_err(|e| e.to_string())?;
    let mut set = ProblemSet::open(Path::new(&args[0])).map_err(|e| e.to_string())?;
    set.select(&[], Some(per_family))
        .map_err(|e| e.to_string())?;
    let loaded = LoadedProblem::load_all(&collision, &set.problems).map_err(|e| e.to_string())?;
    // per scene: its checker, compiled world and free configurations in blocks
    let mut scenes = Vec::new();
    let mut disagreements = 0;
    for (k, p) in loaded.iter().enumerate() {
        let objective = Objective::new(robot.all_active(), p.collision.clone(), p.world.clone());
        let mut fast = FastChecker::new(objective.collision(), objective.active().clone())
            .map_err(|e| e.to_string())?;
        let world = fast.model().world(&p.world);
        let mut scratch = objective.scratch();
        let mut free = Vec::new();
        for q in random_configurations(objective.active(), 512, k as u64) {
            let truth = objective.is_collision_free_in(&q, &p.world, &mut scratch);
            disagreements += usize::from(fast.all_free_unchecked(&q, &p.world, &world) != truth);
            if truth {
                free.extend(q);
            }
        }
        let width = FAST_LANES * objective.dim();
        free.truncate(free.len() / width * width);
        scenes.push((
            p.problem.family.clone(),
            fast,
            world,
            p.world.clone(),
            free,
            width,
        ));
    }
    // the same configurations and checkers in an empty world: the self part alone
    let empty_world = trm_collision::World::new();
    let mut empty = Vec::new();
    for _ in 0..rounds {
        let began = Instant::now();
        for (_, fast, _, _, free, width) in &mut scenes {
            let compiled = fast.model().world(&empty_world);
            for block in free.chunks(*width) {
                std::hint::black_box(fast.all_free_unchecked(block, &empty_world, &compiled));
            }
        }
        empty.push(began.elapsed().as_secs_f64());
    }
    let mut times: std::collections::BTreeMap<String, (Vec<f64>, usize)> = Default::default();
    let mut all = Vec::new();
    for _ in 0..rounds {
        let mut round = std::collections::BTreeMap::<String, f64>::new();
        for (family, fast, world, exact, free, width) in &mut scenes {
            let began = Instant::now();
            for block in free.chunks(*width) {
                std::hint::black_box(fast.all_free_unchecked(block, exact, world));
            }
            *round.entry(family.clone()).or_default() += began.elapsed().as_secs_f64();
        }
        all.push(round.values().sum::<f64>());
        for (family, t) in round {
            times.entry(family).or_default().0.push(t);
        }
    }
    for (family, _, _, _, free, width) in &scenes {
        if let Some(entry) = times.get_mut(family) {
            entry.1 += free.len() / width * FAST_LANES;
        }
    }
    let total: usize = times.values().map(|(_, n)| n).sum();
    if total == 0 {
        return Err(format!(
            "{}: no block of free configurations in the scenes of {} problems (an empty set,              or scenes that fill the robot's reach)",
            args[0],
            scenes.len()
        ));
    }
    println!(
        "{} with {}: free configurations of {per_family} problems per family, blocks of \
         {FAST_LANES}, median of {rounds} rounds",
        args[0], args[1]
    );
    for (family, (t, n)) in &mut times {
        println!(
            "  {family}: {:.1} ns per configuration ({n})",
            median(t) / *n as f64 * 1e9
        );
    }
    println!(
        "  all: {:.1} ns per configuration ({total}); the screen and the exact model differ on \
         {disagreements} configurations",
        median(&mut all) / total as f64 * 1e9
    );
    println!(
        "  the same in an empty world: {:.1} ns per configuration",
        median(&mut empty) / total as f64 * 1e9
    );
    Ok(())
}
