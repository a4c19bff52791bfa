//! What every optimiser shares: the ask/tell trait, start settings, box bounds, stopping rules
//! and the bookkeeping behind `stop()`.

use rand::Rng;
use serde::{Deserialize, Serialize};

use crate::error::{OptimError, Result, invalid};

/// Why an optimiser stopped. `stop()` returns every reason that fired.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[non_exhaustive]
pub enum StopReason {
    /// The evaluation budget is spent.
    MaxEvaluations,
    /// The generation budget is spent.
    MaxGenerations,
    /// The best value reached the target.
    TargetReached,
    /// The best value did not improve for the configured number of evaluations.
    NoImprovement,
    /// The search distribution (or simplex) became smaller than `tol_x` in every direction.
    TolX,
    /// The recent best values and the last population's values span less than `tol_fun`.
    TolFun,
    /// Parallel E-TRM's rule: the mean of the last `recent` fitness values at the distribution
    /// centre exceeds the mean of the last `window`.
    CenterStagnation,
    /// A fitness value was NaN or −∞ (+∞ is allowed: it ranks last).
    InvalidFitness,
    /// The distribution degenerated numerically (e.g. a covariance lost positive definiteness).
    Degenerate,
}

/// Stopping rules; `None` disables a rule.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct StopOptions {
    /// Stop after this many evaluations.
    pub max_evaluations: Option<u64>,
    /// Stop after this many generations (`tell` calls).
    pub max_generations: Option<u64>,
    /// Stop once the best value is ≤ this.
    pub target: Option<f64>,
    /// Stop when the best value has not improved for this many evaluations.
    pub no_improvement_evaluations: Option<u64>,
    /// Stop when every standard deviation of the search distribution is below this.
    pub tol_x: Option<f64>,
    /// Stop when recent best values and the last generation span less than this.
    pub tol_fun: Option<f64>,
    /// Parallel E-TRM's rule `(recent, window)`, usually `(20, 40)`: stagnation when the mean of
    /// the last `recent` centre values exceeds the mean of the last `window`. Needs centre values
    /// ([`Optimizer::record_center_fitness`]; `minimize` evaluates the centre when it is set).
    pub center_stagnation: Option<(usize, usize)>,
}

impl Default for StopOptions {
    fn default() -> Self {
        StopOptions {
            max_evaluations: None,
            max_generations: None,
            target: None,
            no_improvement_evaluations: None,
            tol_x: Some(1e-12),
            tol_fun: Some(1e-12),
            center_stagnation: None,
        }
    }
}

impl StopOptions {
    fn check(&self) -> Result<()> {
        if let Some((recent, window)) = self.center_stagnation {
            if recent == 0 || window <= recent {
                return Err(invalid(
                    "center_stagnation",
                    format!("({recent}, {window}) needs 0 < recent < window"),
                ));
            }
        }
        for (field, v) in [("tol_x", self.tol_x), ("tol_fun", self.tol_fun)] {
            if v.is_some_and(|v| !(v >= 0.0)) {
                return Err(invalid(field, "must be ≥ 0"));
            }
        }
        Ok(())
    }
}

/// Box bounds, e.g. joint limits. Every algorithm samples from its own (unbounded) distribution
/// and clamps candidates into the box before handing them out; the fitness is that of the
/// clamped point. The distributions themselves are not truncated, so a mean can sit on a bound.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Bounds {
    /// Lower bounds.
    pub lower: Vec<f64>,
    /// Upper bounds.
    pub upper: Vec<f64>,
}

impl Bounds {
    /// Checked bounds (`lower ≤ upper`, not NaN; infinite sides allowed).
    pub fn new(lower: Vec<f64>, upper: Vec<f64>) -> Result<Self> {
        if lower.len() != upper.len() {
            return Err(invalid("bounds", "lower and upper differ in length"));
        }
        if let Some(i) = (0..lower.len()).find(|&i| !(lower[i] <= upper[i])) {
            return Err(invalid(
                "bounds",
                format!(
                    "dimension {i}: lower {} is not ≤ upper {}",
                    lower[i], upper[i]
                ),
            ));
        }
        Ok(Bounds { lower, upper })
    }

