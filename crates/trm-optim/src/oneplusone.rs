//! (1+1)-CMA-ES with the Cholesky-factor update of Igel, Suttorp and Hansen ("A computational
//! efficient covariance matrix update and a (1+1)-CMA for evolution strategies", GECCO 2006), and
//! its constrained variant with covariance constraint adaptation of Arnold and Hansen ("A (1+1)-CMA-ES
//! for constrained optimisation", GECCO 2012): a violated constraint shrinks the covariance
//! across the constraint boundary and never moves the parent, so the parent stays feasible.

use nalgebra::{DMatrix, DVector};
use rand::Rng;
use serde::{Deserialize, Serialize};

use crate::core::{Optimizer, Population, Start, State};
use crate::error::{Result, invalid};
use crate::linalg::{all_finite, fill_normal};

/// (1+1)-CMA-ES settings; `None` = the papers' defaults.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct OnePlusOneOptions {
    /// Target success probability (default 2/11).
    pub target_success: Option<f64>,
    /// Number of constraints for [`OnePlusOne::tell_constrained`] (default 0).
    pub constraints: usize,
    /// The active covariance update of Arnold and Hansen (GECCO 2010, part of their
    /// constrained algorithm of 2012): an offspring worse than the fifth-order ancestor of its
    /// parent shrinks the covariance along its step, with c⁻ = 0.4/(n^1.6 + 1) (default on).
    pub active: Option<bool>,
}

/// The (1+1)-CMA-ES. The first `ask` hands out the start point itself (the parent must have a
/// value); every later `ask` one offspring.
#[derive(Debug, Clone)]
pub struct OnePlusOne {
    state: State,
    damping: f64,
    target: f64,
    c_p: f64,
    c_c: f64,
    c_cov: f64,
    /// c⁻ of the active update, 0 when it is off.
    c_minus: f64,
    /// The values of the last five parents (the current one last): the first is the fifth-
    /// order ancestor of the next offspring.
    ancestors: std::collections::VecDeque<f64>,
    threshold: f64,
    cc_constraint: f64,
    beta: f64,
    parent: DVector<f64>,
    parent_f: Option<f64>,
    sigma: f64,
    a: DMatrix<f64>,
    a_inv: DMatrix<f64>,
    path: DVector<f64>,
    success: f64,
    z: DVector<f64>,
    az: DVector<f64>,
    candidate: Population,
    traces: Vec<DVector<f64>>,
    w: Vec<DVector<f64>>,
    t1: DVector<f64>,
    t2: DVector<f64>,
    mean_slice: Vec<f64>,
}

impl OnePlusOne {
    /// A new search from the start point (the parent) with covariance diag(step²).
    pub fn new(start: &Start, options: &OnePlusOneOptions) -> Result<Self> {
        let steps = start.check()?;
        let n = steps.len();
        let nf = n as f64;
        let target = options.target_success.unwrap_or(2.0 / 11.0);
        if !(target > 0.0 && target < 1.0) {
            return Err(invalid("target_success", "must lie in (0, 1)"));
        }
        let a = DMatrix::from_diagonal(&DVector::from_column_slice(&steps));
        let a_inv =
            DMatrix::from_diagonal(&DVector::from_iterator(n, steps.iter().map(|s| 1.0 / s)));
        Ok(OnePlusOne {
            state: State::new(start, 1),
            damping: 1.0 + nf / 2.0,
            target,
            c_p: 1.0 / 12.0,
            c_c: 2.0 / (nf + 2.0),
            c_cov: 2.0 / (nf * nf + 6.0),
            c_minus: if options.active.unwrap_or(true) {
                0.4 / (nf.powf(1.6) + 1.0)
            } else {
                0.0
            },
            ancestors: std::collections::VecDeque::with_capacity(5),
            threshold: 0.44,
            cc_constraint: 1.0 / (nf + 2.0),
            beta: 0.1 / (nf + 2.0),
            parent: DVector::from_column_slice(&start.mean),
            parent_f: None,
            sigma: 1.0,
            a,
            a_inv,
            path: DVector::zeros(n),
            success: target,
            z: DVector::zeros(n),
            az: DVector::zeros(n),
            candidate: Population::from_candidates(&[&start.mean]),
            traces: vec![DVector::zeros(n); options.constraints],
            w: vec![DVector::zeros(n); options.constraints],
            t1: DVector::zeros(n),
            t2: DVector::zeros(n),
            mean_slice: start.mean.clone(),
        })
    }

