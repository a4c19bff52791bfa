//! MotionBenchMaker-like problem sets for any robot, from a task spec: seeded scenes (a table
//! with objects, a shelf, a cage) placed in front of the robot, and starts and goals that put
//! the reaching part at two places of the scene with obstacles between them (one compartment
//! of the shelf and the other, above the cage and inside it, above a block and beside a can),
//! both found by NGIK from the spec's start posture in the scene. Written as MoveIt scenes and requests in MotionBenchMaker's
//! layout, so [`crate::ProblemSet`] and every MotionBenchMaker tool read them.
//!
//! The spec gives the robot, its active motors (the requests' goal joints), the start posture,
//! the costs a goal minimises besides the target (collision, home posture, …), the task (the
//! part that reaches: its position is the target) and the solver.

use std::path::Path;

use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use trm_collision::Shape;
use trm_kinematics::nalgebra::{self, Isometry3, Translation3, UnitQuaternion, Vector3};
use trm_tasks::spec::Problem as TaskProblem;

use crate::error::MbmError;
use trm_moveit::{
    CollisionObject, JointGoal, JointState, MotionPlanRequest, PlanningScene, Primitive,
};

/// The scene families.
pub const FAMILIES: [&str; 3] = ["table", "shelf", "cage"];

/// How a set is generated.
#[derive(Debug, Clone, PartialEq)]
pub struct SetOptions {
    /// Families, of [`FAMILIES`].
    pub families: Vec<String>,
    /// Problems per family.
    pub per_family: usize,
    /// Seed of every random choice.
    pub seed: u64,
    /// Where the scenes are centred (root frame, m); `None`: 8 cm beyond the task part at the
    /// start posture, along `facing`.
    pub center: Option<[f64; 3]>,
    /// The horizontal direction the robot faces (root frame): scenes open toward the robot.
    pub facing: [f64; 2],
    /// Largest distance of the reaching part from its target at a goal, m.
    pub tolerance: f64,
    /// Scenes and targets drawn per problem before giving up.
    pub tries: usize,
}

impl Default for SetOptions {
    fn default() -> Self {
        SetOptions {
            families: FAMILIES.iter().map(|f| f.to_string()).collect(),
            per_family: 20,
            seed: 0,
            center: None,
            facing: [1.0, 0.0],
            tolerance: 0.02,
            tries: 30,
        }
    }
}

/// One generated problem.
#[derive(Debug, Clone, PartialEq)]
pub struct Generated {
    /// Family (`<family>_<robot>`, as MotionBenchMaker names its folders).
    pub family: String,
    /// Number, from 1.
    pub index: u32,
    /// The scene.
    pub scene: PlanningScene,
    /// The request: start state (every motor), joint goal of the active motors.
    pub request: MotionPlanRequest,
    /// The target the goal reaches (root frame).
    pub target: [f64; 3],
}

/// Distance every start and goal keeps from the scene's objects, m.
pub const CLEARANCE: f64 = 0.005;

/// `shape` grown by `margin` on every side (boxes, spheres, cylinders, capsules).
fn padded(shape: &Shape, margin: f64) -> Shape {
    match shape {
        Shape::Box { size } => Shape::Box {
            size: size.map(|s| s + 2.0 * margin),
        },
        Shape::Sphere { radius } => Shape::Sphere {
            radius: radius + margin,
        },
        Shape::Cylinder { radius, length } => Shape::Cylinder {
            radius: radius + margin,
            length: length + 2.0 * margin,
        },
        Shape::Capsule { radius, length } => Shape::Capsule {
            radius: radius + margin,
            length: *length,
        },
        other => other.clone(),
    }
}

fn bad(what: &str, problem: String) -> MbmError {
    MbmError::Generate {
        what: "a set".into(),
        problem: format!("{what}: {problem}"),
        fix: "give the setting in its range".into(),
    }
}

/// The options in range and a spec whose task is a position.
fn check(spec: &TaskProblem, options: &SetOptions) -> Result<(), MbmError> {
    if options.per_family == 0 || options.per_family > 10_000 {
        return Err(bad(
            "per_family",
            format!("{} is not in 1..=10000", options.per_family),
        ));
    }
    if options.tries == 0 || options.tries > 10_000 {
        return Err(bad(
            "tries",
            format!("{} is not in 1..=10000", options.tries),
        ));
    }
    if !(options.tolerance.is_finite() && options.tolerance > 0.0) {
        return Err(bad(
            "tolerance",
            format!("{} is not a positive distance", options.tolerance),
        ));
    }
    let norm = options.facing[0].hypot(options.facing[1]);
    if !(norm.is_finite() && norm > 1e-9) {
        return Err(bad(
            "facing",
            "give a horizontal direction (x, y), not zero".into(),
        ));
    }
    if let Some(c) = options.center
        && c.iter().any(|v| !v.is_finite())
    {
        return Err(bad("center", "give finite coordinates".into()));
    }
    for f in &options.families {
        if !FAMILIES.contains(&f.as_str()) {
            return Err(bad(
                "families",
                format!("`{f}` is not one of {}", FAMILIES.join(", ")),
            ));
        }
    }
    if spec.objective.task().is_none_or(|t| t.dim() != 3) {
        return Err(bad(
            "spec",
            format!(
                "{}: give a position task (the part that reaches), e.g. `task: Some(Position(part: \"hand\"))`",
                spec.origin
            ),
        ));
    }
    Ok(())
}

