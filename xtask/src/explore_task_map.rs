//! `cargo xtask explore-task-map SPEC [--out FILE]`: the map of feasible grasps of an object
//! (Gienger et al., Section II), explored with an RRT from a first grasp (given, or found by
//! random search), with restarts for disjoint clusters; a file and an SVG of the explored hand
//! positions relative to the object (the paper's Fig. 3).

use std::path::PathBuf;

use anyhow::{Context, Result, bail};
use serde::Deserialize;
use trm_collision::{CollisionModel, ObjectSpec, World};
use trm_taskmap::{ExploreSettings, Hand, Metric, explore, find_grasp};

/// Arguments of `explore-task-map`.
#[derive(clap::Args)]
pub struct Args {
    /// The task-map spec (RON, see specs/README.md).
    spec: PathBuf,
    /// Output file (default: target/taskmaps/<spec name>.taskmap.json; an .svg goes beside it).
    #[arg(long)]
    out: Option<PathBuf>,
}

fn right() -> String {
    "r".into()
}

/// A task-map spec.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Spec {
    /// A model file relative to the spec; the embedded iCub upper body when absent.
    #[serde(default)]
    model: Option<PathBuf>,
    /// Which iCub hand: "r" or "l".
    #[serde(default = "right")]
    hand: String,
    /// The object's parts in its own frame (capsules or cylinders along their z axes).
    object: Vec<ObjectSpec>,
    /// The first grasp g₀ (hand position and rotation vector in the object frame); found by
    /// random search when absent.
    #[serde(default)]
    start: Option<[f64; 6]>,
    /// The metric W.
    #[serde(default)]
    metric: Option<Metric>,
    /// RRT settings.
    #[serde(default)]
    explore: ExploreSpec,
    /// Random search for g₀.
    #[serde(default)]
    search: SearchSpec,
}

#[derive(Deserialize)]
#[serde(default, deny_unknown_fields)]
struct ExploreSpec {
    iterations: usize,
    step: f64,
    restarts: usize,
    half_widths: [f64; 6],
    seed: u64,
}

impl Default for ExploreSpec {
    fn default() -> Self {
        ExploreSpec {
            iterations: 3000,
            step: 0.015,
            restarts: 300,
            half_widths: [0.1, 0.1, 0.2, 1.0, 1.0, 1.0],
            seed: 0,
        }
    }
}

#[derive(Deserialize)]
#[serde(default, deny_unknown_fields)]
struct SearchSpec {
    samples: usize,
    lower: [f64; 3],
    upper: [f64; 3],
    seed: u64,
}

impl Default for SearchSpec {
    fn default() -> Self {
        SearchSpec {
            samples: 5000,
            lower: [-0.15, -0.12, -0.08],
            upper: [0.05, 0.12, 0.15],
            seed: 0,
        }
    }
}

/// Everything an explored task map comes with.
pub struct Explored {
    /// The robot.
    pub model: trm_kinematics::RobotModel,
    /// Its collision model.
    pub collision: CollisionModel,
    /// The map.
    pub map: trm_taskmap::TaskMap,
    /// Exploration wall time, s.
    pub seconds: f64,
}

/// Reads a task-map spec, finds the first grasp if needed and explores the map.
pub fn explore_spec(path: &std::path::Path) -> Result<Explored> {
    let text =
        std::fs::read_to_string(path).with_context(|| format!("reading {}", path.display()))?;
    let spec: Spec = ron::from_str(&text).map_err(|e| {
        anyhow::anyhow!(
            "{}:{}:{}: {}",
            path.display(),
            e.span.start.line,
            e.span.start.col,
            e.code
        )
    })?;
    let base = path.parent().map(PathBuf::from).unwrap_or_default();
    let model = crate::load_model(spec.model.as_ref().map(|m| base.join(m)).as_deref())?;
    let collision = CollisionModel::new(&model)?;
    if spec.hand != "r" && spec.hand != "l" {
        bail!(
            "{}: hand must be \"r\" or \"l\", not {:?}",
            path.display(),
            spec.hand
        );
    }
    let hand = Hand::icub(&model, &collision, &spec.hand)?;
    let object = World::from_spec(
        &trm_collision::WorldSpec {
            objects: spec.object,
        },
        &path.display().to_string(),
    )?;
    if object.is_empty() {
        bail!("{}: the object has no parts", path.display());
    }
    let g0 = match spec.start {
        Some(g) => g,
        None => {
            let s = &spec.search;
            let Some((g, q)) = find_grasp(&hand, &object, s.lower, s.upper, s.samples, s.seed)
            else {
                bail!(
                    "{}: no grasp found in {} random hand poses: the hand cannot grasp this object anywhere in the search box (or give `start`)",
                    path.display(),
                    s.samples
                );
            };
            eprintln!("first grasp found by search: quality {q:.3}");
            g
        }
    };
    let e = &spec.explore;
    let settings = ExploreSettings {
        iterations: e.iterations,
        step: e.step,
        restarts: e.restarts,
        seed: e.seed,
        ..ExploreSettings::around(g0, e.half_widths)
    };
    let started = std::time::Instant::now();
    let map = explore(&[g0], &settings, &spec.metric.unwrap_or_default(), |g| {
        hand.quality(&object, g)
    })?;
    Ok(Explored {
        seconds: started.elapsed().as_secs_f64(),
        model,
        collision,
        map,
    })
}

/// Explores and writes the map.
pub fn run(args: &Args) -> Result<()> {
    let Explored { map, seconds, .. } = explore_spec(&args.spec)?;

    let out = args.out.clone().unwrap_or_else(|| {
        let stem = args
            .spec
            .file_stem()
            .map_or("taskmap".into(), |s| s.to_string_lossy().to_string());
        PathBuf::from("target/taskmaps").join(format!("{stem}.taskmap.json"))
    });
    map.save(&out)?;
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
