//! `trm collide [MODEL] --configs IN.json [--world WORLD.ron]`: colliding pairs and the
//! minimum self-distance of each configuration.

use std::path::PathBuf;

use anyhow::{Context, Result};
use serde_json::json;
use trm_collision::{Other, World};

/// Arguments of `collide`.
#[derive(clap::Args)]
pub struct Args {
    /// A .urdf file or a .ron model description; the embedded iCub upper body when absent.
    model: Option<PathBuf>,
    #[command(flatten)]
    configs: crate::support::configs::ConfigsArgs,
    /// World objects (RON: crates/trm-collision/docs/world.md; or a MoveIt planning scene .yaml), checked as well.
    #[arg(long)]
    world: Option<PathBuf>,
    #[command(flatten)]
    meshes: crate::MeshArgs,
    /// Also write the results as JSON to this file.
    #[arg(long)]
    pub out: Option<PathBuf>,
}

/// Checks every configuration and prints (and optionally writes) the results.
pub fn run(args: &Args) -> Result<()> {
    let model = crate::load_model(args.model.as_deref())?;
    let collision = args.meshes.collision_model(&model)?;
    let world = match &args.world {
        Some(path) => trm_moveit::load_world(path)?,
        None => World::new(),
    };
    let (_, all) = args.configs.read(&model)?;
    let mut poses = model.pose_buffer();
    let mut placed = collision.placed_bodies();
    let mut results = Vec::new();
    println!(
        "{}: {} bodies, {} checked link pairs, {} world objects",
        model.origin(),
        collision.bodies().len(),
        collision.num_checked_link_pairs(),
        world.len()
    );
    for (s, joints) in all.iter().enumerate() {
        model
            .forward_joints(joints, &mut poses)
            .with_context(|| format!("{}: sample {s}", args.configs.path.display()))?;
        collision.place(&poses, &mut placed);
        let count = collision.count(&placed, &world);
        let pairs = collision.colliding_pairs(&placed, &world);
        let closest = collision.min_self_distance(&placed);
        let closest_text = closest.map_or("-".to_string(), |d| {
            format!(
                "{:+.4} m ({} / {})",
                d.distance,
                collision.bodies()[d.a].name,
                collision.bodies()[d.b].name
            )
        });
        println!(
            "sample {s}: {} self, {} world colliding pairs; min self-distance {closest_text}",
            count.self_pairs, count.world_pairs
        );
        let mut listed = Vec::new();
        for p in &pairs {
            let (kind, other) = match &p.other {
                Other::Body(b) => ("self", b.as_str()),
                Other::Object(o) => ("world", o.as_str()),
            };
            println!(
                "  {kind:<5} {:<22} {other:<22} {:+.4} m",
                p.body, p.distance
            );
            listed.push(
                json!({"kind": kind, "body": p.body, "other": other, "distance": p.distance}),
            );
        }
        results.push(json!({
            "self_pairs": count.self_pairs,
            "world_pairs": count.world_pairs,
            "colliding": listed,
            "min_self_distance": closest.map(|d| json!({
                "distance": d.distance,
                "a": collision.bodies()[d.a].name,
                "b": collision.bodies()[d.b].name,
            })),
        }));
    }
    if let Some(out) = &args.out {
        crate::write_json(
            out,
            &json!({
                "model": model.origin(),
                "configs": args.configs.path,
                "world": args.world,
                "samples": results,
            }),
        )?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_world_in_specs_loads() {
        let dir = crate::models_dir().join("../specs/worlds");
        let mut n = 0;
        for entry in std::fs::read_dir(&dir).unwrap() {
            let path = entry.unwrap().path();
            if path.extension().is_some_and(|e| e == "ron") {
                let world = World::load(&path).unwrap();
                assert!(!world.is_empty(), "{}", path.display());
                n += 1;
            }
        }
        assert!(n > 0);
    }

    #[test]
    fn collide_reports_crossed_arms_and_a_table_through_the_hand() {
        let model = trm_models::icub_upper_body();
        let dir = crate::test_dir("collide-test");
        let names = [
            "l_shoulder_pitch",
            "l_shoulder_roll",
            "l_shoulder_yaw",
            "l_elbow",
            "r_shoulder_pitch",
            "r_shoulder_roll",
            "r_shoulder_yaw",
            "r_elbow",
        ];
        let crossed: Vec<f64> = [-50.0, 10.0, 60.0, 90.0, -50.0, 10.0, 60.0, 90.0]
            .iter()
            .map(|d: &f64| d.to_radians())
            .collect();
        let open: Vec<f64> = [-30.0, 60.0, 0.0, 45.0, -30.0, 60.0, 0.0, 45.0]
            .iter()
            .map(|d: &f64| d.to_radians())
            .collect();
        let input = dir.join("in.json");
        std::fs::write(
            &input,
            json!({"joint_names": names, "samples": [{"q": crossed}, {"q": open}]}).to_string(),
        )
        .unwrap();
        let world = dir.join("world.ron");
        std::fs::write(&world, "(objects: [(name: \"wall\", shape: Box(size: (0.02, 2.0, 2.0)), xyz: (-0.9, 0.0, 0.0))])").unwrap();
        let out = dir.join("out.json");
        run(&Args {
            model: None,
            configs: crate::support::configs::ConfigsArgs {
                path: input,
                outside_limits: false,
            },
            world: Some(world),
            meshes: crate::MeshArgs::default(),
            out: Some(out.clone()),
        })
        .unwrap();
        let got: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(&out).unwrap()).unwrap();
        let samples = got["samples"].as_array().unwrap();
        assert!(samples[0]["self_pairs"].as_u64().unwrap() > 0);
        assert!(
            samples[0]["colliding"]
                .as_array()
                .unwrap()
                .iter()
                .any(|p| p["body"] == "r_forearm" && p["other"] == "l_forearm")
        );
        assert_eq!(samples[1]["self_pairs"], 0);
        assert_eq!(samples[1]["world_pairs"], 0);
        assert!(
            samples[1]["min_self_distance"]["distance"]
                .as_f64()
                .unwrap()
                > 0.0
        );
        std::fs::remove_dir_all(&dir).unwrap();
        let _ = model;
    }
}
