//! Scenarios: located errors for bad specs; a run keeps the map exactly valid at every step,
//! reaches its goals, and is reproducible under an evaluation budget.

use std::path::Path;

use trm_plan::{Action, Scenario, ScenarioError, ScenarioOptions, run_scenario};
use trm_roadmap::{BuildOptions, Builder, blocked_exhaustive, connect};
use trm_tasks::Problem;

fn root() -> &'static Path {
    Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."))
}

fn error(text: &str) -> String {
    match Scenario::from_ron(text, "s.ron") {
        Err(ScenarioError::Spec(e)) => e.to_string(),
        other => panic!("expected a spec error, got {other:?}"),
    }
}

#[test]
fn bad_scenarios_get_located_errors() {
    let goals = "goals: [(t: 0.0, to: [-0.3, 0.1, 0.0])]";
    let e = error(&format!("(duration: -1.0, {goals})"));
    assert!(
        e.contains("s.ron:1:2: duration") && e.contains("positive"),
        "{e}"
    );
    let e = error(&format!("(duration: 1.0, rate: 0.0, {goals})"));
    assert!(e.contains("rate"), "{e}");
    let e = error(&format!("(duration: 1e9, rate: 1e3, {goals})"));
    assert!(e.contains("at most"), "{e}");
    let e = error("(duration: 1.0, goals: [])");
    assert!(e.contains("goals") && e.contains("at least one"), "{e}");
    let e = error("(duration: 1.0, goals: [(t: 1.0, to: [0.0]), (t: 0.5, to: [0.0])])");
    assert!(e.contains("goals[1].t") && e.contains("ascending"), "{e}");
    let e = error("(duration: 1.0, goals: [(t: 0.0, to: [NaN])])");
    assert!(e.contains("goals[0].to"), "{e}");
    let e = error(&format!(
        "(duration: 1.0, {goals}, objects: [(name: \"b\", shape: Sphere(radius: 0.1), path: [])])"
    ));
    assert!(
        e.contains("objects[0].path") && e.contains("keyframe"),
        "{e}"
    );
    let e = error(&format!(
        "(duration: 1.0, {goals}, objects: [(name: \"b\", shape: Sphere(radius: 0.1), path: [(t: 1.0, xyz: (0, 0, 0)), (t: 0.0, xyz: (0, 0, 0))])])"
    ));
    assert!(e.contains("objects[0].path[1].t"), "{e}");
    let e = error(&format!(
        "(duration: 1.0, {goals}, objects: [(name: \"b\", shape: Sphere(radius: 0.1), path: [(t: 0.0, xyz: (0, 0, 0))]), (name: \"b\", shape: Sphere(radius: 0.1), path: [(t: 0.0, xyz: (0, 0, 0))])])"
    ));
    assert!(
        e.contains("objects[1].name") && e.contains("objects[0]"),
        "{e}"
    );
    let e = error(&format!(
        "(duration: 1.0, {goals}, objects: [(name: \"b\", shape: Sphere(radius: -0.1), path: [(t: 0.0, xyz: (0, 0, 0))])])"
    ));
    assert!(e.contains("objects"), "{e}");
    let e = error(&format!(
        "(duration: 1.0, {goals}, objects: [(name: \"b\", shape: Sphere(radius: 0.1), path: [(t: 0.0, xyz: (0, 0, 0))], appear: 2.0, vanish: Some(1.0))])"
    ));
    assert!(e.contains("objects[0].appear"), "{e}");
    let e = error(&format!("(duration: 1.0, {goals}, durration: 2.0)"));
    assert!(e.contains("durration") && e.contains("s.ron:1:"), "{e}");
    // the shipped scenario loads
    Scenario::load(root().join("specs/scenarios/sliding_box.ron")).unwrap();
}

#[test]
fn objects_follow_their_keyframes_and_goals_switch() {
    let s = Scenario::from_ron(
        "(duration: 2.0, rate: 4.0, goals: [(t: 0.0, to: [1.0]), (t: 1.0, to: [2.0])],
          objects: [(name: \"b\", shape: Sphere(radius: 0.1),
                     path: [(t: 0.0, xyz: (0, 0, 0)), (t: 1.0, xyz: (1, 0, 0))], appear: 0.5, vanish: Some(1.5))])",
        "s.ron",
    )
    .unwrap();
    assert_eq!(s.steps(), 9);
    let base = trm_collision::World::new();
    assert!(s.world_at(&base, 0.25).unwrap().is_empty());
    let at = |t: f64| {
        s.world_at(&base, t)
            .unwrap()
            .object("b")
            .unwrap()
            .pose()
            .translation
            .x
    };
    assert!((at(0.75) - 0.75).abs() < 1e-12);
    assert!((at(1.25) - 1.0).abs() < 1e-12);
    assert!(s.world_at(&base, 1.5).unwrap().is_empty());
    assert_eq!(s.goal_at(0.9), Some(&[1.0][..]));
    assert_eq!(s.goal_at(1.0), Some(&[2.0][..]));
}

