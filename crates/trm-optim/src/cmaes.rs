//! CMA-ES with Hansen's default settings, negative ("active") weights included, as in Hansen,
//! "The CMA evolution strategy: a tutorial" (arXiv:1604.00772, 2016) and pycma's defaults.

use nalgebra::{DMatrix, DVector};
use rand::Rng;
use serde::{Deserialize, Serialize};

use crate::core::{Optimizer, Population, Start, State};
use crate::error::{Result, invalid};
use crate::linalg::{fill_normal, rank};
use crate::xnes::default_population;

/// CMA-ES settings; `None` = the tutorial's default.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct CmaesOptions {
    /// Population size λ (default 4 + ⌊3 ln d⌋).
    pub population: Option<usize>,
    /// Use negative recombination weights for the covariance update (default true).
    pub active: Option<bool>,
    /// Generations between eigendecompositions of C. Default: the tutorial's lazy rule
    /// (after λ/((c₁ + c_μ) d · 10) evaluations), which at d = 41, λ = 30 means every
    /// generation; larger values trade a slightly stale B, D for speed (O(d³) → O(d²)).
    pub eigen_interval: Option<u64>,
}

/// The CMA-ES optimiser.
#[derive(Debug, Clone)]
pub struct Cmaes {
    state: State,
    lambda: usize,
    mu: usize,
    weights: Vec<f64>,
    mu_eff: f64,
    c_sigma: f64,
    d_sigma: f64,
    c_c: f64,
    c_1: f64,
    c_mu: f64,
    chi_n: f64,
    mean: DVector<f64>,
    sigma: f64,
    c: DMatrix<f64>,
    b: DMatrix<f64>,
    d: DVector<f64>,
    p_sigma: DVector<f64>,
    p_c: DVector<f64>,
    z: DMatrix<f64>,
    y: DMatrix<f64>,
    /// Scratch: D Z (columns) in `ask`, W° Yᵀ (rows) in `tell`.
    wyt: DMatrix<f64>,
    candidates: Population,
    order: Vec<usize>,
    step_y: DVector<f64>,
    step_z: DVector<f64>,
    bz: DVector<f64>,
    eigen_at: u64,
    eigen_interval: Option<u64>,
    mean_slice: Vec<f64>,
}

