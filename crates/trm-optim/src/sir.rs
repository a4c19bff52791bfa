//! Sequential importance resampling (SIR) and its direct variant SIRD, the particle baselines of
//! Stollenga et al., "Task-relevant roadmaps" (IROS 2013), Section V: weighted particles target
//! the density ∝ exp(−f/T); each generation moves every particle by a Gaussian proposal and
//! multiplies its weight by exp(−(f′ − f)/T); SIR resamples (systematically) when the effective
//! sample size drops below 75 % of the particles, SIRD every generation. The proposal width is
//! fixed: these methods cannot adapt it, which is the paper's point.

use rand::{Rng, RngExt};
use serde::{Deserialize, Serialize};

use crate::core::{Optimizer, Population, Start, State};
use crate::error::{Result, invalid, positive};
use crate::linalg::fill_normal;

/// SIR/SIRD settings.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SirOptions {
    /// Number of particles (the paper used 300).
    pub particles: usize,
    /// Resample when the effective sample size is below this fraction of the particles
    /// (SIR: 0.75; 1.0 or more resamples every generation, which is SIRD).
    pub resample_below: f64,
    /// Temperature T of the target exp(−f/T).
    pub temperature: f64,
}

impl Default for SirOptions {
    fn default() -> Self {
        SirOptions {
            particles: 300,
            resample_below: 0.75,
            temperature: 1.0,
        }
    }
}

impl SirOptions {
    /// SIRD: resample every generation.
    pub fn direct() -> Self {
        SirOptions {
            resample_below: f64::INFINITY,
            ..Default::default()
        }
    }
}

/// The SIR (or SIRD) sampler used as an optimiser. The start's step is the proposal's standard
/// deviation (per coordinate), also used to spread the first particles around the mean.
#[derive(Debug, Clone)]
pub struct Sir {
    state: State,
    options: SirOptions,
    steps: Vec<f64>,
    particles: Vec<Vec<f64>>,
    values: Vec<f64>,
    log_weights: Vec<f64>,
    proposals: Population,
    initialised: bool,
    scratch: Vec<Vec<f64>>,
    scratch_values: Vec<f64>,
    mean: Vec<f64>,
    resamples: u64,
}

impl Sir {
    /// A new particle set around the start mean.
    pub fn new(start: &Start, options: &SirOptions) -> Result<Self> {
        let steps = start.check()?;
        let d = steps.len();
        if options.particles < 2 {
            return Err(invalid("particles", "needs at least 2"));
        }
        positive(&[("temperature", options.temperature)])?;
        if options.resample_below.is_nan() || options.resample_below < 0.0 {
            return Err(invalid("resample_below", "must be ≥ 0"));
        }
        let n = options.particles;
        Ok(Sir {
            state: State::new(start, n),
            options: options.clone(),
            steps,
            particles: vec![start.mean.clone(); n],
            values: vec![f64::INFINITY; n],
            log_weights: vec![0.0; n],
            proposals: Population::new(d, n),
            initialised: false,
            scratch: vec![vec![0.0; d]; n],
            scratch_values: vec![0.0; n],
            mean: start.mean.clone(),
            resamples: 0,
        })
    }

    /// How many times the particles were resampled.
    pub fn resamples(&self) -> u64 {
        self.resamples
    }

    fn normalised_weights(&mut self) -> f64 {
        let max = self
            .log_weights
            .iter()
            .copied()
            .fold(f64::NEG_INFINITY, f64::max);
        let mut total = 0.0;
        for w in &mut self.log_weights {
            *w = if max.is_finite() {
                (*w - max).exp()
            } else {
                1.0
            };
            total += *w;
        }
        let mut sum_sq = 0.0;
        for w in &mut self.log_weights {
            *w /= total;
            sum_sq += *w * *w;
        }
        1.0 / sum_sq
    }

    /// Systematic resampling with one uniform draw.
    fn resample(&mut self, u: f64) {
        let n = self.particles.len();
        let mut cumulative = self.log_weights[0];
        let mut i = 0;
        for k in 0..n {
            let target = (k as f64 + u) / n as f64;
            while cumulative < target && i < n - 1 {
                i += 1;
                cumulative += self.log_weights[i];
            }
            self.scratch[k].copy_from_slice(&self.particles[i]);
            self.scratch_values[k] = self.values[i];
        }
        std::mem::swap(&mut self.particles, &mut self.scratch);
        std::mem::swap(&mut self.values, &mut self.scratch_values);
        self.log_weights.fill(0.0);
        self.resamples += 1;
    }
}

impl Optimizer for Sir {
    fn name(&self) -> &'static str {
        if self.options.resample_below > 1.0 {
            "sird"
        } else {
            "sir"
        }
    }

    fn dim(&self) -> usize {
        self.mean.len()
    }

    fn ask(&mut self, rng: &mut dyn Rng) -> &Population {
        for (x, p) in self.proposals.iter_mut().zip(&self.particles) {
            fill_normal(rng, x);
            for i in 0..x.len() {
                x[i] = p[i] + self.steps[i] * x[i];
            }
            self.state.clamp(x);
        }
        if self.initialised {
            // the uniform for this generation's possible resampling, drawn now so `tell` needs
            // no generator
            self.scratch_values[0] = rng.random::<f64>();
        }
        self.state.asked(self.proposals.len());
        &self.proposals
    }

    fn tell(&mut self, fitness: &[f64]) -> Result<()> {
        self.state.told(&self.proposals, fitness)?;
        let t = self.options.temperature;
        let u = self.scratch_values[0];
        for k in 0..fitness.len() {
            let f = if fitness[k].is_nan() {
                f64::INFINITY
            } else {
                fitness[k]
            };
            self.log_weights[k] = if f == f64::INFINITY {
                f64::NEG_INFINITY
            } else if self.initialised && self.values[k].is_finite() {
                self.log_weights[k] - (f - self.values[k]) / t
            } else {
                -f / t
            };
            self.particles[k].copy_from_slice(&self.proposals[k]);
            self.values[k] = f;
        }
        let first = !self.initialised;
        self.initialised = true;
        let ess = self.normalised_weights();
        // weighted mean
        self.mean.fill(0.0);
        for (p, w) in self.particles.iter().zip(&self.log_weights) {
            for (m, v) in self.mean.iter_mut().zip(p) {
                *m += w * v;
            }
        }
        let n = self.particles.len() as f64;
        if ess < self.options.resample_below * n || (first && self.options.resample_below > 1.0) {
            self.resample(if first { 0.5 } else { u });
        } else {
            for w in &mut self.log_weights {
                *w = w.ln();
            }
        }
        Ok(())
    }

    fn mean(&self) -> &[f64] {
        &self.mean
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
