//! Cost and task functions against hand computations on the planar arm and the iCub.

use std::path::Path;

use trm_tasks::Problem;

/// A spec on the 3-link planar arm (links 1.0, 0.8, 0.5 m; joints about z; base at z = 0.1).
fn arm(costs: &str, task: &str) -> Problem {
    let text = format!(
        "(model: \"planar_arm\", costs: [{costs}], task: {task}, solver: (max_evaluations: 4000, seed: 3))"
    );
    Problem::from_ron(&text, "arm.ron", Path::new(".")).unwrap()
}

fn tool(q: &[f64]) -> [f64; 3] {
    let (a, b, c) = (q[0], q[0] + q[1], q[0] + q[1] + q[2]);
    [
        a.cos() + 0.8 * b.cos() + 0.5 * c.cos(),
        a.sin() + 0.8 * b.sin() + 0.5 * c.sin(),
        0.1,
    ]
}

fn eval(p: &Problem, q: &[f64]) -> f64 {
    p.objective.eval(q, &mut p.objective.scratch())
}

#[test]
fn position_costs_are_distances_with_masks_boxes_and_balls() {
    let q = [0.3, -0.7, 0.4];
    let t = tool(&q);
    let target = [0.5, 1.0, 0.1];
    let d = ((t[0] - target[0]).powi(2) + (t[1] - target[1]).powi(2)).sqrt();
    let p = arm(
        "(weight: 2.0, cost: Position(part: \"tool\", target: Point((0.5, 1.0, 0.1))))",
        "None",
    );
    assert!((eval(&p, &q) - 2.0 * d).abs() < 1e-12);
    // masking y leaves |x − 0.5|: attraction to a plane
    let p = arm(
        "(weight: 1.0, cost: Position(part: \"tool\", target: Point((0.5, 1.0, 0.1)), mask: (true, false, true)))",
        "None",
    );
    assert!((eval(&p, &q) - (t[0] - 0.5).abs()).abs() < 1e-12);
    // a box containing the tool costs 0; one beside it costs the gap
    let p = arm(
        &format!(
            "(weight: 1.0, cost: Position(part: \"tool\", target: Box(min: ({}, -5.0, -1.0), max: (9.0, 5.0, 1.0))))",
            t[0] + 0.25
        ),
        "None",
    );
    assert!((eval(&p, &q) - 0.25).abs() < 1e-12);
    let p = arm(
        "(weight: 1.0, cost: Position(part: \"tool\", target: Sphere(center: Point((0.0, 0.0, 0.1)), radius: 5.0)))",
        "None",
    );
    assert_eq!(eval(&p, &q), 0.0);
}

#[test]
fn orientation_pointing_and_repel_have_their_published_ranges() {
    // the tool's x axis points along the last link: direction (cos c, sin c, 0)
    let q = [0.2, 0.3, 0.4];
    let c: f64 = 0.9;
    let p = arm(
        &format!(
            "(weight: 1.0, cost: Orientation(part: \"tool\", axis: (1, 0, 0), toward: Fixed(({}, {}, 0.0))))",
            c.cos(),
            c.sin()
        ),
        "None",
    );
    assert!(eval(&p, &q).abs() < 1e-12, "aligned → 0");
    let p = arm(
        &format!(
            "(weight: 1.0, cost: Orientation(part: \"tool\", axis: (1, 0, 0), toward: Fixed(({}, {}, 0.0))))",
            -c.cos(),
            -c.sin()
        ),
        "None",
    );
    assert!((eval(&p, &q) - 1.0).abs() < 1e-12, "opposite → 1");
    // pointing at a point straight ahead along the axis, 2 m away, asked to stay 1.5 m away
    let t = tool(&q);
    let ahead = [t[0] + 2.0 * c.cos(), t[1] + 2.0 * c.sin(), 0.1];
    let p = arm(
        &format!(
            "(weight: 1.0, cost: Pointing(part: \"tool\", axis: (1, 0, 0), at: Point(({}, {}, {})), distance: Some(1.5)))",
            ahead[0], ahead[1], ahead[2]
        ),
        "None",
    );
    assert!((eval(&p, &q) - 0.5).abs() < 1e-9);
    // repel: the tool 0.3 m from a point with d = 0.6 → (0.6 − 0.3)/0.6
    let p = arm(
        &format!(
            "(weight: 1.0, cost: Repel(a: Part(\"tool\"), b: Point(({}, {}, 0.1)), min_distance: 0.6))",
            t[0] + 0.3,
            t[1]
        ),
        "None",
    );
    assert!((eval(&p, &q) - 0.5).abs() < 1e-12);
}

#[test]
fn home_limits_and_displacement_costs() {
    let p = arm(
        "(weight: 1.0, cost: HomePosture(weights: {\"joint1\": 3.0})), (weight: 1.0, cost: Displacement)",
        "None",
    );
    // start = home = neutral (0, 0, 0): both terms are norms of q, joint1 weighted 3
    let q = [0.1, 0.2, -0.2];
    let home = ((0.3f64).powi(2) + 0.04 + 0.04).sqrt();
    let disp = (0.01f64 + 0.04 + 0.04).sqrt();
    assert!((eval(&p, &q) - home - disp).abs() < 1e-12);
    let p = arm("(weight: 1.0, cost: JointLimits(margin: 0.5))", "None");
    assert_eq!(eval(&p, &[0.0, 0.0, 0.0]), 0.0);
    // joint2 at 2.25 is 0.25 into the 0.5 band below 2.5 → 0.5
    assert!((eval(&p, &[0.0, 2.25, 0.0]) - 0.5).abs() < 1e-12);
}

