//! Metropolis–Hastings with Gaussian random-walk proposals (the "MH"/"MC" baseline of
//! Stollenga et al., IROS 2013): one chain targeting exp(−f/T); a proposal is accepted with
//! probability min(1, exp(−(f′ − f)/T)).

use rand::{Rng, RngExt};
use serde::{Deserialize, Serialize};

use crate::core::{Optimizer, Population, Start, State};
use crate::error::{Result, positive};
use crate::linalg::fill_normal;

/// Metropolis–Hastings settings.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct MhOptions {
    /// Temperature T of the target exp(−f/T).
    pub temperature: f64,
}

impl Default for MhOptions {
    fn default() -> Self {
        MhOptions { temperature: 1.0 }
    }
}

/// The chain. The first `ask` hands out the start point; later ones one proposal each, with
/// the start's step as the proposal's standard deviation.
#[derive(Debug, Clone)]
pub struct MetropolisHastings {
    state: State,
    temperature: f64,
    steps: Vec<f64>,
    current: Vec<f64>,
    current_f: Option<f64>,
    candidate: Population,
    uniform: f64,
    accepted: u64,
}

impl MetropolisHastings {
    /// A chain at the start mean.
    pub fn new(start: &Start, options: &MhOptions) -> Result<Self> {
        let steps = start.check()?;
        positive(&[("temperature", options.temperature)])?;
        let mut current = start.mean.clone();
        if let Some(b) = &start.bounds {
            b.clamp(&mut current);
        }
        Ok(MetropolisHastings {
            state: State::new(start, 1),
            temperature: options.temperature,
            steps,
            candidate: Population::from_candidates(&[&current]),
            current,
            current_f: None,
            uniform: 0.0,
            accepted: 0,
        })
    }

    /// Accepted proposals so far.
    pub fn accepted(&self) -> u64 {
        self.accepted
    }
}

impl Optimizer for MetropolisHastings {
    fn name(&self) -> &'static str {
        "mh"
    }

    fn dim(&self) -> usize {
        self.current.len()
    }

    fn ask(&mut self, rng: &mut dyn Rng) -> &Population {
        if self.current_f.is_some() {
            let x = &mut self.candidate[0];
            fill_normal(rng, x);
            for i in 0..x.len() {
                x[i] = self.current[i] + self.steps[i] * x[i];
            }
            self.state.clamp(x);
            self.uniform = rng.random::<f64>();
        }
        self.state.asked(1);
        &self.candidate
    }

    fn tell(&mut self, fitness: &[f64]) -> Result<()> {
        self.state.told(&self.candidate, fitness)?;
        let f = fitness[0];
        let accept = match self.current_f {
            None => true,
            Some(cf) => {
                !f.is_nan() && (f <= cf || self.uniform < (-(f - cf) / self.temperature).exp())
            }
        };
        if accept {
            self.current.copy_from_slice(&self.candidate[0]);
            self.current_f = Some(f);
            self.accepted += 1;
        }
        Ok(())
    }

    fn mean(&self) -> &[f64] {
        &self.current
    }

    fn spread(&self) -> f64 {
        self.steps.iter().copied().fold(0.0, f64::max)
    }

    fn state(&self) -> &State {
        &self.state
    }

    fn state_mut(&mut self) -> &mut State {
        &mut self.state
    }
}
