//! One NGIK cost evaluation of the 41-DOF iCub (forward kinematics, collision placement, self and
//! world counts, and the cost terms) for the Table III posture specs: the unit every map-building
//! step multiplies. `eval` is one candidate at a time; `eval_batch_32` a population of 32 through
//! the batched path (divide by 32 for the time per candidate; criterion's throughput line gives
//! candidates per second).

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use std::hint::black_box;
use trm_benches::random_configurations;
use trm_tasks::Problem;

fn objective(c: &mut Criterion) {
    let mut group = c.benchmark_group("objective_icub_41");
    for name in ["posture1", "posture2"] {
        let path = format!(
            "{}/../specs/table_iii/{name}.ron",
            env!("CARGO_MANIFEST_DIR")
        );
        let problem = Problem::load(&path).expect("shipped spec");
        let samples = random_configurations(problem.objective.active(), 64, 3);
        let mut scratch = problem.objective.scratch();
        let mut k = 0;
        group.bench_function(BenchmarkId::new("eval", name), |b| {
            b.iter(|| {
                k = (k + 1) % samples.len();
                black_box(problem.objective.eval(black_box(&samples[k]), &mut scratch))
            })
        });
        let mut out = vec![0.0; 32];
        group.throughput(Throughput::Elements(32));
        let mut half = 0;
        group.bench_function(BenchmarkId::new("eval_batch_32", name), |b| {
            b.iter(|| {
                // the same 64 samples as `eval`, as two populations
                half = 1 - half;
                let population = &samples[32 * half..32 * (half + 1)];
                problem
                    .objective
                    .eval_batch(black_box(population), &mut scratch, &mut out);
                black_box(&out);
            })
        });
        group.throughput(Throughput::Elements(1));
    }
    group.finish();
}

criterion_group!(benches, objective);
criterion_main!(benches);
