//! Cost and task entries of a spec → catalogue objects, with names checked against the model
//! and the world and errors located by field path.

use std::path::Path;

use trm_collision::World;
use trm_kinematics::nalgebra::{UnitQuaternion, Vector3};
use trm_kinematics::{ActiveSet, FrameId, RobotModel};

use crate::context::Anchor;
use crate::costs::SpecLoaders;
use crate::costs::{
    Collision, Direction, Displacement, HomePosture, JointLimits, Orientation, Pointing, Position,
    Region, Repel,
};
use crate::error::Result;
use crate::tasks::{
    AngleTask, DistanceTask, MidpointTask, PoseTask, PositionTask, RodDirectionTask, RotationTask,
    TaskFunction,
};

use super::problem::Ctx;
use super::*;

pub(super) struct Resolver<'a> {
    pub(super) robot: &'a RobotModel,
    pub(super) world: &'a World,
    pub(super) ctx: &'a Ctx<'a>,
    pub(super) base: &'a Path,
    /// Readers of files other crates own.
    pub(super) loaders: &'a SpecLoaders,
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

    /// The home-posture cost: a named posture (else the start) with per-motor weights (motors
    /// or groups; 1 by default).
    fn home_posture(
        &self,
        posture: Option<&str>,
        weights: &std::collections::BTreeMap<String, f64>,
        active: &ActiveSet,
        motors: &[f64],
        field: &str,
    ) -> Result<HomePosture> {
        let home_motors = match posture {
            None => motors.to_vec(),
            Some(p) => self.robot.posture(p).map(<[f64]>::to_vec).map_err(|_| {
                self.ctx.err(
                    &format!("{field}.cost.posture"),
                    format!("`{p}` is no posture"),
                    self.ctx
                        .suggest(p, self.robot.posture_names(), "use a posture of the model"),
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
        Ok(HomePosture {
            home: active.from_motors(&home_motors),
            weights: w,
        })
    }

    /// A position cost's target region.
    fn region(&self, target: &TargetSpec, field: &str) -> Result<Region> {
        Ok(match target {
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
        })
    }

    pub(super) fn cost(
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
                Box::new(self.home_posture(posture.as_deref(), weights, active, motors, &field)?)
            }
            CostKind::Collision {
                self_collision,
                world,
            } => Box::new(Collision {
                self_collision: *self_collision,
                world: *world,
            }),
            CostKind::Position { part, target, mask } => {
                let target = self.region(target, &field)?;
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
                let loader = self.loaders.pose_maps.ok_or_else(|| {
                    self.ctx.err(
                        &format!("{field}.cost"),
                        "task maps are read by trm-taskmap, and no reader of them was given",
                        "load the spec with Problem::load_with(path, &trm_taskmap::loaders()) (the trm tool and Python do)",
                    )
                })?;
                let map = loader(&path).map_err(|e| {
                    self.ctx.err(
                        &format!("{field}.cost.file"),
                        e,
                        "build it with trm_taskmap::explore (trm explore-task-map)",
                    )
                })?;
                Box::new(crate::costs::TaskMapCost {
                    map,
                    part: self.frame(part, &format!("{field}.cost.part"))?,
                    part_name: part.clone(),
                    object: self.object(object, &format!("{field}.cost.object"))?,
                })
            }
        })
    }

    pub(super) fn task(&self, t: &TaskSpec) -> Result<Box<dyn TaskFunction>> {
        Ok(match t {
            TaskSpec::Position { part, mask } => Box::new(PositionTask {
                part: self.frame(part, "task.part")?,
                part_name: part.clone(),
                mask: self.mask(*mask, "task.mask")?,
            }),
            TaskSpec::Rotation {
                part,
                axis,
                mask,
                relative_to,
            } => Box::new(RotationTask {
                part: self.frame(part, "task.part")?,
                part_name: part.clone(),
                axis: self.unit(*axis, "task.axis")?,
                mask: self.mask(*mask, "task.mask")?,
                relative_to: match relative_to {
                    Some(r) => Some((self.frame(r, "task.relative_to")?, r.clone())),
                    None => None,
                },
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
            TaskSpec::Pose {
                part,
                scale,
                reference,
            } => {
                let [r, p, y] = self.finite(*reference, "task.reference")?;
                Box::new(PoseTask {
                    part: self.frame(part, "task.part")?,
                    part_name: part.clone(),
                    scale: self.positive(*scale, "task.scale")?,
                    reference_inverse: UnitQuaternion::from_euler_angles(r, p, y).inverse(),
                })
            }
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
