//! xNES, the exponential natural evolution strategy (Glasmachers, Schaul, Sun, Wierstra and
//! Schmidhuber, "Exponential natural evolution strategies", GECCO 2010): the search distribution
//! N(μ, σ²BBᵀ) with det B = 1 follows the natural gradient of the expected rank-based utility;
//! B is updated multiplicatively through a matrix exponential.

use nalgebra::{DMatrix, DVector};
use rand::Rng;
use serde::{Deserialize, Serialize};

use crate::core::{Optimizer, Population, Start, State};
use crate::error::{Result, invalid, positive};
use crate::linalg::{ExpmScratch, all_finite, expm, fill_normal, phim, rank};

/// xNES settings; `None` = the paper's default.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct XnesOptions {
    /// Population size λ (default 4 + ⌊3 ln d⌋).
    pub population: Option<usize>,
    /// Learning rate of the mean (default 1).
    pub eta_mean: Option<f64>,
    /// Learning rate of the step size (default 3(3 + ln d)/(5 d √d)).
    pub eta_sigma: Option<f64>,
    /// Learning rate of the shape matrix B (default as `eta_sigma`).
    pub eta_b: Option<f64>,
}

/// Rank-based utilities of the NES papers: max(0, ln(λ/2 + 1) − ln k), normalised, minus 1/λ.
pub(crate) fn nes_utilities(lambda: usize) -> Vec<f64> {
    let raw: Vec<f64> = (1..=lambda)
        .map(|k| ((lambda as f64 / 2.0 + 1.0).ln() - (k as f64).ln()).max(0.0))
        .collect();
    let total: f64 = raw.iter().sum();
    raw.iter()
        .map(|r| r / total - 1.0 / lambda as f64)
        .collect()
}

/// Default NES population size 4 + ⌊3 ln d⌋.
pub(crate) fn default_population(d: usize) -> usize {
    4 + (3.0 * (d as f64).ln()).floor() as usize
}

/// The state of an xNES search between generations ([`Xnes::snapshot`], [`Xnes::resume`]),
/// serialisable with serde. Store it in a format that keeps every f64 bit for bit (infinite
/// values included: the bookkeeping starts at +∞), e.g. a binary one; JSON does not.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct XnesSnapshot {
    population: usize,
    learning_rates: [f64; 3],
    mean: Vec<f64>,
    sigma: f64,
    /// B, column-major.
    shape: Vec<f64>,
    state: State,
}

/// The xNES optimiser.
#[derive(Debug, Clone)]
pub struct Xnes {
    state: State,
    lambda: usize,
    eta_mean: f64,
    eta_sigma: f64,
    eta_b: f64,
    utilities: Vec<f64>,
    mean: DVector<f64>,
    sigma: f64,
    b: DMatrix<f64>,
    /// Samples z (d × λ), and their images B z.
    z: DMatrix<f64>,
    bz: DMatrix<f64>,
    uzt: DMatrix<f64>,
    candidates: Population,
    order: Vec<usize>,
    grad_mean: DVector<f64>,
    step: DVector<f64>,
    g: DMatrix<f64>,
    e: DMatrix<f64>,
    t1: DMatrix<f64>,
    expm_scratch: ExpmScratch,
    /// λ < d: B's update through the low-rank identity exp(Z W Zᵀ) = I + Z φ(W ZᵀZ) W Zᵀ on
    /// λ × λ matrices instead of a d × d exponential.
    low_rank: bool,
    /// Low-rank update: W ZᵀZ and φ of it (λ × λ), φ W Zᵀ (λ × d), scratch for φ.
    k: DMatrix<f64>,
    phi: DMatrix<f64>,
    phi_wzt: DMatrix<f64>,
    phi_scratch: ExpmScratch,
    mean_slice: Vec<f64>,
    /// σ times B's largest row norm (the largest standard deviation), kept up to date.
    spread: f64,
}

/// σ times the largest row norm of `b`, the rows summed column by column into `rows` (in the
/// order `b.row(i).norm_squared()` sums them).
fn largest_deviation(b: &DMatrix<f64>, sigma: f64, rows: &mut [f64]) -> f64 {
    rows.fill(0.0);
    for column in b.as_slice().chunks_exact(b.nrows().max(1)) {
        for (r, v) in rows.iter_mut().zip(column) {
            *r += v * v;
        }
    }
    sigma * rows.iter().copied().fold(0.0, f64::max).sqrt()
}