#[test]
fn task_functions_match_hand_computations() {
    let q = [0.4, 0.5, -0.3];
    let t = tool(&q);
    let value = |task: &str| {
        let p = arm(
            "(weight: 1.0, cost: Displacement)",
            &format!("Some({task})"),
        );
        p.objective.task_value(&q, &mut p.objective.scratch())
    };
    let g = value("Position(part: \"tool\", mask: (true, true, false))");
    assert!((g[0] - t[0]).abs() < 1e-12 && (g[1] - t[1]).abs() < 1e-12 && g.len() == 2);
    let g = value("Distance(a: Part(\"tool\"), b: Point((0.0, 0.0, 0.1)))");
    assert!((g[0] - (t[0] * t[0] + t[1] * t[1]).sqrt()).abs() < 1e-12);
    let g =
        value("Angle(a: Part(\"tool\"), b: Point((0.0, 0.0, 0.1)), u1: (1, 0, 0), u2: (0, 1, 0))");
    assert!((g[0] - t[1].atan2(t[0])).abs() < 1e-12);
    let g = value("Midpoint(a: Part(\"tool\"), b: Part(\"base\"))");
    assert!((g[0] - t[0] / 2.0).abs() < 1e-12 && (g[2] - 0.05).abs() < 1e-12);
    let g = value("RodDirection(a: Part(\"base\"), b: Part(\"tool\"))");
    assert!(((g[0] * g[0] + g[1] * g[1] + g[2] * g[2]) - 1.0).abs() < 1e-12);
    let g = value("Rotation(part: \"tool\", axis: (1, 0, 0))");
    assert!((g[0] - (0.6f64).cos()).abs() < 1e-12 && (g[1] - (0.6f64).sin()).abs() < 1e-12);
    // the planar arm turns the tool by 0.6 rad about z: 0.4 rad from a 0.2 rad reference
    let g = value("Pose(part: \"tool\", scale: 0.5, reference: (0, 0, 0.2))");
    assert_eq!(g.len(), 6);
    assert!((g[0] - t[0]).abs() < 1e-12 && (g[1] - t[1]).abs() < 1e-12);
    assert!(g[3].abs() < 1e-12 && g[4].abs() < 1e-12 && (g[5] - 0.5 * 0.4).abs() < 1e-12);
    for bad in ["scale: 0", "scale: -1", "reference: (0, NaN, 0)"] {
        let text = format!(
            "(model: \"planar_arm\", costs: [(weight: 1.0, cost: Displacement)], task: Some(Pose(part: \"tool\", {bad})))"
        );
        let e = Problem::from_ron(&text, "pose.ron", Path::new("."))
            .unwrap_err()
            .to_string();
        assert!(e.contains("pose.ron") && e.contains("task."), "{bad}: {e}");
    }
}

#[test]
fn robustness_noise_is_deterministic_and_averages_the_cost() {
    let base = "(weight: 1.0, cost: Position(part: \"tool\", target: Point((1.5, 0.5, 0.1))))";
    let plain = arm(base, "None");
    let text = format!(
        "(model: \"planar_arm\", costs: [{base}], noise: Some((samples: 16, sigma: 0.05, seed: 2)))"
    );
    let noisy = Problem::from_ron(&text, "n.ron", Path::new(".")).unwrap();
    let q = [0.3, 0.2, 0.1];
    let (a, b) = (eval(&noisy, &q), eval(&noisy, &q));
    assert_eq!(a, b);
    assert!((a - eval(&plain, &q)).abs() > 1e-6 && (a - eval(&plain, &q)).abs() < 0.1);
}

#[test]
fn ngik_reaches_a_point_with_the_planar_arm() {
    let p = arm(
        "(weight: 1.0, cost: Position(part: \"tool\", target: Point((1.2, 1.1, 0.1))))",
        "Some(Position(part: \"tool\"))",
    );
    let s = trm_tasks::solve(&p.objective, &p.start, &p.spec.solver).unwrap();
    assert!(s.cost < 1e-3, "{}", s.cost);
    assert!((s.task[0] - 1.2).abs() < 1e-3 && (s.task[1] - 1.1).abs() < 1e-3);
    assert!(s.best_at <= s.evaluations);
}

/// The catalogue is open in code: a cost of one's own joins the objective like the built-ins.
#[test]
fn a_user_defined_cost_plugs_into_the_objective() {
    #[derive(Debug)]
    struct TipHeight;
    impl trm_tasks::Cost for TipHeight {
        fn label(&self) -> String {
            "tip height".into()
        }
        fn eval(&self, ctx: &trm_tasks::Context) -> f64 {
            let tool = ctx.robot.frame_id("tool").unwrap();
            (ctx.poses.pose(tool).translation.z - 0.1).abs()
        }
    }
    let p = arm("(weight: 1.0, cost: Displacement)", "None");
    let mut objective = trm_tasks::Objective::new(
        p.objective.active().clone(),
        p.objective.collision().clone(),
        p.objective.world().clone(),
    );
    objective.add(2.0, Box::new(TipHeight)).unwrap();
    assert!(objective.add(f64::NAN, Box::new(TipHeight)).is_err());
    let mut scratch = objective.scratch();
    assert_eq!(objective.eval(&[0.4, 0.2, 0.1], &mut scratch), 0.0);
    let (total, terms) = objective.breakdown(&[0.4, 0.2, 0.1], &mut scratch);
    assert_eq!((total, terms[0].label.as_str()), (0.0, "tip height"));
}
