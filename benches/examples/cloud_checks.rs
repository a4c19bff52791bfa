//! Blocks of configurations among a point cloud against the same scene as primitives, timed
//! in interleaved rounds (the `clouds` bench's worlds and blocks: VAMP's spherized Panda, a
//! table, a box and a shelf board as three boxes, or sampled with 1 000 or 10 000 points on
//! each surface), and the screen's grid for 5 000 points on the table built in the same
//! rounds. On a noisy machine the ratio of each round is steadier than two benches run one
//! after the other:
//!
//! ```sh
//! cargo run --release -p trm-benches --example cloud_checks -- 41
//! ```
//!
//! Argument: the rounds (default 41). Prints the median time of 256 blocks per world, the
//! median over the rounds of each cloud's time over the primitives', and the median build.

use std::hint::black_box;
use std::time::Instant;

use nalgebra::Isometry3;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use trm_benches::{
    median, positive, random_configurations, sampled_table_scene, sphere_queries, table_scene,
};
use trm_collision::fast::{FAST_LANES, FastChecker};
use trm_collision::{CollisionModel, Shape, World};
use trm_kinematics::RobotModel;

fn main() {
    trm_benches::exit_on_error(run);
}

fn run() -> Result<(), String> {
    let rounds = match std::env::args().nth(1) {
        Some(text) => positive(&text, "rounds")?,
        None => 41,
    };
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../models/panda-mbm/panda_spherized.ron"
    );
    let robot = RobotModel::load(path).map_err(|e| e.to_string())?;
    let collision = CollisionModel::new(&robot).map_err(|e| e.to_string())?;
    let active = robot.all_active();
    let mut checker = FastChecker::new(&collision, active.clone()).map_err(|e| e.to_string())?;
    let qs: Vec<f64> = random_configurations(&active, 8 * 256, 3).concat();
    let d = active.len();
    let names = ["3 boxes", "3 x 1 000 points", "3 x 10 000 points"];
    let worlds = [
        table_scene(),
        sampled_table_scene(1000),
        sampled_table_scene(10_000),
    ];
    let compiled: Vec<_> = worlds.iter().map(|w| checker.model().world(w)).collect();
    let mut rng = ChaCha8Rng::seed_from_u64(2);
    let table = Shape::Box {
        size: [0.8, 1.2, 0.05],
    };
    let mut board = World::new();
    let cloud = Shape::Points {
        points: table.surface_samples(5000, &mut rng),
        radius: 0.0025,
    };
    board
        .add("cloud", cloud, Isometry3::identity())
        .map_err(|e| e.to_string())?;
    // the same blocks' spheres, a query of eight at a time (one sphere, eight configurations)
    let queries = sphere_queries(
        &collision,
        &active,
        &random_configurations(&active, 8 * 256, 3),
    );
    let (mut times, mut builds) = (vec![Vec::new(); worlds.len()], Vec::new());
    let mut query_times = vec![Vec::new(); worlds.len()];
    for _ in 0..rounds {
        for (k, (world, fast)) in worlds.iter().zip(&compiled).enumerate() {
            let start = Instant::now();
            for _ in 0..4 {
                let touching: u32 = queries
                    .iter()
                    .map(|(centres, r)| fast.spheres_touching_unchecked(world, centres, *r))
                    .map(u8::count_ones)
                    .sum();
                black_box(touching);
            }
            query_times[k].push(start.elapsed().as_secs_f64() / 4.0 / queries.len() as f64 * 1e9);
        }
        for (k, (world, fast)) in worlds.iter().zip(&compiled).enumerate() {
            let start = Instant::now();
            for _ in 0..40 {
                let free = qs
                    .chunks(d * FAST_LANES)
                    .filter(|b| checker.all_free_unchecked(b, world, fast))
                    .count();
                black_box(free);
            }
            times[k].push(start.elapsed().as_secs_f64() / 40.0 * 1e6);
        }
        let start = Instant::now();
        for _ in 0..5 {
            black_box(checker.model().world(black_box(&board)));
        }
        builds.push(start.elapsed().as_secs_f64() / 5.0 * 1e3);
    }
    println!("{rounds} rounds of 256 blocks of {FAST_LANES} configurations:");
    for (k, name) in names.iter().enumerate() {
        let mut ratios: Vec<f64> = times[k].iter().zip(&times[0]).map(|(a, b)| a / b).collect();
        println!(
            "  {name:<18} {:7.1} µs  ({:.3}× the boxes)",
            median(&mut times[k].clone()),
            median(&mut ratios)
        );
    }
    println!(
        "{} queries of {FAST_LANES} spheres (the blocks' spheres, one at a time), exact answers:",
        queries.len()
    );
    for (k, name) in names.iter().enumerate() {
        let mut ratios: Vec<f64> = query_times[k]
            .iter()
            .zip(&query_times[0])
            .map(|(a, b)| a / b)
            .collect();
        let touching: u32 = queries
            .iter()
            .map(|(centres, r)| compiled[k].spheres_touching_unchecked(&worlds[k], centres, *r))
            .map(u8::count_ones)
            .sum();
        println!(
            "  {name:<18} {:7.1} ns  ({:.3}× the boxes; {touching} spheres touching)",
            median(&mut query_times[k].clone()),
            median(&mut ratios)
        );
    }
    println!(
        "  the screen's grid of 5 000 points: {:.3} ms",
        median(&mut builds)
    );
    Ok(())
}
