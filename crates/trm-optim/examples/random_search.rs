//! Your own optimiser in trm: a (1+1) evolution strategy with Rechenberg's 1/5 success rule,
//! implemented against the `Optimizer` trait, then run by trm's own `minimize_fn` next to xNES
//! on the 10-D Rosenbrock function.
//!
//! `cargo run -p trm-optim --example random_search`

use rand::{Rng, RngExt, SeedableRng};
use rand_distr::StandardNormal;
use trm_optim::functions::TestFunction;
use trm_optim::{
    OptimError, Optimizer, Population, Start, State, StopOptions, Xnes, XnesOptions, minimize_fn,
};

/// A (1+1)-ES: one candidate per generation around the current point; the step grows after a
/// success and shrinks after a failure so that about one in five candidates succeeds.
struct OnePlusOneEs {
    state: State,
    current: Vec<f64>,
    current_f: f64,
    sigma: f64,
    candidate: Population,
}

impl OnePlusOneEs {
    fn new(start: &Start) -> Result<Self, OptimError> {
        let steps = start.check()?; // validates the start, gives the initial step per coordinate
        Ok(OnePlusOneEs {
            state: State::new(start, 1),
            current: start.mean.clone(),
            current_f: f64::INFINITY,
            sigma: steps.iter().copied().fold(0.0, f64::max),
            candidate: Population::from_candidates(&[&start.mean]),
        })
    }
}

impl Optimizer for OnePlusOneEs {
    fn name(&self) -> &'static str {
        "(1+1)-ES, 1/5 rule"
    }
    fn dim(&self) -> usize {
        self.current.len()
    }
    fn ask(&mut self, rng: &mut dyn Rng) -> &Population {
        if self.current_f.is_finite() {
            for (x, c) in self.candidate[0].iter_mut().zip(&self.current) {
                let z: f64 = rng.sample(StandardNormal);
                *x = c + self.sigma * z;
            }
        }
        self.state.clamp(&mut self.candidate[0]);
        self.state.asked(1);
        &self.candidate
    }
    fn tell(&mut self, fitness: &[f64]) -> Result<(), OptimError> {
        self.state.told(&self.candidate, fitness)?;
        if fitness[0] <= self.current_f {
            self.current.copy_from_slice(&self.candidate[0]);
            self.current_f = fitness[0];
            self.sigma *= 1.5;
        } else {
            self.sigma *= 1.5f64.powf(-0.25);
        }
        Ok(())
    }
    fn mean(&self) -> &[f64] {
        &self.current
    }
    fn spread(&self) -> f64 {
        self.sigma
    }
    fn state(&self) -> &State {
        &self.state
    }
    fn state_mut(&mut self) -> &mut State {
        &mut self.state
    }
}

fn main() -> Result<(), OptimError> {
    let f = TestFunction::by_name("rosenbrock", 10, 0)?;
    let start = Start::new(f.start(), 0.5).with_stop(StopOptions {
        target: Some(1e-8),
        max_evaluations: Some(200_000),
        ..Default::default()
    });
    let mut mine = OnePlusOneEs::new(&start)?;
    let mut xnes = Xnes::new(&start, &XnesOptions::default())?;
    for optimizer in [&mut mine as &mut dyn Optimizer, &mut xnes] {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(1);
        let report = minimize_fn(optimizer, &mut rng, |x| f.eval(x));
        println!(
            "{:<20} f = {:.3e} after {:>6} evaluations; stopped: {:?}",
            report.algorithm, report.best_f, report.evaluations, report.reasons
        );
    }
    Ok(())
}
