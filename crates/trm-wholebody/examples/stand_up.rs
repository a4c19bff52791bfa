//! The iCub stands up from a chair: the hand-tuned motion, then the safe trajectory
//! optimisation (bootstrap + constrained (1+1)-CMA-ES), each re-checked independently; the
//! optimised motion is written as CSV.
//!
//! `cargo run -p trm-wholebody --example stand_up [-- MOTION_SPEC.ron [SEED]]` (default: the
//! repository's `specs/wholebody/standup.ron`)

use trm_wholebody::{WholeBody, optimize};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let spec = args.next().unwrap_or_else(|| {
        concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../specs/wholebody/standup.ron"
        )
        .into()
    });
    let seed: u64 = args.next().map_or(Ok(1), |s| s.parse())?;
    let problem = WholeBody::load(&spec)?;
    let result = optimize(&problem, seed, |_, _| {})?;
    for s in &result.solutions {
        println!(
            "{:<13} φ_co {:.3}, {} violated samples, independent re-check: {}",
            s.name,
            s.phi_co,
            s.rollout.violations(),
            if problem.verify(&s.rollout).is_empty() {
                "feasible"
            } else {
                "violations"
            }
        );
    }
    let best = result
        .solutions
        .last()
        .expect("at least the hand-tuned motion");
    trm_io::write_atomic(
        "target/stand_up.csv".as_ref(),
        best.rollout.to_csv(problem.model())?.as_bytes(),
    )?;
    println!("wrote target/stand_up.csv");
    Ok(())
}
