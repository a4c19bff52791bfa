//! Task specs in RON: robot model and active motors, start posture, world, weighted costs, task
//! function, robustness noise, solver and map settings. The format is documented in
//! `specs/README.md`; [`Problem::load`] turns a file into an [`Objective`] with errors that name
//! the file, line, column and field, and suggest the closest valid names.

use std::collections::BTreeMap;
use std::path::Path;

use serde::{Deserialize, Serialize};
use trm_collision::{CollisionModel, World, WorldSpec};
use trm_kinematics::nalgebra::Vector3;
use trm_kinematics::{ActiveSet, FrameId, FrameSpec, RobotModel, closest_names};

use crate::context::Anchor;
use crate::costs::{
    Collision, Direction, Displacement, HomePosture, JointLimits, Orientation, Pointing, Position,
    Region, Repel,
};
use crate::error::{Result, TaskError};
use crate::objective::Objective;
use crate::tasks::{
    AngleTask, DistanceTask, MidpointTask, PositionTask, RodDirectionTask, RotationTask,
    TaskFunction,
};

fn all_axes() -> [bool; 3] {
    [true; 3]
}

fn yes() -> bool {
    true
}

/// A whole spec file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Spec {
    /// `icub_upper_body` (embedded) or a `.urdf`/`.ron` model path relative to the spec.
    pub model: String,
    /// Extra named frames (a link or frame plus an offset), usable as parts in this spec.
    #[serde(default)]
    pub frames: Vec<FrameSpec>,
    /// Active motors: motor or group names; empty = every motor.
    #[serde(default)]
    pub active: Vec<String>,
    /// The start posture (and values of locked motors): a posture name of the model; by default
    /// `home` if the model has one, else every motor at 0 clamped into its limits.
    #[serde(default)]
    pub start: Option<String>,
    /// Motor values overriding the start posture, by motor name.
    #[serde(default)]
    pub start_values: BTreeMap<String, f64>,
    /// World objects.
    #[serde(default)]
    pub world: WorldSpec,
    /// Weighted cost terms (at least one).
    pub costs: Vec<CostSpec>,
    /// Optional task function (needed for maps).
    #[serde(default)]
    pub task: Option<TaskSpec>,
    /// Optional robustness noise on q.
    #[serde(default)]
    pub noise: Option<NoiseSpec>,
    /// Solver settings.
    #[serde(default)]
    pub solver: SolverSpec,
    /// Roadmap settings (used by `build-map`).
    #[serde(default)]
    pub map: Option<MapSpec>,
}

/// `(weight: a, cost: …)`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CostSpec {
    /// aᵢ ≥ 0.
    pub weight: f64,
    /// The term.
    pub cost: CostKind,
}

/// A point: a robot frame (link or named frame), a world object's origin, or fixed coordinates.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum AnchorSpec {
    /// A link or named frame.
    Part(String),
    /// A world object.
    Object(String),
    /// World coordinates.
    Point([f64; 3]),
}

/// Target of a position term.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum TargetSpec {
    /// A link or named frame.
    Part(String),
    /// A world object's origin.
    Object(String),
    /// World coordinates.
    Point([f64; 3]),
    /// Anywhere inside an axis-aligned box.
    Box {
        /// Lower corner.
        min: [f64; 3],
        /// Upper corner.
        max: [f64; 3],
    },
    /// Anywhere inside a ball.
    Sphere {
        /// Centre.
        center: AnchorSpec,
        /// Radius.
        radius: f64,
    },
}

/// A desired direction.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum DirectionSpec {
    /// A fixed world direction.
    Fixed([f64; 3]),
    /// Another frame's axis.
    Axis {
        /// The frame.
        part: String,
        /// The axis in that frame.
        axis: [f64; 3],
    },
}

