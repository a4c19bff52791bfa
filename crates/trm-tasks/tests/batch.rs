//! Batched evaluation: `Objective::eval_batch` / `eval_with_task_batch` give what one-at-a-time
//! evaluation gives, bit for bit (both run the batched kinematics), for every batch split, with
//! robustness noise, and NaN for invalid candidates.

use std::path::Path;

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use trm_tasks::{Objective, Problem};

fn spec(name: &str) -> Problem {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../specs")
        .join(name);
    Problem::load(&path).unwrap_or_else(|e| panic!("{e}"))
}

fn candidates(objective: &Objective, n: usize, seed: u64) -> Vec<Vec<f64>> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    (0..n)
        .map(|_| objective.active().random(&mut rng))
        .collect()
}

fn same(a: f64, b: f64) -> bool {
    a.to_bits() == b.to_bits()
}

fn agrees_with_one_at_a_time(objective: &Objective, qs: &[Vec<f64>]) {
    let mut scratch = objective.scratch();
    let one: Vec<f64> = qs.iter().map(|q| objective.eval(q, &mut scratch)).collect();
    let mut all = vec![0.0; qs.len()];
    objective.eval_batch(qs, &mut scratch, &mut all);
    for (k, (a, b)) in one.iter().zip(&all).enumerate() {
        assert!(
            same(*a, *b) || (a.is_nan() && b.is_nan()),
            "candidate {k}: {a} vs {b}"
        );
    }
    // any split into batches gives the same values, bit for bit
    for split in [1, 3, 5, 7] {
        let mut parts = vec![0.0; qs.len()];
        for (q, out) in qs.chunks(split).zip(parts.chunks_mut(split)) {
            objective.eval_batch(q, &mut scratch, out);
        }
        assert_eq!(
            parts.iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
            all.iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
            "split {split}"
        );
    }
}

#[test]
fn a_table_iii_objective_batched_equals_one_at_a_time() {
    let problem = spec("table_iii/posture1.ron");
    let mut qs = candidates(&problem.objective, 37, 1);
    qs[5][0] = f64::NAN;
    qs[11].pop();
    agrees_with_one_at_a_time(&problem.objective, &qs);
    let mut out = vec![0.0; qs.len()];
    problem
        .objective
        .eval_batch(&qs, &mut problem.objective.scratch(), &mut out);
    assert!(out[5].is_nan() && out[11].is_nan());
    assert!(out.iter().filter(|v| v.is_finite()).count() == 35);
}

#[test]
fn noise_samples_are_extra_lanes_with_the_same_mean() {
    let mut problem = spec("table_iii/posture1.ron");
    problem.objective.set_noise(5, 0.05, 3).unwrap();
    let qs = candidates(&problem.objective, 10, 2);
    agrees_with_one_at_a_time(&problem.objective, &qs);
}

#[test]
fn task_vectors_come_with_the_costs() {
    let problem = spec("reach.ron");
    let objective = &problem.objective;
    let m = objective.task().expect("reach maps a task").dim();
    let qs = candidates(objective, 9, 3);
    let mut scratch = objective.scratch();
    let mut out = vec![0.0; qs.len()];
    let mut tasks = vec![0.0; qs.len() * m];
    objective.eval_with_task_batch(&qs, &mut scratch, &mut out, &mut tasks);
    for (k, q) in qs.iter().enumerate() {
        let mut t = vec![0.0; m];
        let h = objective.eval_with_task(q, &mut scratch, &mut t);
        assert!(same(h, out[k]), "{h} vs {}", out[k]);
        for (a, b) in t.iter().zip(&tasks[k * m..(k + 1) * m]) {
            assert!(same(*a, *b), "{a} vs {b}");
        }
    }
}

