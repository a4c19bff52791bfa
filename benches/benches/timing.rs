//! Cost of turning a planned path into a trajectory: blending the corners of a 7-joint path
//! of 5 waypoints (a MotionBenchMaker Panda path has 4 to 6) and timing it time-optimally
//! (TOPP-RA) under MoveIt's Panda limits, then sampling it every 10 ms. Goal: no more than the
//! planning time of such a path (~0.3 ms on MotionBenchMaker's Panda set).

use criterion::{Criterion, criterion_group, criterion_main};
use std::hint::black_box;
use trm_trajectory::{BlendedPath, JointLimits, TimingOptions, time_optimal};

fn timing(c: &mut Criterion) {
    let waypoints = vec![
        vec![0.0, -0.785, 0.0, -2.356, 0.0, 1.571, 0.785],
        vec![0.6, -0.3, 0.2, -2.0, 0.3, 1.9, 0.5],
        vec![1.1, 0.2, -0.3, -1.6, 0.1, 2.2, 1.0],
        vec![0.7, 0.5, -0.6, -1.2, -0.4, 2.6, 1.4],
        vec![0.2, 0.1, -0.2, -1.9, -0.2, 2.0, 0.9],
    ];
    let limits = JointLimits::new(
        vec![2.175, 2.175, 2.175, 2.175, 2.61, 2.61, 2.61],
        vec![3.75, 1.875, 2.5, 3.125, 3.75, 5.0, 5.0],
    )
    .expect("limits");
    let options = TimingOptions::default();
    let mut group = c.benchmark_group("timing_panda_path_5_waypoints");
    for deviation in [0.0, 0.1, 0.2] {
        group.bench_function(format!("blend_{deviation}_time_sample"), |b| {
            b.iter(|| {
                let path = BlendedPath::new(black_box(&waypoints), deviation).expect("path");
                let timed = time_optimal(&path, &limits, &options).expect("timing");
                black_box(timed.sampled(0.01).expect("samples").len())
            })
        });
    }
    group.finish();
}

criterion_group!(benches, timing);
criterion_main!(benches);
