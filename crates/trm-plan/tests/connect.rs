//! Queries between two postures (`Planner::connect`) round an obstacle: experience kept, saved
//! and loaded; a graph that can only help, taking turns with RRT-Connect; corner cutting.

use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use trm_collision::{Shape, World};
use trm_kinematics::nalgebra::Isometry3;
use trm_plan::rrt::{RrtOptions, path_length};
use trm_plan::{HEAD_START_SAMPLES, Planner, ROUND_GROWTH, Source};

/// The iCub's right arm (3 motors) beside a pole, a start (home) and a goal behind the pole.
fn arm_beside_a_pole() -> (trm_tasks::Objective, Vec<f64>, Vec<f64>) {
    let robot = trm_models::icub_upper_body();
    let home = robot.posture("home").unwrap().to_vec();
    let arm = ["r_shoulder_pitch", "r_shoulder_roll", "r_elbow"];
    let active = robot.active_set(&arm, &home).unwrap();
    let mut world = World::new();
    let pole = Shape::Box {
        size: [0.04, 0.04, 2.0],
    };
    world
        .add("pole", pole, Isometry3::translation(-0.25, 0.3, 0.0))
        .unwrap();
    let collision = trm_collision::CollisionModel::new(&robot).unwrap();
    let objective = trm_tasks::Objective::new(active, collision, world);
    let start = objective.active().from_motors(&home);
    let goal = vec![start[0] - 1.2, start[1] + 0.6, start[2] + 0.5];
    (objective, start, goal)
}

