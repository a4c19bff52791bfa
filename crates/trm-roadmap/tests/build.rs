//! Map construction: spacing, collision-freedom, determinism across thread counts, files.

use std::path::{Path, PathBuf};

use std::sync::Mutex;

use trm_roadmap::{
    BuildOptions, Builder, Checkpoint, CheckpointOptions, Roadmap, Team, connect, on_threads,
};
use trm_tasks::Problem;

fn reach() -> Problem {
    Problem::load(Path::new(env!("CARGO_MANIFEST_DIR")).join("../../specs/reach.ron")).unwrap()
}

fn small(problem: &Problem, threads: usize) -> Roadmap {
    let options = BuildOptions {
        points: Some(25),
        ..Default::default()
    };
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap()
        .install(|| {
            let mut map = Builder::new(problem, &options).run(|_| {}).unwrap();
            connect(&mut map, &problem.objective, 6, 0.05).unwrap();
            map
        })
}

fn tmp(name: &str) -> PathBuf {
    std::env::temp_dir().join(format!("trm-roadmap-{}-{name}", std::process::id()))
}

#[test]
fn map_points_are_collision_free_spaced_and_the_same_on_any_thread_count() {
    let problem = reach();
    let one = small(&problem, 1);
    let two = small(&problem, 2);
    assert_eq!(one.points, two.points);
    assert_eq!(one.edges, two.edges);
    assert_eq!(one.points.len(), 25);
    let d = one.settings.spacing;
    let mut scratch = problem.objective.scratch();
    for (i, p) in one.points.iter().enumerate() {
        assert!(
            problem.objective.is_collision_free(&p.q, &mut scratch),
            "point {i} collides"
        );
        for (j, o) in one.points.iter().enumerate().skip(i + 1) {
            let dt: f64 =
                p.t.iter()
                    .zip(&o.t)
                    .map(|(a, b)| (a - b).powi(2))
                    .sum::<f64>()
                    .sqrt();
            assert!(dt >= d / 2.0 - 1e-12, "points {i} and {j} are {dt} apart");
        }
        // the stored task vector is g(q)
        let g = problem.objective.task_value(&p.q, &mut scratch);
        assert_eq!(g, p.t);
    }
    assert!(!one.edges.is_empty());
    assert!(
        one.edges
            .iter()
            .all(|&(a, b, _)| a < b && b < one.points.len())
    );
}

/// A build resumed from a checkpoint gives exactly the map of the uninterrupted build: from the
/// last checkpoint of a shorter build (the state a longer one passes through) and from one
/// written in the middle, on another thread count; damaged checkpoints and changed settings are
/// errors.
#[test]
fn resumed_builds_give_the_uninterrupted_map() {
    let problem = reach();
    let pool = |threads| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
    };
    let whole = Builder::new(
        &problem,
        &BuildOptions {
            points: Some(60),
            ..Default::default()
        },
    )
    .run(|_| {})
    .unwrap();
    let path = tmp("resume.checkpoint");
    let first = BuildOptions {
        points: Some(35),
        checkpoint: Some(CheckpointOptions {
            path: path.clone(),
            every: 10,
        }),
        ..Default::default()
    };
    // checkpoints in the middle: seen by the progress callback after they are written
    let mut middle = None;
    pool(1).install(|| {
        Builder::new(&problem, &first)
            .run(|p| {
                if p.points >= 20 && middle.is_none() {
                    middle = Some(Checkpoint::load(&path).unwrap());
                }
            })
            .unwrap()
    });
    let middle = middle.unwrap();
    assert!((10..35).contains(&middle.points()), "{}", middle.points());
    let last = Checkpoint::load(&path).unwrap();
    assert_eq!(last.points(), 35);
    for checkpoint in [middle, last] {
        let problem = checkpoint.problem().unwrap();
        let options = BuildOptions {
            points: Some(60),
            ..Default::default()
        };
        let resumed = pool(2)
            .install(|| {
                Builder::new(&problem, &options)
                    .resume(checkpoint)
                    .run(|_| {})
            })
            .unwrap();
        assert_eq!(resumed.points, whole.points);
        assert_eq!(resumed.stats.evaluations, whole.stats.evaluations);
        assert_eq!(resumed.stats.searches_started, whole.stats.searches_started);
        assert_eq!(resumed.stats.failures, whole.stats.failures);
    }
    // changed settings, damaged files
    let checkpoint = Checkpoint::load(&path).unwrap();
    let e = Builder::new(
        &problem,
        &BuildOptions {
            seed: Some(7),
            ..Default::default()
        },
    )
    .resume(checkpoint.clone())
    .run(|_| {})
    .unwrap_err()
    .to_string();
    assert!(
        e.contains("seed 0") && e.contains("leave the seed option out"),
        "{e}"
    );
    let specs = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../specs");
    let other = Problem::from_ron(&format!("{} ", problem.text), &problem.origin, &specs).unwrap();
    let e = Builder::new(&other, &BuildOptions::default())
        .resume(checkpoint)
        .run(|_| {})
        .unwrap_err()
        .to_string();
    assert!(e.contains("Checkpoint::problem"), "{e}");
    let bytes = std::fs::read(&path).unwrap();
    let damaged = tmp("damaged.checkpoint");
    for (what, content) in [
        ("truncated", bytes[..bytes.len() / 2].to_vec()),
        ("checksum", {
            let mut b = bytes.clone();
            b[bytes.len() / 3] ^= 1;
            b
        }),
        (
            "not a trm-checkpoint",
            b"{\"format\": \"trm-roadmap\"}".to_vec(),
        ),
    ] {
        std::fs::write(&damaged, content).unwrap();
        let e = Checkpoint::load(&damaged).unwrap_err().to_string();
        assert!(e.contains(what) && e.contains("damaged.checkpoint"), "{e}");
    }
    let _ = std::fs::remove_file(&path);
    let _ = std::fs::remove_file(&damaged);
}

