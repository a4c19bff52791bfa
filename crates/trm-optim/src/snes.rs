//! SNES, separable natural evolution strategy (Schaul, Glasmachers and Schmidhuber, "High
//! dimensions and heavy tails for natural evolution strategies", GECCO 2011): a diagonal
//! Gaussian, O(d) per candidate, for large d.

use rand::Rng;
use serde::{Deserialize, Serialize};

use crate::core::{Optimizer, Population, Start, State};
use crate::error::{Result, invalid, positive};
use crate::linalg::{fill_normal, rank};
use crate::xnes::{default_population, nes_utilities};

/// SNES settings; `None` = the paper's default.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SnesOptions {
    /// Population size λ (default 4 + ⌊3 ln d⌋).
    pub population: Option<usize>,
    /// Learning rate of the mean (default 1).
    pub eta_mean: Option<f64>,
    /// Learning rate of the standard deviations (default (3 + ln d)/(5 √d)).
    pub eta_sigma: Option<f64>,
}

/// The SNES optimiser.
#[derive(Debug, Clone)]
pub struct Snes {
    state: State,
    lambda: usize,
    eta_mean: f64,
    eta_sigma: f64,
    utilities: Vec<f64>,
    mean: Vec<f64>,
    sigma: Vec<f64>,
    z: Vec<Vec<f64>>,
    candidates: Population,
    order: Vec<usize>,
    grad_mean: Vec<f64>,
    grad_sigma: Vec<f64>,
}

impl Snes {
    /// A new search with per-coordinate standard deviations from the start's step.
    pub fn new(start: &Start, options: &SnesOptions) -> Result<Self> {
        let sigma = start.check()?;
        let d = sigma.len();
        let lambda = options.population.unwrap_or_else(|| default_population(d));
        if lambda < 2 {
            return Err(invalid("population", "SNES needs at least 2 candidates"));
        }
        let eta_mean = options.eta_mean.unwrap_or(1.0);
        let eta_sigma = options
            .eta_sigma
            .unwrap_or((3.0 + (d as f64).ln()) / (5.0 * (d as f64).sqrt()));
        positive(&[("eta_mean", eta_mean), ("eta_sigma", eta_sigma)])?;
        Ok(Snes {
            state: State::new(start, lambda),
            lambda,
            eta_mean,
            eta_sigma,
            utilities: nes_utilities(lambda),
            mean: start.mean.clone(),
            sigma,
            z: vec![vec![0.0; d]; lambda],
            candidates: Population::new(d, lambda),
            order: Vec::with_capacity(lambda),
            grad_mean: vec![0.0; d],
            grad_sigma: vec![0.0; d],
        })
    }
}

impl Optimizer for Snes {
    fn name(&self) -> &'static str {
        "snes"
    }

    fn dim(&self) -> usize {
        self.mean.len()
    }

    fn ask(&mut self, rng: &mut dyn Rng) -> &Population {
        for (z, x) in self.z.iter_mut().zip(self.candidates.iter_mut()) {
            fill_normal(rng, z);
            for i in 0..x.len() {
                x[i] = self.mean[i] + self.sigma[i] * z[i];
            }
            self.state.clamp(x);
        }
        self.state.asked(self.lambda);
        &self.candidates
    }

    fn tell(&mut self, fitness: &[f64]) -> Result<()> {
        self.state.told(&self.candidates, fitness)?;
        rank(fitness, &mut self.order);
        self.grad_mean.fill(0.0);
        self.grad_sigma.fill(0.0);
        for (r, &k) in self.order.iter().enumerate() {
            let u = self.utilities[r];
            for (i, z) in self.z[k].iter().enumerate() {
                self.grad_mean[i] += u * z;
                self.grad_sigma[i] += u * (z * z - 1.0);
            }
        }
        for i in 0..self.mean.len() {
            self.mean[i] += self.eta_mean * self.sigma[i] * self.grad_mean[i];
            self.sigma[i] *= (0.5 * self.eta_sigma * self.grad_sigma[i]).exp();
        }
        if self.sigma.iter().any(|s| !(s.is_finite() && *s > 0.0)) {
            self.state.set_degenerate();
        }
        Ok(())
    }

    fn mean(&self) -> &[f64] {
        &self.mean
    }

    fn spread(&self) -> f64 {
        self.sigma.iter().copied().fold(0.0, f64::max)
    }

    fn state(&self) -> &State {
        &self.state
    }

    fn state_mut(&mut self) -> &mut State {
        &mut self.state
    }
}
