//! Batched forward kinematics: every lane equals the one-configuration path to ≤ 1e-12 on the
//! iCub (couplings), a tree with prismatic, continuous and mimic joints, and the official
//! 75-joint iCub, for random configurations inside and outside the limits; bad input is a
//! clear error.

use std::path::Path;

use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use trm_kinematics::{FrameId, LANES, RobotModel};

fn model(file: &str) -> RobotModel {
    RobotModel::load(
        Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../models")
            .join(file),
    )
    .unwrap()
}

/// Largest difference between lane poses and one-at-a-time poses over `rounds` batches of
/// random motor vectors (within the limits widened by `overshoot` rad on each side).
fn worst_gap(model: &RobotModel, rounds: usize, overshoot: f64, seed: u64) -> f64 {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut batch = model.pose_batch();
    let mut buffer = model.pose_buffer();
    let mut worst = 0.0f64;
    for _ in 0..rounds {
        let q: Vec<f64> = (0..LANES)
            .flat_map(|_| model.motors().iter())
            .map(|m| {
                let (lo, hi) = (m.limits.lower.max(-4.0), m.limits.upper.min(4.0));
                rng.random_range(lo - overshoot..=hi + overshoot)
            })
            .collect();
        model.forward_motors_batch(&q, &mut batch).unwrap();
        let n = model.motors().len();
        for lane in 0..LANES {
            model
                .forward_motors(&q[lane * n..(lane + 1) * n], &mut buffer)
                .unwrap();
            for (k, one) in buffer.poses().iter().enumerate() {
                let many = batch.pose(lane, frame(model, k));
                let dq = (one.rotation.coords - many.rotation.coords).amax();
                let dt = (one.translation.vector - many.translation.vector).amax();
                worst = worst.max(dq).max(dt);
            }
        }
    }
    worst
}

/// The `FrameId` of pose `k` (links then named frames, in buffer order).
fn frame(model: &RobotModel, k: usize) -> FrameId {
    let name = model.frame_names().nth(k).unwrap();
    model.frame_id(name).unwrap()
}

#[test]
fn every_lane_equals_the_one_configuration_path() {
    for (file, rounds) in [
        ("icub_upper_body.ron", 60),
        ("branched_tree.urdf", 200),
        ("icub-visuomanip/model.urdf", 30),
    ] {
        let m = model(file);
        for overshoot in [0.0, 1.0] {
            let gap = worst_gap(&m, rounds, overshoot, 7);
            assert!(gap <= 1e-12, "{file}: lanes differ by {gap:e}");
        }
    }
}

#[test]
fn active_sets_run_in_batches_too() {
    let m = model("icub_upper_body.ron");
    let arm = m
        .active_set(&["right_arm", "torso"], m.posture("home").unwrap())
        .unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    let (lo, hi) = arm.bounds();
    let q: Vec<f64> = (0..LANES * arm.len())
        .map(|i| rng.random_range(lo[i % arm.len()]..hi[i % arm.len()]))
        .collect();
    let mut batch = m.pose_batch();
    arm.forward_batch(&q, &mut batch).unwrap();
    let mut buffer = m.pose_buffer();
    let hand = m.frame_id("r_hand").unwrap();
    for lane in 0..LANES {
        arm.forward(&q[lane * arm.len()..(lane + 1) * arm.len()], &mut buffer)
            .unwrap();
        let gap = (buffer.pose(hand).translation.vector
            - batch.pose(lane, hand).translation.vector)
            .amax();
        assert!(gap <= 1e-12, "lane {lane}: {gap:e}");
        let p = batch.positions(hand);
        let t = batch.pose(lane, hand).translation.vector;
        assert_eq!([p[0][lane], p[1][lane], p[2][lane]], [t.x, t.y, t.z]);
    }
}

#[test]
fn wrong_lengths_non_finite_values_and_foreign_batches_are_errors() {
    let m = model("icub_upper_body.ron");
    let n = m.motors().len();
    let mut batch = m.pose_batch();
    let e = m
        .forward_motors_batch(&vec![0.0; n], &mut batch)
        .unwrap_err()
        .to_string();
    assert!(e.contains(&format!("{}", LANES * n)), "{e}");
    let mut q = vec![0.0; LANES * n];
    q[2 * n + 5] = f64::NAN;
    let e = m
        .forward_motors_batch(&q, &mut batch)
        .unwrap_err()
        .to_string();
    assert!(e.contains(&m.motors()[5].name) && e.contains("NaN"), "{e}");
    let mut other = model("planar_arm.urdf").pose_batch();
    assert!(
        m.forward_motors_batch(&vec![0.0; LANES * n], &mut other)
            .is_err()
    );
}

#[test]
fn random_configurations_are_within_the_limits_and_seeded() {
    let model = model("icub_upper_body.ron");
    let active = model.all_active();
    let (lower, upper) = active.bounds();
    let mut rng = ChaCha8Rng::seed_from_u64(4);
    let samples: Vec<Vec<f64>> = (0..200).map(|_| active.random(&mut rng)).collect();
    for q in &samples {
        assert_eq!(q.len(), lower.len());
        assert!(
            q.iter()
                .zip(&lower)
                .zip(&upper)
                .all(|((v, l), u)| l <= v && v <= u)
        );
    }
    let mut again = ChaCha8Rng::seed_from_u64(4);
    assert_eq!(active.random(&mut again), samples[0]);
    assert_ne!(samples[0], samples[1]);
}

