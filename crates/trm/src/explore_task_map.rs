//! `trm explore-task-map SPEC [--out FILE]`: the map of feasible grasps of an object
//! (Gienger et al., Section II), explored with an RRT from a first grasp (given, or found by
//! random search), with restarts for disjoint clusters; a file and an SVG of the explored hand
//! positions relative to the object (the paper's Fig. 3).

use std::path::PathBuf;

use crate::support::taskmap::explore_spec;
use anyhow::Result;
pub use trm_taskmap::Explored;

/// Arguments of `explore-task-map`.
#[derive(clap::Args)]
pub struct Args {
    /// The task-map spec (RON; format: crates/trm-taskmap/docs/task-map-spec.md).
    spec: PathBuf,
    /// Output file (default: target/taskmaps/<spec name>.taskmap.json; an .svg goes beside it).
    #[arg(long)]
    out: Option<PathBuf>,
}

impl Args {
    /// Where the task map goes: `--out`, or target/taskmaps/<spec name>.taskmap.json.
    pub fn out_path(&self) -> PathBuf {
        crate::default_out(&self.out, &self.spec, "target/taskmaps", "taskmap.json")
    }
}

/// Explores and writes the map.
pub fn run(args: &Args) -> Result<()> {
    let Explored { map, seconds, .. } = explore_spec(&args.spec)?;

    let out = args.out_path();
    crate::write_atomic(&out, map.to_json(&out)?.as_bytes())?;
    let points: Vec<[f64; 3]> = map
        .points
        .iter()
        .map(|p| [p.g[0], p.g[1], p.g[2]])
        .collect();
    let values: Vec<f64> = map.points.iter().map(|p| p.value).collect();
    let svg = out.with_extension("svg");
    let title = format!(
        "{} feasible grasps (hand positions in the object frame), {} clusters",
        map.points.len(),
        map.clusters()
    );
    crate::write_atomic(
        &svg,
        crate::plot::scatter_points(&title, &points, &values, None)?.as_bytes(),
    )?;
    println!(
        "{} feasible grasps in {} clusters from {} evaluations in {seconds:.1} s; wrote {} and {}",
        map.points.len(),
        map.clusters(),
        map.evaluations,
        out.display(),
        svg.display()
    );
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn explores_a_stick_and_reports_an_ungraspable_object() {
        let dir = crate::test_dir("etm");
        let spec = dir.join("stick.ron");
        std::fs::write(
            &spec,
            "(object: [(name: \"stick\", shape: Capsule(radius: 0.02, length: 0.3))],
              explore: (iterations: 150, restarts: 0, step: 0.015, half_widths: (0.1, 0.1, 0.2, 1.5, 1.5, 1.5), seed: 0),
              search: (samples: 2500))",
        )
        .unwrap();
        let out = dir.join("stick.taskmap.json");
        run(&Args {
            spec: spec.clone(),
            out: Some(out.clone()),
        })
        .unwrap();
        let map = trm_taskmap::TaskMap::load(&out).unwrap();
        assert!(map.points.len() > 5);
        assert!(out.with_extension("svg").is_file());
        // a 60 cm box: nothing to wrap the fingers around
        std::fs::write(&spec, "(object: [(name: \"wall\", shape: Box(size: (0.6, 0.6, 0.6)))], search: (samples: 200))").unwrap();
        let e = run(&Args {
            spec,
            out: Some(dir.join("wall.json")),
        })
        .unwrap_err()
        .to_string();
        assert!(e.contains("cannot grasp this object"), "{e}");
        assert!(!dir.join("wall.json").exists(), "no file for an empty map");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
