//! Planning through the reach map: trajectories are collision-free in the current world, within
//! limits and velocity bounds, continuous, and start and end where asked; impossible queries are
//! clear errors.

use std::path::Path;
use std::sync::OnceLock;

use trm_collision::{Shape, World};
use trm_kinematics::nalgebra::Isometry3;
use trm_plan::{ExactGoal, Goal, PlanError, PlanOptions, Planner};
use trm_roadmap::{BuildOptions, Builder, Roadmap, connect};
use trm_tasks::Problem;

fn problem() -> &'static Problem {
    static P: OnceLock<Problem> = OnceLock::new();
    P.get_or_init(|| {
        Problem::load(Path::new(env!("CARGO_MANIFEST_DIR")).join("../../specs/reach.ron")).unwrap()
    })
}

fn map() -> &'static Roadmap {
    static M: OnceLock<Roadmap> = OnceLock::new();
    M.get_or_init(|| {
        let p = problem();
        let mut map = Builder::new(
            p,
            &BuildOptions {
                points: Some(120),
                ..Default::default()
            },
        )
        .run(|_| {})
        .unwrap();
        connect(&mut map, &p.objective, 8, 0.05).unwrap();
        map
    })
}

fn with_box() -> World {
    let mut w = problem().objective.world().clone();
    w.add(
        "new_box",
        Shape::Box {
            size: [0.08, 0.06, 0.16],
        },
        Isometry3::translation(-0.3, 0.08, -0.04),
    )
    .unwrap();
    w
}

/// Every property a returned trajectory must have, checked independently of the planner's own
/// bookkeeping (finer interpolation, limits, velocities).
fn check(planner: &mut Planner, start: &[f64], plan: &trm_plan::Planned, options: &PlanOptions) {
    let p = problem();
    let active = p.objective.active();
    let traj = &plan.trajectory;
    let qs: Vec<Vec<f64>> = traj
        .positions
        .iter()
        .map(|m| active.from_motors(m))
        .collect();
    assert_eq!(qs[0], start, "starts at the start");
    let (lower, upper) = active.bounds();
    for q in &qs {
        for i in 0..q.len() {
            assert!(q[i] >= lower[i] - 1e-12 && q[i] <= upper[i] + 1e-12);
        }
    }
    for (k, w) in qs.windows(2).enumerate() {
        assert!(
            planner.segment_free(&w[0], &w[1], options.resolution / 2.0),
            "segment {k} collides"
        );
    }
    // within the velocity and acceleration limits at every sample
    let limits = options.timing.joint_limits(active).unwrap();
    for (k, (v, a)) in traj.velocities.iter().zip(&traj.accelerations).enumerate() {
        let (v, a) = (active.from_motors(v), active.from_motors(a));
        for j in 0..v.len() {
            assert!(
                v[j].abs() <= limits.velocity[j] * (1.0 + 1e-6),
                "sample {k} too fast"
            );
            assert!(
                a[j].abs() <= limits.acceleration[j] * (1.0 + 1e-6),
                "sample {k}: joint {j} at {} for {}",
                a[j],
                limits.acceleration[j]
            );
        }
    }
    assert!(traj.times.windows(2).all(|t| t[1] >= t[0]));
    assert_eq!(traj.task_path.len(), qs.len());
}

#[test]
fn a_point_goal_is_reached_collision_free_around_a_new_box() {
    let p = problem();
    let map = map();
    let mut planner = Planner::new(&p.objective, &[map]).unwrap();
    planner.set_world(with_box());
    let options = PlanOptions::default();
    let goal_t = map.points[map.points.len() / 2].t.clone();
    let plan = planner
        .plan(
            &p.start,
            &Goal::TaskPoint {
                t: goal_t.clone(),
                tolerance: 0.03,
            },
            &options,
        )
        .unwrap();
    check(&mut planner, &p.start, &plan, &options);
    let end = plan.trajectory.task_path.last().unwrap();
    let d: f64 = end
        .iter()
        .zip(&goal_t)
        .map(|(a, b)| (a - b).powi(2))
        .sum::<f64>()
        .sqrt();
    assert!(d <= 0.03, "ends {d} from the goal");
    // the same query again is reproducible
    let again = planner
        .plan(
            &p.start,
            &Goal::TaskPoint {
                t: goal_t,
                tolerance: 0.03,
            },
            &options,
        )
        .unwrap();
    assert_eq!(again.trajectory, plan.trajectory);
}

