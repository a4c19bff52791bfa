//! Allocations of map building on one thread (exact and repeatable; several threads are a
//! report, `cargo bench -p trm-benches --bench allocations`, since rayon's work stealing
//! allocates now and then): evaluating candidates allocates nothing once the scratch pool is
//! warm; a whole E-TRM build allocates per generation and per search (bookkeeping), not per
//! candidate; an NGIK search allocates per generation, not per candidate (its scratch buffers
//! come from a pool kept across generations), for a population of 30 and for a lone candidate.

mod common {
    pub mod allocations;
}

use common::allocations::measure;

/// One test: the counter is global, so nothing else may run beside it.
#[test]
fn map_building_does_not_allocate_per_candidate() {
    let counts = measure(1);
    println!("{counts:#?}");
    assert_eq!(
        counts.on_threads_per_evaluation, 0.0,
        "evaluating a warm population allocates"
    );
    // ~1.5 today: per-generation and per-search bookkeeping; a scratch made per evaluation
    // chunk (as before the pool) gave 3.8
    assert!(
        counts.build_per_evaluation < 2.0,
        "{:.3} allocations per evaluation",
        counts.build_per_evaluation
    );
    // xNES: each of its 9 matrix products per generation allocates matrixmultiply's packing
    // buffer; nothing allocates per candidate. A lone candidate: nothing per generation.
    let [xnes, lone] = counts.ngik_per_generation;
    assert!(xnes < 10.0, "xnes: {xnes:.2} allocations per generation");
    assert!(
        lone < 0.5,
        "oneplusone: {lone:.2} allocations per generation"
    );
}