    /// Current global step size σ.
    pub fn sigma(&self) -> f64 {
        self.sigma
    }

    /// The parent's value (`None` before the first `tell`).
    pub fn parent_fitness(&self) -> Option<f64> {
        self.parent_f
    }

    /// Rank-one update of C = AAᵀ to α C + β v vᵀ with v = `self.path`, keeping A⁻¹ in step.
    fn rank_one(&mut self, alpha: f64, beta: f64) {
        let v = std::mem::take(&mut self.path);
        self.rank_one_along(&v, alpha, beta);
        self.path = v;
    }

    /// Rank-one update of C = AAᵀ to α C + β v vᵀ, keeping A⁻¹ in step (β may be negative
    /// as long as α + β ‖A⁻¹v‖² > 0).
    fn rank_one_along(&mut self, v: &DVector<f64>, alpha: f64, beta: f64) {
        // w = A⁻¹ v
        self.t1.gemv(1.0, &self.a_inv, v, 0.0);
        let w2 = self.t1.norm_squared();
        if w2 <= 0.0 || !w2.is_finite() {
            return;
        }
        let sa = alpha.sqrt();
        let root = (1.0 + beta / alpha * w2).sqrt();
        // A ← √α A + √α/‖w‖² (root − 1) v wᵀ
        self.a *= sa;
        self.a.ger(sa / w2 * (root - 1.0), v, &self.t1, 1.0);
        // A⁻¹ ← A⁻¹/√α − 1/(√α ‖w‖²) (1 − 1/root) w (wᵀ A⁻¹)
        self.t2.gemv_tr(1.0, &self.a_inv, &self.t1, 0.0);
        self.a_inv *= 1.0 / sa;
        self.a_inv
            .ger(-(1.0 - 1.0 / root) / (sa * w2), &self.t1, &self.t2, 1.0);
    }

    /// The active update for an offspring worse than the parent's fifth-order ancestor:
    /// C ← (1 + c⁻) C − c⁻ (Az)(Az)ᵀ, with c⁻ reduced to 1/(2‖z‖² − 1) where it would
    /// exceed it (so that C stays positive definite).
    fn shrink_along_last_step(&mut self) {
        let z2 = self.z.norm_squared();
        let mut c = self.c_minus;
        if c * (2.0 * z2 - 1.0) > 1.0 {
            c = 1.0 / (2.0 * z2 - 1.0);
        }
        let v = std::mem::take(&mut self.az);
        self.rank_one_along(&v, 1.0 + c, -c);
        self.az = v;
    }

    /// Records a new parent's value.
    fn remember(&mut self, f: f64) {
        if self.ancestors.len() == 5 {
            self.ancestors.pop_front();
        }
        self.ancestors.push_back(f);
    }

    fn update_step(&mut self, succeeded: bool) {
        let s = if succeeded { 1.0 } else { 0.0 };
        self.success = (1.0 - self.c_p) * self.success + self.c_p * s;
        self.sigma *= ((self.success - self.target) / (self.damping * (1.0 - self.target))).exp();
    }

    fn accept(&mut self, f: f64) {
        self.parent.copy_from_slice(&self.candidate[0]);
        self.parent_f = Some(f);
        self.remember(f);
        let cc = self.c_c;
        if self.success < self.threshold {
            self.path.axpy((cc * (2.0 - cc)).sqrt(), &self.az, 1.0 - cc);
            self.rank_one(1.0 - self.c_cov, self.c_cov);
        } else {
            self.path *= 1.0 - cc;
            self.rank_one(1.0 - self.c_cov + self.c_cov * cc * (2.0 - cc), self.c_cov);
        }
        self.mean_slice.copy_from_slice(self.parent.as_slice());
    }

