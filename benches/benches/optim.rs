//! Per-generation overhead of the optimisers at d = 41, λ = 30 (the NGIK setting), excluding
//! evaluations: one `ask` + `tell` with precomputed fitness values. Goal: ≲ 30 µs, below the cost
//! of evaluating the population (a few µs per evaluation).

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use std::hint::black_box;
use trm_optim::{
    Cmaes, CmaesOptions, Optimizer, Snes, SnesOptions, Start, StopOptions, Xnes, XnesOptions,
};

fn generation(c: &mut Criterion) {
    let d = 41;
    let lambda = 30;
    let start = Start::new(vec![0.1; d], 0.3).with_stop(StopOptions {
        tol_x: None,
        tol_fun: None,
        ..Default::default()
    });
    let fitness: Vec<f64> = (0..lambda).map(|k| ((k * 7919) % 31) as f64).collect();
    let mut group = c.benchmark_group("optim_generation_d41_lambda30");
    let mut run = |name: &str, o: &mut dyn Optimizer| {
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        group.bench_function(BenchmarkId::new("ask_tell", name), |b| {
            b.iter(|| {
                let n = o.ask(&mut rng).len();
                o.tell(black_box(&fitness[..n])).expect("λ values");
            })
        });
    };
    run(
        "xnes",
        &mut Xnes::new(
            &start,
            &XnesOptions {
                population: Some(lambda),
                ..Default::default()
            },
        )
        .expect("valid"),
    );
    run(
        "cmaes",
        &mut Cmaes::new(
            &start,
            &CmaesOptions {
                population: Some(lambda),
                ..Default::default()
            },
        )
        .expect("valid"),
    );
    run(
        "cmaes_eigen_every_5",
        &mut Cmaes::new(
            &start,
            &CmaesOptions {
                population: Some(lambda),
                eigen_interval: Some(5),
                ..Default::default()
            },
        )
        .expect("valid"),
    );
    run(
        "snes",
        &mut Snes::new(
            &start,
            &SnesOptions {
                population: Some(lambda),
                ..Default::default()
            },
        )
        .expect("valid"),
    );
    group.finish();
}

criterion_group!(benches, generation);
criterion_main!(benches);
