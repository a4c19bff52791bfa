//! The stand-up problem on the whole iCub (specs/wholebody/standup.ron).

use trm_wholebody::{MotionSpec, WholeBody};

const SPEC: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../../specs/wholebody/standup.ron"
);

fn problem() -> WholeBody {
    WholeBody::load(SPEC).unwrap()
}

#[test]
fn the_desired_com_passes_exactly_through_the_start_and_end_com() {
    let p = problem();
    let (a, b) = p.com_waypoints();
    let times = [0.0, 1.0, 4.5];
    for params in [
        vec![0.0; 15],
        vec![0.7; 15],
        (0..15).map(|i| (i as f64).sin()).collect(),
    ] {
        let d = p.desired_com(&params, 4.5, &times).unwrap();
        assert!((d[0][0] - a.x).abs() < 1e-12 && (d[0][1] - a.y).abs() < 1e-12);
        assert!((d[2][0] - b.x).abs() < 1e-12 && (d[2][1] - b.y).abs() < 1e-12);
    }
}

#[test]
fn symmetric_sagittal_postures_keep_both_soles_flat_on_the_ground() {
    // the closed double-support chain: with the left sole fixed, the right sole stays put
    let p = problem();
    let model = p.model();
    let active = model.all_active();
    let (l, r) = (
        model.frame_id("l_sole").unwrap(),
        model.frame_id("r_sole").unwrap(),
    );
    let mut poses = model.pose_buffer();
    let (start, keys) = p.keyframes();
    let mut first = None;
    for q in [
        start,
        &keys[0][..],
        &keys[1][..],
        &[0.5, -0.9, 0.2, 0.3, -0.5, 0.4, 0.1, 1.0][..],
    ] {
        active.forward(q, &mut poses).unwrap();
        let rel = poses.pose(l).inverse() * poses.pose(r);
        let first = *first.get_or_insert(rel);
        assert!((rel.translation.vector - first.translation.vector).norm() < 2e-4);
        assert!(rel.rotation.angle_to(&first.rotation) < 1e-6);
    }
}

#[test]
fn static_torques_are_the_gradient_of_the_potential_energy_with_the_feet_fixed() {
    // the controller's analytic ground-frame CoM Jacobian against central differences of the
    // CoM with the feet fixed: τ = m g ∂z_com/∂q, split over the two joints of a symmetric motor
    let p = problem();
    let r = p.hand_tuned().unwrap();
    let i = r.phase.iter().position(|&ph| ph == 1).unwrap() + 100;
    let q = &r.q[i];
    let h = 1e-6;
    for (k, m) in p.model().motors().iter().enumerate() {
        let (mut up, mut down) = (q.clone(), q.clone());
        up[k] += h;
        down[k] -= h;
        let dz = (p.com_at(&up)[2] - p.com_at(&down)[2]) / (2.0 * h);
        let joints = if m.name == "torso_pitch" { 1.0 } else { 2.0 };
        let expected = p.mass() * 9.81 * dz / joints;
        assert!(
            (r.torque[i][k] - expected).abs() < 1e-5 * (1.0 + expected.abs()),
            "{}: {} vs {}",
            m.name,
            r.torque[i][k],
            expected
        );
    }
    // the knees carry the body when standing; the seated start CoM is behind the feet, the
    // standing one above them
    assert!(r.torque[i][1].abs() > 1.0);
    let feet = p.feet_polygon();
    let (a, b) = p.com_waypoints();
    assert!(a.x < feet[0] && b.x > feet[0] && b.x < feet[1]);
}

#[test]
fn the_hand_tuned_trajectory_violates_what_the_independent_check_finds() {
    let p = problem();
    let r = p.hand_tuned().unwrap();
    assert!(r.violations() > 0);
    let names = trm_wholebody::constraint_names(&p);
    let violated: Vec<&str> = names
        .iter()
        .zip(&r.violated_samples)
        .filter(|(_, n)| **n > 0)
        .map(|(s, _)| s.as_str())
        .collect();
    let check = p.verify(&r);
    assert!(
        violated.iter().any(|v| v.starts_with("ZMP")),
        "{violated:?}"
    );
    assert!(check.iter().any(|c| c.starts_with("ZMP")), "{check:?}");
    assert!(
        check
            .iter()
            .any(|c| c.starts_with("shoulder_pitch position")),
        "{check:?}"
    );
    assert!(
        !r.fallen,
        "the hand-tuned motion keeps the ZMP on the real feet"
    );
}

#[test]
fn bootstrap_then_cca_finds_a_feasible_better_trajectory_reproducibly() {
    let mut spec = problem().spec().clone();
    spec.optimiser.bootstrap_rollouts = 700;
    spec.optimiser.rollouts = 60;
    let text = std::fs::read_to_string(SPEC).unwrap();
    let p = WholeBody::new(spec, trm_models::icub_sagittal(), SPEC, &text).unwrap();
    let a = trm_wholebody::optimize(&p, 1, |_, _| {}).unwrap();
    assert!(a.feasible);
    let best = a.solutions.last().unwrap();
    assert_eq!(best.name, "constrained");
    assert_eq!(best.rollout.violations(), 0);
    assert!(
        p.verify(&best.rollout).is_empty(),
        "{:?}",
        p.verify(&best.rollout)
    );
    let boot = a
        .solutions
        .iter()
        .find(|s| s.name == "unconstrained")
        .unwrap();
    assert!(best.phi_co <= boot.phi_co);
    assert!(best.normalised.com_error < 1.0 && best.normalised.effort < 1.0);
    let b = trm_wholebody::optimize(&p, 1, |_, _| {}).unwrap();
    assert_eq!(a, b, "same seed, same result");
}

