//! The problems in the plain form peer planners (VAMP, OMPL) read, and their answers read back.

use trm_collision::{Shape, World};
use trm_moveit::{MotionPlanRequest, PlanningScene};

use crate::error::MbmError;
use crate::problems::Problem;
use crate::solve::{Outcome, joint_goal_only};

/// Writes `problems` in the plain-text format that peer planners read for trm's side-by-side
/// benchmark (`benches/peers/vamp/mbm.cc`): a header naming `robot` and the goal's joints,
/// then per problem its family, number, start and goal (in that joint order) and its world's
/// primitives (`box x y z qw qx qy qz hx hy hz`, `cylinder x y z qw qx qy qz radius length`,
/// `sphere x y z radius`), every number in its shortest exact form. With `clouds`, problem k's
/// obstacles are instead the point cloud `clouds[k]` (a world of one [`Shape::Points`], as
/// [`cloud_world`] makes), written as `cloud N RADIUS` and a line `x y z` per point.
pub fn peer_problems(
    robot: &str,
    problems: &[Problem],
    clouds: Option<&[World]>,
) -> Result<String, MbmError> {
    use std::fmt::Write as _;
    let mut joints: Option<Vec<String>> = None;
    let mut body = String::new();
    for (k, p) in problems.iter().enumerate() {
        let scene = PlanningScene::load(&p.scene)?;
        let request = MotionPlanRequest::load(&p.request)?;
        joint_goal_only(&request, "peer planners")?;
        let order = joints.get_or_insert_with(|| request.goal.names.clone());
        let mismatch = |what: &str| MbmError::Invalid {
            path: request.origin.clone(),
            line: 0,
            problem: format!("the {what} does not give the joints {}", order.join(", ")),
            fix: "give one set of problems for one robot and planning group".into(),
        };
        let mut sorted = request.goal.names.clone();
        sorted.sort();
        let mut expected = order.clone();
        expected.sort();
        if sorted != expected {
            return Err(mismatch("goal"));
        }
        let _ = writeln!(body, "problem {} {}", p.family, p.index);
        for (label, names, values) in [
            ("start", &request.start.names, &request.start.positions),
            ("goal", &request.goal.names, &request.goal.positions),
        ] {
            let _ = write!(body, "{label}");
            for joint in order.iter() {
                let i = names
                    .iter()
                    .position(|n| n == joint)
                    .ok_or_else(|| mismatch(label))?;
                let _ = write!(body, " {}", values[i]);
            }
            body.push('\n');
        }
        if let Some(world) = clouds.and_then(|c| c.get(k)) {
            let points = world.objects().iter().filter_map(|o| match o.shape() {
                Shape::Points { points, radius } => Some((points, radius)),
                _ => None,
            });
            let points: Vec<_> = points.collect();
            let _ = writeln!(body, "objects {}", points.len());
            for (points, radius) in points {
                let _ = writeln!(body, "cloud {} {radius}", points.len());
                for q in points {
                    let _ = writeln!(body, "{} {} {}", q[0], q[1], q[2]);
                }
            }
            continue;
        }
        body.push_str(&peer_objects(&scene)?);
    }
    let joints = joints.unwrap_or_default();
    Ok(format!(
        "trm-mbm-problems 1\nrobot {robot}\njoints {} {}\nproblems {}\n{body}",
        joints.len(),
        joints.join(" "),
        problems.len()
    ))
}

/// A scene's primitives as peer planners read them (the `objects` part of [`peer_problems`]'s
/// format): `objects N`, then a line per box, cylinder or sphere with its world pose.
pub fn peer_objects(scene: &PlanningScene) -> Result<String, MbmError> {
    use std::fmt::Write as _;
    let mut body = String::new();
    let primitives: Vec<_> = scene.objects.iter().flat_map(|o| &o.primitives).collect();
    let _ = writeln!(body, "objects {}", primitives.len());
    for primitive in primitives {
        let t = primitive.pose.translation.vector;
        let q = primitive.pose.rotation;
        let pose = format!("{} {} {} {} {} {} {}", t.x, t.y, t.z, q.w, q.i, q.j, q.k);
        let _ = match &primitive.shape {
            trm_collision::Shape::Sphere { radius } => {
                writeln!(body, "sphere {} {} {} {radius}", t.x, t.y, t.z)
            }
            trm_collision::Shape::Box { size } => writeln!(
                body,
                "box {pose} {} {} {}",
                size[0] / 2.0,
                size[1] / 2.0,
                size[2] / 2.0
            ),
            trm_collision::Shape::Cylinder { radius, length } => {
                writeln!(body, "cylinder {pose} {radius} {length}")
            }
            other => {
                return Err(MbmError::Invalid {
                    path: scene.origin.clone(),
                    line: 0,
                    problem: format!("a {other:?} has no peer-file form"),
                    fix: "give boxes, spheres and cylinders (MoveIt's primitives)".into(),
                });
            }
        };
    }
    Ok(body)
}