#[test]
fn experience_is_saved_and_loaded_whole_or_refused_whole() {
    let (objective, start, goal) = arm_beside_a_pole();
    let options = RrtOptions::default();
    let mut kept = Planner::new(&objective, &[]).unwrap();
    let first = kept.connect(&start, &goal, &options).unwrap();
    // a path without waypoints is refused, and keeps nothing a later query would trip on
    let e = kept.add_path(&[]).unwrap_err().to_string();
    assert!(e.contains("no waypoints"), "{e}");
    assert!(kept.kept_paths().is_empty());
    kept.add_path(&first.path).unwrap();
    let dir = std::env::temp_dir().join(format!("trm-experience-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("arm.experience.json");
    kept.save_experience(&file).unwrap();
    let mut fresh = Planner::new(&objective, &[]).unwrap();
    assert_eq!(fresh.load_experience(&file).unwrap(), 1);
    assert_eq!(fresh.kept_paths(), kept.kept_paths());
    let again = fresh.connect(&start, &goal, &options).unwrap();
    assert_eq!(again.source, Source::Retrieved);
    assert_eq!(again.path, first.path);
    // refused whole: other motors, a short waypoint, a cut file, another kind of file
    let text = std::fs::read_to_string(&file).unwrap();
    let bad = |name: &str, text: &str| {
        let path = dir.join(name);
        std::fs::write(&path, text).unwrap();
        let mut planner = Planner::new(&objective, &[]).unwrap();
        let e = planner.load_experience(&path).unwrap_err().to_string();
        assert_eq!(planner.num_nodes(), 0, "{name}: {e}");
        assert!(e.contains(name), "{e}");
        e
    };
    let e = bad("motors.json", &text.replace("r_elbow", "l_elbow"));
    assert!(
        e.contains("l_elbow") && e.contains("the planner moves"),
        "{e}"
    );
    let short = text.replacen("[[[", "[[[1.0],[", 1);
    assert!(bad("short.json", &short).contains("1 values, not 3"));
    assert!(bad("cut.json", &text[..text.len() / 2]).contains("truncated"));
    let other = text.replace("trm-experience", "trm-map");
    assert!(bad("other.json", &other).contains("not a trm-experience file"));
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The pole's query with short steps (RRT-Connect needs more samples than its head start): the
/// objective, start, goal and options, a planner without a graph, and one that keeps the path
/// it found.
fn one_path_kept() -> (
    trm_tasks::Objective,
    Vec<f64>,
    Vec<f64>,
    RrtOptions,
    Planner,
    Planner,
) {
    let (objective, start, goal) = arm_beside_a_pole();
    let short = RrtOptions {
        range: 0.1,
        resolution: 0.05,
        ..Default::default()
    };
    let plain = Planner::new(&objective, &[]).unwrap();
    let mut kept = Planner::new(&objective, &[]).unwrap();
    let first = kept.connect(&start, &goal, &short).unwrap();
    assert_eq!(first.source, Source::Sampled);
    kept.add_path(&first.path).unwrap();
    (objective, start, goal, short, plain, kept)
}

/// The `k`th query near the kept one (farther than a retrieval's reach).
fn near_query(start: &[f64], goal: &[f64], k: usize) -> (Vec<f64>, Vec<f64>) {
    let angle = k as f64 * 0.5;
    let (c, s) = (0.15 * angle.cos(), 0.15 * angle.sin());
    let a = vec![start[0] + c, start[1] + s, start[2] - c];
    let b = vec![goal[0] - s, goal[1] + c, goal[2] + s];
    (a, b)
}

#[test]
fn a_graph_attached_to_connect_can_only_help() {
    let (_, start, goal, short, mut plain, mut kept) = one_path_kept();
    let (mut sampled, mut through_graph) = (0, 0);
    // queries near the kept one, with and without it, with short steps and with the default
    // ones (RRT-Connect answers most in its head start)
    let default = RrtOptions::default();
    for k in 0..24 {
        let options = if k < 12 { &short } else { &default };
        let (a, b) = near_query(&start, &goal, k);
        if !plain.is_free(&a) || !plain.is_free(&b) {
            continue;
        }
        let without = plain.connect(&a, &b, options).unwrap();
        let with = kept.connect(&a, &b, options).unwrap();
        match with.source {
            // RRT-Connect drew the same samples, with or without the graph
            Source::Sampled | Source::Straight => {
                sampled += 1;
                assert_eq!(with.path, without.path, "query {k}");
                assert_eq!(with.iterations, without.iterations, "query {k}");
            }
            Source::Graph | Source::Retrieved => {
                through_graph += 1;
                // at the end of one of RRT-Connect's rounds (the head start, then fourfold
                // ones), which RRT-Connect alone ends without an answer
                let rounds: Vec<usize> = (0..8)
                    .map(|r| HEAD_START_SAMPLES * ROUND_GROWTH.pow(r))
                    .collect();
                assert!(
                    rounds.contains(&with.iterations),
                    "query {k}: {}",
                    with.iterations
                );
                assert!(
                    without.iterations > with.iterations,
                    "query {k}: {} samples alone, {} with the graph",
                    without.iterations,
                    with.iterations
                );
                assert_eq!(with.path.first(), Some(&a));
                assert_eq!(with.path.last(), Some(&b));
                for w in with.path.windows(2) {
                    assert!(plain.segment_free(&w[0], &w[1], options.resolution / 4.0));
                }
            }
        }
    }
    assert!(
        sampled > 0 && through_graph > 0,
        "{sampled} answered by RRT-Connect, {through_graph} through the graph"
    );
}

#[test]
fn a_graph_whose_searches_outweigh_the_sampling_waits_its_turn() {
    let (objective, start, goal, short, mut plain, mut kept) = one_path_kept();
    // the same kept path among 1 500 free postures: a graph whose every search visits more
    // elements than these queries' sampling is worth (`GRAPH_SHARE`, `ELEMENTS_PER_CHECK`)
    let (lower, upper) = objective.active().bounds();
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    let mut added = 0;
    while added < 1500 {
        let q: Vec<f64> = lower
            .iter()
            .zip(&upper)
            .map(|(l, u)| rng.random_range(*l..*u))
            .collect();
        if plain.is_free(&q) {
            kept.add_path(&[q]).unwrap();
            added += 1;
        }
    }
    // the queries the small graph answers (the test above): RRT-Connect answers them here,
    // with the samples and path it draws without a graph
    for k in 0..12 {
        let (a, b) = near_query(&start, &goal, k);
        if !plain.is_free(&a) || !plain.is_free(&b) {
            continue;
        }
        let without = plain.connect(&a, &b, &short).unwrap();
        let with = kept.connect(&a, &b, &short).unwrap();
        assert_eq!(with.source, without.source, "query {k}");
        assert_eq!(with.path, without.path, "query {k}");
        assert_eq!(with.iterations, without.iterations, "query {k}");
    }
}

/// Corner cutting (`RrtOptions::smoothing`) never lengthens a path, shortens the detours
/// RRT-Connect takes round the pole, and keeps every path free at half the resolution.
#[test]
fn corner_cutting_shortens_paths_and_keeps_them_free() {
    let (objective, start, goal) = arm_beside_a_pole();
    let mut planner = Planner::new(&objective, &[]).unwrap();
    let (mut shorter, mut total) = (0, 0);
    for seed in 0..12 {
        let plain = RrtOptions {
            seed,
            smoothing: 0,
            ..Default::default()
        };
        let smoothed = RrtOptions {
            smoothing: trm_plan::rrt::SMOOTHING_ROUNDS,
            ..plain.clone()
        };
        let a = planner.connect(&start, &goal, &plain).unwrap();
        let b = planner.connect(&start, &goal, &smoothed).unwrap();
        let (la, lb) = (path_length(&a.path), path_length(&b.path));
        assert!(lb <= la + 1e-9, "seed {seed}: {lb} > {la}");
        shorter += usize::from(lb < la - 1e-6);
        total += 1;
        assert_eq!(b.path.first(), Some(&start));
        assert_eq!(b.path.last(), Some(&goal));
        for w in b.path.windows(2) {
            assert!(planner.segment_free(&w[0], &w[1], smoothed.resolution / 2.0));
        }
    }
    assert!(shorter * 2 >= total, "{shorter} of {total} paths shortened");
}

/// Among many kept paths, a query repeating one's ends (either way round, each end moved up to
/// the retrieval's reach) gets that path, and one whose end lies beyond the reach gets none.
#[test]
fn among_many_kept_paths_the_repeated_one_is_retrieved() {
    let (objective, _, _) = arm_beside_a_pole();
    let options = RrtOptions::default();
    let near = trm_plan::RETRIEVE_STEPS * options.resolution;
    let mut planner = Planner::new(&objective, &[]).unwrap();
    let (lower, upper) = objective.active().bounds();
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    let mut random = |planner: &mut Planner| loop {
        let q: Vec<f64> = (lower.iter().zip(&upper))
            .map(|(l, u)| rng.random_range(*l + 0.1..*u - 0.1))
            .collect();
        if planner.is_free(&q) {
            return q;
        }
    };
    let mut paths = Vec::new();
    while paths.len() < 150 {
        let (a, b) = (random(&mut planner), random(&mut planner));
        if planner.segment_free(&a, &b, options.resolution) {
            planner.add_path(&[a.clone(), b.clone()]).unwrap();
            paths.push((a, b));
        }
    }
    // an end moved by `by` along the diagonal (its distance: `by`)
    let moved = |q: &[f64], by: f64| -> Vec<f64> {
        let step = by / (q.len() as f64).sqrt();
        q.iter().map(|v| v + step).collect()
    };
    let mut retrieved = 0;
    for (k, (a, b)) in paths.iter().enumerate().step_by(10) {
        // both ends moved the same way: the keys differ by as much as they can
        let (s, g) = (moved(a, 0.99 * near), moved(b, 0.99 * near));
        let (s, g) = if k % 20 == 0 { (g, s) } else { (s, g) };
        if !planner.is_free(&s) || !planner.is_free(&g) {
            continue;
        }
        let found = planner.connect(&s, &g, &options).unwrap();
        assert_eq!(found.source, Source::Retrieved, "path {k}");
        assert_eq!(
            (found.path.first(), found.path.last()),
            (Some(&s), Some(&g))
        );
        retrieved += 1;
        let far = moved(b, 1.5 * near);
        if planner.is_free(&far) {
            let found = planner.connect(a, &far, &options).unwrap();
            assert_ne!(
                found.source,
                Source::Retrieved,
                "path {k}, beyond the reach"
            );
        }
    }
    assert!(retrieved >= 10, "{retrieved} queries tried");
}
