//! `trm-rrd SCENE.json OUT.rrd`: a trm scene (as `cargo xtask view` and the `--view` flags
//! write it) as a Rerun recording.

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if args.len() != 3 {
        eprintln!("usage: trm-rrd SCENE.json OUT.rrd");
        std::process::exit(2);
    }
    let run = || -> Result<(), Box<dyn std::error::Error>> {
        let text = std::fs::read_to_string(&args[1]).map_err(|e| format!("{}: {e}", args[1]))?;
        let scene = trm_view::Scene::from_json(&text).map_err(|e| format!("{}: {e}", args[1]))?;
        trm_rrd::write_rrd(&scene, std::path::Path::new(&args[2]))?;
        eprintln!("wrote {} (open it with `rerun {}`)", args[2], args[2]);
        Ok(())
    };
    if let Err(e) = run() {
        eprintln!("error: {e}");
        std::process::exit(1);
    }
}
