//! A page showing the iCub waving its right arm: writes `target/icub.scene.json` and
//! `target/icub.scene.html` (open it in a browser; three.js from a CDN unless the viewer bundle
//! is built).
//!
//! `cargo run -p trm-view --example view_icub`

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let model = trm_models::icub_upper_body();
    let collision = trm_collision::CollisionModel::new(&model)?;
    let mut scene = trm_view::Scene::new("iCub waving", &collision);
    let home = model.posture("home")?.to_vec();
    let shoulder = model.motor_index("r_shoulder_roll")?;
    for i in 0..20 {
        let mut q = home.clone();
        q[shoulder] += 0.6 * (i as f64 * 0.3).sin().abs();
        scene.add_frame(0.1 * i as f64, &q)?;
    }
    trm_io::write_atomic(
        "target/icub.scene.json".as_ref(),
        scene.to_json()?.as_bytes(),
    )?;
    trm_io::write_atomic(
        "target/icub.scene.html".as_ref(),
        scene.to_html(None)?.as_bytes(),
    )?;
    println!(
        "wrote target/icub.scene.json and target/icub.scene.html ({} frames)",
        scene.frames.len()
    );
    Ok(())
}