/// A world changed by adding or removing objects keeps what the checks found where the change
/// cannot alter it: the plans are those of a planner that checks everything again, with fewer
/// edges checked.
#[test]
fn world_updates_keep_the_checks_they_cannot_change() {
    let p = problem();
    let map = map();
    let options = PlanOptions::default();
    let goal = Goal::TaskPoint {
        t: map.points[map.points.len() / 2].t.clone(),
        tolerance: 0.03,
    };
    let mut kept = Planner::new(&p.objective, &[map]).unwrap();
    let first = kept.plan(&p.start, &goal, &options).unwrap();
    for (world, what) in [
        (with_box(), "a box added"),
        (p.objective.world().clone(), "the box removed"),
        (with_box(), "the box added again"),
    ] {
        kept.set_world(world.clone());
        let planned = kept.plan(&p.start, &goal, &options).unwrap();
        let mut fresh = Planner::new(&p.objective, &[map]).unwrap();
        fresh.set_world(p.objective.world().clone());
        fresh.plan(&p.start, &goal, &options).unwrap();
        // the fresh planner's states: everything checked again in this world
        fresh.set_world(with_box());
        fresh.set_world(World::new());
        fresh.set_world(world);
        let again = fresh.plan(&p.start, &goal, &options).unwrap();
        assert_eq!(planned.trajectory, again.trajectory, "{what}");
        assert!(
            planned.stats.edges_checked <= again.stats.edges_checked,
            "{what}: {} edges checked, {} from scratch",
            planned.stats.edges_checked,
            again.stats.edges_checked
        );
        if what == "the box removed" {
            // back in the map's world: the first query's path is as free as it was
            assert_eq!(planned.trajectory, first.trajectory);
            assert!(planned.stats.edges_checked < again.stats.edges_checked);
        }
    }
}

#[test]
fn a_configuration_goal_ends_exactly_there() {
    let p = problem();
    let map = map();
    let mut planner = Planner::new(&p.objective, &[map]).unwrap();
    let options = PlanOptions {
        timing: trm_plan::Timing {
            default_acceleration: 2.0,
            ..Default::default()
        },
        ..Default::default()
    };
    let goal = map.points[map.points.len() - 1].q.clone();
    let plan = planner
        .plan(&p.start, &Goal::Configuration(goal.clone()), &options)
        .unwrap();
    check(&mut planner, &p.start, &plan, &options);
    let last = p
        .objective
        .active()
        .from_motors(plan.trajectory.positions.last().unwrap());
    assert_eq!(last, goal);
}

