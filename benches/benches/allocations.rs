//! Allocation counts of map building on 1 thread and on every core: a report, not a timing
//! (`cargo bench -p trm-benches --bench allocations`). On several threads rayon's work stealing
//! allocates now and then, so those counts vary from run to run; the test
//! (`tests/map_build_allocations.rs`) holds the one-thread counts to their bounds.

#[path = "../tests/common/allocations.rs"]
mod allocations;

fn main() {
    let cores = std::thread::available_parallelism().map_or(1, usize::from);
    let mut threads = vec![1];
    if cores > 1 {
        threads.push(cores);
    }
    println!(
        "| threads | per evaluation on threads | build: per evaluation | build: per search | NGIK xNES: per generation | NGIK (1+1): per generation |"
    );
    println!("|---|---|---|---|---|---|");
    for t in threads {
        let c = allocations::measure(t);
        println!(
            "| {t} | {:.4} | {:.3} | {:.0} | {:.2} | {:.2} |",
            c.on_threads_per_evaluation,
            c.build_per_evaluation,
            c.build_per_search,
            c.ngik_per_generation[0],
            c.ngik_per_generation[1]
        );
    }
}