impl Cmaes {
    /// A new search; a per-dimension step becomes the initial diagonal of C (σ = 1).
    pub fn new(start: &Start, options: &CmaesOptions) -> Result<Self> {
        let steps = start.check()?;
        let n = steps.len();
        let nf = n as f64;
        let lambda = options.population.unwrap_or_else(|| default_population(n));
        if lambda < 2 {
            return Err(invalid("population", "CMA-ES needs at least 2 candidates"));
        }
        let mu = lambda / 2;
        let raw: Vec<f64> = (1..=lambda)
            .map(|i| ((lambda as f64 + 1.0) / 2.0).ln() - (i as f64).ln())
            .collect();
        let pos: f64 = raw[..mu].iter().sum();
        let mu_eff = pos * pos / raw[..mu].iter().map(|w| w * w).sum::<f64>();
        let neg_sum: f64 = raw[mu..].iter().filter(|w| **w < 0.0).map(|w| -w).sum();
        let neg_sq: f64 = raw[mu..].iter().filter(|w| **w < 0.0).map(|w| w * w).sum();
        let mu_eff_neg = if neg_sq > 0.0 {
            neg_sum * neg_sum / neg_sq
        } else {
            0.0
        };
        let alpha_cov = 2.0;
        let c_1 = alpha_cov / ((nf + 1.3).powi(2) + mu_eff);
        let c_mu = (1.0 - c_1).min(
            alpha_cov * (mu_eff - 2.0 + 1.0 / mu_eff)
                / ((nf + 2.0).powi(2) + alpha_cov * mu_eff / 2.0),
        );
        let active = options.active.unwrap_or(true);
        let neg_scale = (1.0 + c_1 / c_mu)
            .min(1.0 + 2.0 * mu_eff_neg / (mu_eff + 2.0))
            .min((1.0 - c_1 - c_mu) / (nf * c_mu));
        let weights: Vec<f64> = raw
            .iter()
            .map(|&w| {
                if w >= 0.0 {
                    w / pos
                } else if active && neg_sum > 0.0 {
                    neg_scale * w / neg_sum
                } else {
                    0.0
                }
            })
            .collect();
        let c_sigma = (mu_eff + 2.0) / (nf + mu_eff + 5.0);
        let d_sigma = 1.0 + 2.0 * (((mu_eff - 1.0) / (nf + 1.0)).sqrt() - 1.0).max(0.0) + c_sigma;
        let c_c = (4.0 + mu_eff / nf) / (nf + 4.0 + 2.0 * mu_eff / nf);
        let chi_n = nf.sqrt() * (1.0 - 1.0 / (4.0 * nf) + 1.0 / (21.0 * nf * nf));
        let d = DVector::from_column_slice(&steps);
        Ok(Cmaes {
            state: State::new(start, lambda),
            lambda,
            mu,
            weights,
            mu_eff,
            c_sigma,
            d_sigma,
            c_c,
            c_1,
            c_mu,
            chi_n,
            mean: DVector::from_column_slice(&start.mean),
            sigma: 1.0,
            c: DMatrix::from_diagonal(&d.map(|s| s * s)),
            b: DMatrix::identity(n, n),
            d,
            p_sigma: DVector::zeros(n),
            p_c: DVector::zeros(n),
            z: DMatrix::zeros(n, lambda),
            y: DMatrix::zeros(n, lambda),
            wyt: DMatrix::zeros(n.max(lambda), n.max(lambda)),
            candidates: Population::new(n, lambda),
            order: Vec::with_capacity(lambda),
            step_y: DVector::zeros(n),
            step_z: DVector::zeros(n),
            bz: DVector::zeros(n),
            eigen_at: 0,
            eigen_interval: options.eigen_interval.map(|g| g.max(1)),
            mean_slice: start.mean.clone(),
        })
    }

    /// Current global step size σ.
    pub fn sigma(&self) -> f64 {
        self.sigma
    }

    /// Population size λ.
    pub fn population(&self) -> usize {
        self.lambda
    }

    /// Recomputes B and D from C (symmetrised), as the tutorial's lazy update does.
    fn decompose(&mut self) {
        let n = self.c.nrows();
        for i in 0..n {
            for j in 0..i {
                let v = 0.5 * (self.c[(i, j)] + self.c[(j, i)]);
                self.c[(i, j)] = v;
                self.c[(j, i)] = v;
            }
        }
        let eig = nalgebra::SymmetricEigen::new(self.c.clone());
        let (lo, hi) = eig
            .eigenvalues
            .iter()
            .fold((f64::INFINITY, 0.0f64), |(a, b), &v| (a.min(v), b.max(v)));
        if !(lo > 0.0) || !hi.is_finite() || hi / lo > 1e14 {
            self.state.set_degenerate();
        }
        self.b.copy_from(&eig.eigenvectors);
        for i in 0..n {
            self.d[i] = eig.eigenvalues[i].max(f64::MIN_POSITIVE).sqrt();
        }
        self.eigen_at = self.state.evaluations();
    }
}

