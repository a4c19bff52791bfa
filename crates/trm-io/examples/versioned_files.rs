//! A versioned file written atomically and read back, a damaged copy and a file of another
//! version refused, and a spec error located by its field path with a "did you mean":
//! what every trm file format rests on.
//!
//! ```sh
//! cargo run -p trm-io --example versioned_files
//! ```

use std::collections::BTreeMap;
use std::path::Path;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let dir = std::env::temp_dir().join(format!("trm-io-example-{}", std::process::id()));
    std::fs::create_dir_all(&dir)?;

    // JSON with a format name and a version, written with a temporary file and a rename
    let path = dir.join("gains.json");
    let gains = BTreeMap::from([
        ("format".to_string(), serde_json::json!("gains")),
        ("version".to_string(), serde_json::json!(1)),
        ("kp".to_string(), serde_json::json!([120.0, 80.0, 40.0])),
    ]);
    trm_io::save_json(&path, &gains, "gains")?;
    let back: serde_json::Value = trm_io::load_versioned(&path, "gains", 1)?;
    println!("read back {}: kp = {}", path.display(), back["kp"]);
    match trm_io::load_versioned::<serde_json::Value>(&path, "gains", 2) {
        Ok(_) => unreachable!("version 1 is not version 2"),
        Err(e) => println!("another version is refused: {e}"),
    }

    // the binary twin: every f64 bit for bit, a damaged byte found by its checksum
    let values = vec![0.1, f64::INFINITY, -0.0];
    let mut bytes = trm_io::binary_bytes(Path::new("values.bin"), &values, "values", 1)?;
    let again: Vec<f64> =
        trm_io::parse_binary_versioned(Path::new("values.bin"), &bytes, "values", 1)?;
    assert_eq!(
        again.iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
        values.iter().map(|v| v.to_bits()).collect::<Vec<_>>()
    );
    let last = bytes.len() - 5;
    bytes[last] ^= 1;
    if let Err(e) =
        trm_io::parse_binary_versioned::<Vec<f64>>(Path::new("values.bin"), &bytes, "values", 1)
    {
        println!("a damaged copy is refused: {e}");
    }

    // a spec error located at its field, with the closest names
    let spec = "(robot: \"panda\", solver: (algo: \"xnse\", seed: 3))";
    let near = trm_io::closest_names("xnse", ["xnes", "snes", "cmaes"]);
    let error = trm_io::SpecError::at(
        spec,
        "reach.ron",
        "solver.algo",
        "unknown algorithm `xnse`",
        format!("did you mean `{}`?", near.join("`, `")),
    );
    println!("{error}");

    std::fs::remove_dir_all(&dir)?;
    Ok(())
}