/// The cost catalogue (Table I).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum CostKind {
    /// ‖W (q − q*)‖; q* a posture of the model (default: the spec's start), W per motor or group.
    HomePosture {
        /// Posture name; the spec's start when absent.
        #[serde(default)]
        posture: Option<String>,
        /// Weights by motor or group name; 1 for the rest.
        #[serde(default)]
        weights: BTreeMap<String, f64>,
    },
    /// Number of colliding pairs.
    Collision {
        /// Count self-collisions.
        #[serde(default = "yes")]
        self_collision: bool,
        /// Count collisions with world objects.
        #[serde(default = "yes")]
        world: bool,
    },
    /// Attract a part to a point, part, object, box or ball.
    Position {
        /// The part.
        part: String,
        /// Where to.
        target: TargetSpec,
        /// Axes that count.
        #[serde(default = "all_axes")]
        mask: [bool; 3],
    },
    /// Align a part's axis with a direction.
    Orientation {
        /// The part.
        part: String,
        /// Its axis.
        axis: [f64; 3],
        /// The direction.
        toward: DirectionSpec,
    },
    /// Point a part's axis at something, optionally from a distance.
    Pointing {
        /// The part.
        part: String,
        /// Its axis.
        axis: [f64; 3],
        /// The target.
        at: AnchorSpec,
        /// Distance to keep.
        #[serde(default)]
        distance: Option<f64>,
    },
    /// Push two anchors apart up to a distance.
    Repel {
        /// First.
        a: AnchorSpec,
        /// Second.
        b: AnchorSpec,
        /// Distance from which repulsion starts.
        min_distance: f64,
        /// Axes that count.
        #[serde(default = "all_axes")]
        mask: [bool; 3],
    },
    /// Soft joint limits.
    JointLimits {
        /// Margin inside the limits (radians).
        margin: f64,
    },
    /// Minimal displacement from the start posture.
    Displacement,
    /// Distance (metric W of the map) from the part's pose relative to a world object to the
    /// nearest point of a task map file (`cargo xtask explore-task-map`).
    TaskMap {
        /// The task map file, relative to the spec.
        file: String,
        /// The part (e.g. `r_hand`).
        part: String,
        /// The world object the map is relative to.
        object: String,
    },
}

/// The task catalogue (Table II and composites).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum TaskSpec {
    /// A part's position.
    Position {
        /// The part.
        part: String,
        /// Axes kept.
        #[serde(default = "all_axes")]
        mask: [bool; 3],
    },
    /// A part's axis direction.
    Rotation {
        /// The part.
        part: String,
        /// The axis.
        axis: [f64; 3],
        /// Components kept.
        #[serde(default = "all_axes")]
        mask: [bool; 3],
    },
    /// Distance between two anchors.
    Distance {
        /// First.
        a: AnchorSpec,
        /// Second.
        b: AnchorSpec,
    },
    /// Angle of b→a projected on the plane (u1, u2).
    Angle {
        /// First.
        a: AnchorSpec,
        /// Second.
        b: AnchorSpec,
        /// First plane axis.
        u1: [f64; 3],
        /// Second plane axis.
        u2: [f64; 3],
    },
    /// Midpoint of two anchors.
    Midpoint {
        /// First.
        a: AnchorSpec,
        /// Second.
        b: AnchorSpec,
        /// Axes kept.
        #[serde(default = "all_axes")]
        mask: [bool; 3],
    },
    /// Direction of the rod from a to b.
    RodDirection {
        /// First.
        a: AnchorSpec,
        /// Second.
        b: AnchorSpec,
        /// Components kept.
        #[serde(default = "all_axes")]
        mask: [bool; 3],
    },
}

/// Robustness: the expected cost under N(0, σ²) noise on q.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct NoiseSpec {
    /// Noise samples per evaluation.
    pub samples: usize,
    /// Standard deviation (radians).
    pub sigma: f64,
    /// Seed of the (fixed) noise offsets.
    #[serde(default)]
    pub seed: u64,
}

/// Solver settings for NGIK.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SolverSpec {
    /// Algorithm name (see `trm_optim::ALGORITHMS`).
    pub algo: String,
    /// Initial step size (radians).
    pub sigma: f64,
    /// Population size; the algorithm's default when absent.
    pub population: Option<usize>,
    /// Evaluation budget.
    pub max_evaluations: u64,
    /// Stop when the best has not improved for this many evaluations.
    pub no_improvement: Option<u64>,
    /// Stop at this cost.
    pub target: Option<f64>,
    /// Seed.
    pub seed: u64,
}

impl Default for SolverSpec {
    fn default() -> Self {
        SolverSpec {
            algo: "xnes".into(),
            sigma: 0.4,
            population: None,
            max_evaluations: 100_000,
            no_improvement: Some(10_000),
            target: None,
            seed: 0,
        }
    }
}

