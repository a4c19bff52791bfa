//! One configuration at a time against [`trm_kinematics::LANES`] at once (structure of arrays,
//! SIMD lanes), side by side: forward kinematics of every link and frame (the 41-motor iCub upper
//! body and the official 75-joint iCub), collision placement with the self-collision count, the
//! early-exit self check and the world count (random configurations, FK excluded), and one NGIK
//! evaluation (Table III posture 1). Each benchmark handles `LANES` configurations (the NGIK
//! one a population of 32), and the table printed at the end gives the median time per
//! configuration of both paths and their ratio.

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group};
use std::hint::black_box;
use trm_benches::random_configurations;
use trm_collision::{CollisionModel, World};
use trm_kinematics::LANES;
use trm_tasks::Problem;

fn forward_kinematics(c: &mut Criterion) {
    let mut group = c.benchmark_group("fk_per_lanes_configurations");
    group.throughput(Throughput::Elements(LANES as u64));
    for (name, model) in [
        ("icub_upper_body_41_motors", trm_models::icub_upper_body()),
        ("icub_official_75_joints", trm_models::icub_official()),
    ] {
        let active = model.all_active();
        let samples: Vec<Vec<f64>> = random_configurations(&active, 64, 7);
        let batches: Vec<Vec<f64>> = samples.chunks(LANES).map(|c| c.concat()).collect();
        let mut buffer = model.pose_buffer();
        let mut batch = model.pose_batch();
        let first = first_link(&model);
        let mut k = 0;
        group.bench_function(BenchmarkId::new("one_at_a_time", name), |b| {
            b.iter(|| {
                k = (k + 1) % batches.len();
                let mut x = 0.0;
                for lane in 0..LANES {
                    active.forward_unchecked(black_box(&samples[k * LANES + lane]), &mut buffer);
                    x += buffer.poses()[1].translation.x;
                }
                black_box(x)
            })
        });
        group.bench_function(BenchmarkId::new("batch", name), |b| {
            b.iter(|| {
                k = (k + 1) % batches.len();
                active.forward_batch_unchecked(black_box(&batches[k]), &mut batch);
                black_box(batch.positions(first)[0][0])
            })
        });
    }
    group.finish();
}

/// The first link after the root.
fn first_link(model: &trm_kinematics::RobotModel) -> trm_kinematics::FrameId {
    let name = model.frame_names().nth(1).expect("two links");
    model.frame_id(name).expect("its own frame")
}

fn collision(c: &mut Criterion) {
    let robot = trm_models::icub_upper_body();
    let model = CollisionModel::new(&robot).expect("shipped model");
    let active = robot.all_active();
    let samples = random_configurations(&active, 64, 11);
    let batches: Vec<Vec<f64>> = samples.chunks(LANES).map(|c| c.concat()).collect();
    let poses: Vec<_> = batches
        .iter()
        .map(|q| {
            let mut b = robot.pose_batch();
            active.forward_batch(q, &mut b).expect("within bounds");
            b
        })
        .collect();
    let single: Vec<_> = samples
        .iter()
        .map(|q| {
            let mut p = robot.pose_buffer();
            active.forward(q, &mut p).expect("within bounds");
            p
        })
        .collect();
    let world = World::from_ron(
        include_str!("../../specs/worlds/table.ron"),
        "specs/worlds/table.ron",
    )
    .expect("valid world");
    let mut placed = model.placed_bodies();
    let mut placed_batch = model.placed_batch();
    let mut group = c.benchmark_group("collision_per_lanes_configurations");
    group.throughput(Throughput::Elements(LANES as u64));
    type One<'a> = Box<dyn Fn(&CollisionModel, &trm_collision::PlacedBodies) -> usize + 'a>;
    type Many<'a> = Box<dyn Fn(&CollisionModel, &trm_collision::PlacedBatch) -> usize + 'a>;
    let queries: [(&str, One, Many); 3] = [
        (
            "place_and_count_self",
            Box::new(|m, p| m.count_self(p)),
            Box::new(|m, p| m.count_self_batch(p).iter().sum()),
        ),
        (
            "place_and_any_self",
            Box::new(|m, p| usize::from(m.any_self_collision(p))),
            Box::new(|m, p| m.any_self_collision_batch(p).iter().filter(|&&b| b).count()),
        ),
        (
            "place_and_count_world_table_3_boxes",
            Box::new(|m, p| m.count_world(p, &world)),
            Box::new(|m, p| m.count_world_batch(p, &world).iter().sum()),
        ),
    ];
    for (name, one, many) in &queries {
        let mut k = 0;
        group.bench_function(BenchmarkId::new("one_at_a_time", name), |b| {
            b.iter(|| {
                k = (k + 1) % batches.len();
                let mut n = 0;
                for lane in 0..LANES {
                    model.place(black_box(&single[k * LANES + lane]), &mut placed);
                    n += one(&model, &placed);
                }
                black_box(n)
            })
        });
        group.bench_function(BenchmarkId::new("batch", name), |b| {
            b.iter(|| {
                k = (k + 1) % batches.len();
                model.place_batch(black_box(&poses[k]), LANES, &mut placed_batch);
                black_box(many(&model, &placed_batch))
            })
        });
    }
    group.finish();
}