#[test]
fn impossible_queries_are_clear_errors() {
    let p = problem();
    let map = map();
    let mut planner = Planner::new(&p.objective, &[map]).unwrap();
    let far = Goal::TaskPoint {
        t: vec![1.0, 1.0, 1.0],
        tolerance: 0.03,
    };
    match planner.plan(&p.start, &far, &PlanOptions::default()) {
        Err(PlanError::Unreachable {
            closest_node: Some(_),
            closest_distance,
            ..
        }) => {
            assert!(closest_distance > 0.5)
        }
        other => panic!("{other:?}"),
    }
    // a wall through the whole workspace in front of the robot cuts every path to the goal
    let mut wall = p.objective.world().clone();
    wall.add(
        "wall",
        Shape::Box {
            size: [0.02, 2.0, 2.0],
        },
        Isometry3::translation(-0.27, 0.0, 0.0),
    )
    .unwrap();
    planner.set_world(wall);
    let goal_t = map.points[map.points.len() / 2].t.clone();
    let e = planner.plan(
        &p.start,
        &Goal::TaskPoint {
            t: goal_t,
            tolerance: 0.05,
        },
        &PlanOptions::default(),
    );
    assert!(
        matches!(
            e,
            Err(PlanError::InvalidStart(_)) | Err(PlanError::Unreachable { .. })
        ),
        "{e:?}"
    );
    let e = planner
        .plan(&p.start[..3], &far, &PlanOptions::default())
        .unwrap_err();
    assert!(matches!(e, PlanError::InvalidStart(_)));
    let mut nan_start = p.start.clone();
    nan_start[2] = f64::NAN;
    let e = planner.plan(&nan_start, &far, &PlanOptions::default());
    assert!(
        matches!(&e, Err(PlanError::InvalidStart(m)) if m.contains("start[2] is NaN")),
        "{e:?}"
    );
}

#[test]
fn goals_that_do_not_fit_the_spaces_are_named_not_searched_for() {
    let p = problem();
    let mut planner = Planner::new(&p.objective, &[map()]).unwrap();
    let point = |t: Vec<f64>, tolerance: f64| Goal::TaskPoint { t, tolerance };
    let mut wrong_length = p.start.clone();
    wrong_length.pop();
    for (goal, says) in [
        (
            point(vec![0.1, 0.2], 0.03),
            "the goal point has 2 values; the task space has 3",
        ),
        (
            point(vec![0.1, f64::NAN, 0.0], 0.03),
            "the goal point[1] is NaN",
        ),
        (point(vec![0.1, 0.2, 0.0], f64::NAN), "the tolerance is NaN"),
        (point(vec![0.1, 0.2, 0.0], -0.1), "the tolerance is -0.1"),
        (
            Goal::Configuration(wrong_length),
            "the goal configuration has",
        ),
        (
            Goal::Configuration(vec![f64::INFINITY; p.start.len()]),
            "the goal configuration[0] is inf",
        ),
        (
            Goal::TaskRegion {
                min: vec![0.0, 0.0, 1.0],
                max: vec![1.0, 1.0, 0.0],
            },
            "min[2] = 1 is above max[2] = 0",
        ),
        (
            Goal::TaskRegion {
                min: vec![0.0; 3],
                max: vec![1.0; 4],
            },
            "the region's max has 4 values",
        ),
    ] {
        let e = planner
            .plan(&p.start, &goal, &PlanOptions::default())
            .unwrap_err();
        assert!(
            matches!(e, PlanError::InvalidGoal { .. }),
            "{goal:?}: {e:?}"
        );
        let text = e.to_string();
        assert!(
            text.contains(says) && text.contains("fix:"),
            "{goal:?}: {text}"
        );
    }
}

#[test]
fn an_attached_map_is_checked_in_the_planners_world_not_trusted() {
    let p = problem();
    let map = map();
    let mut objective = p.objective.clone();
    objective.set_world(with_box());
    let mut planner = Planner::new(&objective, &[]).unwrap();
    assert_eq!(planner.add_map(map).unwrap(), map.points.len());
    assert_eq!(planner.num_edges(), map.edges.len());
    let goal = Goal::TaskPoint {
        t: map.points[map.points.len() / 2].t.clone(),
        tolerance: 0.03,
    };
    let options = PlanOptions::default();
    let planned = planner.plan(&p.start, &goal, &options).unwrap();
    check(&mut planner, &p.start, &planned, &options);
    assert!(planned.stats.edges_checked > 0);
    // the same as the map's own planner moved into that world (nothing trusted there either)
    let mut moved = Planner::new(&p.objective, &[map]).unwrap();
    moved.set_world(with_box());
    let again = moved.plan(&p.start, &goal, &options).unwrap();
    assert_eq!(planned.trajectory, again.trajectory);
    assert_eq!(planned.stats.edges_checked, again.stats.edges_checked);
    // a second map joins the first through its nearest nodes
    planner.add_map(map).unwrap();
    assert_eq!(
        planner.num_edges(),
        2 * map.edges.len() + 3 * map.points.len()
    );
    // a map of other motors is refused, naming them
    let mut other = map.clone();
    other.active[0] = "l_elbow".into();
    let e = planner.add_map(&other).unwrap_err().to_string();
    assert!(e.contains("l_elbow") && e.contains("map 2"), "{e}");
}

