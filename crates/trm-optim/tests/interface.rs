//! The ask/tell contract: determinism, invalid values, bounds, budgets, stopping rules and the
//! constrained search with its bootstrap.

use proptest::prelude::*;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use trm_optim::functions::TestFunction;
use trm_optim::*;

const ALGOS: [&str; 8] = [
    "xnes",
    "snes",
    "cmaes",
    "oneplusone",
    "simplex",
    "sir",
    "sird",
    "mh",
];

fn optimiser(algo: &str, start: &Start) -> Box<dyn Optimizer + Send> {
    // small particle sets keep the tests fast
    let particles = algo.starts_with("sir").then_some(20);
    by_name(algo, start, particles).unwrap()
}

fn budget(n: u64) -> StopOptions {
    StopOptions {
        max_evaluations: Some(n),
        ..Default::default()
    }
}

#[test]
fn the_same_seed_gives_the_same_trace_and_another_seed_does_not() {
    let f = TestFunction::by_name("rotated-ellipsoid", 6, 2).unwrap();
    for algo in ALGOS {
        let run = |seed| {
            let start = Start::new(f.start(), 0.3).with_stop(budget(600));
            let mut o = optimiser(algo, &start);
            let mut rng = ChaCha8Rng::seed_from_u64(seed);
            minimize_fn(o.as_mut(), &mut rng, |x| f.eval(x))
        };
        let (a, b, c) = (run(5), run(5), run(6));
        assert_eq!(a, b, "{algo}");
        if algo != "simplex" {
            assert_ne!(a.trace, c.trace, "{algo} ignores its seed");
        }
    }
}

#[test]
fn nan_fitness_is_a_stop_reason_not_a_panic() {
    for algo in ALGOS {
        let start = Start::new(vec![0.5; 4], 0.1).with_stop(budget(10_000));
        let mut o = optimiser(algo, &start);
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        let r = minimize_fn(o.as_mut(), &mut rng, |x| {
            if x[0] > 0.5 { f64::NAN } else { x[0] * x[0] }
        });
        assert!(
            r.reasons.contains(&StopReason::InvalidFitness),
            "{algo}: {:?}",
            r.reasons
        );
        assert!(r.best_f.is_finite());
    }
}

#[test]
fn candidates_stay_inside_the_bounds() {
    let bounds = Bounds::new(vec![-0.1, 0.0, 0.2], vec![0.1, 0.05, 0.3]).unwrap();
    for algo in ALGOS {
        let start = Start::new(vec![0.0, 0.02, 0.25], 1.0)
            .with_bounds(bounds.clone())
            .with_stop(budget(500));
        let mut o = optimiser(algo, &start);
        let mut rng = ChaCha8Rng::seed_from_u64(2);
        let r = minimize(
            o.as_mut(),
            &mut rng,
            |xs, out| {
                for (x, o) in xs.iter().zip(out.iter_mut()) {
                    for i in 0..3 {
                        assert!(
                            x[i] >= bounds.lower[i] && x[i] <= bounds.upper[i],
                            "{algo}: {x:?}"
                        );
                    }
                    *o = (x[0] - 1.0).powi(2) + x[1] * x[1] + x[2] * x[2];
                }
            },
            |_| true,
        );
        // the unconstrained optimum (1, 0, 0) is outside: the best sits on the bound x0 = 0.1
        assert!((r.best_x[0] - 0.1).abs() < 0.02, "{algo}: {:?}", r.best_x);
    }
}

#[test]
fn budgets_targets_and_no_improvement_stop_the_run() {
    let f = TestFunction::by_name("sphere", 5, 0).unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    let start = Start::new(f.start(), 0.5).with_stop(budget(100));
    let mut o = Xnes::new(&start, &XnesOptions::default()).unwrap();
    let r = minimize_fn(&mut o, &mut rng, |x| f.eval(x));
    assert_eq!(r.reasons, [StopReason::MaxEvaluations]);
    assert!(r.evaluations >= 100 && r.evaluations < 100 + o.population() as u64);
    assert!(r.best_at_evaluation <= r.evaluations);

    let start = Start::new(f.start(), 0.5).with_stop(StopOptions {
        no_improvement_evaluations: Some(200),
        max_evaluations: Some(100_000),
        ..Default::default()
    });
    let mut o = Cmaes::new(&start, &CmaesOptions::default()).unwrap();
    let r = minimize_fn(&mut o, &mut rng, |_| 1.0);
    assert!(
        r.reasons.contains(&StopReason::NoImprovement),
        "{:?}",
        r.reasons
    );
    assert!(r.evaluations < 300);
}

#[test]
fn the_centre_rule_stops_a_stagnating_search_and_counts_centre_evaluations() {
    let f = TestFunction::by_name("sphere", 4, 0).unwrap();
    let start = Start::new(f.start(), 0.5).with_stop(StopOptions {
        center_stagnation: Some((20, 40)),
        max_evaluations: Some(1_000_000),
        tol_x: None,
        tol_fun: None,
        ..Default::default()
    });
    let mut o = Xnes::new(&start, &XnesOptions::default()).unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(4);
    // a noise floor: once the mean is near 0 the centre values stop falling
    let mut noise = ChaCha8Rng::seed_from_u64(9);
    let r = minimize_fn(&mut o, &mut rng, |x| {
        f.eval(x) + 1e-3 * rand::RngExt::random::<f64>(&mut noise)
    });
    assert_eq!(r.reasons, [StopReason::CenterStagnation]);
    assert!(r.best_f < 0.01);
    assert_eq!(r.evaluations, r.generations * (o.population() as u64 + 1));
}

