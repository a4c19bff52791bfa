//! The two-stage optimisation of the paper: (1+1)-CMA-ES on the total constraint violation
//! φ_bs until a trajectory satisfies every constraint, then (1+1)-CMA-ES with constrained
//! covariance adaptation on φ_co from there, never moving to an infeasible trajectory.

use std::cell::RefCell;

use crate::WholeBodyError;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};
use trm_optim::{Start, StopOptions, oneplusone::minimize_constrained};

use crate::Result;
use crate::motion::{Costs, Rollout, WholeBody};

/// One solution of Table II: its parameters, phase ends, rollout and normalised costs.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Comparison {
    /// "hand-tuned", "unconstrained" (the bootstrap's result) or "constrained".
    pub name: String,
    /// Trajectory parameters.
    pub params: Vec<f64>,
    /// Phase end times, seconds.
    pub ends: Vec<f64>,
    /// The cost terms normalised as in the paper's Table II: CoM error and effort by the
    /// hand-tuned trajectory's, backward motion by b_max.
    pub normalised: Costs,
    /// φ_co (weighted mean of the normalised terms; lower is better).
    pub phi_co: f64,
    /// The simulated motion.
    pub rollout: Rollout,
}

/// Everything `cargo xtask stand-up` reports.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct StandUpResult {
    /// The seed.
    pub seed: u64,
    /// Hand-tuned, bootstrap (when the start was infeasible) and constrained solutions.
    pub solutions: Vec<Comparison>,
    /// Rollouts spent by the bootstrap (0 when the start was already feasible).
    pub bootstrap_rollouts: u64,
    /// Rollouts in total.
    pub rollouts: u64,
    /// Best φ_co so far after each constrained rollout: (rollout, φ_co) (the paper's Fig. 4).
    pub trace: Vec<(u64, f64)>,
    /// Whether a feasible trajectory was found.
    pub feasible: bool,
}

impl WholeBody {
    /// φ_co of a rollout (lower is better), normalised by `reference` (the hand-tuned costs):
    /// (w₁ E/E_ref + w₂ U/U_ref + w₃ B/b_max) / (w₁ + w₂ + w₃).
    pub fn phi_co(&self, costs: &Costs, reference: &Costs) -> (f64, Costs) {
        let w = &self.spec().weights;
        let normalised = Costs {
            com_error: costs.com_error / reference.com_error.max(f64::MIN_POSITIVE),
            effort: costs.effort / reference.effort.max(f64::MIN_POSITIVE),
            backward: costs.backward / w.backward_max,
            reach: costs.reach,
        };
        let phi = (w.com_error * normalised.com_error
            + w.effort * normalised.effort
            + w.backward * normalised.backward)
            / (w.com_error + w.effort + w.backward).max(f64::MIN_POSITIVE);
        (phi, normalised)
    }

    fn comparison(
        &self,
        name: &str,
        params: &[f64],
        ends: &[f64],
        reference: &Costs,
    ) -> Result<Comparison> {
        let rollout = self.rollout(params, ends)?;
        let (phi_co, normalised) = self.phi_co(&rollout.costs, reference);
        Ok(Comparison {
            name: name.into(),
            params: params.to_vec(),
            ends: ends.to_vec(),
            normalised,
            phi_co,
            rollout,
        })
    }
}

/// Runs the bootstrap and the constrained search with `seed`; `progress(rollouts, best φ_co)`
/// is called after every constrained rollout (φ_co is NaN until a feasible rollout exists).
pub fn optimize(
    problem: &WholeBody,
    seed: u64,
    mut progress: impl FnMut(u64, f64),
) -> Result<StandUpResult> {
    let spec = problem.spec();
    let hand = problem.hand_tuned()?;
    let reference = hand.costs;
    let ends = problem.ends();
    let n = problem.num_params();
    let x0 = spec.optimiser.start.clone().unwrap_or_else(|| vec![0.0; n]);
    let mut start = Start::new(x0, spec.optimiser.exploration);
    start.stop = StopOptions {
        max_evaluations: Some(spec.optimiser.rollouts),
        ..StopOptions::default()
    };
    let nc = crate::constraint_names(problem).len();
    // one rollout per candidate serves both the constraints and the objective
    let cache: RefCell<Option<(Vec<f64>, Rollout)>> = RefCell::new(None);
    let failure: RefCell<Option<WholeBodyError>> = RefCell::new(None);
    let run = |x: &[f64]| -> Option<Rollout> {
        if let Some((cx, r)) = cache.borrow().as_ref() {
            if cx == x {
                return Some(r.clone());
            }
        }
        match problem.rollout(x, &ends) {
            Ok(r) => {
                *cache.borrow_mut() = Some((x.to_vec(), r.clone()));
                Some(r)
            }
            Err(e) => {
                failure.borrow_mut().get_or_insert(e);
                None
            }
        }
    };
    let rollouts = RefCell::new(0u64);
    let best = RefCell::new(f64::NAN);
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let report = minimize_constrained(
        &start,
        Some(spec.optimiser.bootstrap_rollouts),
        nc,
        &mut rng,
        |x| {
            let phi = run(x).map_or(f64::NAN, |r| problem.phi_co(&r.costs, &reference).0);
            let mut b = best.borrow_mut();
            if b.is_nan() || phi < *b {
                *b = phi;
            }
            phi
        },
        |x, g| {
            *rollouts.borrow_mut() += 1;
            match run(x) {
                Some(r) => g.copy_from_slice(&r.constraints),
                None => g.fill(f64::NAN),
            }
            progress(*rollouts.borrow(), *best.borrow());
        },
    )
    .map_err(|e| WholeBodyError::Invalid {
        what: "optimisation".into(),
        problem: e.to_string(),
    })?;
    if let Some(e) = failure.into_inner() {
        return Err(e);
    }
    let mut solutions = vec![problem.comparison(
        "hand-tuned",
        &spec.hand_tuned.params,
        &spec.hand_tuned.ends,
        &reference,
    )?];
    if report.bootstrap_evaluations > 0 {
        if let Some(s) = &report.feasible_start {
            solutions.push(problem.comparison("unconstrained", s, &ends, &reference)?);
        }
    }
    if report.feasible {
        let best = &report.report.best_x;
        solutions.push(problem.comparison("constrained", best, &ends, &reference)?);
    } else {
        // no feasible trajectory: report the bootstrap's least-violating one
        let best = &report.report.best_x;
        solutions.push(problem.comparison(
            "unconstrained (infeasible)",
            best,
            &ends,
            &reference,
        )?);
    }
    let offset = report.bootstrap_evaluations;
    Ok(StandUpResult {
        seed,
        solutions,
        bootstrap_rollouts: report.bootstrap_evaluations,
        rollouts: report.report.evaluations,
        trace: report
            .report
            .trace
            .iter()
            .filter(|(e, f)| *e > offset && f.is_finite())
            .map(|&(e, f)| (e - offset, f))
            .collect(),
        feasible: report.feasible,
    })
}