/// `f` run by every member of a team of `size` threads, in rank order.
fn on_team<T: Send>(size: usize, f: impl Fn(&mut dyn Team) -> T + Sync) -> Vec<T> {
    let all = Mutex::new(Vec::new());
    on_threads(
        size,
        1,
        |team, _| {
            let rank = team.rank();
            let value = f(team);
            all.lock().unwrap().push((rank, value));
            Ok(())
        },
        |_| {},
    )
    .unwrap();
    let mut all = all.into_inner().unwrap();
    all.sort_by_key(|(rank, _)| *rank);
    all.into_iter().map(|(_, value)| value).collect()
}

/// A build shared among 2 or 3 processes (threads here, MPI ranks in `xtask/tests/mpi.rs`),
/// each running some of the searches and a slice of the edge checks, gives every one of them
/// the map one process builds, edges included; a checkpoint written by a team of 3 resumes on
/// a team of 2 to it; a member that fails stops the others (no hang) with its own error.
#[test]
fn a_build_shared_among_processes_gives_the_map_of_one() {
    let problem = reach();
    let options = BuildOptions {
        points: Some(40),
        ..Default::default()
    };
    let alone = Builder::new(&problem, &options)
        .connected()
        .run_with(&mut trm_roadmap::Solo, |_| {})
        .unwrap();
    for size in [2, 3] {
        let maps = on_team(size, |team| {
            Builder::new(&problem, &options)
                .connected()
                .run_with(team, |_| {})
                .unwrap()
        });
        for (rank, map) in maps.iter().enumerate() {
            assert_eq!(map.points, alone.points, "{size} processes, rank {rank}");
            assert_eq!(map.edges, alone.edges, "{size} processes, rank {rank}");
            assert_eq!(map.stats.evaluations, alone.stats.evaluations);
            assert_eq!(map.stats.searches_started, alone.stats.searches_started);
        }
    }
    let path = tmp("team.checkpoint");
    let first = BuildOptions {
        points: Some(25),
        checkpoint: Some(CheckpointOptions {
            path: path.clone(),
            every: 10,
        }),
        ..Default::default()
    };
    on_team(3, |team| {
        Builder::new(&problem, &first)
            .connected()
            .run_with(team, |_| {})
            .unwrap()
    });
    let checkpoint = Checkpoint::load(&path).unwrap();
    assert_eq!(checkpoint.points(), 25);
    let maps = on_team(2, |team| {
        let checkpoint = checkpoint.clone();
        Builder::new(&problem, &options)
            .connected()
            .resume(checkpoint)
            .run_with(team, |_| {})
            .unwrap()
    });
    for map in maps {
        assert_eq!(map.points, alone.points);
        assert_eq!(map.edges, alone.edges);
        assert_eq!(map.stats.evaluations, alone.stats.evaluations);
    }
    let _ = std::fs::remove_file(&path);
    // rank 0 cannot write its checkpoint (its directory would be a file): the build on 2
    // threads ends with that error
    let file = tmp("not-a-dir");
    std::fs::write(&file, "").unwrap();
    let nowhere = BuildOptions {
        checkpoint: Some(CheckpointOptions {
            path: file.join("map.checkpoint"),
            every: 5,
        }),
        ..options.clone()
    };
    let e = rayon::ThreadPoolBuilder::new()
        .num_threads(2)
        .build()
        .unwrap()
        .install(|| Builder::new(&problem, &nowhere).connected().run(|_| {}))
        .unwrap_err()
        .to_string();
    assert!(e.contains("not-a-dir"), "{e}");
    let _ = std::fs::remove_file(&file);
}

