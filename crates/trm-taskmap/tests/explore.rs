//! Exploration, files and the task-map cost on synthetic feasible sets with known shapes.

use trm_taskmap::{ExploreOptions, Metric, TaskMap, TaskMapError, explore, to_params, to_pose};

/// Feasible: along a 20 cm stick (|x| ≤ 0.1), within 1 cm of its axis, tilted at most 0.2 rad,
/// any roll about the axis (rotation vector component 3 free).
fn stick(g: &[f64; 6]) -> f64 {
    let off_axis = g[1].abs().max(g[2].abs());
    let tilt = g[4].abs().max(g[5].abs());
    (0.01 - off_axis).min(0.2 - tilt).min(0.1 - g[0].abs())
}

fn settings() -> ExploreOptions {
    ExploreOptions {
        iterations: 4000,
        ..ExploreOptions::around([0.0; 6], [0.15, 0.02, 0.02, 3.2, 0.3, 0.3])
    }
}

#[test]
fn the_rrt_explores_the_whole_stick_and_keeps_only_feasible_points() {
    let map = explore(&[[0.0; 6]], &settings(), &Metric::default(), stick).unwrap();
    assert!(map.points.len() > 100, "{}", map.points.len());
    assert!(
        map.points
            .iter()
            .all(|p| stick(&p.g) > 0.0 && p.value > 0.0)
    );
    let (lo, hi) = map
        .points
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), p| {
            (a.min(p.g[0]), b.max(p.g[0]))
        });
    assert!(lo < -0.08 && hi > 0.08, "x range [{lo}, {hi}]");
    // tree links are at most one step long
    for p in &map.points {
        if let Some(parent) = p.parent {
            assert!(map.metric.distance(&p.g, &map.points[parent].g) <= settings().step + 1e-12);
            assert_eq!(map.points[parent].cluster, p.cluster);
        }
    }
}

#[test]
fn restarts_find_disjoint_clusters() {
    // two separate sticks, 20 cm apart in y: one RRT cannot cross the gap
    let two = |g: &[f64; 6]| {
        let mut h = *g;
        h[1] = if g[1] > 0.1 { g[1] - 0.2 } else { g[1] };
        stick(&h)
    };
    let mut s = ExploreOptions {
        iterations: 6000,
        ..ExploreOptions::around(
            [0.0, 0.1, 0.0, 0.0, 0.0, 0.0],
            [0.15, 0.13, 0.02, 3.2, 0.3, 0.3],
        )
    };
    s.restarts = 3000;
    let map = explore(&[[0.0; 6]], &s, &Metric::default(), two).unwrap();
    let far = map.points.iter().filter(|p| p.g[1] > 0.1).count();
    assert!(
        map.clusters() >= 2 && far > 20,
        "{} clusters, {far} points on the second stick",
        map.clusters()
    );
    let mut single = s.clone();
    single.restarts = 0;
    let one = explore(&[[0.0; 6]], &single, &Metric::default(), two).unwrap();
    assert!(
        one.points.iter().all(|p| p.g[1] < 0.1),
        "without restarts the RRT stays on one stick"
    );
}

#[test]
fn bad_starts_and_metrics_are_clear_errors() {
    let e = explore(
        &[[0.0, 0.5, 0.0, 0.0, 0.0, 0.0]],
        &settings(),
        &Metric::default(),
        stick,
    )
    .unwrap_err();
    assert!(
        matches!(e, TaskMapError::InfeasibleStart { index: 0, .. }),
        "{e}"
    );
    let e = explore(
        &[[0.0; 6]],
        &settings(),
        &Metric {
            position: 1.0,
            orientation: 0.0,
        },
        stick,
    )
    .unwrap_err();
    assert!(e.to_string().contains("degenerate"), "{e}");
    let empty = explore(
        &[[0.0; 6]],
        &ExploreOptions {
            iterations: 0,
            ..settings()
        },
        &Metric::default(),
        stick,
    )
    .unwrap();
    assert_eq!(empty.points.len(), 1);
}

#[test]
fn maps_round_trip_and_the_cost_has_the_right_gradient() {
    let map = explore(&[[0.0; 6]], &settings(), &Metric::default(), stick).unwrap();
    let path = std::env::temp_dir().join(format!("trm-taskmap-{}.json", std::process::id()));
    map.save(&path).unwrap();
    let back = TaskMap::load(&path).unwrap();
    assert_eq!(back, map);
    std::fs::write(&path, "{\"points\": []}").unwrap();
    assert!(
        TaskMap::load(&path)
            .unwrap_err()
            .to_string()
            .contains("not a trm-taskmap file")
    );
    std::fs::remove_file(&path).unwrap();
    // zero at a map point, positive off the map, gradient = finite differences
    let on = map.points[7].g;
    assert_eq!(back.cost(&on).0, 0.0);
    let x = [0.03, 0.05, -0.04, 0.3, 0.6, -0.5];
    let (c, grad) = back.cost(&x);
    assert!(c > 0.0);
    for k in 0..6 {
        let h = 1e-7;
        let (mut xp, mut xm) = (x, x);
        xp[k] += h;
        xm[k] -= h;
        let fd = (back.cost(&xp).0 - back.cost(&xm).0) / (2.0 * h);
        assert!(
            (fd - grad[k]).abs() < 1e-5 * grad[k].abs().max(1.0),
            "{k}: {fd} vs {}",
            grad[k]
        );
    }
    // pose parameters round-trip
    let pose = to_pose(&[0.1, -0.2, 0.3, 0.4, -0.5, 0.6]);
    let g = to_params(&pose);
    assert!(
        (to_pose(&g).to_homogeneous() - pose.to_homogeneous())
            .abs()
            .max()
            < 1e-12
    );
}
