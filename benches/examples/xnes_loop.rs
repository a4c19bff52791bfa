//! A long xNES ask/tell loop at d = 41, λ = 30, for profilers (`perf record`).
use rand::SeedableRng;
use trm_optim::{Optimizer, Start, StopOptions, Xnes, XnesOptions};
fn main() {
    let start = Start::new(vec![0.1; 41], 0.3).with_stop(StopOptions {
        tol_x: None,
        tol_fun: None,
        ..Default::default()
    });
    let mut o = Xnes::new(
        &start,
        &XnesOptions {
            population: Some(30),
            ..Default::default()
        },
    )
    .expect("valid");
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(1);
    let fitness: Vec<f64> = (0..30).map(|k| ((k * 7919) % 31) as f64).collect();
    for _ in 0..20_000 {
        o.ask(&mut rng);
        o.tell(&fitness).expect("30 values");
    }
    println!("{}", o.sigma());
}