/// Roadmap settings (E-TRM and parallel E-TRM; defaults from the papers).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct MapSpec {
    /// Desired task-space spacing d between neighbouring points.
    pub spacing: f64,
    /// Weight of the map-building cost.
    pub construct_weight: f64,
    /// Smoothness weight c on ‖q − q′‖.
    pub smoothness: f64,
    /// Consecutive failures after which construction stops (k).
    pub failure_limit: usize,
    /// Largest number of points.
    pub max_points: usize,
    /// (λ, σ) of the first point's search.
    pub first_search: (usize, f64),
    /// (λ, σ) of later searches.
    pub later_search: (usize, f64),
    /// Concurrent searches P of parallel E-TRM.
    pub searches: usize,
    /// Configuration-space neighbours per node for edges.
    pub edge_neighbours: usize,
}

impl Default for MapSpec {
    fn default() -> Self {
        MapSpec {
            spacing: 0.025,
            construct_weight: 1.0,
            smoothness: 0.01,
            failure_limit: 100,
            max_points: 1000,
            first_search: (150, 0.15),
            later_search: (30, 0.03),
            searches: 1,
            edge_neighbours: 8,
        }
    }
}

/// A loaded spec: the objective and everything needed to solve it.
#[derive(Debug)]
pub struct Problem {
    /// Where it came from.
    pub origin: String,
    /// The spec text, verbatim.
    pub text: String,
    /// The parsed file.
    pub spec: Spec,
    /// The robot.
    pub robot: RobotModel,
    /// The objective.
    pub objective: Objective,
    /// Start values of the active motors.
    pub start: Vec<f64>,
}

struct Ctx<'a> {
    origin: &'a str,
    text: &'a str,
}

impl Ctx<'_> {
    /// A spec error at field path `field` (`costs[2].cost.part`), located in the text by that
    /// path — or by its nearest ancestor the text spells out.
    fn err(&self, field: &str, problem: impl Into<String>, fix: impl Into<String>) -> TaskError {
        TaskError::Spec(Box::new(trm_kinematics::SpecError::at(
            self.text,
            self.origin,
            field,
            problem,
            fix,
        )))
    }

    fn suggest<'a>(
        &self,
        name: &str,
        candidates: impl IntoIterator<Item = &'a str>,
        otherwise: &str,
    ) -> String {
        let near = closest_names(name, candidates);
        if near.is_empty() {
            otherwise.to_string()
        } else {
            format!("did you mean `{}`?", near.join("`, `"))
        }
    }
}

impl Problem {
    /// Reads and builds a spec file.
    pub fn load(path: impl AsRef<Path>) -> Result<Self> {
        let path = path.as_ref();
        let text = std::fs::read_to_string(path).map_err(|source| TaskError::Io {
            path: path.to_path_buf(),
            source,
        })?;
        let base = path.parent().map(Path::to_path_buf).unwrap_or_default();
        Self::from_ron(&text, &path.display().to_string(), &base)
    }

    /// Parses and builds spec text; `origin` names it in errors, `base` resolves relative paths.
    pub fn from_ron(text: &str, origin: &str, base: &Path) -> Result<Self> {
        let spec: Spec = ron::from_str(text).map_err(|e| ron_error(&e, origin))?;
        Self::build(spec, text, origin, base)
    }