impl Optimizer for Cmaes {
    fn name(&self) -> &'static str {
        "cmaes"
    }

    fn dim(&self) -> usize {
        self.mean.len()
    }

    fn ask(&mut self, rng: &mut dyn Rng) -> &Population {
        let n = self.mean.len();
        let gap = match self.eigen_interval {
            Some(g) => (g * self.lambda as u64) as f64 - 0.5,
            None => self.lambda as f64 / (self.c_1 + self.c_mu) / n as f64 / 10.0,
        };
        if (self.state.evaluations() - self.eigen_at) as f64 > gap {
            self.decompose();
        }
        fill_normal(rng, self.z.as_mut_slice());
        // Y = B (D Z)
        for k in 0..self.lambda {
            for i in 0..n {
                self.wyt[(i, k)] = self.d[i] * self.z[(i, k)];
            }
        }
        self.y
            .gemm(1.0, &self.b, &self.wyt.view((0, 0), (n, self.lambda)), 0.0);
        for k in 0..self.lambda {
            let x = &mut self.candidates[k];
            for i in 0..n {
                x[i] = self.mean[i] + self.sigma * self.y[(i, k)];
            }
            self.state.clamp(x);
        }
        self.state.asked(self.lambda);
        &self.candidates
    }

    fn tell(&mut self, fitness: &[f64]) -> Result<()> {
        self.state.told(&self.candidates, fitness)?;
        rank(fitness, &mut self.order);
        let n = self.mean.len();
        let nf = n as f64;
        // ⟨y⟩_w and Σ w z over the μ best
        self.step_y.fill(0.0);
        self.step_z.fill(0.0);
        for (r, &k) in self.order[..self.mu].iter().enumerate() {
            self.step_y.axpy(self.weights[r], &self.y.column(k), 1.0);
            self.step_z.axpy(self.weights[r], &self.z.column(k), 1.0);
        }
        self.mean.axpy(self.sigma, &self.step_y, 1.0);
        // p_σ ← (1 − c_σ) p_σ + √(c_σ(2 − c_σ) μ_eff) B Σ w z   (= C^{-1/2} ⟨y⟩_w)
        self.bz.gemv(1.0, &self.b, &self.step_z, 0.0);
        let cs = self.c_sigma;
        self.p_sigma
            .axpy((cs * (2.0 - cs) * self.mu_eff).sqrt(), &self.bz, 1.0 - cs);
        let ps_norm = self.p_sigma.norm();
        let g = self.state.generations() as i32;
        let h_sigma =
            ps_norm / (1.0 - (1.0 - cs).powi(2 * g)).sqrt() < (1.4 + 2.0 / (nf + 1.0)) * self.chi_n;
        let cc = self.c_c;
        let h = if h_sigma { 1.0 } else { 0.0 };
        self.p_c.axpy(
            h * (cc * (2.0 - cc) * self.mu_eff).sqrt(),
            &self.step_y,
            1.0 - cc,
        );
        let delta = (1.0 - h) * cc * (2.0 - cc);
        let weight_sum: f64 = self.weights.iter().sum();
        let decay = 1.0 + self.c_1 * delta - self.c_1 - self.c_mu * weight_sum;
        self.c *= decay;
        self.c.ger(self.c_1, &self.p_c, &self.p_c, 1.0);
        // rank-μ update C += c_μ Y W° Yᵀ, as one product Y (W° Yᵀ)
        for (r, &k) in self.order.iter().enumerate() {
            let w = self.weights[r];
            // for negative weights, w° = w n / ‖C^{-1/2} y‖² and C^{-1/2} y = B z
            let w = if w >= 0.0 {
                w
            } else {
                w * nf / self.z.column(k).norm_squared().max(1e-300)
            };
            for i in 0..n {
                self.wyt[(k, i)] = w * self.y[(i, k)];
            }
        }
        self.c.gemm(
            self.c_mu,
            &self.y,
            &self.wyt.view((0, 0), (self.lambda, n)),
            1.0,
        );
        self.sigma *= ((cs / self.d_sigma) * (ps_norm / self.chi_n - 1.0)).exp();
        if !(self.sigma.is_finite() && self.sigma > 0.0) {
            self.state.set_degenerate();
        }
        self.mean_slice.copy_from_slice(self.mean.as_slice());
        Ok(())
    }

    fn mean(&self) -> &[f64] {
        &self.mean_slice
    }

    fn spread(&self) -> f64 {
        let n = self.mean.len();
        let max_var = (0..n).map(|i| self.c[(i, i)]).fold(0.0, f64::max);
        self.sigma * max_var.sqrt()
    }

    fn state(&self) -> &State {
        &self.state
    }

    fn state_mut(&mut self) -> &mut State {
        &mut self.state
    }
}