/// `scene` with every primitive grown by [`CLEARANCE`].
fn padded_scene(scene: &PlanningScene) -> PlanningScene {
    PlanningScene {
        objects: scene
            .objects
            .iter()
            .map(|o| CollisionObject {
                primitives: o
                    .primitives
                    .iter()
                    .map(|p| Primitive {
                        shape: padded(&p.shape, CLEARANCE),
                        pose: p.pose,
                    })
                    .collect(),
                ..o.clone()
            })
            .collect(),
        ..scene.clone()
    }
}

/// A request from `from` (the moving motors' values, the others at the start) to `goal`.
fn request(
    origin: String,
    motor_names: Vec<String>,
    active: &trm_kinematics::ActiveSet,
    from: Vec<f64>,
    active_names: Vec<String>,
    goal: Vec<f64>,
) -> MotionPlanRequest {
    MotionPlanRequest {
        origin: origin.into(),
        start: JointState {
            names: motor_names,
            positions: active.to_motors(&from),
        },
        attached: Vec::new(),
        goal: JointGoal {
            names: active_names,
            tolerances: vec![(0.0, 0.0); goal.len()],
            positions: goal,
        },
        group: String::new(),
        planning_time: Some(10.0),
        pose_goal: Default::default(),
        velocity_scaling: None,
        acceleration_scaling: None,
    }
}

/// Generates the set for `spec` (its world is replaced by each scene). `progress(done, total)`
/// is called after each problem. A problem for which `tries` scenes and targets give no
/// collision-free goal within the tolerance (or a start that collides) is an error naming it.
pub fn generate(
    spec: &TaskProblem,
    options: &SetOptions,
    mut progress: impl FnMut(usize, usize),
) -> Result<Vec<Generated>, MbmError> {
    check(spec, options)?;
    let objective = &spec.objective;
    let norm = options.facing[0].hypot(options.facing[1]);
    let robot = &spec.robot;
    let mut scratch = objective.scratch();
    let start = spec.start.clone();
    let home = objective.task_value(&start, &mut scratch);
    let yaw = options.facing[1].atan2(options.facing[0]);
    let facing = [options.facing[0] / norm, options.facing[1] / norm];
    let center = options.center.unwrap_or([
        home[0] + 0.08 * facing[0],
        home[1] + 0.08 * facing[1],
        home[2],
    ]);
    let motor_names: Vec<String> = robot.motor_names();
    let active_names: Vec<String> = objective.active().names().map(String::from).collect();
    let active = objective.active();
    let total = options.families.len() * options.per_family;
    let mut set = Vec::with_capacity(total);
    for (f, family) in options.families.iter().enumerate() {
        for index in 1..=options.per_family as u32 {
            let mut rng = ChaCha8Rng::seed_from_u64(
                options.seed
                    ^ (f as u64 + 1).wrapping_mul(0x9e37_79b9_7f4a_7c15)
                    ^ u64::from(index) << 32,
            );
            let mut found = None;
            // tries that found no start, and a start but no goal
            let mut missed = (0, 0);
            for _ in 0..options.tries {
                let (objects, local_from, local_to) = layout(family, &mut rng);
                let turn = yaw + rng.random_range(-0.15..0.15);
                let shift = Vector3::new(
                    rng.random_range(-0.02..0.04),
                    rng.random_range(-0.04..0.04),
                    rng.random_range(-0.03..0.03),
                );
                let frame = Isometry3::from_parts(
                    Translation3::new(center[0], center[1], center[2]),
                    UnitQuaternion::from_euler_angles(0.0, 0.0, turn),
                ) * Translation3::from(shift);
                let scene = PlanningScene {
                    origin: format!("{family} {index}").into(),
                    robot_model_name: robot.name().to_string(),
                    objects: objects
                        .into_iter()
                        .map(|(id, shape, at)| CollisionObject {
                            id: id.to_string(),
                            primitives: vec![Primitive {
                                shape,
                                pose: frame * Translation3::from(at),
                            }],
                            line: 0,
                        })
                        .collect(),
                    ..Default::default()
                };
                // starts and goals keep CLEARANCE from every object (a posture that only just
                // touches may collide once the scene is written and read back)
                let world = padded_scene(&scene).to_world()?;
                // NGIK from the start posture to a point of the scene frame
                let mut reach = |local: Vector3<f64>| -> Result<Option<Vec<f64>>, MbmError> {
                    let t = frame * nalgebra::Point3::from(local);
                    let target = [t.x, t.y, t.z];
                    let objective = objective
                        .clone()
                        .with_world(world.clone())
                        .with_task_target(&target, 100.0)?;
                    let solution = trm_tasks::solve(&objective, &start, &spec.spec.solver)?;
                    let reached = objective.task_value(&solution.q, &mut scratch);
                    let error = reached
                        .iter()
                        .zip(&target)
                        .map(|(a, b)| (a - b) * (a - b))
                        .sum::<f64>()
                        .sqrt();
                    Ok((error <= options.tolerance
                        && objective.is_collision_free_in(&solution.q, &world, &mut scratch))
                    .then_some(solution.q))
                };
                let Some(from) = reach(local_from)? else {
                    missed.0 += 1;
                    continue;
                };
                let Some(to) = reach(local_to)? else {
                    missed.1 += 1;
                    continue;
                };
                let t = frame * nalgebra::Point3::from(local_to);
                found = Some((scene, from, to, [t.x, t.y, t.z]));
                break;
            }
            let Some((scene, from, goal, target)) = found else {
                return Err(MbmError::Generate {
                    what: format!("{family} {index}"),
                    problem: format!(
                        "NGIK found no collision-free start and goal within {} m of their targets in {} scenes ({} without a start, {} with a start but no goal)",
                        options.tolerance, options.tries, missed.0, missed.1
                    ),
                    fix: "centre the scenes where the robot reaches (`center`, `facing`), or loosen `tolerance`".into(),
                });
            };
            let family_name = format!("{family}_{}", robot.name());
            let origin = format!("{family_name}/request{index:04}.yaml");
            set.push(Generated {
                family: family_name,
                index,
                scene: PlanningScene {
                    origin: format!("{}", scene.origin.display()).into(),
                    ..scene
                },
                request: request(
                    origin,
                    motor_names.clone(),
                    active,
                    from,
                    active_names.clone(),
                    goal,
                ),
                target,
            });
            progress(set.len(), total);
        }
    }
    Ok(set)
}

