//! A spec file → a [`Problem`]: its model (embedded or a file, plus the spec's frames), active
//! motors, start posture, world and objective.

use std::path::Path;

use trm_collision::{CollisionModel, World};
use trm_io::closest_names;
use trm_kinematics::{FrameSpec, RobotModel};

use crate::costs::SpecLoaders;
use crate::error::{Result, TaskError};
use crate::objective::Objective;

use super::resolve::Resolver;
use super::*;

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

pub(super) struct Ctx<'a> {
    pub(super) origin: &'a str,
    pub(super) text: &'a str,
}

impl Ctx<'_> {
    /// A spec error at field path `field` (`costs[2].cost.part`), located in the text by that
    /// path — or by its nearest ancestor the text spells out.
    pub(super) fn err(
        &self,
        field: &str,
        problem: impl Into<String>,
        fix: impl Into<String>,
    ) -> TaskError {
        TaskError::Spec(Box::new(trm_io::SpecError::at(
            self.text,
            self.origin,
            field,
            problem,
            fix,
        )))
    }

    pub(super) fn suggest<'a>(
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
    /// Reads and builds a spec file whose costs name no file another crate reads (a task map:
    /// [`Problem::load_with`]).
    pub fn load(path: impl AsRef<Path>) -> Result<Self> {
        Self::load_with(path, &SpecLoaders::default())
    }

    /// Reads and builds a spec file, its costs' files read by `loaders`.
    pub fn load_with(path: impl AsRef<Path>, loaders: &SpecLoaders) -> Result<Self> {
        let path = path.as_ref();
        let text = trm_io::read_input(path).map_err(|source| TaskError::Io {
            path: path.to_path_buf(),
            source,
        })?;
        let base = path.parent().map(Path::to_path_buf).unwrap_or_default();
        Self::from_ron_with(&text, &path.display().to_string(), &base, loaders)
    }

    /// Parses and builds spec text; `origin` names it in errors, `base` resolves relative paths.
    pub fn from_ron(text: &str, origin: &str, base: &Path) -> Result<Self> {
        Self::from_ron_with(text, origin, base, &SpecLoaders::default())
    }

    /// [`Problem::from_ron`], its costs' files read by `loaders`.
    pub fn from_ron_with(
        text: &str,
        origin: &str,
        base: &Path,
        loaders: &SpecLoaders,
    ) -> Result<Self> {
        let spec: Spec = ron::from_str(text).map_err(|e| ron_error(&e, origin))?;
        Self::build(spec, text, origin, base, loaders)
    }

    fn build(
        spec: Spec,
        text: &str,
        origin: &str,
        base: &Path,
        loaders: &SpecLoaders,
    ) -> Result<Self> {
        let ctx = Ctx { origin, text };
        let robot = load_model(&spec.model, base, &ctx)?;
        let robot = with_frames(robot, &spec.frames, &ctx)?;
        let motors = start_motors(&spec, &robot, &ctx)?;
        let active = active_motors(&spec, &robot, &motors, &ctx)?;
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
            loaders,
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
        check_solver(&spec, &ctx)?;
        check_numbers(&spec, &ctx)?;
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

/// The start's motor values: the spec's `start` posture (else `home`, else neutral) with its
/// `start_values` over it, each within its motor's limits.
fn start_motors(spec: &Spec, robot: &RobotModel, ctx: &Ctx) -> Result<Vec<f64>> {
    let mut motors = match &spec.start {
        None => robot.home_motors(),
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
        let limits = &robot.motors()[i].limits;
        if !(v.is_finite() && *v >= limits.lower && *v <= limits.upper) {
            return Err(ctx.err(
                &format!("start_values.{name}"),
                format!(
                    "{v} is outside `{name}`'s limits [{}, {}]",
                    limits.lower, limits.upper
                ),
                "give a start value within the motor's limits",
            ));
        }
        motors[i] = *v;
    }
    Ok(motors)
}

/// The moving motors: the spec's `active` motors and groups (each named once), the others
/// locked at `motors`; every motor when the list is empty.
fn active_motors(
    spec: &Spec,
    robot: &RobotModel,
    motors: &[f64],
    ctx: &Ctx,
) -> Result<trm_kinematics::ActiveSet> {
    Ok(if spec.active.is_empty() {
        robot.all_active()
    } else {
        for (i, name) in spec.active.iter().enumerate() {
            if let Some(first) = spec.active[..i].iter().position(|n| n == name) {
                return Err(ctx.err(
                    &format!("active[{i}]"),
                    format!("`{name}` is given twice (also active[{first}])"),
                    "name each motor or group once (groups that share motors are joined)",
                ));
            }
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
        robot.active_set(&spec.active, motors)?
    })
}

/// The solver's algorithm (a known one) and initial step (positive).
fn check_solver(spec: &Spec, ctx: &Ctx) -> Result<()> {
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
    Ok(())
}

/// Range checks of the solver's and the map's numbers, each error at its field.
fn check_numbers(spec: &Spec, ctx: &Ctx) -> Result<()> {
    let s = &spec.solver;
    let count = |field: &str, v: usize, lo: usize, hi: usize| {
        if (lo..=hi).contains(&v) {
            Ok(())
        } else {
            Err(ctx.err(
                field,
                format!("{v} is not in {lo}..={hi}"),
                "give a count in that range",
            ))
        }
    };
    if let Some(p) = s.population {
        count("solver.population", p, 2, 1_000_000)?;
    }
    if !(1..=10_000_000_000).contains(&s.max_evaluations) {
        return Err(ctx.err(
            "solver.max_evaluations",
            format!("{} is not in 1..=10000000000", s.max_evaluations),
            "give an evaluation budget in that range",
        ));
    }
    if s.no_improvement == Some(0) {
        return Err(ctx.err(
            "solver.no_improvement",
            "0 stops at once",
            "give at least 1, or leave it out",
        ));
    }
    if let Some(t) = s.target {
        if !t.is_finite() {
            return Err(ctx.err(
                "solver.target",
                format!("{t} is not finite"),
                "give a finite cost, or leave it out",
            ));
        }
    }
    if let Some(m) = &spec.map {
        m.check()
            .map_err(|p| ctx.err(&format!("map.{}", p.field), p.problem, p.fix))?;
    }
    Ok(())
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