    fn build(spec: Spec, text: &str, origin: &str, base: &Path) -> Result<Self> {
        let ctx = Ctx { origin, text };
        let robot = load_model(&spec.model, base, &ctx)?;
        let robot = with_frames(robot, &spec.frames, &ctx)?;
        let mut motors = match &spec.start {
            None => robot
                .posture("home")
                .map(<[f64]>::to_vec)
                .unwrap_or_else(|_| robot.neutral_motors()),
            Some(start) => robot.posture(start).map(<[f64]>::to_vec).map_err(|_| {
                ctx.err(
                    "start",
                    format!("`{start}` is no posture of the model"),
                    ctx.suggest(
                        start,
                        robot.posture_names(),
                        "use a posture of the model description",
                    ),
                )
            })?,
        };
        for (name, v) in &spec.start_values {
            let i = robot.motor_index(name).map_err(|_| {
                ctx.err(
                    &format!("start_values.{name}"),
                    format!("`{name}` is no motor"),
                    ctx.suggest(
                        name,
                        robot.motors().iter().map(|m| m.name.as_str()),
                        "use motor names",
                    ),
                )
            })?;
            motors[i] = *v;
        }
        let active = if spec.active.is_empty() {
            robot.all_active()
        } else {
            for (i, name) in spec.active.iter().enumerate() {
                if robot.select_motors(&[name]).is_err() {
                    let candidates = robot
                        .motors()
                        .iter()
                        .map(|m| m.name.as_str())
                        .chain(robot.groups().map(|(g, _)| g));
                    return Err(ctx.err(
                        &format!("active[{i}]"),
                        format!("`{name}` is no motor or group"),
                        ctx.suggest(name, candidates, "use motor or group names"),
                    ));
                }
            }
            robot.active_set(&spec.active, &motors)?
        };
        let world = World::from_spec_in(&spec.world, origin, text, "world.objects")?;
        let collision = CollisionModel::new(&robot)?;
        let start = active.from_motors(&motors);
        if spec.costs.is_empty() {
            return Err(ctx.err(
                "costs",
                "the list is empty",
                "add at least one weighted cost term",
            ));
        }
        let resolver = Resolver {
            robot: &robot,
            world: &world,
            ctx: &ctx,
            base,
        };
        let mut terms = Vec::new();
        for (k, c) in spec.costs.iter().enumerate() {
            if !(c.weight.is_finite() && c.weight >= 0.0) {
                return Err(ctx.err(
                    &format!("costs[{k}].weight"),
                    format!("{} is not a finite number ≥ 0", c.weight),
                    "weights are non-negative multipliers",
                ));
            }
            terms.push((
                c.weight,
                resolver.cost(&c.cost, &active, &motors, &start, k)?,
            ));
        }
        let task = spec.task.as_ref().map(|t| resolver.task(t)).transpose()?;
        let mut objective = Objective::new(active.clone(), collision, world);
        for (weight, cost) in terms {
            objective.add(weight, cost)?;
        }
        if let Some(task) = task {
            objective.set_task(task);
        }
        if let Some(n) = &spec.noise {
            if !(n.sigma.is_finite() && n.sigma >= 0.0) {
                return Err(ctx.err(
                    "noise.sigma",
                    format!("{} is not a finite number ≥ 0", n.sigma),
                    "give a standard deviation in radians",
                ));
            }
            objective.set_noise(n.samples, n.sigma, n.seed)?;
        }
        if !trm_optim::ALGORITHMS.contains(&spec.solver.algo.as_str()) {
            return Err(ctx.err(
                "solver.algo",
                format!("unknown algorithm `{}`", spec.solver.algo),
                ctx.suggest(
                    &spec.solver.algo,
                    trm_optim::ALGORITHMS,
                    "use one of trm_optim::ALGORITHMS",
                ),
            ));
        }
        if !(spec.solver.sigma.is_finite() && spec.solver.sigma > 0.0) {
            return Err(ctx.err(
                "solver.sigma",
                "must be positive",
                "give an initial step in radians",
            ));
        }
        if let Some(m) = &spec.map {
            if !(m.spacing.is_finite() && m.spacing > 0.0) {
                return Err(ctx.err(
                    "map.spacing",
                    "must be positive",
                    "give the task-space spacing d",
                ));
            }
        }
        Ok(Problem {
            origin: origin.to_string(),
            text: text.to_string(),
            spec,
            robot,
            objective,
            start,
        })
    }
}

/// The spec's model: an embedded one by name or a file relative to the spec
/// ([`trm_models::load`]), with errors located at the spec's `model` field.
fn load_model(name: &str, base: &Path, ctx: &Ctx) -> Result<RobotModel> {
    trm_models::load(name, base).map_err(|e| match e {
        trm_kinematics::KinematicsError::UnknownModel { looked_for, .. } => ctx.err(
            "model",
            format!(
                "`{name}` is neither an embedded model nor a file (looked for {})",
                looked_for.display()
            ),
            ctx.suggest(
                name,
                trm_models::NAMES.iter().copied(),
                "give a .urdf/.ron path relative to the spec, or icub_upper_body",
            ),
        ),
        other => other.into(),
    })
}