#[test]
fn tell_rejects_a_wrong_number_of_values() {
    let start = Start::new(vec![0.0; 3], 1.0);
    let mut o = Cmaes::new(&start, &CmaesOptions::default()).unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(0);
    assert_eq!(o.tell(&[1.0]), Err(OptimError::NoPendingAsk));
    let n = o.ask(&mut rng).len();
    assert_eq!(
        o.tell(&[1.0]),
        Err(OptimError::WrongFitnessCount {
            expected: n,
            got: 1
        })
    );
}

#[test]
fn bad_settings_are_errors() {
    assert!(Xnes::new(&Start::new(vec![], 1.0), &XnesOptions::default()).is_err());
    assert!(Xnes::new(&Start::new(vec![0.0], -1.0), &XnesOptions::default()).is_err());
    assert!(Cmaes::new(&Start::new(vec![f64::NAN], 1.0), &CmaesOptions::default()).is_err());
    assert!(Bounds::new(vec![1.0], vec![0.0]).is_err());
    let e = Snes::new(
        &Start::new(vec![0.0; 2], StepSize::PerDimension(vec![1.0])),
        &SnesOptions::default(),
    )
    .unwrap_err();
    assert!(e.to_string().contains("1 values for dimension 2"), "{e}");
}

#[test]
fn per_dimension_steps_scale_the_first_samples() {
    let start = Start::new(vec![0.0; 2], StepSize::PerDimension(vec![1.0, 1e-3]));
    let mut o = Xnes::new(
        &start,
        &XnesOptions {
            population: Some(200),
            ..Default::default()
        },
    )
    .unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(0);
    let xs = o.ask(&mut rng);
    let spread = |i: usize| xs.iter().map(|x| x[i] * x[i]).sum::<f64>() / xs.len() as f64;
    let ratio = (spread(0) / spread(1)).sqrt();
    assert!(ratio > 700.0 && ratio < 1400.0, "{ratio}");
}

#[test]
fn the_constrained_search_bootstraps_a_feasible_start_and_stays_feasible() {
    // minimise ‖x‖² subject to x₀ ≥ 1 and x₁ ≥ 0.5 from an infeasible start
    let start = Start::new(vec![-2.0, -2.0, 3.0, 1.0], 0.5).with_stop(StopOptions {
        max_evaluations: Some(20_000),
        tol_x: Some(1e-9),
        ..Default::default()
    });
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    let mut infeasible_objective_calls = 0;
    let result = minimize_constrained(
        &start,
        None,
        2,
        &mut rng,
        |x| {
            if x[0] < 1.0 || x[1] < 0.5 {
                infeasible_objective_calls += 1;
            }
            x.iter().map(|v| v * v).sum()
        },
        |x, g| {
            g[0] = 1.0 - x[0];
            g[1] = 0.5 - x[1];
        },
    )
    .unwrap();
    assert!(result.feasible);
    assert!(result.bootstrap_evaluations > 0);
    assert_eq!(infeasible_objective_calls, 0);
    let x = &result.report.best_x;
    assert!(x[0] >= 1.0 && x[1] >= 0.5);
    assert!(
        (result.report.best_f - 1.25).abs() < 1e-4,
        "{}",
        result.report.best_f
    );
}

#[test]
fn an_unreachable_feasible_set_is_reported_not_hidden() {
    let start = Start::new(vec![0.0, 0.0], 0.5).with_stop(budget(2_000));
    let mut rng = ChaCha8Rng::seed_from_u64(1);
    let result = minimize_constrained(
        &start,
        None,
        1,
        &mut rng,
        |x| x[0],
        |x, g| {
            g[0] = 1.0 + x[0] * x[0]; // never ≤ 0
        },
    )
    .unwrap();
    assert!(!result.feasible);
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(40))]

    #[test]
    fn the_best_value_never_gets_worse(seed in any::<u64>(), algo in 0usize..ALGOS.len()) {
        let f = TestFunction::by_name("rastrigin", 5, 0).unwrap();
        let start = Start::new(vec![2.0; 5], 1.0).with_stop(budget(800));
        let mut o = optimiser(ALGOS[algo], &start);
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let r = minimize_fn(o.as_mut(), &mut rng, |x| f.eval(x));
        prop_assert!(r.trace.windows(2).all(|w| w[1].1 <= w[0].1 && w[1].0 > w[0].0));
        prop_assert!((f.eval(&r.best_x) - r.best_f).abs() < 1e-12);
    }
}

/// `spread_below(t)` answers `spread() < t` for every algorithm, at every generation of a run
/// and for thresholds below, at and above the spread (the simplex and (1+1)-CMA-ES stop
/// looking at the first part of their spread that reaches t).
#[test]
fn spread_below_answers_as_the_spread_does() {
    let f = TestFunction::by_name("rotated-ellipsoid", 8, 3).unwrap();
    for algo in ALGOS {
        let start = Start::new(f.start(), 0.3);
        let mut o = optimiser(algo, &start);
        let mut rng = ChaCha8Rng::seed_from_u64(2);
        for _ in 0..60 {
            let candidates: Vec<Vec<f64>> = o.ask(&mut rng).iter().map(<[f64]>::to_vec).collect();
            let fitness: Vec<f64> = candidates.iter().map(|x| f.eval(x)).collect();
            o.tell(&fitness).unwrap();
            let s = o.spread();
            for t in [0.0, s * 0.5, s, s * (1.0 + 1e-15), s * 2.0, f64::INFINITY] {
                assert_eq!(o.spread_below(t), s < t, "{algo}: spread {s}, t {t}");
            }
        }
    }
}