    /// Clamps `x` into the box.
    #[inline]
    pub fn clamp(&self, x: &mut [f64]) {
        for ((v, l), u) in x.iter_mut().zip(&self.lower).zip(&self.upper) {
            *v = v.clamp(*l, *u);
        }
    }
}

/// Initial step size: one for all coordinates, or one per coordinate.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum StepSize {
    /// The same standard deviation for every coordinate.
    Scalar(f64),
    /// One standard deviation per coordinate.
    PerDimension(Vec<f64>),
}

impl StepSize {
    /// The per-coordinate values for dimension `d`, checked positive and finite.
    pub fn per_dimension(&self, d: usize) -> Result<Vec<f64>> {
        let v = match self {
            StepSize::Scalar(s) => vec![*s; d],
            StepSize::PerDimension(v) => v.clone(),
        };
        if v.len() != d {
            return Err(invalid(
                "step size",
                format!("{} values for dimension {d}", v.len()),
            ));
        }
        if v.iter().any(|s| !(s.is_finite() && *s > 0.0)) {
            return Err(invalid(
                "step size",
                "every value must be positive and finite",
            ));
        }
        Ok(v)
    }
}

impl From<f64> for StepSize {
    fn from(s: f64) -> Self {
        StepSize::Scalar(s)
    }
}

/// Settings every algorithm takes.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Start {
    /// Initial mean (or point).
    pub mean: Vec<f64>,
    /// Initial step size.
    pub step: StepSize,
    /// Optional box.
    #[serde(default)]
    pub bounds: Option<Bounds>,
    /// Stopping rules.
    #[serde(default)]
    pub stop: StopOptions,
}

impl Start {
    /// A start at `mean` with step `step`, no bounds, default stopping rules.
    pub fn new(mean: Vec<f64>, step: impl Into<StepSize>) -> Self {
        Start {
            mean,
            step: step.into(),
            bounds: None,
            stop: StopOptions::default(),
        }
    }

    /// Adds box bounds.
    pub fn with_bounds(mut self, bounds: Bounds) -> Self {
        self.bounds = Some(bounds);
        self
    }

    /// Replaces the stopping rules.
    pub fn with_stop(mut self, stop: StopOptions) -> Self {
        self.stop = stop;
        self
    }

    /// Checks the settings and returns the per-coordinate initial step sizes (what a new
    /// algorithm's constructor calls first).
    pub fn check(&self) -> Result<Vec<f64>> {
        let d = self.mean.len();
        if d == 0 {
            return Err(invalid("mean", "dimension 0"));
        }
        if self.mean.iter().any(|v| !v.is_finite()) {
            return Err(invalid("mean", "not finite"));
        }
        if let Some(b) = &self.bounds {
            if b.lower.len() != d {
                return Err(invalid(
                    "bounds",
                    format!("{} bounds for dimension {d}", b.lower.len()),
                ));
            }
        }
        self.stop.check()?;
        self.step.per_dimension(d)
    }
}

/// Bookkeeping shared by all algorithms: counts, the best point, and the histories the stopping
/// rules read. Allocated once.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct State {
    stop: StopOptions,
    bounds: Option<Bounds>,
    evaluations: u64,
    generations: u64,
    best_x: Vec<f64>,
    best_f: f64,
    best_at: u64,
    invalid: bool,
    degenerate: bool,
    /// Best value of each recent generation (ring buffer) for TolFun.
    history: Vec<f64>,
    history_len: usize,
    last_range: f64,
    /// Recent centre values (ring buffer) for the centre-stagnation rule.
    centre: Vec<f64>,
    centre_len: usize,
    pending: usize,
}

impl State {
    /// Bookkeeping for `start`'s dimension and `lambda` candidates per generation (the
    /// constructor of an [`Optimizer`] implementation creates one).
    pub fn new(start: &Start, lambda: usize) -> Self {
        let d = start.mean.len();
        let history = 10 + (30 * d).div_ceil(lambda.max(1));
        State {
            stop: start.stop.clone(),
            bounds: start.bounds.clone(),
            evaluations: 0,
            generations: 0,
            best_x: start.mean.clone(),
            best_f: f64::INFINITY,
            best_at: 0,
            invalid: false,
            degenerate: false,
            history: vec![f64::INFINITY; history],
            history_len: 0,
            last_range: f64::INFINITY,
            centre: vec![0.0; start.stop.center_stagnation.map_or(0, |c| c.1)],
            centre_len: 0,
            pending: 0,
        }
    }

