//! Time-optimal timing of blended paths: against closed-form optima, limits at 1 kHz, the
//! blends' deviation, reported derivatives against finite differences of the positions.

use proptest::prelude::*;
use trm_trajectory::{BlendedPath, JointLimits, TimedPath, TimingOptions, time_optimal};

/// Time of a stop-to-stop segment of length `d` at speed `v`, acceleration `a` (trapezoid or
/// triangle): the closed-form optimum on a straight line.
fn rest_to_rest(d: f64, v: f64, a: f64) -> f64 {
    if d >= v * v / a {
        d / v + v / a
    } else {
        2.0 * (d / a).sqrt()
    }
}

fn timed(waypoints: &[Vec<f64>], deviation: f64, limits: &JointLimits) -> TimedPath {
    let path = BlendedPath::new(waypoints, deviation).unwrap();
    time_optimal(&path, limits, &TimingOptions::default()).unwrap()
}

/// Largest excess of any joint over its limits, relative, sampled at 1 kHz.
fn worst_excess(t: &TimedPath, limits: &JointLimits) -> f64 {
    let mut worst: f64 = 0.0;
    for s in t.sampled(1e-3).unwrap() {
        for j in 0..limits.velocity.len() {
            worst = worst.max(s.velocity[j].abs() / limits.velocity[j] - 1.0);
            worst = worst.max(s.acceleration[j].abs() / limits.acceleration[j] - 1.0);
        }
    }
    worst
}

#[test]
fn a_straight_segment_takes_the_closed_form_time() {
    for (d, v, a) in [(1.0, 1.0, 2.0), (0.2, 1.0, 2.0), (3.0, 0.5, 10.0)] {
        let limits = JointLimits::new(vec![v], vec![a]).unwrap();
        let t = timed(&[vec![0.0], vec![d]], 0.1, &limits);
        let best = rest_to_rest(d, v, a);
        let ratio = t.duration() / best;
        assert!(
            (1.0 - 1e-9..1.005).contains(&ratio),
            "d {d}: {} s for the optimum {best} s",
            t.duration()
        );
    }
}

#[test]
fn the_slowest_joint_sets_a_straight_segment_s_time() {
    // joint 0 moves 1 at 2 rad/s, 1 rad/s²; joint 1 moves 2 at 1 rad/s, 4 rad/s². Following
    // the line keeps them in step: in units of the segment, speed min(2/1, 1/2) = 0.5 and
    // acceleration min(1/1, 4/2) = 1
    let limits = JointLimits::new(vec![2.0, 1.0], vec![1.0, 4.0]).unwrap();
    let t = timed(&[vec![0.0, 0.0], vec![1.0, 2.0]], 0.1, &limits);
    let best = rest_to_rest(1.0, 0.5, 1.0);
    assert!(
        (t.duration() / best - 1.0).abs() < 0.005,
        "{}",
        t.duration()
    );
}

#[test]
fn limits_hold_at_1_khz_and_the_motion_ends_at_rest_at_the_goal() {
    let limits = JointLimits::new(vec![2.175, 2.175, 2.61], vec![3.75, 1.875, 5.0]).unwrap();
    let waypoints = vec![
        vec![0.0, 0.0, 0.0],
        vec![1.0, 0.5, -0.3],
        vec![1.2, -0.4, 0.8],
        vec![0.1, -0.5, 0.9],
    ];
    let t = timed(&waypoints, 0.2, &limits);
    assert!(worst_excess(&t, &limits) <= 1e-6);
    let end = t.sample(t.duration());
    assert!(distance(&end.position, &waypoints[3]) < 1e-9);
    assert!(end.velocity.iter().all(|v| v.abs() < 1e-9));
    let start = t.sample(0.0);
    assert_eq!(start.position, waypoints[0]);
    assert!(start.velocity.iter().all(|v| *v == 0.0));
}