    /// Tells the value and the constraint values (feasible where ≤ 0) of the last candidate.
    /// An infeasible candidate never replaces the parent: it shrinks the covariance across the
    /// violated constraints instead, and its value is ignored (pass anything, e.g. NaN).
    /// The parent (first candidate) must be feasible.
    pub fn tell_constrained(&mut self, fitness: f64, constraints: &[f64]) -> Result<()> {
        if constraints.len() != self.traces.len() {
            return Err(invalid(
                "constraints",
                format!(
                    "{} values for {} constraints",
                    constraints.len(),
                    self.traces.len()
                ),
            ));
        }
        let violated = constraints.iter().filter(|g| !(**g <= 0.0)).count();
        if violated == 0 {
            return self.tell(&[fitness]);
        }
        if self.parent_f.is_none() {
            return Err(invalid(
                "start",
                "the start point violates a constraint; find a feasible one first \
                 (minimize_constrained bootstraps one)",
            ));
        }
        // An infeasible offspring counts as an evaluation that improved nothing.
        self.state.told(&self.candidate, &[f64::INFINITY])?;
        let cc = self.cc_constraint;
        for (j, g) in constraints.iter().enumerate() {
            if !(*g <= 0.0) {
                self.traces[j].axpy(cc, &self.az, 1.0 - cc);
                self.w[j].gemv(1.0, &self.a_inv, &self.traces[j], 0.0);
            }
        }
        let scale = self.beta / violated as f64;
        for (j, g) in constraints.iter().enumerate() {
            if *g <= 0.0 {
                continue;
            }
            let ww = self.w[j].norm_squared();
            if !(ww > 0.0) {
                continue;
            }
            // A ← A + u qᵀ with u = −β/k v_j, q = w_j/‖w_j‖²; A⁻¹ by Sherman–Morrison.
            let u_scale = -scale;
            self.a.ger(u_scale / ww, &self.traces[j], &self.w[j], 1.0);
            self.t1.gemv(u_scale, &self.a_inv, &self.traces[j], 0.0); // A⁻¹u
            self.t2.gemv_tr(1.0 / ww, &self.a_inv, &self.w[j], 0.0); // (qᵀA⁻¹)ᵀ
            let denom = 1.0 + self.w[j].dot(&self.t1) / ww;
            if denom.abs() < 1e-300 {
                self.state.set_degenerate();
                continue;
            }
            self.a_inv.ger(-1.0 / denom, &self.t1, &self.t2, 1.0);
        }
        Ok(())
    }
}

impl Optimizer for OnePlusOne {
    fn name(&self) -> &'static str {
        "oneplusone"
    }

    fn dim(&self) -> usize {
        self.parent.len()
    }

    fn ask(&mut self, rng: &mut dyn Rng) -> &Population {
        if self.parent_f.is_some() {
            fill_normal(rng, self.z.as_mut_slice());
            self.az.gemv(1.0, &self.a, &self.z, 0.0);
            let x = &mut self.candidate[0];
            for i in 0..x.len() {
                x[i] = self.parent[i] + self.sigma * self.az[i];
            }
            self.state.clamp(x);
        }
        self.state.asked(1);
        &self.candidate
    }

    fn tell(&mut self, fitness: &[f64]) -> Result<()> {
        self.state.told(&self.candidate, fitness)?;
        let f = fitness[0];
        match self.parent_f {
            None => {
                self.state.clamp(&mut self.candidate[0]);
                self.parent.copy_from_slice(&self.candidate[0]);
                self.parent_f = Some(f);
                self.remember(f);
            }
            Some(pf) => {
                let succeeded = f <= pf;
                self.update_step(succeeded);
                if succeeded {
                    self.accept(f);
                } else if self.c_minus > 0.0
                    && self.ancestors.len() == 5
                    && self.ancestors.front().is_some_and(|&a| f > a)
                {
                    self.shrink_along_last_step();
                }
            }
        }
        if !(self.sigma.is_finite() && self.sigma > 0.0 && all_finite(self.a.as_slice())) {
            self.state.set_degenerate();
        }
        Ok(())
    }

    fn mean(&self) -> &[f64] {
        &self.mean_slice
    }

    fn spread(&self) -> f64 {
        let max_row = (0..self.parent.len())
            .map(|i| self.a.row(i).norm_squared())
            .fold(0.0, f64::max);
        self.sigma * max_row.sqrt()
    }

    fn spread_below(&self, t: f64) -> bool {
        // σ √m grows with m, so the largest row decides: stop at the first that reaches t
        let mut max_row = 0.0f64;
        for i in 0..self.parent.len() {
            let row = self.a.row(i).norm_squared();
            if self.sigma * row.sqrt() >= t {
                return false;
            }
            max_row = max_row.max(row);
        }
        self.sigma * max_row.sqrt() < t
    }

    fn state(&self) -> &State {
        &self.state
    }

    fn state_mut(&mut self) -> &mut State {
        &mut self.state
    }
}