/// A family's objects (id, shape, centre in the scene frame: x away from the robot, z up) and
/// where the reaching part starts and where it goes, drawn from `rng`: the straight motion
/// between the two is blocked as a rule (over a board, out of a cage, past an object).
type Layout = (
    Vec<(&'static str, Shape, Vector3<f64>)>,
    Vector3<f64>,
    Vector3<f64>,
);

fn layout(family: &str, rng: &mut ChaCha8Rng) -> Layout {
    match family {
        "table" => table(rng),
        "shelf" => shelf(rng),
        _ => cage(rng),
    }
}

/// A box of these sides.
fn boxed(x: f64, y: f64, z: f64) -> Shape {
    Shape::Box { size: [x, y, z] }
}

/// A table with a can and a block: from above the block to beside the can.
fn table(rng: &mut ChaCha8Rng) -> Layout {
    let top = -0.10 - rng.random_range(0.0..0.05);
    let can = Vector3::new(
        rng.random_range(0.02..0.16),
        rng.random_range(-0.15..0.15),
        top + 0.075,
    );
    let block = Vector3::new(
        rng.random_range(0.05..0.2),
        can.y + if can.y > 0.0 { -0.12 } else { 0.12 },
        top + 0.055,
    );
    // from above the block to beside the can, on its near side
    let from = Vector3::new(block.x, block.y, top + 0.2 + rng.random_range(0.0..0.05));
    let to = Vector3::new(
        can.x - 0.07,
        can.y,
        top + 0.07 + rng.random_range(0.0..0.03),
    );
    (
        vec![
            (
                "table_top",
                boxed(0.4, 0.7, 0.03),
                Vector3::new(0.12, 0.0, top - 0.015),
            ),
            (
                "can",
                Shape::Cylinder {
                    radius: 0.03,
                    length: 0.12,
                },
                can + Vector3::new(0.0, 0.0, -0.015),
            ),
            (
                "block",
                boxed(0.05, 0.05, 0.08),
                block - Vector3::new(0.0, 0.0, 0.015),
            ),
        ],
        from,
        to,
    )
}

/// A shelf of two compartments: from one to the other, over the middle board.
fn shelf(rng: &mut ChaCha8Rng) -> Layout {
    // from one compartment to the other, over the middle board
    let (low, high) = (
        -0.14 - rng.random_range(0.0..0.02),
        0.2 + rng.random_range(0.0..0.02),
    );
    let mid = (low + high) / 2.0 + rng.random_range(-0.01..0.01);
    let inside = |rng: &mut ChaCha8Rng, floor: f64, ceiling: f64| {
        Vector3::new(
            rng.random_range(0.05..0.14),
            rng.random_range(-0.12..0.12),
            (floor + ceiling) / 2.0 + rng.random_range(-0.01..0.01),
        )
    };
    let (lower, upper) = (inside(rng, low, mid), inside(rng, mid, high));
    let (from, to) = if rng.random_bool(0.5) {
        (upper, lower)
    } else {
        (lower, upper)
    };
    (
        vec![
            (
                "shelf_low",
                boxed(0.3, 0.6, 0.02),
                Vector3::new(0.17, 0.0, low),
            ),
            (
                "shelf_mid",
                boxed(0.3, 0.6, 0.02),
                Vector3::new(0.17, 0.0, mid),
            ),
            (
                "shelf_high",
                boxed(0.3, 0.6, 0.02),
                Vector3::new(0.17, 0.0, high),
            ),
            (
                "shelf_back",
                boxed(0.02, 0.6, 0.6),
                Vector3::new(0.33, 0.0, 0.02),
            ),
            (
                "shelf_left",
                boxed(0.3, 0.02, 0.6),
                Vector3::new(0.17, 0.31, 0.02),
            ),
            (
                "shelf_right",
                boxed(0.3, 0.02, 0.6),
                Vector3::new(0.17, -0.31, 0.02),
            ),
        ],
        from,
        to,
    )
}

/// A cage open towards the robot: from above it into it.
fn cage(rng: &mut ChaCha8Rng) -> Layout {
    let (depth, width, height) = (
        0.32 + rng.random_range(0.0..0.04),
        0.42 + rng.random_range(0.0..0.06),
        0.30 + rng.random_range(0.0..0.04),
    );
    // from above the cage into it, through its open side
    let from = Vector3::new(
        rng.random_range(0.04..0.14),
        rng.random_range(-width * 0.25..width * 0.25),
        height / 2.0 + rng.random_range(0.05..0.08),
    );
    let to = Vector3::new(
        rng.random_range(0.06..depth * 0.45),
        rng.random_range(-width * 0.25..width * 0.25),
        rng.random_range(-height * 0.2..height * 0.1),
    );
    let mid = depth / 2.0;
    // the cage sits a little low, so that the hand reaches above it
    let low = -0.06;
    let (from, to) = (
        from + Vector3::new(0.0, 0.0, low),
        to + Vector3::new(0.0, 0.0, low),
    );
    (
        vec![
            (
                "cage_bottom",
                boxed(depth, width, 0.02),
                Vector3::new(mid, 0.0, low - height / 2.0),
            ),
            (
                "cage_top",
                boxed(depth, width, 0.02),
                Vector3::new(mid, 0.0, low + height / 2.0),
            ),
            (
                "cage_back",
                boxed(0.02, width, height),
                Vector3::new(depth, 0.0, low),
            ),
            (
                "cage_left",
                boxed(depth, 0.02, height),
                Vector3::new(mid, width / 2.0, low),
            ),
            (
                "cage_right",
                boxed(depth, 0.02, height),
                Vector3::new(mid, -width / 2.0, low),
            ),
        ],
        from,
        to,
    )
}

/// Writes `set` under `dir` in MotionBenchMaker's layout (`<family>/sceneNNNN.yaml`,
/// `<family>/requestNNNN.yaml`), each file written whole (temporary file, then renamed).
pub fn write_set(dir: &Path, set: &[Generated]) -> Result<(), MbmError> {
    let io = |path: &Path, source: std::io::Error| MbmError::Io {
        path: path.to_path_buf(),
        source,
    };
    for g in set {
        let folder = dir.join(&g.family);
        std::fs::create_dir_all(&folder).map_err(|e| io(&folder, e))?;
        for (name, text) in [
            (format!("scene{:04}.yaml", g.index), g.scene.to_yaml()?),
            (format!("request{:04}.yaml", g.index), g.request.to_yaml()?),
        ] {
            let path = folder.join(name);
            let temporary = folder.join(format!(".{}.tmp", g.index));
            std::fs::write(&temporary, text).map_err(|e| io(&temporary, e))?;
            std::fs::rename(&temporary, &path).map_err(|e| io(&path, e))?;
        }
    }
    Ok(())
}
