//! NGIK: natural-gradient inverse kinematics — minimise the objective over the active motors with
//! any optimiser of `trm-optim`, evaluating each population in parallel (results do not depend
//! on the thread count: every candidate's value is a pure function of it).

use std::time::{Duration, Instant};

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;
use trm_kinematics::LANES;
use trm_optim::{Bounds, Optimizer, Start, StopOptions, StopReason, by_name, minimize};

use crate::error::Result;
use crate::objective::{Objective, TermValue};
use crate::spec::SolverSpec;

/// A solved posture.
#[derive(Debug, Clone)]
pub struct Solution {
    /// Active motor values.
    pub q: Vec<f64>,
    /// The full motor vector.
    pub motors: Vec<f64>,
    /// Final cost (with noise, if the objective has it).
    pub cost: f64,
    /// Per-term values at `q` (without noise).
    pub breakdown: Vec<TermValue>,
    /// Evaluations in total.
    pub evaluations: u64,
    /// Evaluation at which the best was found.
    pub best_at: u64,
    /// Why the search stopped.
    pub reasons: Vec<StopReason>,
    /// Free of self- and world collisions (the hard constraint of roadmaps).
    pub collision_free: bool,
    /// The task vector at `q` (empty without a task function).
    pub task: Vec<f64>,
    /// Wall time of the search.
    pub wall_time: Duration,
    /// Best-so-far trace `(evaluations, cost)`.
    pub trace: Vec<(u64, f64)>,
}

/// The optimiser's start for `objective` from the active values `start` with the solver
/// settings: mean `start`, step `solver.sigma`, the motor limits as bounds, the spec's budgets
/// (an evaluation budget of 0 is an error).
/// Build your own [`Optimizer`] from it and hand it to [`solve_with`].
pub fn solver_start(objective: &Objective, start: &[f64], solver: &SolverSpec) -> Result<Start> {
    if solver.max_evaluations == 0 {
        return Err(crate::TaskError::Invalid {
            what: "max_evaluations".into(),
            problem: "0: give an evaluation budget of at least 1".into(),
        });
    }
    let (lower, upper) = objective.active().bounds();
    Ok(Start::new(start.to_vec(), solver.sigma)
        .with_bounds(Bounds::new(lower, upper)?)
        .with_stop(StopOptions {
            max_evaluations: Some(solver.max_evaluations),
            no_improvement_evaluations: solver.no_improvement,
            target: solver.target,
            ..Default::default()
        }))
}

/// Minimises `objective` from the active values `start` with the solver settings (the
/// optimiser named by `solver.algo`, seeded with `solver.seed`). Candidates are kept within the
/// motor limits. The start itself is evaluated too (one extra evaluation): the result is never
/// worse than the start.
pub fn solve(objective: &Objective, start: &[f64], solver: &SolverSpec) -> Result<Solution> {
    let settings = solver_start(objective, start, solver)?;
    let mut optimizer = by_name(&solver.algo, &settings, solver.population)?;
    let mut rng = ChaCha8Rng::seed_from_u64(solver.seed);
    solve_with(objective, start, optimizer.as_mut(), &mut rng)
}

/// NGIK with any optimiser — yours included (implement [`Optimizer`]): minimises `objective`
/// from the active values `start`, evaluating each population in parallel, drawing every random
/// number from `rng`. The optimiser must have `objective.dim()` variables (see
/// [`solver_start`]). The start is evaluated too, clamped into the motor limits: the result is
/// never worse than the start.
///
/// ```
/// use rand::SeedableRng;
/// let spec = r#"(model: "planar_arm",
///     costs: [(weight: 1.0, cost: Position(part: "tool", target: Point((0.4, 0.9, 0.1))))])"#;
/// let problem = trm_tasks::Problem::from_ron(spec, "<example>", ".".as_ref())?;
/// let start = trm_tasks::solver_start(&problem.objective, &problem.start, &problem.spec.solver)?;
/// // any Optimizer: here CMA-ES from trm-optim; yours works the same
/// let mut cmaes = trm_optim::Cmaes::new(&start, &Default::default())?;
/// let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(1);
/// let s = trm_tasks::solve_with(&problem.objective, &problem.start, &mut cmaes, &mut rng)?;
/// assert!(s.cost < 1e-6, "{}", s.cost);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn solve_with(
    objective: &Objective,
    start: &[f64],
    optimizer: &mut dyn Optimizer,
    rng: &mut dyn Rng,
) -> Result<Solution> {
    if optimizer.dim() != objective.dim() || start.len() != objective.dim() {
        return Err(crate::TaskError::Invalid {
            what: "solve_with".into(),
            problem: format!(
                "the optimiser has {} variables and the start {} values for an objective of {} active motors",
                optimizer.dim(),
                start.len(),
                objective.dim()
            ),
        });
    }
    let started = Instant::now();
    let pool = crate::ScratchPool::default();
    let report = minimize(
        optimizer,
        rng,
        |xs, out| {
            let d = xs.dim().max(1);
            xs.as_slice()
                .par_chunks(LANES * d)
                .zip(out.par_chunks_mut(LANES))
                .for_each_init(
                    || pool.lease(objective),
                    |scratch, (xs, out)| {
                        if let [one] = out {
                            // one candidate (MH, (1+1)-ES, simplex steps, centres): the
                            // one-configuration path, equal to a batch of one bit for bit
                            *one = objective.eval(xs, scratch);
                            return;
                        }
                        let mut rows = [&[][..]; LANES];
                        for (r, x) in rows.iter_mut().zip(xs.chunks_exact(d)) {
                            *r = x;
                        }
                        objective.eval_batch(&rows[..out.len()], scratch, out);
                    },
                );
        },
        |_| true,
    );
    let mut scratch = objective.scratch();
    let mut report = report;
    let mut clamped = start.to_vec();
    let (lower, upper) = objective.active().bounds();
    for ((x, lo), hi) in clamped.iter_mut().zip(&lower).zip(&upper) {
        *x = x.clamp(*lo, *hi);
    }
    // the same (batched) evaluation as the population's
    let mut start_cost = [0.0];
    objective.eval_batch(&[&clamped], &mut scratch, &mut start_cost);
    let start_cost = start_cost[0];
    report.evaluations += 1;
    if start_cost < report.best_f || report.best_f.is_nan() {
        report.best_f = start_cost;
        report.best_x = clamped;
        report.best_at_evaluation = report.evaluations;
    }
    let wall_time = started.elapsed();
    let (_, breakdown) = objective.breakdown(&report.best_x, &mut scratch);
    Ok(Solution {
        motors: objective.active().to_motors(&report.best_x),
        collision_free: objective.is_collision_free(&report.best_x, &mut scratch),
        task: objective.task_value(&report.best_x, &mut scratch),
        q: report.best_x,
        cost: report.best_f,
        breakdown,
        evaluations: report.evaluations,
        best_at: report.best_at_evaluation,
        reasons: report.reasons,
        wall_time,
        trace: report.trace,
    })
}