    /// Clamps a candidate into the bounds, if any.
    #[inline]
    pub fn clamp(&self, x: &mut [f64]) {
        if let Some(b) = &self.bounds {
            b.clamp(x);
        }
    }

    /// Dimension of the search space.
    pub fn dim(&self) -> usize {
        self.best_x.len()
    }

    /// Whether candidates were handed out and not yet told.
    pub fn pending(&self) -> bool {
        self.pending > 0
    }

    /// Checks that bookkeeping read back from a file fits together (buffer sizes, bounds of
    /// this dimension), so a damaged one is an error rather than a panic later.
    pub fn check(&self) -> Result<()> {
        let d = self.dim();
        let window = self.stop.center_stagnation.map_or(0, |c| c.1);
        self.stop.check()?;
        let fits = !self.history.is_empty()
            && self.history_len <= self.history.len()
            && self.centre.len() == window
            && self.bounds.as_ref().is_none_or(|b| {
                b.lower.len() == d && Bounds::new(b.lower.clone(), b.upper.clone()).is_ok()
            });
        if fits {
            Ok(())
        } else {
            Err(crate::error::invalid(
                "state",
                "the bookkeeping's buffers or bounds do not fit its dimension",
            ))
        }
    }

    /// Notes that `n` candidates were handed out (call at the end of `ask`).
    pub fn asked(&mut self, n: usize) {
        self.pending = n;
    }

    /// Records a generation's values for its candidates (call at the start of `tell`); returns
    /// an error on a count mismatch or a `tell` without `ask`.
    pub fn told(&mut self, candidates: &Population, fitness: &[f64]) -> Result<()> {
        if self.pending == 0 {
            return Err(OptimError::NoPendingAsk);
        }
        if fitness.len() != self.pending || candidates.len() < fitness.len() {
            return Err(OptimError::WrongFitnessCount {
                expected: self.pending,
                got: fitness.len(),
            });
        }
        self.pending = 0;
        let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
        for (x, &f) in candidates.iter().zip(fitness) {
            self.evaluations += 1;
            if f.is_nan() || f == f64::NEG_INFINITY {
                self.invalid = true;
                continue;
            }
            lo = lo.min(f);
            hi = hi.max(f);
            if f < self.best_f {
                self.best_f = f;
                self.best_x.copy_from_slice(x);
                self.best_at = self.evaluations;
            }
        }
        self.generations += 1;
        let n = self.history.len();
        self.history[(self.generations as usize - 1) % n] = lo;
        self.history_len = (self.history_len + 1).min(n);
        self.last_range = hi - lo;
        Ok(())
    }

    /// Marks the search distribution as degenerate (a [`StopReason`] from now on).
    pub fn set_degenerate(&mut self) {
        self.degenerate = true;
    }

    /// Records the value `f` of the distribution centre `x` (counts as an evaluation).
    pub fn record_center(&mut self, x: &[f64], f: f64) {
        self.evaluations += 1;
        if f.is_nan() || f == f64::NEG_INFINITY {
            self.invalid = true;
        } else if f < self.best_f {
            self.best_f = f;
            self.best_x.copy_from_slice(x);
            self.best_at = self.evaluations;
        }
        let n = self.centre.len();
        if n > 0 {
            self.centre[self.centre_len % n] = f;
            self.centre_len += 1;
        }
    }

    /// Every stopping reason that holds, given the distribution's largest standard deviation.
    pub fn reasons(&self, spread: f64) -> Vec<StopReason> {
        self.reasons_given(self.stop.tol_x.is_some_and(|t| spread < t))
    }

