//! Spec files: every example spec loads, mistakes are located and explained, and an infeasible
//! spec still returns its best posture, marked as not meeting the hard constraint.

use std::path::{Path, PathBuf};

use trm_tasks::{Problem, TaskError, solve};

fn specs_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../specs")
}

fn error(text: &str) -> String {
    match Problem::from_ron(text, "bad.ron", Path::new(".")) {
        Err(e) => e.to_string(),
        Ok(_) => panic!("accepted:\n{text}"),
    }
}

#[test]
fn every_example_spec_loads() {
    let mut n = 0;
    let mut stack = vec![specs_dir()];
    while let Some(dir) = stack.pop() {
        for entry in std::fs::read_dir(&dir).unwrap() {
            let path = entry.unwrap().path();
            // worlds/, taskmaps/, wholebody/ and scenarios/ hold other formats (worlds,
            // explore-task-map specs, whole-body motion specs, scenarios: each tested by its
            // own crate)
            if ["worlds", "taskmaps", "wholebody", "scenarios"]
                .iter()
                .any(|d| path.ends_with(d))
            {
                continue;
            }
            if path.is_dir() {
                stack.push(path);
            } else if path.extension().is_some_and(|e| e == "ron") {
                Problem::load(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
                n += 1;
            }
        }
    }
    assert!(n >= 3, "{n} specs");
}

#[test]
fn unknown_names_are_located_with_suggestions() {
    let e = error(
        "(model: \"icub_upper_body\",\n costs: [(weight: 1.0, cost: Positon(part: \"r_hand\", target: Point((0, 0, 0))))])",
    );
    assert!(
        e.starts_with("bad.ron:2:")
            && e.contains("unknown variant `Positon`")
            && e.contains("did you mean `Position`"),
        "{e}"
    );
    let e = error(
        "(model: \"icub_upper_body\", costs: [(weight: 1.0, cost: Displacement)], solvr: ())",
    );
    assert!(
        e.contains("unknown field `solvr`") && e.contains("did you mean `solver`"),
        "{e}"
    );
    let e = error(
        "(model: \"icub_upper_body\",\n costs: [\n (weight: 1.0, cost: Position(part: \"r_palm_centre\", target: Point((0, 0, 0))))])",
    );
    assert!(
        e.starts_with("bad.ron:3:")
            && e.contains("r_palm_centre")
            && e.contains("did you mean `r_palm_center`"),
        "{e}"
    );
    let e = error(
        "(model: \"icub_upper_body\", active: [\"right_arms\"], costs: [(weight: 1.0, cost: Displacement)])",
    );
    assert!(e.contains("did you mean `right_arm`"), "{e}");
    let e = error("(model: \"icub_upper_bdy\", costs: [(weight: 1.0, cost: Displacement)])");
    assert!(e.contains("did you mean `icub_upper_body`"), "{e}");
    let e = error(
        "(model: \"icub_upper_body\", costs: [(weight: 1.0, cost: Pointing(part: \"gaze\", axis: (0, 0, 1), at: Object(\"bal\")))], world: (objects: [(name: \"ball\", shape: Sphere(radius: 0.05))]))",
    );
    assert!(e.contains("did you mean `ball`"), "{e}");
    let e = error(
        "(model: \"icub_upper_body\", costs: [(weight: 1.0, cost: Displacement)], solver: (algo: \"xnse\"))",
    );
    assert!(e.contains("did you mean `xnes`"), "{e}");
}

#[test]
fn bad_values_are_errors() {
    for (text, says) in [
        ("(model: \"planar_arm\", costs: [])", "the list is empty"),
        (
            "(model: \"planar_arm\", costs: [(weight: -1.0, cost: Displacement)])",
            "-1 is not a finite number ≥ 0",
        ),
        (
            "(model: \"planar_arm\", costs: [(weight: NaN, cost: Displacement)])",
            "NaN is not a finite number ≥ 0",
        ),
        (
            "(model: \"planar_arm\", costs: [(weight: 1.0, cost: Orientation(part: \"tool\", axis: (0, 0, 0), toward: Fixed((1, 0, 0))))])",
            "the axis is zero",
        ),
        (
            "(model: \"planar_arm\", costs: [(weight: 1.0, cost: Position(part: \"tool\", target: Point((0, 0, 0)), mask: (false, false, false)))])",
            "masks every axis out",
        ),
        (
            "(model: \"planar_arm\", costs: [(weight: 1.0, cost: Repel(a: Part(\"tool\"), b: Part(\"base\"), min_distance: 0.0))])",
            "must be positive",
        ),
        (
            "(model: \"planar_arm\", costs: [(weight: 1.0, cost: Position(part: \"tool\", target: Box(min: (1, 0, 0), max: (0, 1, 1))))])",
            "min exceeds its max",
        ),
        (
            "(model: \"planar_arm\", costs: [(weight: 1.0, cost: Displacement)], start: Some(\"hom\"))",
            "no posture",
        ),
        (
            "(model: \"planar_arm\", costs: [(weight: 1.0, cost: Position(part: \"tool\"))])",
            "missing field `target`",
        ),
        (
            "(model: \"planar_arm\", costs: [(weight: 1.0, cost: Displacement)], start_values: {\"joint2\": 3.0})",
            "start_values.joint2: 3 is outside `joint2`'s limits [-2.5, 2.5]",
        ),
        (
            "(model: \"planar_arm\", costs: [(weight: 1.0, cost: Displacement)], start_values: {\"joint1\": NaN})",
            "NaN is outside",
        ),
        (
            "(model: \"planar_arm\", costs: [(weight: 1.0, cost: Displacement)], active: [\"joint1\", \"joint2\", \"joint1\"])",
            "active[2]: `joint1` is given twice (also active[0])",
        ),
        (
            "(model: \"planar_arm\", costs: [(weight: 1.0, cost: Displacement)], solver: (max_evaluations: 0))",
            "max_evaluations",
        ),
    ] {
        let e = error(text);
        assert!(e.contains(says), "{text}\n→ {e}");
    }
    assert!(matches!(
        Problem::load("no/such/spec.ron"),
        Err(TaskError::Io { .. })
    ));
}

#[test]
fn an_infeasible_spec_returns_its_best_posture_marked_as_colliding() {
    // a box through the robot's torso: no posture avoids it
    let text = "(model: \"icub_upper_body\", active: [\"right_arm\"],
        world: (objects: [(name: \"wall\", shape: Box(size: (0.2, 0.2, 0.2)), xyz: (0, 0, 0.1))]),
        costs: [(weight: 1.0, cost: Collision()), (weight: 1.0, cost: HomePosture())],
        solver: (max_evaluations: 600, seed: 1))";
    let p = Problem::from_ron(text, "wall.ron", Path::new(".")).unwrap();
    let s = solve(&p.objective, &p.start, &p.spec.solver).unwrap();
    assert!(!s.collision_free);
    assert!(s.cost >= 1.0);
    assert_eq!(s.q.len(), 7);
}

#[test]
fn ngik_solves_the_reach_example_collision_free() {
    let p = Problem::load(specs_dir().join("reach_point.ron")).unwrap();
    let mut solver = p.spec.solver.clone();
    solver.max_evaluations = 12_000;
    let s = solve(&p.objective, &p.start, &solver).unwrap();
    let start = p.objective.eval(&p.start, &mut p.objective.scratch());
    assert!(s.cost < 0.7 * start, "{} from {start}", s.cost);
    assert!(s.collision_free);
    // the palm is within 1 cm of the point above the cup
    let reach: f64 = s
        .breakdown
        .iter()
        .filter(|t| t.label.starts_with("position"))
        .map(|t| t.value)
        .sum();
    assert!(reach < 0.01, "{:?}", s.breakdown);
    // the run is reproducible
    let again = solve(&p.objective, &p.start, &solver).unwrap();
    assert_eq!(s.q, again.q);
}

#[test]
fn spec_frames_become_parts() {
    let text = "(model: \"planar_arm\",
        frames: [(name: \"tip\", link: \"tool\", xyz: (0.25, 0.0, 0.0))],
        costs: [(weight: 1.0, cost: Position(part: \"tip\", target: Point((2.55, 0.0, 0.1))))])";
    let p = Problem::from_ron(text, "frames.ron", Path::new(".")).unwrap();
    // stretched out, the tool is at x = 2.3: the tip 0.25 further reaches 2.55 exactly
    let c = p
        .objective
        .eval(&[0.0, 0.0, 0.0], &mut p.objective.scratch());
    assert!(c.abs() < 1e-12, "{c}");
    let e = error(
        "(model: \"planar_arm\", frames: [(name: \"tip\", link: \"tol\")], costs: [(weight: 1.0, cost: Displacement)])",
    );
    assert!(e.contains("did you mean `tool`"), "{e}");
    let e = error(
        "(model: \"planar_arm\", frames: [(name: \"link2\", link: \"tool\")], costs: [(weight: 1.0, cost: Displacement)])",
    );
    assert!(e.contains("already names"), "{e}");
}

#[test]
fn errors_point_at_their_own_field_not_the_first_matching_word() {
    // a bad solver.sigma after a good noise sigma
    let e = error(
        "(model: \"planar_arm\",\n costs: [(weight: 1.0, cost: Displacement)],\n noise: Some((samples: 4, sigma: 0.1, seed: 1)),\n solver: (algo: \"xnes\", sigma: -1.0),\n)",
    );
    assert!(e.starts_with("bad.ron:4:25: solver.sigma:"), "{e}");
    // the second of two identical part names
    let e = error(
        "(model: \"planar_arm\", costs: [\n (weight: 1.0, cost: Position(part: \"tool\", target: Point((0.5, 0.0, 0.0)))),\n (weight: 1.0, cost: Position(part: \"tool\", target: Part(\"tol\"))),\n])",
    );
    assert!(
        e.starts_with("bad.ron:3:45: costs[1].cost.target:") && e.contains("did you mean `tool`"),
        "{e}"
    );
    // a world object names its line
    let e = error(
        "(model: \"planar_arm\", costs: [(weight: 1.0, cost: Displacement)],\n world: (objects: [\n (name: \"a\", shape: Sphere(radius: 0.1)),\n (name: \"b\", shape: Sphere(radius: -0.1)),\n ]),\n)",
    );
    assert!(e.starts_with("bad.ron:4: world.objects[1] (\"b\")"), "{e}");
    // a weight of a home-posture group
    let e = error(
        "(model: \"icub_upper_body\", costs: [\n (weight: 1.0, cost: HomePosture(weights: {\"torso\": 2.0, \"tosro\": 1.0})),\n])",
    );
    assert!(
        e.starts_with("bad.ron:2:58: costs[0].cost.weights.tosro:") && e.contains("`torso`"),
        "{e}"
    );
}

/// `Rotation(…, relative_to)` is the part's axis in the reference's frame: R_ref⁻¹ R_part u,
/// checked against the frames' world poses at a few postures.
#[test]
fn a_rotation_relative_to_another_part_is_the_axis_in_its_frame() {
    let spec = "(model: \"icub_upper_body\", start: Some(\"home\"), costs: [(weight: 1.0, cost: Collision())],
        task: Some(Rotation(part: \"r_hand\", axis: (0, -1, 0), relative_to: Some(\"head\"))))";
    let problem = Problem::from_ron(spec, "relative.ron", &specs_dir()).unwrap();
    let objective = &problem.objective;
    let robot = &problem.robot;
    let (hand, head) = (
        robot.frame_names().position(|n| n == "r_hand").unwrap(),
        robot.frame_names().position(|n| n == "head").unwrap(),
    );
    let mut scratch = objective.scratch();
    for k in 0..4 {
        let q: Vec<f64> = problem
            .start
            .iter()
            .enumerate()
            .map(|(i, v)| v + 0.1 * ((i * 7 + k * 3) % 5) as f64 - 0.2)
            .collect();
        let mut q = q;
        let (lower, upper) = objective.active().bounds();
        for i in 0..q.len() {
            q[i] = q[i].clamp(lower[i], upper[i]);
        }
        let got = objective.task_value(&q, &mut scratch);
        let poses = objective.poses(&q, &mut scratch);
        let world =
            poses.poses()[hand].rotation * trm_kinematics::nalgebra::Vector3::new(0.0, -1.0, 0.0);
        let want = poses.poses()[head].rotation.inverse() * world;
        for i in 0..3 {
            assert!((got[i] - want[i]).abs() < 1e-12, "{got:?} vs {want:?}");
        }
    }
    let label = objective.task().unwrap().label();
    assert_eq!(label, "rotation r_hand relative to head");
}

/// Task maps are another crate's format: without its reader given, a spec naming a task map is a
/// located error saying what to pass.
#[test]
fn a_task_map_cost_without_a_reader_says_what_to_pass() {
    let e = error(
        "(model: \"icub_upper_body\", active: [\"torso\"],
          world: (objects: [(name: \"stick\", shape: Sphere(radius: 0.01))]),
          costs: [(weight: 1.0, cost: TaskMap(file: \"stick.taskmap.json\", part: \"r_hand\", object: \"stick\"))])",
    );
    assert!(
        e.contains("trm_taskmap::loaders()") && e.contains("costs[0]"),
        "{e}"
    );
}

#[test]
fn a_callers_solver_choices_override_the_spec_and_unknown_algorithms_get_a_suggestion() {
    let spec = trm_tasks::spec::SolverSpec::default();
    let s = spec.overridden(Some("cmaes"), Some(7), None).unwrap();
    assert_eq!((s.algo.as_str(), s.seed), ("cmaes", 7));
    assert_eq!(s.max_evaluations, spec.max_evaluations);
    assert_eq!(spec.overridden(None, None, None).unwrap(), spec);
    let e = spec
        .overridden(Some("xnse"), None, None)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("`xnse`") && e.contains("did you mean `xnes`"),
        "{e}"
    );
}
