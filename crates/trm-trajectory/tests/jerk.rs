//! Jerk-limited stop-and-go motions: limits at 1 kHz, derivatives against finite differences,
//! the closed-form limit without jerk, bad input.

use proptest::prelude::*;
use trm_trajectory::{BlendedPath, JointLimits, TimingOptions, jerk_limited, time_optimal};

fn rest_to_rest(d: f64, v: f64, a: f64) -> f64 {
    if d >= v * v / a {
        d / v + v / a
    } else {
        2.0 * (d / a).sqrt()
    }
}

#[test]
fn without_a_jerk_limit_to_speak_of_the_trapezoid_returns() {
    let limits = JointLimits::new(vec![1.0], vec![2.0]).unwrap();
    for d in [0.1, 1.0, 3.0] {
        let motion = jerk_limited(&[vec![0.0], vec![d]], &limits, &[1e7]).unwrap();
        let best = rest_to_rest(d, 1.0, 2.0);
        assert!(
            (motion.duration() / best - 1.0).abs() < 1e-3,
            "{d}: {}",
            motion.duration()
        );
    }
    // a tight jerk limit costs time
    let slow = jerk_limited(&[vec![0.0], vec![1.0]], &limits, &[2.0]).unwrap();
    assert!(slow.duration() > rest_to_rest(1.0, 1.0, 2.0) * 1.2);
}

#[test]
fn bad_input_is_refused() {
    let limits = JointLimits::new(vec![1.0, 1.0], vec![1.0, 1.0]).unwrap();
    let path = [vec![0.0, 0.0], vec![1.0, 1.0]];
    for (jerk, needle) in [
        (vec![1.0, 0.0], "joint 1"),
        (vec![f64::NAN, 1.0], "joint 0"),
        (vec![1.0], "1 jerk limits"),
    ] {
        let e = jerk_limited(&path, &limits, &jerk).unwrap_err().to_string();
        assert!(e.contains(needle), "{e}");
    }
    let e = jerk_limited(
        &[vec![0.0, 0.0], vec![1.0, f64::INFINITY]],
        &limits,
        &[1.0, 1.0],
    );
    assert!(e.unwrap_err().to_string().contains("waypoint 1"));
    assert!(jerk_limited(&[], &limits, &[1.0, 1.0]).is_err());
    let still = jerk_limited(&[vec![0.5, 0.5]], &limits, &[1.0, 1.0]).unwrap();
    assert_eq!(still.duration(), 0.0);
    assert_eq!(still.sample(1.0).position, vec![0.5, 0.5]);
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]

    /// Random waypoints and limits: velocity, acceleration and jerk within limits at 1 kHz,
    /// reported derivatives those of the positions, the end exact, and never faster than the
    /// time-optimal motion without a jerk limit stopping at the same waypoints.
    #[test]
    fn random_motions_keep_every_limit(
        points in prop::collection::vec(prop::collection::vec(-2.0..2.0f64, 4), 2..6),
        velocity in prop::collection::vec(0.3..3.0f64, 4),
        acceleration in prop::collection::vec(0.5..20.0f64, 4),
        jerk in prop::collection::vec(1.0..200.0f64, 4),
    ) {
        let limits = JointLimits::new(velocity, acceleration).unwrap();
        let motion = jerk_limited(&points, &limits, &jerk).unwrap();
        let mut worst: f64 = 0.0;
        let steps = (motion.duration() / 1e-3).ceil() as usize;
        for k in 0..=steps {
            let (s, j) = motion.sample_with_jerk(k as f64 * 1e-3);
            for i in 0..4 {
                worst = worst.max(s.velocity[i].abs() / limits.velocity[i] - 1.0);
                worst = worst.max(s.acceleration[i].abs() / limits.acceleration[i] - 1.0);
                worst = worst.max(j[i].abs() / jerk[i] - 1.0);
            }
        }
        prop_assert!(worst <= 1e-6, "{worst}");
        let h = 1e-6;
        for k in 1..10 {
            let t = motion.duration() * k as f64 / 10.0;
            let (a, b, c) = (motion.sample(t - h), motion.sample(t), motion.sample(t + h));
            for i in 0..4 {
                let v = (c.position[i] - a.position[i]) / (2.0 * h);
                prop_assert!((v - b.velocity[i]).abs() < 1e-4 * (1.0 + v.abs()));
                let acc = (c.velocity[i] - a.velocity[i]) / (2.0 * h);
                prop_assert!((acc - b.acceleration[i]).abs() < 1e-3 * (1.0 + acc.abs()));
            }
        }
        let end = motion.sampled(0.01).unwrap();
        prop_assert_eq!(&end.last().unwrap().position, points.last().unwrap());
        let sharp = BlendedPath::new(&points, 0.0).unwrap();
        let optimal = time_optimal(&sharp, &limits, &TimingOptions::default()).unwrap();
        // (the time-optimal timing is exact up to its grid: an interval starting from rest
        // cannot switch from accelerating to cruising inside it, a few % at most)
        prop_assert!(motion.duration() >= optimal.duration() * 0.97);
    }
}