#[test]
fn maps_round_trip_through_files_and_bad_files_are_clear_errors() {
    let problem = reach();
    let map = small(&problem, 2);
    let path = tmp("map.json");
    map.save(&path).unwrap();
    let back = Roadmap::load(&path).unwrap();
    assert_eq!(back, map);
    assert!(back.spec.contains("r_palm_center"));
    // truncated
    let text = std::fs::read_to_string(&path).unwrap();
    std::fs::write(&path, &text[..text.len() / 2]).unwrap();
    let e = Roadmap::load(&path).unwrap_err().to_string();
    assert!(e.contains("truncated"), "{e}");
    // foreign JSON
    std::fs::write(&path, "{\"points\": []}").unwrap();
    let e = Roadmap::load(&path).unwrap_err().to_string();
    assert!(e.contains("not a trm-roadmap file"), "{e}");
    // newer version
    std::fs::write(&path, text.replacen("\"version\":1", "\"version\":99", 1)).unwrap();
    let e = Roadmap::load(&path).unwrap_err().to_string();
    assert!(e.contains("version 99"), "{e}");
    std::fs::remove_file(&path).unwrap();
}

#[test]
fn a_spec_without_a_task_function_cannot_make_a_map() {
    let text = "(model: \"planar_arm\", costs: [(weight: 1.0, cost: Displacement)])";
    let problem = Problem::from_ron(text, "notask.ron", Path::new(".")).unwrap();
    let e = Builder::new(&problem, &BuildOptions::default())
        .run(|_| {})
        .unwrap_err()
        .to_string();
    assert!(e.contains("no task function"), "{e}");
}

#[test]
fn a_small_map_on_the_planar_arm_covers_its_workspace() {
    let text = "(model: \"planar_arm\",
        costs: [(weight: 0.01, cost: Displacement)],
        task: Some(Position(part: \"tool\", mask: (true, true, false))),
        map: Some((spacing: 0.2, max_points: 40, construct_weight: 5.0, searches: 2)))";
    let problem = Problem::from_ron(text, "arm.ron", Path::new(".")).unwrap();
    let map = Builder::new(&problem, &BuildOptions::default())
        .run(|_| {})
        .unwrap();
    assert_eq!(map.points.len(), 40);
    // grown from the stretched start (x = 2.3) along the rim of the reachable disc: over seeds
    // 1–7 the 40 points span 0.69–1.3 m in x and 1.85–2.7 m in y
    let extent = map.extent();
    assert!(
        extent[0].1 - extent[0].0 > 0.5 && extent[1].1 - extent[1].0 > 1.5,
        "{extent:?}"
    );
}

#[test]
fn every_fig6_spec_builds_a_non_trivial_map() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../specs/fig6");
    let mut specs: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "ron"))
        .collect();
    specs.sort();
    assert_eq!(specs.len(), 10);
    for spec in specs {
        let problem = Problem::load(&spec).unwrap();
        let map = Builder::new(
            &problem,
            &BuildOptions {
                points: Some(15),
                searches: Some(2),
                ..Default::default()
            },
        )
        .run(|_| {})
        .unwrap();
        assert_eq!(
            map.points.len(),
            15,
            "{}: {}",
            spec.display(),
            map.stats.stopped_because
        );
        let spread: f64 = map
            .extent()
            .iter()
            .map(|(lo, hi)| hi - lo)
            .fold(0.0, f64::max);
        assert!(
            spread >= 2.0 * map.settings.spacing,
            "{}: extent {spread}",
            spec.display()
        );
    }
}

#[test]
fn zero_counts_and_a_zero_step_are_errors_not_hangs() {
    let problem = reach();
    for options in [
        BuildOptions {
            points: Some(0),
            ..Default::default()
        },
        BuildOptions {
            searches: Some(0),
            ..Default::default()
        },
        BuildOptions {
            points: Some(usize::MAX),
            ..Default::default()
        },
    ] {
        let e = Builder::new(&problem, &options)
            .run(|_| {})
            .unwrap_err()
            .to_string();
        assert!(e.contains("give 1 to"), "{e}");
    }
    let mut map = small(&problem, 1);
    let mut broken = map.clone();
    broken.points[0].cost = f64::NAN;
    let path = tmp("nan.map.json");
    assert!(
        broken
            .save(&path)
            .unwrap_err()
            .to_string()
            .contains("not written")
    );
    assert!(!path.exists(), "no file for a map that cannot be read back");
    for (neighbours, resolution) in [(6, 0.0), (6, f64::NAN), (6, -0.1), (0, 0.05)] {
        assert!(connect(&mut map, &problem.objective, neighbours, resolution).is_err());
    }
}