/// One problem as a peer planner reported it (`result` lines of `benches/peers/vamp/mbm.cc`):
/// the family, the number and the outcome (time = planning + simplification; `checks` 0: the
/// peer does not count them; an 11th field, when given, the time to build the obstacles'
/// structures).
pub fn parse_peer_results(text: &str) -> Result<Vec<(String, u32, Outcome)>, String> {
    let mut results: Vec<(String, u32, Outcome)> = Vec::new();
    for (n, line) in text.lines().enumerate() {
        let at = |problem: &str| format!("line {}: {problem}: `{line}`", n + 1);
        let mut words = line.split_whitespace();
        match words.next() {
            Some("result") => {
                let fields: Vec<&str> = words.collect();
                // the 11th, when there is one: building the obstacles' structures (a cloud's), ns
                if !(10..=11).contains(&fields.len()) {
                    return Err(at("a result has 10 or 11 fields"));
                }
                let number = |k: usize| -> Result<f64, String> {
                    fields[k]
                        .parse::<f64>()
                        .ok()
                        .filter(|v| v.is_finite())
                        .ok_or_else(|| at("not a finite number"))
                };
                let index = fields[1].parse().map_err(|_| at("not a problem number"))?;
                let valid = number(2)? != 0.0;
                let solved = number(3)? != 0.0;
                let outcome = Outcome {
                    valid,
                    solved: valid && solved,
                    seconds: (number(4)? + number(5)?) * 1e-9,
                    simplify_seconds: number(5)? * 1e-9,
                    length: number(7)?,
                    waypoints: number(9)? as usize,
                    build_seconds: if fields.len() == 11 {
                        number(10)? * 1e-9
                    } else {
                        0.0
                    },
                    note: match (valid, solved) {
                        (false, _) => "start or goal in collision for the peer".into(),
                        (true, false) => "not solved by the peer".into(),
                        _ => String::new(),
                    },
                    ..Default::default()
                };
                results.push((fields[0].to_string(), index, outcome));
            }
            Some("path") => {
                let q: Result<Vec<f64>, String> = words
                    .map(|w| {
                        w.parse::<f64>()
                            .ok()
                            .filter(|v| v.is_finite())
                            .ok_or_else(|| at("not a finite number"))
                    })
                    .collect();
                let last = results
                    .last_mut()
                    .ok_or_else(|| at("a path line before any result"))?;
                last.2.path.push(q?);
            }
            None => {}
            Some(_) => return Err(at("neither `result` nor `path`")),
        }
    }
    Ok(results)
}

/// Which obstacles trm plans among in a benchmark.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub enum Obstacles {
    /// The scenes' own: cylinders as cylinders.
    #[default]
    AsGiven,
    /// The obstacles VAMP plans among ([`vamp_world`]): its checks have no cylinder, so both
    /// planners face the same, larger, obstacles.
    AsVamp,
    /// The scenes as a depth camera would see them ([`cloud_world`]), as VAMP's
    /// `evaluate_mbm.py --pointcloud` makes them: `per_object` points on every object's
    /// surface, thinned to [`CLOUD_SPACING`], each a ball of [`CLOUD_POINT_RADIUS`].
    Cloud {
        /// Points drawn on each object (VAMP's default: 10 000).
        per_object: usize,
    },
}

/// The spacing a benchmark's clouds are thinned to, m (VAMP's `filter_radius`).
pub const CLOUD_SPACING: f64 = 0.02;

/// The radius of a benchmark cloud's points, m (VAMP's `POINT_RADIUS`).
pub const CLOUD_POINT_RADIUS: f64 = 0.0025;