    /// [`State::reasons`], given whether the spread is below `tol_x`.
    fn reasons_given(&self, below_tol_x: bool) -> Vec<StopReason> {
        let s = &self.stop;
        let mut out = Vec::new();
        if s.max_evaluations.is_some_and(|m| self.evaluations >= m) {
            out.push(StopReason::MaxEvaluations);
        }
        if s.max_generations.is_some_and(|m| self.generations >= m) {
            out.push(StopReason::MaxGenerations);
        }
        if s.target.is_some_and(|t| self.best_f <= t) {
            out.push(StopReason::TargetReached);
        }
        if s.no_improvement_evaluations
            .is_some_and(|n| self.evaluations >= self.best_at + n)
        {
            out.push(StopReason::NoImprovement);
        }
        if below_tol_x {
            out.push(StopReason::TolX);
        }
        if let Some(t) = s.tol_fun {
            // the history's range only when the cheap conditions hold, and only until it is
            // known to reach t (a range never shrinks as values join it; a population of one,
            // whose history is 10 + 30d generations long, had this fold at every evaluation)
            let full = self.history_len == self.history.len();
            if full && self.last_range < t {
                let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
                let mut within = true;
                for &v in &self.history[..self.history_len] {
                    (lo, hi) = (lo.min(v), hi.max(v));
                    if !(hi - lo < t) && lo.is_finite() {
                        within = false;
                        break;
                    }
                }
                if within && hi - lo < t {
                    out.push(StopReason::TolFun);
                }
            }
        }
        if let Some((recent, window)) = s.center_stagnation {
            if self.centre_len >= window {
                let mean_last = |k: usize| {
                    (0..k)
                        .map(|i| self.centre[(self.centre_len - 1 - i) % window])
                        .sum::<f64>()
                        / k as f64
                };
                if mean_last(recent) > mean_last(window) {
                    out.push(StopReason::CenterStagnation);
                }
            }
        }
        if self.invalid {
            out.push(StopReason::InvalidFitness);
        }
        if self.degenerate {
            out.push(StopReason::Degenerate);
        }
        out
    }

    /// Evaluations so far.
    pub fn evaluations(&self) -> u64 {
        self.evaluations
    }

    /// Generations (`tell` calls) so far.
    pub fn generations(&self) -> u64 {
        self.generations
    }

    /// The best point so far (the start mean before any evaluation).
    pub fn best_x(&self) -> &[f64] {
        &self.best_x
    }

    /// The best value so far (+∞ before any evaluation).
    pub fn best_f(&self) -> f64 {
        self.best_f
    }

    /// The evaluation (1-based count) at which the best value was found.
    pub fn best_at(&self) -> u64 {
        self.best_at
    }

    /// The stopping rules in force.
    pub fn stop_options(&self) -> &StopOptions {
        &self.stop
    }
}

/// The candidates of one generation in one contiguous buffer, one after the other: candidate
/// `k` is `as_slice()[k·dim..(k + 1)·dim]` (a `dim × n` column-major matrix, ready for batched
/// evaluation or to be handed to other languages without a copy per candidate). Index it
/// (`population[k]`), iterate it (`for x in &population`) or read the whole buffer.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Population {
    values: Vec<f64>,
    dim: usize,
}

impl Population {
    /// `n` candidates of `dim` zeros.
    pub fn new(dim: usize, n: usize) -> Self {
        Population {
            values: vec![0.0; dim * n],
            dim,
        }
    }

    /// Copies of `candidates` (all of one length).
    ///
    /// # Panics
    /// If the candidates differ in length.
    pub fn from_candidates<Q: AsRef<[f64]>>(candidates: &[Q]) -> Self {
        let mut p = Population::default();
        p.fill_from(candidates);
        p
    }

    /// Number of candidates.
    pub fn len(&self) -> usize {
        self.values.len().checked_div(self.dim).unwrap_or(0)
    }

    /// Whether there is no candidate.
    pub fn is_empty(&self) -> bool {
        self.values.is_empty()
    }

    /// Values per candidate.
    pub fn dim(&self) -> usize {
        self.dim
    }

    /// Every value, candidate after candidate.
    pub fn as_slice(&self) -> &[f64] {
        &self.values
    }

