//! Allocation counts of map building, shared by the test (`tests/map_build_allocations.rs`,
//! one thread: the counts are exact and repeatable) and the report
//! (`cargo bench -p trm-benches --bench allocations`, also on several threads, where rayon's
//! work stealing allocates now and then, so the counts vary from run to run).
//!
//! A global counter sees every thread: the binary including this module must run nothing else
//! at the same time.

// A global allocator can only be written with `unsafe`; it forwards to the system allocator.
#![allow(unsafe_code)]

use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering};

struct Counting;

static ALLOCATIONS: AtomicUsize = AtomicUsize::new(0);

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

fn allocations() -> usize {
    ALLOCATIONS.load(Ordering::Relaxed)
}

fn spec(name: &str) -> trm_tasks::Problem {
    let path = format!("{}/../specs/{name}", env!("CARGO_MANIFEST_DIR"));
    trm_tasks::Problem::load(path).unwrap()
}

/// What one measurement found.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Counts {
    /// Allocations per candidate of `evaluate_on_threads` once its scratch pool is warm.
    pub on_threads_per_evaluation: f64,
    /// Extra allocations per extra evaluation between a 40- and a 120-point E-TRM build.
    pub build_per_evaluation: f64,
    /// The same, per extra search.
    pub build_per_search: f64,
    /// Extra allocations per extra generation of NGIK with xNES (λ = 30) and with
    /// (1+1)-CMA-ES (a lone candidate), between 3 000 and 12 000 evaluations.
    pub ngik_per_generation: [f64; 2],
    /// The same, per extra evaluation.
    pub ngik_per_evaluation: [f64; 2],
}

/// Measures on a pool of `threads` threads.
pub fn measure(threads: usize) -> Counts {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap()
        .install(|| {
            let on_threads_per_evaluation = evaluating_on_the_threads();
            let (build_per_evaluation, build_per_search) = a_map_build();
            let (ngik_per_generation, ngik_per_evaluation) = ngik_searches();
            Counts {
                on_threads_per_evaluation,
                build_per_evaluation,
                build_per_search,
                ngik_per_generation,
                ngik_per_evaluation,
            }
        })
}

fn evaluating_on_the_threads() -> f64 {
    let problem = spec("reach.ron");
    let objective = &problem.objective;
    let population = trm_benches::random_configurations(objective.active(), 64, 5);
    let qs: Vec<&[f64]> = population.iter().map(|q| q.as_slice()).collect();
    let dim = objective.task().map_or(0, |t| t.dim());
    let (mut fitness, mut tasks) = (vec![0.0; qs.len()], vec![0.0; qs.len() * dim]);
    let pool = trm_roadmap::ScratchPool::default();
    // the first calls fill the pool (as many buffers as rayon ever runs pieces of one call at
    // once: a thread waiting in a join may run a stolen piece with a second buffer)
    for _ in 0..20 {
        trm_roadmap::evaluate_on_threads(objective, &qs, &mut fitness, &mut tasks, &pool);
    }
    let before = allocations();
    for _ in 0..100 {
        trm_roadmap::evaluate_on_threads(objective, &qs, &mut fitness, &mut tasks, &pool);
    }
    assert!(fitness.iter().all(|f| f.is_finite()));
    (allocations() - before) as f64 / (100 * qs.len()) as f64
}

fn a_map_build() -> (f64, f64) {
    let problem = spec("reach.ron");
    let build = |points: usize| {
        let before = allocations();
        let map = trm_roadmap::Builder::new(
            &problem,
            &trm_roadmap::BuildOptions {
                points: Some(points),
                ..Default::default()
            },
        )
        .run(|_| {})
        .unwrap();
        let allocations = allocations() - before;
        (
            allocations,
            map.stats.evaluations,
            map.stats.searches_started,
        )
    };
    let (a1, e1, g1) = build(40);
    let (a2, e2, g2) = build(120);
    assert!(e2 > e1 + 10_000, "{e1} and {e2} evaluations");
    (
        (a2 - a1) as f64 / (e2 - e1) as f64,
        (a2 - a1) as f64 / (g2 - g1).max(1) as f64,
    )
}

fn ngik_searches() -> ([f64; 2], [f64; 2]) {
    let problem = spec("table_iii/posture1.ron");
    let mut per_generation = [0.0; 2];
    let mut per_evaluation = [0.0; 2];
    for (k, (algo, population)) in [("xnes", Some(30)), ("oneplusone", None)]
        .into_iter()
        .enumerate()
    {
        let run = |max_evaluations: u64| {
            let solver = trm_tasks::spec::SolverSpec {
                algo: algo.into(),
                population,
                max_evaluations,
                no_improvement: None,
                ..problem.spec.solver.clone()
            };
            let before = allocations();
            let s = trm_tasks::solve(&problem.objective, &problem.start, &solver).unwrap();
            (allocations() - before, s.evaluations, s.trace.len())
        };
        let (a1, e1, g1) = run(3_000);
        let (a2, e2, g2) = run(12_000);
        assert!(e2 > e1 + 5_000, "{algo}: {e1} and {e2} evaluations");
        per_generation[k] = (a2 as f64 - a1 as f64) / (g2 - g1) as f64;
        per_evaluation[k] = (a2 as f64 - a1 as f64) / (e2 - e1) as f64;
    }
    (per_generation, per_evaluation)
}