#[test]
fn two_maps_are_joined_through_configuration_space() {
    let p = problem();
    let map = map();
    // split the map by the palm's y into two maps without edges between them
    let split = |left: bool| {
        let keep: Vec<usize> = (0..map.points.len())
            .filter(|&i| (map.points[i].t[1] < 0.1) == left)
            .collect();
        let index = |i: usize| keep.iter().position(|&k| k == i);
        let mut m = map.clone();
        m.points = keep.iter().map(|&i| map.points[i].clone()).collect();
        m.edges = map
            .edges
            .iter()
            .filter_map(|&(a, b, l)| Some((index(a)?, index(b)?, l)))
            .collect();
        m
    };
    let (a, b) = (split(true), split(false));
    assert!(!a.points.is_empty() && !b.points.is_empty());
    let mut planner = Planner::new(&p.objective, &[&a, &b]).unwrap();
    assert!(planner.num_edges() > a.edges.len() + b.edges.len());
    // from a node of map b to a point only map a covers
    let start = b.points[0].q.clone();
    let goal_t = a.points[a.points.len() / 2].t.clone();
    let options = PlanOptions {
        shortcuts: 0,
        ..Default::default()
    };
    let plan = planner
        .plan(
            &start,
            &Goal::TaskPoint {
                t: goal_t,
                tolerance: 0.01,
            },
            &options,
        )
        .unwrap();
    check(&mut planner, &start, &plan, &options);
    assert!(
        plan.nodes.iter().any(|&n| n < a.points.len())
            && plan.nodes.iter().any(|&n| n >= a.points.len())
    );
}

#[test]
fn a_region_goal_ends_inside_the_region() {
    let p = problem();
    let map = map();
    let mut planner = Planner::new(&p.objective, &[map]).unwrap();
    let t = &map.points[map.points.len() / 3].t;
    let (min, max): (Vec<f64>, Vec<f64>) = t.iter().map(|v| (v - 0.02, v + 0.02)).unzip();
    let options = PlanOptions::default();
    let plan = planner
        .plan(
            &p.start,
            &Goal::TaskRegion {
                min: min.clone(),
                max: max.clone(),
            },
            &options,
        )
        .unwrap();
    check(&mut planner, &p.start, &plan, &options);
    let end = plan.trajectory.task_path.last().unwrap();
    assert!(
        end.iter()
            .enumerate()
            .all(|(i, v)| *v >= min[i] && *v <= max[i]),
        "{end:?}"
    );
}

#[test]
fn out_of_range_options_are_refused_before_planning() {
    let (problem, map) = (problem(), map());
    let mut planner = Planner::new(&problem.objective, &[map]).unwrap();
    let goal = Goal::TaskPoint {
        t: map.points[0].t.clone(),
        tolerance: 0.03,
    };
    for options in [
        PlanOptions {
            timing: trm_plan::Timing {
                default_velocity: 0.0,
                ..Default::default()
            },
            ..Default::default()
        },
        PlanOptions {
            resolution: 0.0,
            ..Default::default()
        },
        PlanOptions {
            timing: trm_plan::Timing {
                default_acceleration: f64::NAN,
                ..Default::default()
            },
            ..Default::default()
        },
        PlanOptions {
            timing: trm_plan::Timing {
                velocity_scaling: 1.5,
                ..Default::default()
            },
            ..Default::default()
        },
        PlanOptions {
            timing: trm_plan::Timing {
                max_deviation: -0.1,
                ..Default::default()
            },
            ..Default::default()
        },
        PlanOptions {
            attach_neighbours: 0,
            ..Default::default()
        },
        PlanOptions {
            exact_tolerance: 0.0,
            ..Default::default()
        },
        PlanOptions {
            exact_tolerance: f64::NAN,
            ..Default::default()
        },
        PlanOptions {
            exact_evaluations: 0,
            ..Default::default()
        },
    ] {
        let e = planner.plan(&problem.start, &goal, &options).unwrap_err();
        assert!(matches!(e, PlanError::InvalidOptions { .. }), "{e}");
    }
}

