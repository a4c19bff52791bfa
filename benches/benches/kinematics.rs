//! Forward kinematics of every link: the 41-motor iCub upper body and the official 75-joint URDF.
//! Target: ≤ 1 µs per FK of the 41-DOF model (median, one core).

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use std::hint::black_box;
use trm_benches::random_configurations;

fn forward_kinematics(c: &mut Criterion) {
    let mut group = c.benchmark_group("fk_all_links");
    let cases = [
        ("icub_upper_body_41_motors", trm_models::icub_upper_body()),
        ("icub_official_75_joints", trm_models::icub_official()),
    ];
    for (name, model) in cases {
        let active = model.all_active();
        let samples = random_configurations(&active, 64, 7);
        let mut buffer = model.pose_buffer();
        let mut k = 0;
        group.bench_function(BenchmarkId::new("unchecked", name), |b| {
            b.iter(|| {
                k = (k + 1) % samples.len();
                active.forward_unchecked(black_box(&samples[k]), &mut buffer);
                black_box(buffer.poses()[1].translation.x)
            })
        });
        group.bench_function(BenchmarkId::new("checked", name), |b| {
            b.iter(|| {
                k = (k + 1) % samples.len();
                active.forward(black_box(&samples[k]), &mut buffer).unwrap();
                black_box(buffer.poses()[1].translation.x)
            })
        });
    }
    // The usual optimisation setting: a few motors active, the rest locked (folded into constants).
    let model = trm_models::icub_upper_body();
    let home = model.posture("home").expect("home posture");
    let arm = model
        .active_set(&["torso", "right_arm"], home)
        .expect("groups exist");
    let samples = random_configurations(&arm, 64, 7);
    let mut buffer = model.pose_buffer();
    let mut k = 0;
    group.bench_function(
        BenchmarkId::new("unchecked", "icub_upper_body_torso_right_arm_10_motors"),
        |b| {
            b.iter(|| {
                k = (k + 1) % samples.len();
                arm.forward_unchecked(black_box(&samples[k]), &mut buffer);
                black_box(buffer.poses()[1].translation.x)
            })
        },
    );
    group.finish();
}

criterion_group!(benches, forward_kinematics);
criterion_main!(benches);