#[test]
fn spec_errors_name_the_place_and_the_fix() {
    let text = std::fs::read_to_string(SPEC).unwrap();
    let bad = text.replace("\"torso_pitch\": 60", "\"torso_pich\": 60");
    let spec = MotionSpec::from_ron(&bad, "standup.ron").unwrap();
    let e = WholeBody::new(spec, trm_models::icub_sagittal(), "standup.ron", &bad)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("standup.ron:") && e.contains("torso_pich") && e.contains("torso_pitch"),
        "{e}"
    );
    let bad = text.replace("end: 1.5", "end: 5.0");
    let e = MotionSpec::from_ron(&bad, "standup.ron")
        .unwrap_err()
        .to_string();
    assert!(e.contains("do not increase"), "{e}");
    let bad = text.replace("rbfs: 5,", "rbfs: 4,");
    let e = MotionSpec::from_ron(&bad, "standup.ron")
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("hand_tuned.params") && e.contains("12 values"),
        "{e}"
    );
    let bad = text.replace("support_margin: 0.015", "support_margin: 0.5");
    let e = MotionSpec::from_ron(&bad, "standup.ron")
        .unwrap_err()
        .to_string();
    assert!(e.contains("support_margin"), "{e}");
    let bad = text.replace(
        "keyframe: {\"torso_pitch\": 60",
        "keyframe: {\"torso_pitch\": 95",
    );
    let spec = MotionSpec::from_ron(&bad, "standup.ron").unwrap();
    let e = WholeBody::new(spec, trm_models::icub_sagittal(), "standup.ron", &bad)
        .unwrap_err()
        .to_string();
    assert!(e.contains("outside") && e.contains("torso_pitch"), "{e}");
}

#[test]
fn the_same_machinery_reaches_towards_a_low_shelf() {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../specs/wholebody/low_shelf.ron"
    );
    let p = WholeBody::load(path).unwrap();
    let names = trm_wholebody::constraint_names(&p);
    assert_eq!(names.last().unwrap(), "reach target");
    let (start, _) = p.keyframes();
    let palm = p.point_at(start, "l_palm_center").unwrap();
    let target = p.spec().reach.as_ref().unwrap().target;
    let r = p.rollout(&[0.0; 15], &p.ends()).unwrap();
    let last = r.hand.last().unwrap();
    let before = ((palm[0] - target.0).powi(2) + (palm[2] - target.1).powi(2)).sqrt();
    assert!(
        r.costs.reach < 0.2 * before,
        "{} vs {before}",
        r.costs.reach
    );
    assert!((last[0] - palm[0]).abs() > 0.0);
    // the slow hand-tuned reach misses its target and touches the shelf: both found twice
    let hand = p.hand_tuned().unwrap();
    let check = p.verify(&hand);
    assert!(
        check.iter().any(|c| c.starts_with("reach target missed")),
        "{check:?}"
    );
    assert!(
        check.iter().any(|c| c.starts_with("world collision")),
        "{check:?}"
    );
    let i = names.iter().position(|n| n == "world collision").unwrap();
    assert!(hand.violated_samples[i] > 0 && hand.violated_samples[names.len() - 1] == 1);
}

/// A rollout as a ROS 2 JointTrajectory: one point per control step, the URDF joints without
/// mimics, joint velocities that match the positions' finite differences.
#[test]
fn a_rollout_exports_as_a_ros_joint_trajectory() {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../specs/wholebody/low_shelf.ron"
    );
    let p = WholeBody::load(path).unwrap();
    let r = p.rollout(&[0.0; 15], &p.ends()).unwrap();
    let text = r.to_ros_yaml(p.model()).unwrap();
    let points = text.matches("  - positions: [").count();
    assert_eq!(points, r.times.len());
    let numbers = |line: &str| -> Vec<f64> {
        let inner = line.split('[').nth(1).unwrap().trim_end_matches(']');
        inner.split(", ").map(|v| v.parse().unwrap()).collect()
    };
    let positions: Vec<Vec<f64>> = text
        .lines()
        .filter(|l| l.starts_with("  - positions:"))
        .map(numbers)
        .collect();
    let velocities: Vec<Vec<f64>> = text
        .lines()
        .filter(|l| l.starts_with("    velocities:"))
        .map(numbers)
        .collect();
    // the middle of the motion, where it moves: central differences against the velocities
    let k = r.times.len() / 2;
    let dt = r.times[k + 1] - r.times[k - 1];
    let scale = velocities[k].iter().fold(0.0f64, |m, v| m.max(v.abs()));
    assert!(scale > 0.0, "the motion moves at step {k}");
    for j in 0..positions[k].len() {
        let fd = (positions[k + 1][j] - positions[k - 1][j]) / dt;
        assert!(
            (fd - velocities[k][j]).abs() <= 0.05 * scale,
            "joint {j}: {fd} vs {}",
            velocities[k][j]
        );
    }
}

#[test]
fn budgets_given_at_load_replace_the_specs_and_are_checked_as_its_own() {
    let problem = WholeBody::load_with_budgets(SPEC, Some(7), Some(3)).unwrap();
    assert_eq!(problem.spec().optimiser.rollouts, 7);
    assert_eq!(problem.spec().optimiser.bootstrap_rollouts, 3);
    let e = WholeBody::load_with_budgets(SPEC, Some(100_000_000), None).unwrap_err();
    let text = e.to_string();
    assert!(
        text.contains("optimiser.rollouts") && text.contains("standup.ron"),
        "{text}"
    );
}