/// A point goal off the map nodes: the path goes through a node within the tolerance and then
/// to the point itself (NGIK, checked last segment); without the exact finish, or when it
/// cannot reach the asked accuracy, the path ends at the node and says why.
#[test]
fn a_point_goal_is_finished_exactly_or_falls_back_clearly() {
    let p = problem();
    let map = map();
    let mut planner = Planner::new(&p.objective, &[map]).unwrap();
    let node = &map.points[map.points.len() / 3].t;
    let goal_t: Vec<f64> = node
        .iter()
        .zip([0.012, -0.008, 0.006])
        .map(|(a, b)| a + b)
        .collect();
    let goal = Goal::TaskPoint {
        t: goal_t.clone(),
        tolerance: 0.03,
    };
    let options = PlanOptions::default();
    let plan = planner.plan(&p.start, &goal, &options).unwrap();
    check(&mut planner, &p.start, &plan, &options);
    assert!(
        matches!(plan.stats.exact, ExactGoal::Reached { .. }),
        "{:?}",
        plan.stats.exact
    );
    let error = plan.stats.goal_error.unwrap();
    assert!(error <= 1e-3, "ends {error} from the goal");
    let end = plan.trajectory.task_path.last().unwrap();
    let d = trm_collision::edge::distance(end, &goal_t);
    assert!((d - error).abs() < 1e-12, "{d} vs {error}");

    let at_node = planner
        .plan(
            &p.start,
            &goal,
            &PlanOptions {
                exact_goal: false,
                ..Default::default()
            },
        )
        .unwrap();
    assert_eq!(at_node.stats.exact, ExactGoal::NotTried);
    assert!(at_node.stats.goal_error.unwrap() > 1e-3);
    assert_eq!(
        at_node.waypoints.len() + 1,
        plan.waypoints.len(),
        "one more waypoint"
    );

    let strict = PlanOptions {
        exact_tolerance: 1e-14,
        exact_evaluations: 2_000,
        ..Default::default()
    };
    let fallback = planner.plan(&p.start, &goal, &strict).unwrap();
    check(&mut planner, &p.start, &fallback, &strict);
    match &fallback.stats.exact {
        ExactGoal::Fallback { reason } => assert!(reason.contains("came within"), "{reason}"),
        other => panic!("{other:?}"),
    }
    assert_eq!(fallback.trajectory, at_node.trajectory);
}