#[test]
fn blending_beats_stopping_at_every_waypoint() {
    let limits = JointLimits::new(vec![1.0, 1.0], vec![2.0, 2.0]).unwrap();
    let waypoints: Vec<Vec<f64>> = vec![
        vec![0.0, 0.0],
        vec![1.0, 0.2],
        vec![2.0, 0.0],
        vec![3.0, 0.3],
    ];
    let stopping: f64 = waypoints
        .windows(2)
        .map(|w| {
            (0..2)
                .map(|j| rest_to_rest((w[1][j] - w[0][j]).abs(), 1.0, 2.0))
                .fold(0.0, f64::max)
        })
        .sum();
    let blended = timed(&waypoints, 0.1, &limits).duration();
    assert!(blended < 0.85 * stopping, "{blended} s vs {stopping} s");
    // no blend at all: the motion stops at every corner and takes about what stopping does
    let sharp = timed(&waypoints, 0.0, &limits).duration();
    assert!(sharp > blended && sharp <= stopping * 1.005, "{sharp} s");
}

#[test]
fn blends_stay_within_their_deviation_and_keep_the_tangent() {
    let waypoints = vec![
        vec![0.0, 0.0, 0.0],
        vec![1.0, 0.0, 0.0],
        vec![1.0, 1.0, 0.5],
    ];
    for deviation in [0.01, 0.1, 10.0] {
        let path = BlendedPath::new(&waypoints, deviation).unwrap();
        let blends = path.blends();
        assert_eq!(blends.len(), 1);
        let (corner, range) = blends[0].clone();
        assert_eq!(corner, 1);
        // the farthest point of the arc from the corner's lines is at its middle
        let mid = path.position((range.start + range.end) / 2.0);
        let off = distance(&mid, &waypoints[1]);
        assert!(off <= deviation + 1e-12, "{off} > {deviation}");
        // tangent continuous where the arc meets the lines
        let (mut q, mut before, mut after) = (vec![0.0; 3], vec![0.0; 3], vec![0.0; 3]);
        path.evaluate(range.start - 1e-9, &mut q, &mut before, &mut []);
        path.evaluate(range.start + 1e-9, &mut q, &mut after, &mut []);
        assert!(distance(&before, &after) < 1e-6);
        // at most half of each segment is cut
        assert!(range.start >= 0.5 - 1e-12);
    }
}

#[test]
fn a_path_that_turns_back_stops_at_the_turn() {
    let limits = JointLimits::new(vec![1.0], vec![1.0]).unwrap();
    let t = timed(&[vec![0.0], vec![1.0], vec![0.5]], 0.1, &limits);
    assert_eq!(t.path().stops(), &[0.0, 1.0, 1.5]);
    let best = rest_to_rest(1.0, 1.0, 1.0) + rest_to_rest(0.5, 1.0, 1.0);
    assert!((t.duration() / best - 1.0).abs() < 0.005);
    assert!(worst_excess(&t, &limits) <= 1e-6);
}

#[test]
fn bad_input_is_refused_with_the_place_named() {
    let nan = BlendedPath::new(&[vec![0.0, 0.0], vec![f64::NAN, 1.0]], 0.1).unwrap_err();
    assert!(nan.to_string().contains("waypoint 1, value 0"), "{nan}");
    let ragged = BlendedPath::new(&[vec![0.0, 0.0], vec![1.0]], 0.1).unwrap_err();
    assert!(
        ragged.to_string().contains("waypoint 1 has 1 values"),
        "{ragged}"
    );
    let deviation = BlendedPath::new(&[vec![0.0], vec![1.0]], -1.0).unwrap_err();
    assert!(deviation.to_string().contains("deviation"), "{deviation}");
    assert!(BlendedPath::new(&[], 0.1).is_err());
    let limits = JointLimits::new(vec![1.0, 0.0], vec![1.0, 1.0]).unwrap_err();
    assert!(limits.to_string().contains("joint 1"), "{limits}");
    let path = BlendedPath::new(&[vec![0.0, 0.0], vec![1.0, 1.0]], 0.1).unwrap();
    let one = JointLimits::new(vec![1.0], vec![1.0]).unwrap();
    assert!(time_optimal(&path, &one, &TimingOptions::default()).is_err());
    let scaled = one.scaled(1.5, 1.0).unwrap_err();
    assert!(scaled.to_string().contains("(0, 1]"), "{scaled}");
}

#[test]
fn a_single_point_is_a_motion_of_no_time() {
    let limits = JointLimits::new(vec![1.0], vec![1.0]).unwrap();
    let t = timed(&[vec![0.3]], 0.1, &limits);
    assert_eq!(t.duration(), 0.0);
    assert_eq!(t.sample(1.0).position, vec![0.3]);
}

fn distance(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).powi(2))
        .sum::<f64>()
        .sqrt()
}