impl Xnes {
    /// A new search. A per-dimension step makes B diagonal with σ their geometric mean.
    pub fn new(start: &Start, options: &XnesOptions) -> Result<Self> {
        let steps = start.check()?;
        let d = steps.len();
        let lambda = options.population.unwrap_or_else(|| default_population(d));
        if lambda < 2 {
            return Err(invalid("population", "xNES needs at least 2 candidates"));
        }
        let default_eta = 3.0 * (3.0 + (d as f64).ln()) / (5.0 * d as f64 * (d as f64).sqrt());
        let eta_mean = options.eta_mean.unwrap_or(1.0);
        let eta_sigma = options.eta_sigma.unwrap_or(default_eta);
        let eta_b = options.eta_b.unwrap_or(default_eta);
        positive(&[
            ("eta_mean", eta_mean),
            ("eta_sigma", eta_sigma),
            ("eta_b", eta_b),
        ])?;
        let sigma = (steps.iter().map(|s| s.ln()).sum::<f64>() / d as f64).exp();
        let b = DMatrix::from_diagonal(&DVector::from_iterator(d, steps.iter().map(|s| s / sigma)));
        Ok(Self::with_distribution(
            State::new(start, lambda),
            [eta_mean, eta_sigma, eta_b],
            DVector::from_column_slice(&start.mean),
            sigma,
            b,
            lambda,
        ))
    }

    /// An xNES search at N(mean, σ²BBᵀ) with the given bookkeeping, learning rates
    /// (mean, σ, B) and population.
    fn with_distribution(
        state: State,
        [eta_mean, eta_sigma, eta_b]: [f64; 3],
        mean: DVector<f64>,
        sigma: f64,
        b: DMatrix<f64>,
        lambda: usize,
    ) -> Self {
        let d = mean.len();
        Xnes {
            state,
            lambda,
            eta_mean,
            eta_sigma,
            eta_b,
            utilities: nes_utilities(lambda),
            mean_slice: mean.as_slice().to_vec(),
            spread: largest_deviation(&b, sigma, &mut vec![0.0; d]),
            mean,
            sigma,
            b,
            z: DMatrix::zeros(d, lambda),
            bz: DMatrix::zeros(d, lambda),
            uzt: DMatrix::zeros(lambda, d),
            candidates: Population::new(d, lambda),
            order: Vec::with_capacity(lambda),
            grad_mean: DVector::zeros(d),
            step: DVector::zeros(d),
            g: DMatrix::zeros(d, d),
            e: DMatrix::zeros(d, d),
            t1: DMatrix::zeros(d, d),
            expm_scratch: ExpmScratch::new(d),
            low_rank: lambda < d,
            k: DMatrix::zeros(lambda, lambda),
            phi: DMatrix::zeros(lambda, lambda),
            phi_wzt: DMatrix::zeros(lambda, d),
            phi_scratch: ExpmScratch::new(lambda),
        }
    }

    /// Everything this search needs to go on exactly where it is (distribution, learning rates,
    /// stopping bookkeeping), for checkpoints: [`Xnes::resume`] continues it, and with the same
    /// random stream the continued search asks and tells exactly what this one would have.
    /// Taken between generations; an `ask` still waiting for its `tell` is an error (its
    /// candidates are not part of the snapshot).
    pub fn snapshot(&self) -> Result<XnesSnapshot> {
        if self.state.pending() {
            return Err(invalid(
                "snapshot",
                "an ask is waiting for its tell; take snapshots between generations",
            ));
        }
        Ok(XnesSnapshot {
            population: self.lambda,
            learning_rates: [self.eta_mean, self.eta_sigma, self.eta_b],
            mean: self.mean.as_slice().to_vec(),
            sigma: self.sigma,
            shape: self.b.as_slice().to_vec(),
            state: self.state.clone(),
        })
    }

    /// Continues a search from its [`Xnes::snapshot`]; a snapshot whose sizes do not fit
    /// together (mean, d × d shape, bookkeeping of another dimension) is an error.
    pub fn resume(snapshot: XnesSnapshot) -> Result<Self> {
        let d = snapshot.mean.len();
        if snapshot.population < 2 {
            return Err(invalid("population", "xNES needs at least 2 candidates"));
        }
        if d == 0 || snapshot.shape.len() != d * d || snapshot.state.dim() != d {
            return Err(invalid(
                "snapshot",
                format!(
                    "a mean of {d} values needs a {d} × {d} shape matrix ({} values given) and bookkeeping of dimension {d} ({})",
                    snapshot.shape.len(),
                    snapshot.state.dim()
                ),
            ));
        }
        snapshot.state.check()?;
        positive(&[
            ("eta_mean", snapshot.learning_rates[0]),
            ("eta_sigma", snapshot.learning_rates[1]),
            ("eta_b", snapshot.learning_rates[2]),
            ("sigma", snapshot.sigma),
        ])?;
        Ok(Self::with_distribution(
            snapshot.state,
            snapshot.learning_rates,
            DVector::from_vec(snapshot.mean),
            snapshot.sigma,
            DMatrix::from_vec(d, d, snapshot.shape),
            snapshot.population,
        ))
    }