/// A point goal beyond the map's edge — its nearest node farther than the tolerance but within
/// twice it — is reached through that node and NGIK; farther than twice the tolerance, or
/// without the exact finish, it stays unreachable.
#[test]
fn a_point_goal_just_off_the_map_is_reached_through_its_nearest_node() {
    let p = problem();
    let map = map();
    let mut planner = Planner::new(&p.objective, &[map]).unwrap();
    // the node farthest out along +y, and a goal 4 cm beyond it
    let edge = map
        .points
        .iter()
        .max_by(|a, b| a.t[1].total_cmp(&b.t[1]))
        .unwrap();
    let goal_t = vec![edge.t[0], edge.t[1] + 0.04, edge.t[2]];
    let nearest = map
        .points
        .iter()
        .map(|m| trm_collision::edge::distance(&m.t, &goal_t))
        .fold(f64::INFINITY, f64::min);
    assert!(nearest > 0.03 && nearest <= 0.06, "{nearest}");
    let goal = Goal::TaskPoint {
        t: goal_t.clone(),
        tolerance: 0.03,
    };
    let options = PlanOptions::default();
    let plan = planner.plan(&p.start, &goal, &options).unwrap();
    check(&mut planner, &p.start, &plan, &options);
    assert!(matches!(plan.stats.exact, ExactGoal::Reached { .. }));
    assert!(plan.stats.goal_error.unwrap() <= 1e-3);
    let no_exact = PlanOptions {
        exact_goal: false,
        ..Default::default()
    };
    assert!(matches!(
        planner.plan(&p.start, &goal, &no_exact),
        Err(PlanError::Unreachable { .. })
    ));
    let narrow = Goal::TaskPoint {
        t: goal_t,
        tolerance: nearest / 2.5,
    };
    assert!(matches!(
        planner.plan(&p.start, &narrow, &options),
        Err(PlanError::Unreachable { .. })
    ));
}

/// The ROS 2 JointTrajectory YAML of a plan parses as YAML and carries the URDF joints (no
/// mimics), their values through the couplings, zero waypoint velocities and the times.
#[test]
fn trajectories_export_as_ros_joint_trajectories() {
    use yaml_rust2::YamlLoader;
    let p = problem();
    let map = map();
    let mut planner = Planner::new(&p.objective, &[map]).unwrap();
    let options = PlanOptions {
        exact_goal: false,
        ..Default::default()
    };
    let goal = Goal::TaskPoint {
        t: map.points[7].t.clone(),
        tolerance: 0.03,
    };
    let plan = planner.plan(&p.start, &goal, &options).unwrap();
    let traj = &plan.trajectory;
    let robot = &p.robot;
    let path = Path::new("plan.ros.yaml");
    let text = traj.to_ros_yaml(robot, path).unwrap();
    let doc = &YamlLoader::load_from_str(&text).unwrap()[0];
    let commanded: Vec<usize> = (0..robot.num_joints())
        .filter(|&j| robot.joint(j).mimic.is_none())
        .collect();
    let names: Vec<&str> = doc["joint_names"]
        .as_vec()
        .unwrap()
        .iter()
        .map(|n| n.as_str().unwrap())
        .collect();
    let want: Vec<&str> = commanded
        .iter()
        .map(|&j| robot.joint(j).name.as_str())
        .collect();
    assert_eq!(names, want);
    let points = doc["points"].as_vec().unwrap();
    assert_eq!(points.len(), traj.times.len());
    let mut joints = vec![0.0; robot.num_joints()];
    for (k, point) in points.iter().enumerate() {
        robot
            .motors_to_joints(&traj.positions[k], &mut joints)
            .unwrap();
        let positions: Vec<f64> = point["positions"]
            .as_vec()
            .unwrap()
            .iter()
            .map(|v| v.as_f64().unwrap())
            .collect();
        let expected: Vec<f64> = commanded.iter().map(|&j| joints[j]).collect();
        assert_eq!(positions, expected, "point {k}");
        let velocities: Vec<f64> = point["velocities"]
            .as_vec()
            .unwrap()
            .iter()
            .map(|v| v.as_f64().unwrap())
            .collect();
        assert_eq!(velocities.len(), commanded.len());
        // at rest at both ends, moving between
        let moving = velocities.iter().any(|v| *v != 0.0);
        assert_eq!(moving, k > 0 && k + 1 < points.len(), "point {k}");
        assert_eq!(
            point["accelerations"].as_vec().unwrap().len(),
            commanded.len()
        );
        let t = &point["time_from_start"];
        let time = t["sec"].as_i64().unwrap() as f64 + t["nanosec"].as_i64().unwrap() as f64 * 1e-9;
        assert!(
            (time - traj.times[k]).abs() <= 1e-9,
            "{time} vs {}",
            traj.times[k]
        );
    }
    // a trajectory of another robot is refused with the file named
    let mut other = traj.clone();
    other.names[0] = "no_such_motor".into();
    let e = other.to_ros_yaml(robot, path).unwrap_err().to_string();
    assert!(
        e.contains("plan.ros.yaml") && e.contains("no_such_motor"),
        "{e}"
    );
}