/// How a problem's point cloud was made ([`cloud_world`]).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct CloudBuild {
    /// Points drawn on the objects.
    pub sampled: usize,
    /// Points kept after thinning.
    pub kept: usize,
    /// Thinning them, s (done once; the peers get the thinned cloud).
    pub thin_seconds: f64,
    /// Building the world object (with its exact grid; its bounding-volume tree waits for a
    /// distance query) and compiling the screen's grid for the robot, s.
    pub build_seconds: f64,
}

/// `world` as a depth camera would see it: `per_object` points drawn on each object's surface
/// (seeded by `seed`), thinned to [`CLOUD_SPACING`] ([`trm_collision::thin_points`]), one
/// object `cloud` of points of radius [`CLOUD_POINT_RADIUS`]; `compile` (the screen's world
/// compilation, timed with the build) may be `None`.
pub fn cloud_world(
    world: &World,
    per_object: usize,
    seed: u64,
    compile: Option<&trm_collision::fast::FastModel>,
) -> Result<(World, CloudBuild), MbmError> {
    use rand::SeedableRng;
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let mut points = Vec::new();
    for o in world.objects() {
        let pose = o.pose();
        points.extend(
            o.shape()
                .surface_samples(per_object, &mut rng)
                .into_iter()
                .map(|p| {
                    <[f64; 3]>::from((pose * trm_kinematics::nalgebra::Point3::from(p)).coords)
                }),
        );
    }
    let began = std::time::Instant::now();
    let kept = trm_collision::thin_points(&points, CLOUD_SPACING);
    let thin_seconds = began.elapsed().as_secs_f64();
    let build = CloudBuild {
        sampled: points.len(),
        kept: kept.len(),
        thin_seconds,
        ..Default::default()
    };
    let mut cloud = World::new();
    if kept.is_empty() {
        return Ok((cloud, build));
    }
    let began = std::time::Instant::now();
    let shape = Shape::Points {
        points: kept,
        radius: CLOUD_POINT_RADIUS,
    };
    cloud.add("cloud", shape, Default::default())?;
    if let Some(model) = compile {
        std::hint::black_box(model.world(&cloud));
    }
    let build_seconds = began.elapsed().as_secs_f64();
    Ok((
        cloud,
        CloudBuild {
            build_seconds,
            ..build
        },
    ))
}

/// `world` as VAMP's MotionBenchMaker loader gives it to VAMP's checks (which never read
/// cylinders): each cylinder a capsule of the same radius and axis length (its caps beyond the
/// cylinder's ends), and in the `box` family (`box` or `box_…`, whose goals grasp a can from
/// above) a box of the cylinder's diameter and length; every other object as it is.
pub fn vamp_world(world: &World, family: &str) -> World {
    let boxes = family == "box" || family.starts_with("box_");
    let mut out = World::new();
    for o in world.objects() {
        let shape = match *o.shape() {
            Shape::Cylinder { radius, length } if boxes => Shape::Box {
                size: [2.0 * radius, 2.0 * radius, length],
            },
            Shape::Cylinder { radius, length } => Shape::Capsule { radius, length },
            ref other => other.clone(),
        };
        out.add(o.name(), shape, *o.pose())
            .expect("the names of a world are unique and its shapes valid");
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use trm_kinematics::nalgebra::Isometry3;

    #[test]
    fn vamp_sees_cylinders_as_capsules_and_in_the_box_family_as_boxes() {
        let mut world = World::new();
        let pose = Isometry3::translation(0.5, 0.0, 0.3);
        let can = Shape::Cylinder {
            radius: 0.04,
            length: 0.12,
        };
        world.add("can", can.clone(), pose).unwrap();
        world
            .add("ball", Shape::Sphere { radius: 0.1 }, Isometry3::identity())
            .unwrap();
        let shapes =
            |w: &World| -> Vec<Shape> { w.objects().iter().map(|o| o.shape().clone()).collect() };
        let table = vamp_world(&world, "table_pick_panda");
        assert_eq!(
            shapes(&table),
            [
                Shape::Capsule {
                    radius: 0.04,
                    length: 0.12
                },
                Shape::Sphere { radius: 0.1 }
            ]
        );
        assert_eq!(table.objects()[0].pose(), &pose);
        let boxes = vamp_world(&world, "box_panda");
        assert_eq!(
            shapes(&boxes)[0],
            Shape::Box {
                size: [0.08, 0.08, 0.12]
            }
        );
        // a family merely containing "box" is not the box family
        assert!(matches!(
            vamp_world(&world, "toolbox_panda").objects()[0].shape(),
            Shape::Capsule { .. }
        ));
    }
}