/// The model with the spec's extra frames added (checked here, so errors point into the spec).
fn with_frames(robot: RobotModel, frames: &[FrameSpec], ctx: &Ctx) -> Result<RobotModel> {
    if frames.is_empty() {
        return Ok(robot);
    }
    let mut known: Vec<String> = robot.frame_names().map(str::to_string).collect();
    for (i, f) in frames.iter().enumerate() {
        if known.contains(&f.name) {
            return Err(ctx.err(
                &format!("frames[{i}].name"),
                format!("`{}` already names a link or frame", f.name),
                "choose a new name",
            ));
        }
        if !known.contains(&f.link) {
            return Err(ctx.err(
                &format!("frames[{i}].link"),
                format!("`{}` is no link or earlier frame", f.link),
                ctx.suggest(
                    &f.link,
                    known.iter().map(String::as_str),
                    "attach frames to links or earlier frames",
                ),
            ));
        }
        if f.xyz.iter().chain(&f.rpy).any(|v| !v.is_finite()) {
            return Err(ctx.err(
                &format!("frames[{i}]"),
                "the offset is not finite",
                "write finite numbers",
            ));
        }
        known.push(f.name.clone());
    }
    Ok(robot.with_frames(frames, ctx.origin)?)
}

struct Resolver<'a> {
    robot: &'a RobotModel,
    world: &'a World,
    ctx: &'a Ctx<'a>,
    base: &'a Path,
}