#[test]
fn a_configuration_goal_the_maps_do_not_reach_is_finished_by_rrt_connect() {
    use rand::SeedableRng;
    let p = problem();
    let mut planner = Planner::new(&p.objective, &[map()]).unwrap();
    let maps_only = PlanOptions {
        sampling: None,
        attach_neighbours: 1,
        ..Default::default()
    };
    let with_sampling = PlanOptions {
        attach_neighbours: 1,
        ..Default::default()
    };
    // seeded random goals: the first free one the map alone cannot reach
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
    let mut found = 0;
    for _ in 0..300 {
        let q = p.objective.active().random(&mut rng);
        if !planner.is_free(&q) {
            continue;
        }
        let goal = Goal::Configuration(q.clone());
        if !matches!(
            planner.plan(&p.start, &goal, &maps_only),
            Err(PlanError::Unreachable { .. })
        ) {
            continue;
        }
        let planned = planner.plan(&p.start, &goal, &with_sampling).unwrap();
        let (samples, checks) = planned.stats.sampled.expect("RRT-Connect answered");
        assert!(samples > 0 && checks > 0);
        let last = planned.trajectory.positions.last().unwrap();
        assert_eq!(&p.objective.active().from_motors(last), &q);
        check(&mut planner, &p.start, &planned, &with_sampling);
        found += 1;
        if found == 3 {
            break;
        }
    }
    assert_eq!(found, 3, "too few goals the map alone cannot reach");
}

/// Options of a search through the graph alone: no shortcut, no sampling, no exact finish.
fn graph_only() -> PlanOptions {
    PlanOptions {
        shortcuts: 0,
        exact_goal: false,
        sampling: None,
        ..Default::default()
    }
}

/// A query that repeats a kept path's ends is answered by that path, without a search, when it
/// is free (checked in the current world), and by a search otherwise; a query elsewhere
/// searches.
#[test]
fn repeated_queries_retrieve_the_kept_path_while_it_is_free() {
    let p = problem();
    let map = map();
    let options = graph_only();
    let goal = map.points[map.points.len() / 2].q.clone();
    let found = Planner::new(&p.objective, &[map])
        .unwrap()
        .plan(&p.start, &Goal::Configuration(goal.clone()), &options)
        .unwrap();
    assert!(!found.stats.retrieved && found.waypoints.len() >= 2);
    // a planner that knows only this path
    let mut planner = Planner::new(&p.objective, &[]).unwrap();
    planner.add_path(&found.waypoints).unwrap();
    let again = planner
        .plan(&p.start, &Goal::Configuration(goal.clone()), &options)
        .unwrap();
    assert!(again.stats.retrieved);
    assert_eq!(again.waypoints, found.waypoints);
    check(&mut planner, &p.start, &again, &options);
    // backwards, and with ends a resolution step away
    let mut nudged = p.start.clone();
    nudged[0] += options.resolution;
    let back = planner
        .plan(&goal, &Goal::Configuration(nudged.clone()), &options)
        .unwrap();
    assert!(back.stats.retrieved);
    assert_eq!(back.waypoints.last().unwrap(), &nudged);
    // far from the kept ends: no retrieval
    let mut far = p.start.clone();
    far[0] += 3.0 * options.resolution;
    if let Ok(plan) = planner.plan(&far, &Goal::Configuration(goal.clone()), &options) {
        assert!(!plan.stats.retrieved);
    }
    // an obstacle on the path's middle edge: the path is not returned through it
    let (a, b) = {
        let m = found.waypoints.len() / 2;
        (&found.waypoints[m - 1], &found.waypoints[m])
    };
    let middle: Vec<f64> = a.iter().zip(b).map(|(x, y)| 0.5 * (x + y)).collect();
    let mut scratch = p.objective.scratch();
    let hand = p.objective.task_value(&middle, &mut scratch);
    let mut world = p.objective.world().clone();
    world
        .add(
            "on_the_path",
            Shape::Sphere { radius: 0.005 },
            Isometry3::translation(hand[0], hand[1], hand[2]),
        )
        .unwrap();
    planner.set_world(world);
    if !planner.is_free(a) || !planner.is_free(b) || planner.segment_free(a, b, options.resolution)
    {
        return; // the sphere missed the edge or hit its ends: nothing to learn here
    }
    match planner.plan(&p.start, &Goal::Configuration(goal), &options) {
        Ok(plan) => {
            assert!(!plan.stats.retrieved);
            check(&mut planner, &p.start, &plan, &options);
        }
        Err(e) => assert!(matches!(e, PlanError::Unreachable { .. }), "{e}"),
    }
}

