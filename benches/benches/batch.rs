//! One configuration at a time against [`trm_kinematics::LANES`] at once (structure of arrays,
//! SIMD lanes): forward kinematics of every link and frame of the 41-motor iCub upper body and
//! of the official 75-joint iCub. Each benchmark evaluates `LANES` configurations, so per
//! configuration = time / LANES. Issue 17's target: ≤ 0.30 µs per configuration on the iCub.

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use std::hint::black_box;
use trm_benches::random_configurations;
use trm_kinematics::LANES;

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

criterion_group!(benches, forward_kinematics);
criterion_main!(benches);