/// A run of [`minimize_constrained`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ConstrainedReport {
    /// The constrained phase (or the bootstrap's, when no feasible point was found).
    pub report: crate::runner::Report,
    /// Evaluations the bootstrap spent finding a feasible start (0 when the start was feasible).
    pub bootstrap_evaluations: u64,
    /// Whether the best point satisfies every constraint.
    pub feasible: bool,
    /// The feasible point the constrained search started from (the bootstrap's result, or the
    /// start itself when it was feasible); `None` when the bootstrap found none.
    pub feasible_start: Option<Vec<f64>>,
}

/// Minimises `objective` subject to `constraints(x, g)` (feasible where every `g_j ≤ 0`) with the
/// (1+1)-CMA-ES with constrained covariance adaptation, bootstrapped as in Modugno et al.'s safe
/// trajectory optimisation: when the start violates a constraint, an unconstrained
/// (1+1)-CMA-ES first minimises the total violation Σ max(0, g_j) until a feasible point appears;
/// the constrained search then starts there with the initial step size. The objective is only
/// evaluated at feasible points. With `bootstrap_budget: None`, `start.stop` budgets the whole
/// run; with `Some(n)` the bootstrap gets at most n evaluations and the constrained search
/// `start.stop` on its own (the paper's 500 + 500 rollouts).
pub fn minimize_constrained<F, G>(
    start: &Start,
    bootstrap_budget: Option<u64>,
    constraints: usize,
    rng: &mut dyn Rng,
    mut objective: F,
    mut constraint_values: G,
) -> Result<ConstrainedReport>
where
    F: FnMut(&[f64]) -> f64,
    G: FnMut(&[f64], &mut [f64]),
{
    let mut g = vec![0.0; constraints];
    let violation = |g: &[f64]| {
        g.iter()
            .map(|v| {
                if v.is_nan() {
                    f64::INFINITY
                } else {
                    v.max(0.0)
                }
            })
            .sum::<f64>()
    };
    let mut x0 = start.mean.clone();
    if let Some(b) = &start.bounds {
        b.clamp(&mut x0);
    }
    constraint_values(&x0, &mut g);
    let mut bootstrap_evaluations = 0;
    let mut current = start.clone();
    current.mean = x0;
    if violation(&g) > 0.0 {
        let mut boot_start = current.clone();
        if bootstrap_budget.is_some() {
            boot_start.stop.max_evaluations = bootstrap_budget;
        }
        let mut boot = OnePlusOne::new(&boot_start, &OnePlusOneOptions::default())?;
        let found: std::cell::RefCell<Option<Vec<f64>>> = Default::default();
        let report = crate::runner::minimize(
            &mut boot,
            rng,
            |xs, out| {
                for (x, o) in xs.iter().zip(out.iter_mut()) {
                    constraint_values(x, &mut g);
                    *o = violation(&g);
                    if *o == 0.0 && found.borrow().is_none() {
                        *found.borrow_mut() = Some(x.to_vec());
                    }
                }
            },
            |_| found.borrow().is_none(),
        );
        bootstrap_evaluations = report.evaluations;
        match found.into_inner() {
            Some(x) => current.mean = x,
            None => {
                return Ok(ConstrainedReport {
                    report,
                    bootstrap_evaluations,
                    feasible: false,
                    feasible_start: None,
                });
            }
        }
        if bootstrap_budget.is_none() {
            if let Some(m) = current.stop.max_evaluations.as_mut() {
                *m = m.saturating_sub(bootstrap_evaluations);
            }
        }
    }
    let feasible_start = current.mean.clone();
    let mut search = OnePlusOne::new(
        &current,
        &OnePlusOneOptions {
            constraints,
            ..Default::default()
        },
    )?;
    let mut x = current.mean.clone();
    let mut trace = Vec::new();
    while search.stop().is_empty() {
        x.copy_from_slice(&search.ask(rng)[0]);
        constraint_values(&x, &mut g);
        let feasible = violation(&g) == 0.0;
        let f = if feasible { objective(&x) } else { f64::NAN };
        search.tell_constrained(f, &g)?;
        let s = search.state();
        trace.push((s.evaluations() + bootstrap_evaluations, s.best_f()));
    }
    let s = search.state();
    let report = crate::runner::Report {
        algorithm: "oneplusone-cca".into(),
        best_x: s.best_x().to_vec(),
        best_f: s.best_f(),
        best_at_evaluation: s.best_at() + bootstrap_evaluations,
        evaluations: s.evaluations() + bootstrap_evaluations,
        generations: s.generations(),
        reasons: search.stop(),
        trace,
    };
    Ok(ConstrainedReport {
        report,
        bootstrap_evaluations,
        feasible: true,
        feasible_start: Some(feasible_start),
    })
}