/// A path the iCub's planner found (41 motors, most of them still): rows whose path
/// acceleration term is tiny beside their speed term once stalled the exact LP's steps; the
/// limits must hold anyway.
#[test]
fn a_41_motor_path_with_still_motors_keeps_its_limits() {
    let text = include_str!("fixtures/icub_arm_path.json");
    let waypoints: Vec<Vec<f64>> = text
        .trim()
        .trim_start_matches('[')
        .trim_end_matches(']')
        .split("], [")
        .map(|r| r.split(", ").map(|v| v.parse().unwrap()).collect())
        .collect();
    assert_eq!((waypoints.len(), waypoints[0].len()), (7, 41));
    let limits = JointLimits::new(vec![1.0; 41], vec![1.0; 41]).unwrap();
    for deviation in [0.05, 0.2] {
        let t = timed(&waypoints, deviation, &limits);
        assert!(worst_excess(&t, &limits) <= 1e-6, "deviation {deviation}");
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]

    /// Paths of 12 joints, some of them still and some barely moving, limits apart by orders
    /// of magnitude: every limit holds at 1 kHz.
    #[test]
    fn paths_with_still_and_slow_joints_keep_their_limits(
        points in prop::collection::vec(prop::collection::vec(-2.0..2.0f64, 12), 3..7),
        scale in prop::collection::vec(prop_oneof![Just(0.0), Just(1e-7), Just(1e-3), Just(1.0)], 12),
        velocity in prop::collection::vec(0.1..10.0f64, 12),
        acceleration in prop::collection::vec(0.1..50.0f64, 12),
    ) {
        let points: Vec<Vec<f64>> = points
            .iter()
            .map(|p| p.iter().zip(&scale).map(|(v, s)| v * s).collect())
            .collect();
        prop_assume!(points.windows(2).any(|w| distance(&w[0], &w[1]) > 1e-3));
        let limits = JointLimits::new(velocity, acceleration).unwrap();
        let t = timed(&points, 0.2, &limits);
        prop_assert!(worst_excess(&t, &limits) <= 1e-6);
    }

    /// Random paths and limits: every limit holds at 1 kHz; the reported velocities and
    /// accelerations are the derivatives of the reported positions; the path never leaves the
    /// polyline by more than the deviation.
    #[test]
    fn random_paths_keep_their_limits(
        points in prop::collection::vec(prop::collection::vec(-2.0..2.0f64, 3), 2..7),
        velocity in prop::collection::vec(0.3..3.0f64, 3),
        acceleration in prop::collection::vec(0.5..20.0f64, 3),
        deviation in 0.0..0.5f64,
    ) {
        let limits = JointLimits::new(velocity, acceleration).unwrap();
        let t = timed(&points, deviation, &limits);
        prop_assert!(worst_excess(&t, &limits) <= 1e-6);
        let h = 1e-6;
        for k in 1..20 {
            let at = t.duration() * k as f64 / 20.0;
            let (a, b, c) = (t.sample(at - h), t.sample(at), t.sample(at + h));
            for j in 0..3 {
                let v = (c.position[j] - a.position[j]) / (2.0 * h);
                prop_assert!((v - b.velocity[j]).abs() < 1e-4 * (1.0 + v.abs()), "v {v} vs {}", b.velocity[j]);
            }
            let polyline = points.windows(2).map(|w| segment_distance(&b.position, &w[0], &w[1])).fold(f64::INFINITY, f64::min);
            prop_assert!(polyline <= deviation + 1e-9, "{polyline} from the polyline");
        }
        let end = t.sample(t.duration());
        prop_assert!(distance(&end.position, points.last().unwrap()) < 1e-9);
    }
}

fn segment_distance(p: &[f64], a: &[f64], b: &[f64]) -> f64 {
    let ab: Vec<f64> = b.iter().zip(a).map(|(x, y)| x - y).collect();
    let len2: f64 = ab.iter().map(|v| v * v).sum();
    let t = if len2 > 0.0 {
        (p.iter()
            .zip(a)
            .zip(&ab)
            .map(|((p, a), d)| (p - a) * d)
            .sum::<f64>()
            / len2)
            .clamp(0.0, 1.0)
    } else {
        0.0
    };
    let closest: Vec<f64> = a.iter().zip(&ab).map(|(a, d)| a + t * d).collect();
    distance(p, &closest)
}