impl Resolver<'_> {
    fn frame(&self, name: &str, field: &str) -> Result<FrameId> {
        self.robot.frame_id(name).map_err(|_| {
            self.ctx.err(
                field,
                format!("`{name}` is no link or named frame of the model"),
                self.ctx.suggest(
                    name,
                    self.robot.frame_names(),
                    "use link or frame names (cargo xtask model-info --links)",
                ),
            )
        })
    }

    fn anchor(&self, a: &AnchorSpec, field: &str) -> Result<Anchor> {
        Ok(match a {
            AnchorSpec::Part(p) => Anchor::Frame(self.frame(p, field)?),
            AnchorSpec::Object(o) => Anchor::Object(self.object(o, field)?),
            AnchorSpec::Point(p) => Anchor::Point(self.finite(*p, field)?),
        })
    }

    fn object(&self, name: &str, field: &str) -> Result<usize> {
        self.world.index(name).map_err(|_| {
            self.ctx.err(
                field,
                format!("`{name}` is no world object"),
                self.ctx.suggest(
                    name,
                    self.world.objects().iter().map(|o| o.name()),
                    "add it under world: (objects: [...])",
                ),
            )
        })
    }

    fn finite(&self, v: [f64; 3], field: &str) -> Result<[f64; 3]> {
        if v.iter().all(|x| x.is_finite()) {
            Ok(v)
        } else {
            Err(self.ctx.err(
                field,
                format!("{v:?} is not finite"),
                "write finite numbers",
            ))
        }
    }

    fn unit(&self, v: [f64; 3], field: &str) -> Result<Vector3<f64>> {
        let v = Vector3::from(self.finite(v, field)?);
        let n = v.norm();
        if n < 1e-12 {
            return Err(self.ctx.err(
                field,
                "the axis is zero",
                "give a non-zero axis, e.g. (0, 0, 1)",
            ));
        }
        Ok(v / n)
    }

    fn mask(&self, m: [bool; 3], field: &str) -> Result<[bool; 3]> {
        if m.iter().any(|b| *b) {
            Ok(m)
        } else {
            Err(self
                .ctx
                .err(field, "masks every axis out", "keep at least one axis"))
        }
    }

    fn positive(&self, v: f64, field: &str) -> Result<f64> {
        if v.is_finite() && v > 0.0 {
            Ok(v)
        } else {
            Err(self.ctx.err(
                field,
                format!("{v} must be positive"),
                "give a positive length",
            ))
        }
    }

    fn cost(
        &self,
        c: &CostKind,
        active: &ActiveSet,
        motors: &[f64],
        start: &[f64],
        k: usize,
    ) -> Result<Box<dyn crate::Cost>> {
        let field = format!("costs[{k}]");
        Ok(match c {
            CostKind::HomePosture { posture, weights } => {
                let home_motors = match posture {
                    None => motors.to_vec(),
                    Some(p) => self.robot.posture(p).map(<[f64]>::to_vec).map_err(|_| {
                        self.ctx.err(
                            &format!("{field}.cost.posture"),
                            format!("`{p}` is no posture"),
                            self.ctx.suggest(
                                p,
                                self.robot.posture_names(),
                                "use a posture of the model",
                            ),
                        )
                    })?,
                };
                let mut w = vec![1.0; active.len()];
                for (name, value) in weights {
                    if !(value.is_finite() && *value >= 0.0) {
                        return Err(self.ctx.err(
                            &format!("{field}.cost.weights.{name}"),
                            format!("weight {value} is not a finite number ≥ 0"),
                            "use non-negative weights",
                        ));
                    }
                    let members = self.robot.select_motors(&[name]).map_err(|_| {
                        let candidates = self
                            .robot
                            .motors()
                            .iter()
                            .map(|m| m.name.as_str())
                            .chain(self.robot.groups().map(|(g, _)| g));
                        self.ctx.err(
                            &format!("{field}.cost.weights.{name}"),
                            format!("`{name}` is no motor or group"),
                            self.ctx
                                .suggest(name, candidates, "use motor or group names"),
                        )
                    })?;
                    for m in members {
                        if let Some(i) = active.motor_indices().iter().position(|a| *a == m) {
                            w[i] = *value;
                        }
                    }
                }
                Box::new(HomePosture {
                    home: active.from_motors(&home_motors),
                    weights: w,
                })
            }
            CostKind::Collision {
                self_collision,
                world,
            } => Box::new(Collision {
                self_collision: *self_collision,
                world: *world,
            }),
            CostKind::Position { part, target, mask } => {
                let target = match target {
                    TargetSpec::Part(p) => Region::Point(Anchor::Frame(
                        self.frame(p, &format!("{field}.cost.target"))?,
                    )),
                    TargetSpec::Object(o) => Region::Point(Anchor::Object(
                        self.object(o, &format!("{field}.cost.target"))?,
                    )),
                    TargetSpec::Point(p) => Region::Point(Anchor::Point(
                        self.finite(*p, &format!("{field}.cost.target"))?,
                    )),
                    TargetSpec::Box { min, max } => {
                        let (min, max) = (
                            self.finite(*min, &format!("{field}.cost.target.min"))?,
                            self.finite(*max, &format!("{field}.cost.target.max"))?,
                        );
                        if (0..3).any(|i| min[i] > max[i]) {
                            return Err(self.ctx.err(
                                &format!("{field}.cost.target.min"),
                                "a box min exceeds its max",
                                "swap the corners",
                            ));
                        }
                        Region::Box { min, max }
                    }
                    TargetSpec::Sphere { center, radius } => Region::Sphere {
                        center: self.anchor(center, &format!("{field}.cost.target.center"))?,
                        radius: self.positive(*radius, &format!("{field}.cost.target.radius"))?,
                    },
                };
                Box::new(Position {
                    part: self.frame(part, &format!("{field}.cost.part"))?,
                    part_name: part.clone(),
                    target,
                    mask: self.mask(*mask, &format!("{field}.cost.mask"))?,
                })
            }
            CostKind::Orientation { part, axis, toward } => Box::new(Orientation {
                part: self.frame(part, &format!("{field}.cost.part"))?,
                part_name: part.clone(),
                axis: self.unit(*axis, &format!("{field}.cost.axis"))?,
                target: match toward {
                    DirectionSpec::Fixed(d) => {
                        Direction::Fixed(self.unit(*d, &format!("{field}.cost.toward"))?)
                    }
                    DirectionSpec::Axis { part, axis } => Direction::Axis(
                        self.frame(part, &format!("{field}.cost.toward.part"))?,
                        self.unit(*axis, &format!("{field}.cost.toward.axis"))?,
                    ),
                },
            }),
            CostKind::Pointing {
                part,
                axis,
                at,
                distance,
            } => Box::new(Pointing {
                part: self.frame(part, &format!("{field}.cost.part"))?,
                part_name: part.clone(),
                axis: self.unit(*axis, &format!("{field}.cost.axis"))?,
                target: self.anchor(at, &format!("{field}.cost.at"))?,
                distance: match distance {
                    Some(d) => Some(self.positive(*d, &format!("{field}.cost.distance"))?),
                    None => None,
                },
            }),
            CostKind::Repel {
                a,
                b,
                min_distance,
                mask,
            } => Box::new(Repel {
                a: self.anchor(a, &format!("{field}.cost.a"))?,
                b: self.anchor(b, &format!("{field}.cost.b"))?,
                names: format!("{} / {}", anchor_name(a), anchor_name(b)),
                min_distance: self
                    .positive(*min_distance, &format!("{field}.cost.min_distance"))?,
                mask: self.mask(*mask, &format!("{field}.cost.mask"))?,
            }),
            CostKind::JointLimits { margin } => {
                let (lower, upper) = active.bounds();
                Box::new(JointLimits {
                    lower,
                    upper,
                    margin: self.positive(*margin, &format!("{field}.cost.margin"))?,
                })
            }
            CostKind::Displacement => Box::new(Displacement {
                start: start.to_vec(),
            }),
            CostKind::TaskMap { file, part, object } => {
                let path = self.base.join(file);
                let map = trm_taskmap::TaskMap::load(&path).map_err(|e| {
                    self.ctx.err(
                        &format!("{field}.cost.file"),
                        e.to_string(),
                        "build it with trm_taskmap::explore (cargo xtask explore-task-map)",
                    )
                })?;
                Box::new(crate::costs::TaskMapCost {
                    map: std::sync::Arc::new(map),
                    part: self.frame(part, &format!("{field}.cost.part"))?,
                    part_name: part.clone(),
                    object: self.object(object, &format!("{field}.cost.object"))?,
                })
            }
        })
    }

    fn task(&self, t: &TaskSpec) -> Result<Box<dyn TaskFunction>> {
        Ok(match t {
            TaskSpec::Position { part, mask } => Box::new(PositionTask {
                part: self.frame(part, "task.part")?,
                part_name: part.clone(),
                mask: self.mask(*mask, "task.mask")?,
            }),
            TaskSpec::Rotation { part, axis, mask } => Box::new(RotationTask {
                part: self.frame(part, "task.part")?,
                part_name: part.clone(),
                axis: self.unit(*axis, "task.axis")?,
                mask: self.mask(*mask, "task.mask")?,
            }),
            TaskSpec::Distance { a, b } => Box::new(DistanceTask {
                a: self.anchor(a, "task.a")?,
                b: self.anchor(b, "task.b")?,
                names: format!("{} / {}", anchor_name(a), anchor_name(b)),
            }),
            TaskSpec::Angle { a, b, u1, u2 } => Box::new(AngleTask {
                a: self.anchor(a, "task.a")?,
                b: self.anchor(b, "task.b")?,
                names: format!("{} / {}", anchor_name(a), anchor_name(b)),
                u1: self.unit(*u1, "task.u1")?,
                u2: self.unit(*u2, "task.u2")?,
            }),
            TaskSpec::Midpoint { a, b, mask } => Box::new(MidpointTask {
                a: self.anchor(a, "task.a")?,
                b: self.anchor(b, "task.b")?,
                names: format!("{} / {}", anchor_name(a), anchor_name(b)),
                mask: self.mask(*mask, "task.mask")?,
            }),
            TaskSpec::RodDirection { a, b, mask } => Box::new(RodDirectionTask {
                a: self.anchor(a, "task.a")?,
                b: self.anchor(b, "task.b")?,
                names: format!("{} / {}", anchor_name(a), anchor_name(b)),
                mask: self.mask(*mask, "task.mask")?,
            }),
        })
    }
}

fn anchor_name(a: &AnchorSpec) -> String {
    match a {
        AnchorSpec::Part(p) | AnchorSpec::Object(p) => p.clone(),
        AnchorSpec::Point(p) => format!("({}, {}, {})", p[0], p[1], p[2]),
    }
}

/// A RON error with its position and, for unknown names, the closest valid ones.
pub fn ron_error(e: &ron::error::SpannedError, origin: &str) -> TaskError {
    TaskError::Spec(Box::new(trm_kinematics::SpecError::from_ron(e, origin)))
}
