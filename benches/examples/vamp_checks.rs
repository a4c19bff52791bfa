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
//! the joint limits), and optionally the rounds (default 7). Both sides check blocks of
//! configurations (trm [`trm_kinematics::LANES`], VAMP its float lanes), stopping a block at
//! its first collision, in an empty world.

use std::io::{BufRead, BufReader, Write};
use std::process::{Command, Stdio};
use std::time::Instant;

use trm_benches::random_configurations;
use trm_collision::{CollisionModel, World};
use trm_kinematics::{LANES, RobotModel};
use trm_tasks::Objective;

fn objective(path: &str) -> Objective {
    let robot = RobotModel::load(path).unwrap_or_else(|e| panic!("{path}: {e}"));
    let collision = CollisionModel::new(&robot).unwrap_or_else(|e| panic!("{path}: {e}"));
    Objective::new(robot.all_active(), collision, World::new())
}

fn median(values: &mut [f64]) -> f64 {
    values.sort_by(f64::total_cmp);
    values[values.len() / 2]
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.len() < 4 {
        eprintln!("usage: vamp_checks TIMED_MODEL EXACT_MODEL VAMP_PROGRAM COUNT [ROUNDS]");
        std::process::exit(2);
    }
    let (timed, exact) = (objective(&args[0]), objective(&args[1]));
    let n: usize = args[3].parse().expect("COUNT is a number");
    let rounds: usize = args
        .get(4)
        .map_or(7, |r| r.parse().expect("ROUNDS is a number"));
    let qs = random_configurations(timed.active(), n, 0);
    let world = World::new();

    let mut vamp = Command::new(&args[2])
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .spawn()
        .unwrap_or_else(|e| {
            panic!(
                "{}: {e} (build it with benches/peers/vamp/build.sh)",
                args[2]
            )
        });
    let mut to_vamp = vamp.stdin.take().expect("piped");
    let mut from_vamp = BufReader::new(vamp.stdout.take().expect("piped")).lines();
    let mut input = format!(
        "trm-mbm-problems 1\nrobot {}\nconfigurations {n}\n",
        timed.active().model().name()
    );
    for q in &qs {
        input.push_str(
            &q.iter()
                .map(|v| format!("{v}"))
                .collect::<Vec<_>>()
                .join(" "),
        );
        input.push('\n');
    }
    input.push_str(&format!("{rounds}\n"));
    to_vamp.write_all(input.as_bytes()).unwrap();
    to_vamp.flush().unwrap();

    let flat: Vec<f64> = qs.iter().flatten().copied().collect();
    let d = timed.dim();
    let mut scratch = timed.scratch();
    let (mut ours, mut theirs) = (Vec::new(), Vec::new());
    for round in 0..rounds {
        let began = Instant::now();
        let mut free_blocks = 0;
        for block in flat.chunks(LANES * d) {
            free_blocks += usize::from(timed.all_collision_free_in(block, &world, &mut scratch));
        }
        ours.push(began.elapsed().as_nanos() as f64 / n as f64);
        std::hint::black_box(free_blocks);
        let line = from_vamp.next().expect("VAMP answers").unwrap();
        let ns: f64 = line
            .split_whitespace()
            .nth(1)
            .and_then(|v| v.parse().ok())
            .unwrap_or_else(|| panic!("VAMP said `{line}`"));
        theirs.push(ns);
        if round + 1 < rounds {
            to_vamp.write_all(b"next\n").unwrap();
            to_vamp.flush().unwrap();
        }
    }
    let vamp_free: Vec<bool> = (0..n)
        .map(|_| from_vamp.next().expect("a verdict").unwrap() == "valid 1")
        .collect();
    let _ = vamp.wait();

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
    let (a, b) = (median(&mut ours), median(&mut theirs));
    println!(
        "{n} configurations of {} (seed 0), FK + self-collision in blocks, median of {rounds} interleaved rounds:",
        timed.active().model().name()
    );
    println!("  trm  ({}): {a:.1} ns per configuration", args[0]);
    println!("  VAMP ({}): {b:.1} ns per configuration", args[2]);
    println!("  trm / VAMP: {:.2}×", a / b);
    println!(
        "verdicts against the exact model ({}, {colliding} of {n} colliding): VAMP missed {missed} collisions, refused {false_positive} free configurations; VAMP and trm's copy of its spheres agree on {agree_spheres} of {n}",
        args[1]
    );
}