#[test]
fn a_planar_arm_with_a_masked_task_batched_equals_one_at_a_time() {
    let text = "(model: \"planar_arm\",
        costs: [(weight: 0.01, cost: Displacement)],
        task: Some(Position(part: \"tool\", mask: (true, true, false))))";
    let problem = Problem::from_ron(text, "arm.ron", Path::new(".")).unwrap();
    let objective = &problem.objective;
    let qs = candidates(objective, 11, 4);
    agrees_with_one_at_a_time(objective, &qs);
    let m = objective.task().unwrap().dim();
    let mut scratch = objective.scratch();
    let (mut out, mut tasks) = (vec![0.0; qs.len()], vec![0.0; qs.len() * m]);
    objective.eval_with_task_batch(&qs, &mut scratch, &mut out, &mut tasks);
    for (k, q) in qs.iter().enumerate() {
        let t = objective.task_value(q, &mut scratch);
        for (a, b) in t.iter().zip(&tasks[k * m..(k + 1) * m]) {
            assert!(same(*a, *b), "candidate {k}: {a} vs {b}");
        }
    }
}

/// h and g of `qs` through the batch equal one-at-a-time evaluation, bit for bit.
fn tasks_agree(objective: &Objective, qs: &[Vec<f64>]) {
    let Some(task) = objective.task() else {
        return;
    };
    let m = task.dim();
    let mut scratch = objective.scratch();
    let (mut out, mut tasks) = (vec![0.0; qs.len()], vec![0.0; qs.len() * m]);
    objective.eval_with_task_batch(qs, &mut scratch, &mut out, &mut tasks);
    for (k, q) in qs.iter().enumerate() {
        // the one-candidate path: scalar kinematics and each term's `eval`
        let h = objective.eval(q, &mut scratch);
        assert!(same(h, out[k]), "candidate {k}: {h} vs {}", out[k]);
        let t = objective.task_value(q, &mut scratch);
        for (a, b) in t.iter().zip(&tasks[k * m..(k + 1) * m]) {
            assert!(same(*a, *b), "candidate {k}: {a} vs {b}");
        }
    }
}

/// Every spec shipped in `specs/` (the Fig. 6 maps, Table III, the reach maps: every catalogue
/// term they use read in place from the batch) evaluates as one-at-a-time evaluation does.
#[test]
fn every_shipped_spec_batched_equals_one_at_a_time() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../specs");
    let mut checked = 0;
    for dir in [root.clone(), root.join("fig6"), root.join("table_iii")] {
        let mut files: Vec<_> = std::fs::read_dir(&dir)
            .unwrap()
            .map(|e| e.unwrap().path())
            .filter(|p| p.extension().is_some_and(|e| e == "ron"))
            .collect();
        files.sort();
        for path in files {
            let name = path
                .strip_prefix(&root)
                .unwrap()
                .to_string_lossy()
                .to_string();
            let Ok(problem) = Problem::load(&path) else {
                continue; // specs of other robots' files (checked by their own tests)
            };
            let qs = candidates(&problem.objective, 9, 7);
            agrees_with_one_at_a_time(&problem.objective, &qs);
            tasks_agree(&problem.objective, &qs);
            checked += 1;
            eprintln!("{name}: batched = one at a time");
        }
    }
    assert!(checked >= 14, "{checked} specs checked");
}

/// Every catalogue cost and task function on the planar arm, batched and alone, including a
/// task target and anchors on world objects.
#[test]
fn every_catalogue_term_batched_equals_one_at_a_time() {
    let costs = "(weight: 1.0, cost: HomePosture(weights: {\"joint1\": 3.0})),
        (weight: 0.5, cost: Displacement),
        (weight: 0.2, cost: JointLimits(margin: 0.4)),
        (weight: 1.0, cost: Collision()),
        (weight: 1.0, cost: Position(part: \"tool\", target: Point((0.5, 1.0, 0.1)), mask: (true, false, true))),
        (weight: 1.0, cost: Position(part: \"tool\", target: Box(min: (0.2, -5.0, -1.0), max: (9.0, 5.0, 1.0)))),
        (weight: 1.0, cost: Position(part: \"link3\", target: Sphere(center: Object(\"ball\"), radius: 0.3))),
        (weight: 1.0, cost: Orientation(part: \"tool\", axis: (1, 0, 0), toward: Fixed((0.0, 1.0, 0.0)))),
        (weight: 1.0, cost: Pointing(part: \"tool\", axis: (1, 0, 0), at: Object(\"ball\"), distance: Some(1.5))),
        (weight: 1.0, cost: Repel(a: Part(\"tool\"), b: Point((1.0, 0.5, 0.1)), min_distance: 0.6))";
    let tasks = [
        "Position(part: \"tool\")",
        "Rotation(part: \"tool\", axis: (1, 0, 0), mask: (true, true, false), relative_to: Some(\"link1\"))",
        "Distance(a: Part(\"tool\"), b: Object(\"ball\"))",
        "Angle(a: Part(\"tool\"), b: Part(\"link2\"), u1: (1, 0, 0), u2: (0, 1, 0))",
        "Midpoint(a: Part(\"tool\"), b: Part(\"link2\"), mask: (true, true, false))",
        "Pose(part: \"tool\")",
        "RodDirection(a: Part(\"link2\"), b: Part(\"tool\"))",
    ];
    for task in tasks {
        let text = format!(
            "(model: \"planar_arm\",
              world: (objects: [(name: \"ball\", shape: Sphere(radius: 0.1), xyz: (1.0, 1.0, 0.0))]),
              costs: [{costs}], task: Some({task}))"
        );
        let problem =
            Problem::from_ron(&text, "arm.ron", Path::new(".")).unwrap_or_else(|e| panic!("{e}"));
        let objective = &problem.objective;
        let qs = candidates(objective, 11, 9);
        agrees_with_one_at_a_time(objective, &qs);
        tasks_agree(objective, &qs);
        // the exact goal of a planned path: a target of the task, batched through it
        let mut scratch = objective.scratch();
        let at = objective.task_value(&qs[0], &mut scratch);
        let pulled = objective.with_task_target(&at, 10.0).unwrap();
        agrees_with_one_at_a_time(&pulled, &qs);
    }
}

/// Each catalogue term alone on the iCub, reading frames on two branches of its tree (the
/// hands): batched, the objective computes only the frames its terms say they read
/// (`Cost::frames_read`, `TaskFunction::frames_read`), so a frame left out would be stale
/// there and differ from the one-at-a-time value.
#[test]
fn every_catalogue_term_on_a_branching_tree_batched_equals_one_at_a_time() {
    let costs = [
        "Position(part: \"l_hand\", target: Point((-0.3, 0.2, 0.1)))",
        "Position(part: \"l_hand\", target: Sphere(center: Part(\"r_hand\"), radius: 0.05))",
        "Position(part: \"l_hand\", target: Part(\"r_hand\"))",
        "Orientation(part: \"l_hand\", axis: (1, 0, 0), toward: Axis(part: \"r_hand\", axis: (0, 1, 0)))",
        "Pointing(part: \"l_hand\", axis: (1, 0, 0), at: Part(\"r_hand\"), distance: Some(0.2))",
        "Repel(a: Part(\"l_hand\"), b: Part(\"r_hand\"), min_distance: 0.6)",
    ];
    let tasks = [
        "Distance(a: Part(\"l_hand\"), b: Part(\"r_hand\"))",
        "Angle(a: Part(\"l_hand\"), b: Part(\"r_hand\"), u1: (1, 0, 0), u2: (0, 1, 0))",
        "Midpoint(a: Part(\"l_hand\"), b: Part(\"r_hand\"), mask: (true, true, false))",
        "RodDirection(a: Part(\"l_hand\"), b: Part(\"r_hand\"))",
        "Rotation(part: \"r_hand\", axis: (1, 0, 0), mask: (true, true, false), relative_to: Some(\"l_hand\"))",
        "Pose(part: \"r_hand\")",
    ];
    let objectives = costs
        .iter()
        .map(|cost| format!("costs: [(weight: 1.0, cost: {cost})], task: None"))
        .chain(tasks.iter().map(|task| {
            format!("costs: [(weight: 1.0, cost: HomePosture())], task: Some({task})")
        }));
    for terms in objectives {
        let text = format!("(model: \"icub_upper_body\", {terms})");
        let problem =
            Problem::from_ron(&text, "icub.ron", Path::new(".")).unwrap_or_else(|e| panic!("{e}"));
        let qs = candidates(&problem.objective, 9, 3);
        agrees_with_one_at_a_time(&problem.objective, &qs);
        tasks_agree(&problem.objective, &qs);
    }
}

#[test]
fn batched_collision_checks_agree_and_nan_collides() {
    let problem = spec("table_iii/posture1.ron");
    let objective = &problem.objective;
    let qs = candidates(objective, 40, 6);
    let mut scratch = objective.scratch();
    let world = objective.world();
    for (k, window) in qs.windows(3).enumerate() {
        let flat: Vec<f64> = window.concat();
        let one = window
            .iter()
            .all(|q| objective.is_collision_free_in(q, world, &mut scratch));
        assert_eq!(
            objective.all_collision_free_in(&flat, world, &mut scratch),
            one,
            "window {k}"
        );
    }
    let mut flat = qs[0].clone();
    flat[3] = f64::NAN;
    assert!(!objective.all_collision_free_in(&flat, world, &mut scratch));
}

#[test]
fn a_task_target_needs_a_task_function_and_a_finite_point_of_its_dimension() {
    let problem = spec("reach.ron");
    let objective = &problem.objective;
    let e = objective
        .with_task_target(&[0.1, 0.2], 100.0)
        .unwrap_err()
        .to_string();
    assert!(e.contains("2 values for a task of 3 outputs"), "{e}");
    let e = objective
        .with_task_target(&[0.1, f64::NAN, 0.0], 100.0)
        .unwrap_err()
        .to_string();
    assert!(e.contains("not finite"), "{e}");
    let e = objective
        .with_task_target(&[0.1, 0.2, 0.0], -1.0)
        .unwrap_err()
        .to_string();
    assert!(e.contains("-1"), "{e}");
    let no_task = spec("table_iii/posture1.ron");
    assert!(no_task.objective.task().is_none());
    let e = no_task
        .objective
        .with_task_target(&[0.0; 3], 1.0)
        .unwrap_err()
        .to_string();
    assert!(e.contains("no task function"), "{e}");
    // the target term is zero exactly at g(q), and the copy keeps every other term
    let q = problem.start.clone();
    let mut scratch = objective.scratch();
    let at = objective.task_value(&q, &mut scratch);
    let pulled = objective.with_task_target(&at, 100.0).unwrap();
    assert_eq!(pulled.num_terms(), objective.num_terms() + 1);
    assert_eq!(
        pulled.eval(&q, &mut scratch),
        objective.eval(&q, &mut scratch)
    );
}