    /// Current global step size σ.
    pub fn sigma(&self) -> f64 {
        self.sigma
    }

    /// Population size λ.
    pub fn population(&self) -> usize {
        self.lambda
    }
}

impl Optimizer for Xnes {
    fn name(&self) -> &'static str {
        "xnes"
    }

    fn dim(&self) -> usize {
        self.mean.len()
    }

    fn ask(&mut self, rng: &mut dyn Rng) -> &Population {
        fill_normal(rng, self.z.as_mut_slice());
        self.bz.gemm(1.0, &self.b, &self.z, 0.0);
        let (mean, sigma) = (self.mean.as_slice(), self.sigma);
        let d = mean.len();
        for (x, bz) in self
            .candidates
            .iter_mut()
            .zip(self.bz.as_slice().chunks_exact(d))
        {
            for ((v, m), b) in x.iter_mut().zip(mean).zip(bz) {
                *v = m + sigma * b;
            }
            self.state.clamp(x);
        }
        self.state.asked(self.lambda);
        &self.candidates
    }

    fn tell(&mut self, fitness: &[f64]) -> Result<()> {
        self.state.told(&self.candidates, fitness)?;
        rank(fitness, &mut self.order);
        let d = self.mean.len();
        // Natural gradients: G_δ = Σ u_k z_k, G_M = Σ u_k (z_k z_kᵀ − I) (Σ u_k = 0).
        // U Zᵀ (λ × d), then G_M = Z (U Zᵀ) and G_δ = (U Zᵀ)ᵀ 1
        // and G_σ = tr(G_M)/d = Σ u_k |z_k|² / d
        let (lambda, z, uzt) = (self.lambda, self.z.as_slice(), self.uzt.as_mut_slice());
        let mut g_sigma = 0.0;
        for (&u, &k) in self.utilities.iter().zip(&self.order) {
            let zk = &z[k * d..(k + 1) * d];
            for (i, &v) in zk.iter().enumerate() {
                uzt[i * lambda + k] = u * v;
            }
            g_sigma += u * zk.iter().map(|v| v * v).sum::<f64>();
        }
        g_sigma /= d as f64;
        for (g, column) in self.grad_mean.iter_mut().zip(uzt.chunks_exact(lambda)) {
            *g = column.iter().sum();
        }
        // μ ← μ + η_μ σ B G_δ
        self.step.gemv(1.0, &self.b, &self.grad_mean, 0.0);
        self.mean.axpy(self.eta_mean * self.sigma, &self.step, 1.0);
        self.sigma *= (0.5 * self.eta_sigma * g_sigma).exp();
        // B ← B exp(η_B/2 G_B), G_B = G_M − G_σ I
        let half = 0.5 * self.eta_b;
        if self.low_rank {
            // B exp(η_B/2 G_M) = B + (B Z) φ(K) Ŵ Zᵀ, Ŵ = η_B/2 U, K = Ŵ ZᵀZ; and
            // exp(−η_B/2 G_σ I) is a scalar
            self.k.gemm(half, &self.uzt, &self.z, 0.0);
            phim(&self.k, &mut self.phi, &mut self.phi_scratch);
            self.phi_wzt.gemm(half, &self.phi, &self.uzt, 0.0);
            self.b.gemm(1.0, &self.bz, &self.phi_wzt, 1.0);
            self.b *= (-half * g_sigma).exp();
        } else {
            self.g.gemm(1.0, &self.z, &self.uzt, 0.0);
            for j in 0..d {
                for i in 0..j {
                    let v = 0.5 * (self.g[(i, j)] + self.g[(j, i)]);
                    self.g[(i, j)] = v;
                    self.g[(j, i)] = v;
                }
            }
            for i in 0..d {
                self.g[(i, i)] -= g_sigma;
            }
            self.g *= half;
            expm(&self.g, &mut self.e, &mut self.expm_scratch);
            self.t1.gemm(1.0, &self.b, &self.e, 0.0);
            std::mem::swap(&mut self.b, &mut self.t1);
        }
        if !(self.sigma.is_finite() && self.sigma > 0.0 && all_finite(self.b.as_slice())) {
            self.state.set_degenerate();
        }
        self.mean_slice.copy_from_slice(self.mean.as_slice());
        self.spread = largest_deviation(&self.b, self.sigma, self.step.as_mut_slice());
        Ok(())
    }

    fn mean(&self) -> &[f64] {
        &self.mean_slice
    }

    fn spread(&self) -> f64 {
        self.spread
    }

    fn state(&self) -> &State {
        &self.state
    }

    fn state_mut(&mut self) -> &mut State {
        &mut self.state
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;

    /// The low-rank update of B equals the d × d exponential's.
    #[test]
    fn low_rank_and_full_updates_agree() {
        let d = 23;
        let start = Start::new(vec![0.3; d], 0.5);
        let options = XnesOptions {
            population: Some(9),
            ..Default::default()
        };
        let mut low = Xnes::new(&start, &options).unwrap();
        assert!(low.low_rank);
        let mut full = low.clone();
        full.low_rank = false;
        let (mut r1, mut r2) = (
            rand_chacha::ChaCha8Rng::seed_from_u64(3),
            rand_chacha::ChaCha8Rng::seed_from_u64(3),
        );
        for generation in 0..60 {
            let fitness: Vec<f64> = low
                .ask(&mut r1)
                .iter()
                .map(|x| {
                    x.iter()
                        .enumerate()
                        .map(|(i, v)| (i + 1) as f64 * v * v)
                        .sum()
                })
                .collect();
            full.ask(&mut r2);
            low.tell(&fitness).unwrap();
            full.tell(&fitness).unwrap();
            let scale = full.b.abs().max();
            let diff = (&low.b - &full.b).abs().max();
            assert!(diff <= 1e-12 * scale, "generation {generation}: {diff}");
            assert!((low.sigma - full.sigma).abs() <= 1e-14 * full.sigma);
        }
    }

    /// A search resumed from a snapshot (through serde) asks and tells exactly what the
    /// uninterrupted one does, and damaged snapshots are errors.
    #[test]
    fn a_resumed_search_continues_bit_for_bit() {
        let d = 12;
        let f = |x: &[f64]| {
            x.iter()
                .enumerate()
                .map(|(i, v)| (i + 1) as f64 * v * v)
                .sum::<f64>()
        };
        for population in [6, 20] {
            let start = Start::new(vec![0.5; d], 0.3).with_stop(crate::StopOptions {
                center_stagnation: Some((20, 40)),
                ..Default::default()
            });
            let options = XnesOptions {
                population: Some(population),
                ..Default::default()
            };
            let mut whole = Xnes::new(&start, &options).unwrap();
            let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(9);
            let step = |x: &mut Xnes, rng: &mut rand_chacha::ChaCha8Rng| {
                let fitness: Vec<f64> = x.ask(rng).iter().map(&f).collect();
                x.tell(&fitness).unwrap();
                let m = x.mean().to_vec();
                x.record_center_fitness(&m, f(&m));
            };
            for _ in 0..25 {
                step(&mut whole, &mut rng);
            }
            let mut resumed = Xnes::resume(whole.snapshot().unwrap()).unwrap();
            let mut rng2 = rng.clone();
            for _ in 0..40 {
                step(&mut whole, &mut rng);
                step(&mut resumed, &mut rng2);
                assert_eq!(whole.snapshot().unwrap(), resumed.snapshot().unwrap());
                assert_eq!(whole.stop(), resumed.stop());
            }
            // mid-generation and damaged snapshots
            whole.ask(&mut rng);
            assert!(whole.snapshot().is_err());
            let mut bad = resumed.snapshot().unwrap();
            bad.shape.pop();
            assert!(Xnes::resume(bad).is_err());
            let mut bad = resumed.snapshot().unwrap();
            bad.state = State::new(&Start::new(vec![0.0; d + 1], 1.0), population);
            assert!(Xnes::resume(bad).is_err());
            let mut bad = resumed.snapshot().unwrap();
            bad.state = State::new(&Start::new(vec![0.0; d], 1.0), population); // no stagnation rule
            assert!(Xnes::resume(bad).is_ok());
            let mut bad = resumed.snapshot().unwrap();
            bad.sigma = f64::NAN;
            assert!(Xnes::resume(bad).is_err());
        }
    }
}
