//! Runs FK of the 41-DOF iCub in a loop (for profilers): `cargo run --release -p trm-benches --example fk_loop`.
use trm_benches::random_configurations;
fn main() {
    let model = trm_models::icub_upper_body();
    let active = model.all_active();
    let samples = random_configurations(&active, 64, 7);
    let mut buffer = model.pose_buffer();
    let n = 2_000_000;
    let t = std::time::Instant::now();
    let mut acc = 0.0;
    for k in 0..n {
        active.forward_unchecked(&samples[k % 64], &mut buffer);
        acc += buffer.poses()[5].translation.x;
    }
    println!(
        "{:.1} ns per FK ({acc})",
        t.elapsed().as_nanos() as f64 / n as f64
    );
}