/// The shipped sliding-box scenario on a small reach map, under an evaluation budget: at every
/// step the parked nodes are exactly what the exhaustive check blocks in that step's world, the
/// goals are reached, and a second run gives the same steps and motion.
#[test]
fn a_scenario_run_keeps_the_map_valid_reaches_goals_and_is_reproducible() {
    let problem = Problem::load(root().join("specs/reach.ron")).unwrap();
    let mut map = Builder::new(
        &problem,
        &BuildOptions {
            points: Some(120),
            ..Default::default()
        },
    )
    .run(|_| {})
    .unwrap();
    connect(&mut map, &problem.objective, 8, 0.05).unwrap();
    let scenario = Scenario::load(root().join("specs/scenarios/sliding_box.ron")).unwrap();
    // the iCub's model gives no acceleration limits: an arm that reaches 1 rad/s in 0.25 s
    let mut plan = ScenarioOptions::default().plan;
    plan.timing.default_acceleration = 4.0;
    let options = ScenarioOptions {
        repair_seconds: None,
        repair_evaluations: Some(3_000),
        plan,
        ..Default::default()
    };
    for bad in [
        ScenarioOptions {
            tolerance: f64::NAN,
            ..options.clone()
        },
        ScenarioOptions {
            reached: -1.0,
            ..options.clone()
        },
        ScenarioOptions {
            repair_seconds: Some(f64::NAN),
            ..options.clone()
        },
    ] {
        assert!(run_scenario(&map, &problem, &scenario, &bad).is_err());
    }
    // an object that swallows the robot at its start is named, not stepped through
    let text = std::fs::read_to_string(root().join("specs/scenarios/sliding_box.ron")).unwrap();
    let swallowing = text.replace(
        "(t: 0.0, xyz: (-0.24, 0.3, -0.06))],\n            appear: 2.0,",
        "(t: 0.0, xyz: (0.0, 0.0, 0.0))],",
    );
    let swallowing = swallowing.replace(
        "Cylinder(radius: 0.03, length: 0.12)",
        "Sphere(radius: 0.5)",
    );
    assert_ne!(swallowing, text);
    let scenario_in = Scenario::from_ron(&swallowing, "swallow.ron").unwrap();
    let e = run_scenario(&map, &problem, &scenario_in, &options)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("swallow.ron") && e.contains("objects[1].path") && e.contains("`can` collides"),
        "{e}"
    );
    let run = run_scenario(&map, &problem, &scenario, &options).unwrap();
    assert_eq!(run.steps.len(), scenario.steps());
    assert_eq!(run.motion.positions.len(), run.steps.len());
    let (mut blocked, mut restored, mut at_goal) = (0, 0, 0);
    for (step, world) in run.steps.iter().zip(&run.worlds) {
        let mut seen = run.map.clone();
        seen.points.truncate(step.nodes);
        seen.edges.truncate(step.edges);
        let exhaustive = blocked_exhaustive(&seen, &problem.objective, world).unwrap();
        assert_eq!(step.parked_nodes, exhaustive.nodes, "t = {}", step.t);
        // parked edges: the blocked ones and those of parked nodes
        let mut want: Vec<usize> = (0..seen.edges.len())
            .filter(|k| {
                let (a, b, _) = seen.edges[*k];
                exhaustive.edges.binary_search(k).is_ok()
                    || exhaustive.nodes.binary_search(&a).is_ok()
                    || exhaustive.nodes.binary_search(&b).is_ok()
            })
            .collect();
        want.sort_unstable();
        assert_eq!(step.parked_edges, want, "t = {}", step.t);
        blocked += step.blocked;
        restored += step.restored;
        at_goal += usize::from(step.goal_error.is_some_and(|e| e <= options.reached));
    }
    eprintln!(
        "{blocked} blocked, {restored} restored, at the goal in {at_goal} of {} steps",
        run.steps.len()
    );
    assert!(blocked > 0 && restored > 0);
    assert!(at_goal >= run.steps.len() / 4, "{at_goal}");
    assert!(
        run.steps
            .iter()
            .any(|s| matches!(s.action, Action::Replanned(_)))
    );
    let again = run_scenario(&map, &problem, &scenario, &options).unwrap();
    assert_eq!(again.motion, run.motion);
    for (a, b) in again.steps.iter().zip(&run.steps) {
        assert_eq!(
            (&a.action, a.blocked, a.restored, a.added, &a.parked_nodes),
            (&b.action, b.blocked, b.restored, b.added, &b.parked_nodes)
        );
    }
}