    /// Every value, writable (for optimisers filling their population).
    pub fn as_mut_slice(&mut self) -> &mut [f64] {
        &mut self.values
    }

    /// Candidate `k`, if there is one.
    pub fn get(&self, k: usize) -> Option<&[f64]> {
        (k < self.len()).then(|| &self.values[k * self.dim..(k + 1) * self.dim])
    }

    /// The candidates in order.
    pub fn iter(&self) -> std::slice::ChunksExact<'_, f64> {
        self.values.chunks_exact(self.dim.max(1))
    }

    /// The candidates in order, writable.
    pub fn iter_mut(&mut self) -> std::slice::ChunksExactMut<'_, f64> {
        self.values.chunks_exact_mut(self.dim.max(1))
    }

    /// Makes it `n` candidates of `dim` values (new values are zeros; keeps the allocation
    /// when it shrinks).
    pub fn resize(&mut self, dim: usize, n: usize) {
        self.dim = dim;
        self.values.resize(dim * n, 0.0);
    }

    /// Replaces the candidates with copies of `candidates` (all of one length).
    ///
    /// # Panics
    /// If the candidates differ in length.
    pub fn fill_from<Q: AsRef<[f64]>>(&mut self, candidates: &[Q]) {
        let dim = candidates.first().map_or(self.dim, |q| q.as_ref().len());
        self.resize(dim, candidates.len());
        for (x, q) in self.iter_mut().zip(candidates) {
            x.copy_from_slice(q.as_ref());
        }
    }
}

impl std::ops::Index<usize> for Population {
    type Output = [f64];
    fn index(&self, k: usize) -> &[f64] {
        assert!(k < self.len(), "candidate {k} of {}", self.len());
        &self.values[k * self.dim..(k + 1) * self.dim]
    }
}

impl std::ops::IndexMut<usize> for Population {
    fn index_mut(&mut self, k: usize) -> &mut [f64] {
        assert!(k < self.len(), "candidate {k} of {}", self.len());
        &mut self.values[k * self.dim..(k + 1) * self.dim]
    }
}

impl<'a> IntoIterator for &'a Population {
    type Item = &'a [f64];
    type IntoIter = std::slice::ChunksExact<'a, f64>;
    fn into_iter(self) -> Self::IntoIter {
        self.iter()
    }
}

/// An ask/tell optimiser minimising a function of `dim()` variables.
///
/// Implement it for your own algorithm and every runner of trm accepts it ([`crate::minimize`],
/// NGIK's `trm_tasks::solve_with`, map building): keep a [`State`] (from [`State::new`]), clamp
/// candidates with [`State::clamp`], call [`State::asked`] at the end of `ask` and
/// [`State::told`] at the start of `tell`; the stopping rules then work as for the built-in
/// algorithms. `examples/random_search.rs` is a complete one.
///
/// Each generation: `ask` hands out candidates (reused buffers: no allocation), the caller
/// evaluates them in any order or in parallel, `tell` takes their values in the same order.
/// NaN or −∞ values are recorded as [`StopReason::InvalidFitness`], never a panic.
pub trait Optimizer {
    /// The algorithm's short name.
    fn name(&self) -> &'static str;
    /// Number of variables.
    fn dim(&self) -> usize;
    /// Candidates of the next generation, in one contiguous buffer.
    fn ask(&mut self, rng: &mut dyn Rng) -> &Population;
    /// Values of the candidates of the last `ask`, in order.
    fn tell(&mut self, fitness: &[f64]) -> Result<()>;
    /// The centre of the search distribution (the current point for single-point methods).
    fn mean(&self) -> &[f64];
    /// The largest standard deviation of the search distribution (for TolX).
    fn spread(&self) -> f64;
    /// Whether [`Optimizer::spread`] is below `t` (TolX's question), the same answer: an
    /// algorithm whose spread costs O(d²) stops looking at the first part of it that reaches
    /// `t`.
    fn spread_below(&self, t: f64) -> bool {
        self.spread() < t
    }
    /// Counts, best point and stopping histories.
    fn state(&self) -> &State;
    /// Mutable bookkeeping (for [`Optimizer::record_center_fitness`]).
    fn state_mut(&mut self) -> &mut State;

