//! `minimize`: the generation loop with a batch objective, an observer and a report.

use rand::Rng;
use serde::{Deserialize, Serialize};

use crate::core::{Optimizer, Population, StopReason};

/// One generation, as the observer sees it.
#[derive(Clone, Copy)]
pub struct Generation<'a> {
    /// Generations so far.
    pub generation: u64,
    /// Evaluations so far.
    pub evaluations: u64,
    /// Best value so far.
    pub best_f: f64,
    /// Best point so far.
    pub best_x: &'a [f64],
    /// The optimiser's spread, computed when asked ([`Generation::spread`]).
    spread: &'a dyn Fn() -> f64,
}

impl Generation<'_> {
    /// Largest standard deviation of the search distribution (computed when asked: O(d²) for
    /// some algorithms).
    pub fn spread(&self) -> f64 {
        (self.spread)()
    }
}

impl std::fmt::Debug for Generation<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Generation")
            .field("generation", &self.generation)
            .field("evaluations", &self.evaluations)
            .field("best_f", &self.best_f)
            .field("best_x", &self.best_x)
            .finish_non_exhaustive()
    }
}

/// What a run found.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Report {
    /// Algorithm name.
    pub algorithm: String,
    /// Best point.
    pub best_x: Vec<f64>,
    /// Best value.
    pub best_f: f64,
    /// Evaluation (1-based) at which the best value was found.
    pub best_at_evaluation: u64,
    /// Evaluations in total (centre evaluations included).
    pub evaluations: u64,
    /// Generations.
    pub generations: u64,
    /// Every stopping reason that fired.
    pub reasons: Vec<StopReason>,
    /// Best-so-far value after each generation: `(evaluations, best_f)`.
    pub trace: Vec<(u64, f64)>,
}

/// Runs `optimizer` until a stopping rule fires (or the observer returns `false`).
///
/// `objective(candidates, fitness)` writes one value per candidate: evaluate them in parallel if
/// you like (e.g. `fitness.par_iter_mut().zip(candidates)` with rayon). When the centre-stagnation
/// rule is set, the centre is evaluated once per generation as well (counted as an evaluation).
pub fn minimize<O, F, B>(
    optimizer: &mut O,
    rng: &mut dyn Rng,
    mut objective: F,
    mut observer: B,
) -> Report
where
    O: Optimizer + ?Sized,
    F: FnMut(&Population, &mut [f64]),
    B: FnMut(&Generation) -> bool,
{
    let mut fitness = Vec::new();
    let mut centre = Population::new(optimizer.dim(), 1);
    let mut centre_f = [0.0];
    let with_centre = optimizer.state().stop_options().center_stagnation.is_some();
    let mut trace = Vec::new();
    loop {
        if !optimizer.stop().is_empty() {
            break;
        }
        let candidates = optimizer.ask(rng);
        fitness.resize(candidates.len(), 0.0);
        objective(candidates, &mut fitness);
        if optimizer.tell(&fitness).is_err() {
            unreachable!("minimize always tells as many values as it was asked");
        }
        if with_centre {
            centre.as_mut_slice().copy_from_slice(optimizer.mean());
            objective(&centre, &mut centre_f);
            optimizer.record_center_fitness(&centre[0], centre_f[0]);
        }
        let s = optimizer.state();
        trace.push((s.evaluations(), s.best_f()));
        let generation = Generation {
            generation: s.generations(),
            evaluations: s.evaluations(),
            best_f: s.best_f(),
            best_x: s.best_x(),
            spread: &|| optimizer.spread(),
        };
        if !observer(&generation) {
            break;
        }
    }
    let s = optimizer.state();
    Report {
        algorithm: optimizer.name().to_string(),
        best_x: s.best_x().to_vec(),
        best_f: s.best_f(),
        best_at_evaluation: s.best_at(),
        evaluations: s.evaluations(),
        generations: s.generations(),
        reasons: optimizer.stop(),
        trace,
    }
}

/// [`minimize`] with a function of one point, evaluated candidate by candidate, and no observer.
pub fn minimize_fn<O, F>(optimizer: &mut O, rng: &mut dyn Rng, mut f: F) -> Report
where
    O: Optimizer + ?Sized,
    F: FnMut(&[f64]) -> f64,
{
    minimize(
        optimizer,
        rng,
        |xs, out| {
            for (x, o) in xs.iter().zip(out.iter_mut()) {
                *o = f(x);
            }
        },
        |_| true,
    )
}