/// Batched segment checks give the one-configuration-at-a-time verdicts, in the map's world and
/// in a cluttered one, on segments of every length (1 to 200 samples).
#[test]
fn batched_segment_checks_agree_with_one_sample_at_a_time() {
    use rand::SeedableRng;
    let problem = reach();
    let objective = &problem.objective;
    let mut world = objective.world().clone();
    world
        .add(
            "box",
            trm_collision::Shape::Box {
                size: [0.3, 0.3, 0.3],
            },
            trm_kinematics::nalgebra::Isometry3::translation(-0.25, 0.15, 0.1),
        )
        .unwrap();
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(9);
    let mut random = || objective.active().random(&mut rng);
    let mut scratch = objective.scratch();
    let mut q = vec![0.0; objective.dim()];
    let (mut free, mut blocked) = (0, 0);
    for k in 0..300 {
        let (a, b) = (random(), random());
        let resolution = [0.005, 0.05, 0.5, 10.0][k % 4];
        for w in [objective.world(), &world] {
            let one = trm_roadmap::segment_is_free(&a, &b, resolution, &mut q, |x| {
                objective.is_collision_free_in(x, w, &mut scratch)
            });
            let batched = objective
                .world_checker(w)
                .unwrap()
                .span_free(&a, &b, resolution);
            assert_eq!(one, batched, "segment {k}");
            if one { free += 1 } else { blocked += 1 }
        }
    }
    assert!(free > 20 && blocked > 20, "{free} free, {blocked} blocked");
}

/// `failure_limit` counts every failed search by default (Algorithm 1), or only those since
/// the last accepted point with `failures: Consecutive`.
#[test]
fn the_failure_limit_counts_all_failures_or_consecutive_ones() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let text = std::fs::read_to_string(root.join("specs/reach.ron")).unwrap();
    assert!(text.contains("failure_limit: 60,"));
    let with = |setting: &str| {
        let spec = text
            .replace("failure_limit: 60,", setting)
            .replace("spacing: 0.025,", "spacing: 0.08,");
        let problem = Problem::from_ron(&spec, "reach.ron", &root.join("specs")).unwrap();
        Builder::new(
            &problem,
            &BuildOptions {
                // a wide spacing: the workspace fills up and searches fail
                points: Some(400),
                ..Default::default()
            },
        )
        .run(|_| {})
        .unwrap()
    };
    let total = with("failure_limit: 3,");
    // searches that end in the same generation are checked together: the count may pass k
    let stop = &total.stats.stopped_because;
    assert!(
        stop.ends_with(" failed searches (k = 3)") && !stop.contains("consecutive"),
        "{stop}"
    );
    assert!(
        total.stats.failures >= 3 && total.stats.failures <= 6,
        "{:?}",
        total.stats
    );
    let consecutive = with("failure_limit: 3, failures: Consecutive,");
    assert!(
        consecutive
            .stats
            .stopped_because
            .ends_with(" consecutive failed searches (k = 3)"),
        "{}",
        consecutive.stats.stopped_because
    );
    assert!(consecutive.stats.failures >= 3);
    assert!(consecutive.points.len() >= total.points.len());
}

#[test]
fn build_connected_is_build_then_connect_and_checks_the_resolution_first() {
    let problem = reach();
    let options = BuildOptions {
        points: Some(12),
        edge_resolution: 0.07,
        ..Default::default()
    };
    let one = trm_roadmap::Builder::new(&problem, &options)
        .connected()
        .run(|_| {})
        .unwrap();
    let mut two = Builder::new(&problem, &options).run(|_| {}).unwrap();
    let neighbours = two.settings.edge_neighbours;
    connect(&mut two, &problem.objective, neighbours, 0.07).unwrap();
    assert_eq!(one.points, two.points);
    assert_eq!(one.edges, two.edges);
    assert!(!one.edges.is_empty());
    let mut built = false;
    let bad = BuildOptions {
        edge_resolution: f64::NAN,
        ..options
    };
    let e = trm_roadmap::Builder::new(&problem, &bad)
        .connected()
        .run(|_| built = true)
        .unwrap_err();
    assert!(e.to_string().contains("edge resolution"), "{e}");
    assert!(!built, "the resolution is checked before building");
}
