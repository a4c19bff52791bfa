//! Shared inputs for trm's criterion benches (`cargo bench -p trm-benches`). The suites are in
//! `benches/benches/`.

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use trm_kinematics::ActiveSet;

/// `n` seeded uniform samples within the bounds of `active`.
pub fn random_configurations(active: &ActiveSet, n: usize, seed: u64) -> Vec<Vec<f64>> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    (0..n).map(|_| active.random(&mut rng)).collect()
}

/// The median of `values` (the upper one of an even count), sorting them in place.
///
/// # Panics
/// If `values` is empty.
pub fn median(values: &mut [f64]) -> f64 {
    values.sort_by(f64::total_cmp);
    values[values.len() / 2]
}

/// A command-line count: `text` as a positive whole number, else an error naming `what`.
pub fn positive(text: &str, what: &str) -> Result<usize, String> {
    match text.parse::<usize>() {
        Ok(v) if v > 0 => Ok(v),
        _ => Err(format!("{what}: `{text}` is not a positive whole number")),
    }
}

/// Runs an example's `run`, printing its error and exiting with status 2 when it fails.
pub fn exit_on_error(run: impl FnOnce() -> Result<(), String>) {
    if let Err(e) = run() {
        eprintln!("error: {e}");
        std::process::exit(2);
    }
}