    /// Every stopping reason that holds now (empty: go on).
    fn stop(&self) -> Vec<StopReason> {
        let tol_x = self.state().stop_options().tol_x;
        self.state()
            .reasons_given(tol_x.is_some_and(|t| self.spread_below(t)))
    }

    /// Records the fitness `f` of the distribution centre `centre` (a copy of [`Optimizer::mean`])
    /// for the centre-stagnation rule; it counts as an evaluation.
    fn record_center_fitness(&mut self, centre: &[f64], f: f64) {
        self.state_mut().record_center(centre, f);
    }
}

#[cfg(test)]
mod tests {
    use super::{Population, Start, State, StopOptions, StopReason};

    /// TolFun, which stops scanning the history once its range reaches tol_fun, says what the
    /// range of the whole history says: flat, drifting, infinite and mixed histories of a
    /// population of one, whose history is long.
    #[test]
    fn tol_fun_reads_the_whole_history_range() {
        let t = 1e-3;
        let start = Start::new(vec![0.0; 2], 1.0).with_stop(StopOptions {
            tol_fun: Some(t),
            ..Default::default()
        });
        let one = Population::new(2, 1);
        let histories: Vec<Vec<f64>> = vec![
            vec![1.0; 80],
            (0..80).map(|k| 1.0 + k as f64 * 1e-6).collect(),
            (0..80).map(|k| 1.0 + k as f64 * 1e-4).collect(),
            vec![f64::INFINITY; 80],
            (0..80)
                .map(|k| if k % 7 == 0 { f64::INFINITY } else { 2.0 })
                .collect(),
            (0..80)
                .map(|k| if k < 79 { f64::INFINITY } else { 2.0 })
                .collect(),
            (0..80)
                .map(|k| if k == 40 { 2.0005 } else { 2.0 })
                .collect(),
        ];
        for (h, values) in histories.iter().enumerate() {
            let mut state = State::new(&start, 1);
            for &v in values {
                state.asked(1);
                state.told(&one, &[v]).unwrap();
            }
            let n = state.history_len;
            let window = &state.history[..n];
            let (lo, hi) = window
                .iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
                    (a.min(v), b.max(v))
                });
            let want = n == state.history.len() && hi - lo < t && state.last_range < t;
            let got = state.reasons(1.0).contains(&StopReason::TolFun);
            assert_eq!(got, want, "history {h}");
        }
    }

    /// A population is its candidates one after the other: indexing, iterating, resizing and
    /// copying agree with the flat buffer, and an empty or zero-dimensional one has none.
    #[test]
    fn a_population_is_its_candidates_one_after_the_other() {
        let mut p = Population::from_candidates(&[vec![1.0, 2.0], vec![3.0, 4.0], vec![5.0, 6.0]]);
        assert_eq!((p.len(), p.dim(), p.is_empty()), (3, 2, false));
        assert_eq!(p.as_slice(), &[1.0, 2.0, 3.0, 4.0, 5.0, 6.0]);
        assert_eq!(&p[1], &[3.0, 4.0]);
        assert_eq!(p.get(2), Some(&[5.0, 6.0][..]));
        assert_eq!(p.get(3), None);
        p[0][1] = -2.0;
        for x in p.iter_mut() {
            x[0] += 10.0;
        }
        let rows: Vec<&[f64]> = (&p).into_iter().collect();
        assert_eq!(rows, [&[11.0, -2.0][..], &[13.0, 4.0], &[15.0, 6.0]]);
        p.resize(2, 1);
        assert_eq!((p.len(), p.as_slice()), (1, &[11.0, -2.0][..]));
        p.resize(2, 2);
        assert_eq!(p.as_slice(), &[11.0, -2.0, 0.0, 0.0]);
        let mut q = Population::default();
        q.clone_from(&p);
        assert_eq!(q, p);
        assert_eq!(Population::default().len(), 0);
        assert_eq!(Population::new(0, 5).len(), 0);
        assert!(Population::new(3, 0).is_empty());
        assert!(std::panic::catch_unwind(|| Population::new(2, 2)[2].len()).is_err());
    }
}