/// Forgetting the kept paths leaves the maps as they were (nodes, edges, answers); paths kept
/// afterwards are searched as by a planner made with the maps and given only them. A path whose
/// waypoints are map nodes takes nothing of the map with it.
#[test]
fn forgotten_paths_leave_the_maps_as_they_were() {
    let p = problem();
    let map = map();
    let options = graph_only();
    let mut kept = Planner::new(&p.objective, &[map]).unwrap();
    let (nodes, edges) = (kept.num_nodes(), kept.num_edges());
    let goal = |k: usize| Goal::Configuration(map.points[k * map.points.len() / 5].q.clone());
    let first = kept.plan(&p.start, &goal(2), &options).unwrap();
    kept.add_path(&first.waypoints).unwrap();
    kept.add_path(&[map.points[0].q.clone(), map.points[1].q.clone()])
        .unwrap();
    assert!(kept.num_nodes() > nodes && kept.num_edges() > edges + 1);
    kept.forget_paths();
    assert_eq!((kept.num_nodes(), kept.num_edges()), (nodes, edges));
    assert!(kept.kept_paths().is_empty());
    let second = Planner::new(&p.objective, &[map])
        .unwrap()
        .plan(&p.start, &goal(4), &options)
        .unwrap();
    let mut fresh = Planner::new(&p.objective, &[map]).unwrap();
    for planner in [&mut kept, &mut fresh] {
        planner.add_path(&second.waypoints).unwrap();
    }
    assert_eq!(kept.kept_paths(), fresh.kept_paths());
    assert_eq!(kept.num_edges(), fresh.num_edges());
    // the path kept last, forgotten: as though it had never been kept
    let edges = kept.num_edges();
    kept.add_path(&first.waypoints).unwrap();
    assert!(kept.num_edges() > edges);
    assert!(kept.forget_last_path());
    assert_eq!(kept.kept_paths(), fresh.kept_paths());
    assert_eq!(
        (kept.num_nodes(), kept.num_edges()),
        (fresh.num_nodes(), edges)
    );
    for k in 0..5 {
        let (a, b) = (
            kept.plan(&p.start, &goal(k), &options),
            fresh.plan(&p.start, &goal(k), &options),
        );
        match (a, b) {
            (Ok(a), Ok(b)) => {
                assert_eq!(a.waypoints, b.waypoints, "goal {k}");
                assert_eq!(a.stats.retrieved, b.stats.retrieved, "goal {k}");
            }
            (a, b) => assert_eq!(a.is_err(), b.is_err(), "goal {k}"),
        }
    }
    // not past a map attached after it, nor with no path kept
    kept.add_map(map).unwrap();
    assert!(!kept.forget_last_path());
    let mut bare = Planner::new(&p.objective, &[map]).unwrap();
    assert!(!bare.forget_last_path());
    assert_eq!(bare.num_nodes(), nodes);
}