/// Single-precision blocks: every lane within a few units of 2⁻²⁴ per joint of the `f64` poses
/// (the bound the collision screen's margin is built on), on the official 75-joint iCub (the
/// deepest chains shipped) and a tree with prismatic, continuous and mimic joints; bad lengths
/// are errors.
#[test]
fn single_precision_blocks_stay_within_their_rounding_bound() {
    use trm_kinematics::BLOCK_LANES;
    for file in [
        "icub-visuomanip/model.urdf",
        "branched_tree.urdf",
        "icub_upper_body.ron",
    ] {
        let model = model(file);
        let active = model.all_active();
        let d = active.len();
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        let mut block = model.pose_block();
        let mut buffer = model.pose_buffer();
        let mut worst = 0.0f64;
        for _ in 0..50 {
            let q: Vec<f64> = (0..BLOCK_LANES)
                .flat_map(|_| active.random(&mut rng))
                .collect();
            active.forward_block(&q, &mut block).unwrap();
            for lane in 0..BLOCK_LANES {
                active
                    .forward(&q[lane * d..(lane + 1) * d], &mut buffer)
                    .unwrap();
                for (one, many) in buffer.poses().iter().zip(block.lanes()) {
                    let c = one.rotation.coords;
                    let t = one.translation.vector;
                    let exact = [c.w, c.x, c.y, c.z, t.x, t.y, t.z];
                    for (k, e) in exact.iter().enumerate() {
                        worst = worst.max((f64::from(many[k][lane]) - e).abs());
                    }
                }
            }
        }
        // measured: 5.7e-7 (official iCub), 5.6e-7 (upper body), 2.3e-7 (tree), with sines and
        // cosines in f32 (6.6e-7, 5.2e-7, 1.9e-7 when they were rounded from f64); the analysis
        // bound for 20 joints within 2 m is 20 × 8 × 2⁻²⁴ × 2 ≈ 2e-5
        assert!(worst < 2e-6, "{file}: {worst:e}");
        assert!(worst > 0.0, "{file}: f32 rounding should show");
        let e = active
            .forward_block(&vec![0.0; d], &mut block)
            .unwrap_err()
            .to_string();
        assert!(e.contains("active motor values"), "{e}");
    }
}

/// A pruned active set computes the kept links and their ancestors as the full one does, bit
/// for bit (one configuration, batches and single-precision blocks), and leaves every other
/// pose as it was.
#[test]
fn pruned_forward_kinematics_computes_the_kept_links_and_leaves_the_rest() {
    use trm_kinematics::BLOCK_LANES;
    let model = model("icub_upper_body.ron");
    let active = model.all_active();
    let d = active.len();
    let kept = [
        model.tree().link_index("r_hand").unwrap(),
        model.tree().link_index("head").unwrap(),
    ];
    let pruned = active.pruned_to(kept);
    assert!(pruned.num_distinct_joint_values() < active.num_distinct_joint_values());
    // the kept links' ancestors, by the parents of the tree
    let tree = model.tree();
    let mut needed = vec![false; model.num_links()];
    for &k in &kept {
        let mut l = k;
        needed[l] = true;
        while let Some(j) = tree.joints.iter().find(|j| j.child == l) {
            l = j.parent;
            needed[l] = true;
        }
    }
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    let (mut full, mut part) = (model.pose_buffer(), model.pose_buffer());
    let (mut full_block, mut part_block) = (model.pose_block(), model.pose_block());
    for _ in 0..20 {
        let q: Vec<f64> = (0..BLOCK_LANES)
            .flat_map(|_| active.random(&mut rng))
            .collect();
        active.forward(&q[..d], &mut full).unwrap();
        // stale poses: those of another configuration
        pruned.forward(&q[d..2 * d], &mut part).unwrap();
        active.forward(&q[d..2 * d], &mut part).unwrap();
        let stale = part.poses().to_vec();
        pruned.forward(&q[..d], &mut part).unwrap();
        for (l, (a, b)) in full.poses().iter().zip(part.poses()).enumerate() {
            if l < needed.len() && needed[l] {
                assert_eq!(a, b, "link {l}");
            } else {
                assert_eq!(*b, stale[l], "link {l} left as it was");
            }
        }
        active.forward_block(&q, &mut full_block).unwrap();
        let mut other = q.clone();
        other.rotate_left(d);
        active.forward_block(&other, &mut part_block).unwrap();
        let stale = part_block.lanes().to_vec();
        pruned.forward_block(&q, &mut part_block).unwrap();
        for (l, (a, b)) in full_block
            .lanes()
            .iter()
            .zip(part_block.lanes())
            .enumerate()
        {
            if l < needed.len() && needed[l] {
                assert_eq!(a, b, "link {l} (block)");
            } else {
                assert_eq!(*b, stale[l], "link {l} (block) left as it was");
            }
        }
    }
}
