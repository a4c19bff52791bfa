//! Every built-in algorithm of trm-optim on the 10-D Rosenbrock function, picked by name (as
//! the task specs do), seeded: evaluations to reach 1e-8, or where it stopped.
//!
//! `cargo run -p trm-optim --example rosenbrock`

use rand::SeedableRng;
use trm_optim::functions::TestFunction;
use trm_optim::{ALGORITHMS, OptimError, Start, StopOptions, by_name, minimize_fn};

fn main() -> Result<(), OptimError> {
    let f = TestFunction::by_name("rosenbrock", 10, 0)?;
    for name in ALGORITHMS {
        let start = Start::new(f.start(), 0.5).with_stop(StopOptions {
            target: Some(1e-8),
            max_evaluations: Some(100_000),
            ..Default::default()
        });
        let mut optimizer = by_name(name, &start, None)?;
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
        let report = minimize_fn(optimizer.as_mut(), &mut rng, |x| f.eval(x));
        println!(
            "{name:<11} best {:.3e} at evaluation {:>6} of {:>6}; stopped: {:?}",
            report.best_f, report.best_at_evaluation, report.evaluations, report.reasons
        );
    }
    Ok(())
}
