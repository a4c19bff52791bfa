//! `trm fk [MODEL] --configs IN.json --out OUT.json`.

use std::path::PathBuf;

use crate::support::configs::ConfigsArgs;
use anyhow::{Context, Result};
use serde_json::{Map, Value, json};

/// Arguments of `fk`.
#[derive(clap::Args)]
pub struct Args {
    /// A .urdf file or a .ron model description; the embedded iCub upper body when absent.
    model: Option<PathBuf>,
    #[command(flatten)]
    configs: ConfigsArgs,
    /// Output file: the input plus, per sample, "links": {"<link>": {"p": [x,y,z], "R": [[...],[...],[...]]}}
    /// (and "frames" for named frames). Printed to stdout when absent.
    #[arg(long)]
    pub out: Option<PathBuf>,
}

fn pose_json(p: &nalgebra::Isometry3<f64>) -> Value {
    let r = p.rotation.to_rotation_matrix();
    let m = r.matrix();
    json!({
        "p": [p.translation.x, p.translation.y, p.translation.z],
        "R": [[m[(0, 0)], m[(0, 1)], m[(0, 2)]], [m[(1, 0)], m[(1, 1)], m[(1, 2)]], [m[(2, 0)], m[(2, 1)], m[(2, 2)]]],
    })
}

/// Computes and writes the poses.
pub fn run(args: &Args) -> Result<()> {
    let model = crate::load_model(args.model.as_deref())?;
    let (configs, all) = args.configs.read(&model)?;
    let mut buffer = model.pose_buffer();
    let mut samples_out = Vec::with_capacity(configs.samples.len());
    for (s, (sample, joints)) in configs.samples.iter().zip(&all).enumerate() {
        model
            .forward_joints(joints, &mut buffer)
            .with_context(|| format!("{}: sample {s}", args.configs.path.display()))?;
        let mut links = Map::new();
        let mut frames = Map::new();
        for (i, name) in model.frame_names().enumerate() {
            let target = if i < model.num_links() {
                &mut links
            } else {
                &mut frames
            };
            target.insert(name.to_string(), pose_json(&buffer.poses()[i]));
        }
        let mut out = Map::new();
        out.insert("q".into(), json!(sample.q));
        out.insert("links".into(), Value::Object(links));
        if !frames.is_empty() {
            out.insert("frames".into(), Value::Object(frames));
        }
        samples_out.push(Value::Object(out));
    }
    let result = json!({ "model": model.origin(), "joint_names": configs.joint_names, "samples": samples_out });
    let text = serde_json::to_string_pretty(&result)?;
    match &args.out {
        Some(path) => {
            crate::write_atomic(path, text.as_bytes())?;
            eprintln!(
                "wrote {} samples × {} links to {}",
                configs.samples.len(),
                model.num_links(),
                path.display()
            );
        }
        None => println!("{text}"),
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `fk` on the Pinocchio fixture's inputs reproduces its poses (the fixture is both a valid
    /// input file and the expected output).
    #[test]
    fn fk_command_reproduces_pinocchio_poses_of_the_official_urdf() {
        let root = crate::models_dir().join("..");
        let fixture =
            root.join("crates/trm-kinematics/tests/fixtures/icub_visuomanip.pinocchio.json");
        let expected: Value =
            serde_json::from_str(&std::fs::read_to_string(&fixture).unwrap()).unwrap();
        let dir = crate::test_dir("fk-test");
        let input = dir.join("in.json");
        let configs = json!({"joint_names": expected["joint_names"], "samples": expected["samples"].as_array().unwrap().iter().map(|s| json!({"q": s["q"]})).collect::<Vec<_>>()});
        std::fs::write(&input, configs.to_string()).unwrap();
        let out = dir.join("out.json");
        let args = Args {
            model: Some(crate::models_dir().join("icub-visuomanip/model.urdf")),
            // Pinocchio's samples include values outside the limits
            configs: ConfigsArgs {
                path: input,
                outside_limits: true,
            },
            out: Some(out.clone()),
        };
        run(&args).unwrap();
        let got: Value = serde_json::from_str(&std::fs::read_to_string(&out).unwrap()).unwrap();
        let mut worst = 0.0f64;
        for (g, e) in got["samples"]
            .as_array()
            .unwrap()
            .iter()
            .zip(expected["samples"].as_array().unwrap())
        {
            let links = e["links"].as_object().unwrap();
            assert_eq!(g["links"].as_object().unwrap().len(), links.len());
            for (name, pose) in links {
                let a = &g["links"][name];
                for i in 0..3 {
                    worst = worst
                        .max((a["p"][i].as_f64().unwrap() - pose["p"][i].as_f64().unwrap()).abs());
                    for j in 0..3 {
                        worst = worst.max(
                            (a["R"][i][j].as_f64().unwrap() - pose["R"][i][j].as_f64().unwrap())
                                .abs(),
                        );
                    }
                }
            }
        }
        std::fs::remove_dir_all(&dir).unwrap();
        assert!(worst < 1e-9, "worst difference {worst:e}");
    }

    #[test]
    fn fk_rejects_unknown_joint_names_with_a_suggestion() {
        let dir = crate::test_dir("fk-bad");
        let input = dir.join("in.json");
        std::fs::write(
            &input,
            r#"{"joint_names": ["r_elbw"], "samples": [{"q": [0.1]}]}"#,
        )
        .unwrap();
        let err = run(&Args {
            model: None,
            configs: ConfigsArgs {
                path: input,
                outside_limits: false,
            },
            out: Some(dir.join("out.json")),
        })
        .unwrap_err();
        let text = format!("{err:#}");
        assert!(
            text.contains("r_elbow") && text.contains("in.json"),
            "{text}"
        );
        assert!(!dir.join("out.json").exists(), "no output on error");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