/// One NGIK evaluation of Table III's posture 1 (FK, placement, self and world counts, costs):
/// one candidate at a time through `eval`, and a population of 32 through `eval_batch`.
fn objective(c: &mut Criterion) {
    let path = format!(
        "{}/../specs/table_iii/posture1.ron",
        env!("CARGO_MANIFEST_DIR")
    );
    let problem = Problem::load(&path).expect("shipped spec");
    let samples = random_configurations(problem.objective.active(), 32, 3);
    let mut scratch = problem.objective.scratch();
    let mut out = vec![0.0; samples.len()];
    let mut group = c.benchmark_group("ngik_evaluation_per_32_candidates");
    group.throughput(Throughput::Elements(samples.len() as u64));
    group.bench_function(BenchmarkId::new("one_at_a_time", "posture1"), |b| {
        b.iter(|| {
            for (q, o) in samples.iter().zip(out.iter_mut()) {
                *o = problem.objective.eval(black_box(q), &mut scratch);
            }
            black_box(&out);
        })
    });
    group.bench_function(BenchmarkId::new("batch", "posture1"), |b| {
        b.iter(|| {
            problem
                .objective
                .eval_batch(black_box(&samples), &mut scratch, &mut out);
            black_box(&out);
        })
    });
    group.finish();
}

/// Prints each measure's median time per configuration, one at a time and batched, from
/// criterion's estimates of this run.
fn side_by_side() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../target/criterion");
    let median = |group: &str, path: &str, id: &str| -> Option<f64> {
        let file = root
            .join(group)
            .join(path)
            .join(id)
            .join("new/estimates.json");
        let text = std::fs::read_to_string(file).ok()?;
        let value: serde_json::Value = serde_json::from_str(&text).ok()?;
        value["median"]["point_estimate"].as_f64()
    };
    println!("\nper configuration (median)          one at a time      batch    ratio");
    let rows = [
        (
            "fk_per_lanes_configurations",
            "icub_upper_body_41_motors",
            LANES,
            "FK, 41-motor iCub",
        ),
        (
            "fk_per_lanes_configurations",
            "icub_official_75_joints",
            LANES,
            "FK, official 75-joint iCub",
        ),
        (
            "collision_per_lanes_configurations",
            "place_and_count_self",
            LANES,
            "place + self count",
        ),
        (
            "collision_per_lanes_configurations",
            "place_and_any_self",
            LANES,
            "place + early-exit self",
        ),
        (
            "collision_per_lanes_configurations",
            "place_and_count_world_table_3_boxes",
            LANES,
            "place + world count",
        ),
        (
            "ngik_evaluation_per_32_candidates",
            "posture1",
            32,
            "NGIK evaluation, posture 1",
        ),
    ];
    for (group, id, per, label) in rows {
        let (Some(one), Some(many)) = (
            median(group, "one_at_a_time", id),
            median(group, "batch", id),
        ) else {
            continue;
        };
        let (one, many) = (one / per as f64 / 1e3, many / per as f64 / 1e3);
        println!(
            "{label:<34} {one:>10.3} µs {many:>8.3} µs {:>7.1}×",
            one / many
        );
    }
}

criterion_group!(benches, forward_kinematics, collision, objective);

fn main() {
    benches();
    Criterion::default().configure_from_args().final_summary();
    side_by_side();
}
