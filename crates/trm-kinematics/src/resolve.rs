//! Resolving a model description against a URDF tree: motors and couplings, named frames,
//! groups, postures and the allowed-collision pairs, each checked with located errors.

use std::collections::HashMap;

use crate::description::{CouplingSpec, FrameSpec, ModelDescription, MotorSpec};
use crate::error::{KinematicsError, Result};
use crate::model::{Coupling, DisabledCollision, Motor, NamedFrame};
use crate::tree::{JointKind, Limits, Tree, pose_from_xyz_rpy};

pub(crate) struct DescCtx<'a> {
    pub(crate) origin: &'a str,
    pub(crate) text: Option<&'a str>,
}

impl DescCtx<'_> {
    fn invalid(
        &self,
        element: String,
        quoted: &str,
        problem: impl Into<String>,
        fix: impl Into<String>,
    ) -> KinematicsError {
        // the element starts with its field path (`motors[3] ("r_thumb")`): locate that, else
        // fall back to the first line naming `quoted`
        let path = element.split(" (").next().unwrap_or("");
        let needle = format!("\"{quoted}\"");
        let line = self.text.and_then(|t| {
            trm_io::locate_ron_field(t, path)
                .map(|(line, _)| line)
                .or_else(|| {
                    t.lines()
                        .position(|l| l.contains(&needle) && !l.trim_start().starts_with("//"))
                        .map(|i| i + 1)
                })
        });
        KinematicsError::InvalidModel {
            origin: self.origin.to_string(),
            line,
            element,
            problem: problem.into(),
            fix: fix.into(),
        }
    }
}

/// `couplings[i] (joint "name")`: the element of the coupling of joint `joint`.
fn coupling_element(desc: &ModelDescription, joint: &str) -> String {
    match desc.couplings.iter().position(|c| c.joint == joint) {
        Some(i) => format!("couplings[{i}] (joint \"{joint}\")"),
        None => format!("coupling of joint \"{joint}\""),
    }
}

fn suggestion_fix<'a>(
    name: &str,
    candidates: impl IntoIterator<Item = &'a str>,
    otherwise: &str,
) -> String {
    let near = trm_io::closest_names(name, candidates);
    if near.is_empty() {
        otherwise.to_string()
    } else {
        format!("did you mean `{}`?", near.join("`, `"))
    }
}

type Declared<'a> = HashMap<&'a str, (usize, &'a MotorSpec)>;
type Coupled<'a> = HashMap<&'a str, &'a CouplingSpec>;

/// The motors and each movable joint's coupling to them: declared motors, explicit couplings,
/// one motor per independent joint, `<mimic>` joints following their leader; every step
/// checked against the description with located errors.
pub(crate) fn resolve_motors(
    tree: &Tree,
    desc: &ModelDescription,
    ctx: &DescCtx,
) -> Result<(Vec<Motor>, Vec<Coupling>)> {
    let joint_names: Vec<&str> = tree
        .movable
        .iter()
        .map(|&j| tree.joints[j].name.as_str())
        .collect();
    let declared = declared_motors(desc, ctx)?;
    let coupled = coupled_joints(tree, desc, ctx, &joint_names)?;
    let own_motor = |j: usize| {
        let joint = &tree.joints[j];
        joint.mimic.is_none() && !coupled.contains_key(joint.name.as_str())
    };
    for &j in &tree.movable {
        let name = tree.joints[j].name.as_str();
        if own_motor(j) && declared.contains_key(name) {
            return Err(ctx.invalid(
                format!("motors[{}] (\"{name}\")", declared[name].0),
                name,
                "has the name of an uncoupled joint, which is already a motor of its own",
                "rename the motor, or add a coupling for the joint",
            ));
        }
    }
    let (motors, couplings) = assign_motors(
        tree,
        desc,
        ctx,
        &declared,
        &coupled,
        &joint_names,
        &own_motor,
    )?;
    let couplings = follow_mimics(tree, couplings);
    check_coupling_limits(tree, desc, ctx, &coupled, &motors, &couplings)?;
    Ok((motors, couplings))
}

/// The declared motors by name, with their limits checked.
fn declared_motors<'a>(desc: &'a ModelDescription, ctx: &DescCtx) -> Result<Declared<'a>> {
    let mut declared: HashMap<&str, (usize, &crate::description::MotorSpec)> = HashMap::new();
    for (i, m) in desc.motors.iter().enumerate() {
        let element = format!("motors[{i}] (\"{}\")", m.name);
        if !(m.lower.is_finite() && m.upper.is_finite())
            || m.velocity.is_some_and(|v| v.is_nan() || v <= 0.0)
        {
            return Err(ctx.invalid(
                element,
                &m.name,
                "has a non-finite limit or a non-positive velocity",
                "write finite limits and a positive velocity",
            ));
        }
        if m.lower > m.upper {
            return Err(ctx.invalid(
                element,
                &m.name,
                format!("lower {} is above upper {}", m.lower, m.upper),
                "swap the limits",
            ));
        }
        if declared.insert(m.name.as_str(), (i, m)).is_some() {
            return Err(ctx.invalid(
                element,
                &m.name,
                "is declared twice",
                "give every motor a unique name",
            ));
        }
    }
    Ok(declared)
}

/// The explicit couplings by joint name, checked against the tree.
fn coupled_joints<'a>(
    tree: &Tree,
    desc: &'a ModelDescription,
    ctx: &DescCtx,
    joint_names: &[&str],
) -> Result<Coupled<'a>> {
    let mut coupled: HashMap<&str, &crate::description::CouplingSpec> = HashMap::new();
    for (i, c) in desc.couplings.iter().enumerate() {
        let element = format!("couplings[{i}] (joint \"{}\")", c.joint);
        let Some(j) = tree.joint_index(&c.joint) else {
            return Err(ctx.invalid(
                element,
                &c.joint,
                "names no joint of the URDF",
                suggestion_fix(
                    &c.joint,
                    joint_names.iter().copied(),
                    "name a movable URDF joint",
                ),
            ));
        };
        if !tree.joints[j].kind.is_movable() {
            return Err(ctx.invalid(
                element,
                &c.joint,
                "names a fixed joint",
                "couple only movable joints",
            ));
        }
        if tree.joints[j].mimic.is_some() {
            return Err(ctx.invalid(
                element,
                &c.joint,
                "names a joint that already has a <mimic>",
                "remove the <mimic> or the coupling",
            ));
        }
        if !c.offset.is_finite() || c.motors.iter().any(|(_, f)| !f.is_finite()) {
            return Err(ctx.invalid(
                element,
                &c.joint,
                "has a non-finite factor or offset",
                "write finite numbers",
            ));
        }
        if coupled.insert(c.joint.as_str(), c).is_some() {
            return Err(ctx.invalid(
                element,
                &c.joint,
                "is coupled twice",
                "give one coupling per joint",
            ));
        }
    }
    Ok(coupled)
}

/// Motors in joint order and the coupling of every non-mimic joint (mimic joints: `None`).
fn assign_motors(
    tree: &Tree,
    desc: &ModelDescription,
    ctx: &DescCtx,
    declared: &Declared,
    coupled: &Coupled,
    joint_names: &[&str],
    own_motor: &dyn Fn(usize) -> bool,
) -> Result<(Vec<Motor>, Vec<Option<Coupling>>)> {
    let mut motors: Vec<Motor> = Vec::new();
    let mut index_of: HashMap<String, usize> = HashMap::new();
    let mut motor_index =
        |name: &str, motors: &mut Vec<Motor>, make: &dyn Fn() -> Motor| -> usize {
            *index_of.entry(name.to_string()).or_insert_with(|| {
                motors.push(make());
                motors.len() - 1
            })
        };
    let mut couplings: Vec<Option<Coupling>> = vec![None; tree.movable.len()];
    for (coord, &j) in tree.movable.iter().enumerate() {
        let joint = &tree.joints[j];
        if joint.mimic.is_some() {
            continue;
        }
        if let Some(c) = coupled.get(joint.name.as_str()) {
            let mut terms = Vec::new();
            for (mname, factor) in &c.motors {
                let m = if let Some(&(_, spec)) = declared.get(mname.as_str()) {
                    motor_index(mname, &mut motors, &|| Motor {
                        name: spec.name.clone(),
                        limits: Limits {
                            lower: spec.lower,
                            upper: spec.upper,
                            velocity: spec.velocity.unwrap_or(f64::INFINITY),
                            effort: f64::INFINITY,
                            acceleration: f64::INFINITY,
                            jerk: f64::INFINITY,
                        },
                    })
                } else if let Some(other) = tree
                    .joint_index(mname)
                    .filter(|&o| tree.joints[o].kind.is_movable() && own_motor(o))
                {
                    let other = &tree.joints[other];
                    motor_index(mname, &mut motors, &|| own_motor_of(other))
                } else {
                    let candidates = desc
                        .motors
                        .iter()
                        .map(|m| m.name.as_str())
                        .chain(joint_names.iter().copied());
                    return Err(ctx.invalid(
                        coupling_element(desc, &joint.name),
                        mname,
                        format!("names motor `{mname}`, which is neither declared in `motors` nor an uncoupled joint"),
                        suggestion_fix(mname, candidates, "declare the motor in `motors`"),
                    ));
                };
                terms.push((m, *factor));
            }
            couplings[coord] = Some(Coupling {
                terms,
                offset: c.offset,
            });
        } else {
            let m = motor_index(&joint.name, &mut motors, &|| own_motor_of(joint));
            couplings[coord] = Some(Coupling {
                terms: vec![(m, 1.0)],
                offset: 0.0,
            });
        }
    }
    for (i, m) in desc.motors.iter().enumerate() {
        if !index_of.contains_key(&m.name) {
            return Err(ctx.invalid(
                format!("motors[{i}] (\"{}\")", m.name),
                &m.name,
                "drives no joint",
                "use it in a coupling or remove it",
            ));
        }
    }
    Ok((motors, couplings))
}

/// Mimic joints follow their leader's coupling (scaled and offset).
fn follow_mimics(tree: &Tree, mut couplings: Vec<Option<Coupling>>) -> Vec<Coupling> {
    for (coord, &j) in tree.movable.iter().enumerate() {
        let Some(mimic) = &tree.joints[j].mimic else {
            continue;
        };
        let leader = tree.joints[tree.joint_index(&mimic.leader).expect("checked by Tree")]
            .coordinate
            .expect("movable");
        let lc = couplings[leader]
            .clone()
            .expect("leaders are resolved in the first pass");
        couplings[coord] = Some(Coupling {
            terms: lc
                .terms
                .iter()
                .map(|&(m, f)| (m, f * mimic.multiplier))
                .collect(),
            offset: lc.offset * mimic.multiplier + mimic.offset,
        });
    }
    let couplings: Vec<Coupling> = couplings
        .into_iter()
        .map(|c| c.expect("every movable joint resolved"))
        .collect();
    couplings
}

/// Explicit couplings must keep their joints within the URDF limits over the motor box.
fn check_coupling_limits(
    tree: &Tree,
    desc: &ModelDescription,
    ctx: &DescCtx,
    coupled: &Coupled,
    motors: &[Motor],
    couplings: &[Coupling],
) -> Result<()> {
    for (coord, c) in couplings.iter().enumerate() {
        let joint = &tree.joints[tree.movable[coord]];
        if !coupled.contains_key(joint.name.as_str()) || joint.kind == JointKind::Continuous {
            continue;
        }
        let (mut lo, mut hi) = (c.offset, c.offset);
        for &(m, f) in &c.terms {
            let (a, b) = (f * motors[m].limits.lower, f * motors[m].limits.upper);
            lo += a.min(b);
            hi += a.max(b);
        }
        let tol = 1e-9;
        if lo < joint.limits.lower - tol || hi > joint.limits.upper + tol {
            return Err(ctx.invalid(
                coupling_element(desc, &joint.name),
                &joint.name,
                format!(
                    "drives the joint over [{lo:.6}, {hi:.6}], outside its URDF limits [{:.6}, {:.6}]",
                    joint.limits.lower, joint.limits.upper
                ),
                "narrow the motor limits or correct the factors/offset",
            ));
        }
    }
    Ok(())
}

fn own_motor_of(joint: &crate::tree::Joint) -> Motor {
    let mut limits = joint.limits;
    if joint.kind == JointKind::Continuous {
        limits.lower = -std::f64::consts::PI;
        limits.upper = std::f64::consts::PI;
    }
    Motor {
        name: joint.name.clone(),
        limits,
    }
}

/// `existing` frames followed by `specs`, resolved against the tree and the frames before them.
pub(crate) fn resolve_frames(
    tree: &Tree,
    existing: Vec<NamedFrame>,
    specs: &[FrameSpec],
    ctx: &DescCtx,
) -> Result<Vec<NamedFrame>> {
    let mut frames = existing;
    for (i, f) in specs.iter().enumerate() {
        let element = format!("frames[{i}] (\"{}\")", f.name);
        if tree.link_index(&f.name).is_some() || frames.iter().any(|g| g.name == f.name) {
            return Err(ctx.invalid(
                element,
                &f.name,
                "has the name of a link or another frame",
                "give the frame a unique name",
            ));
        }
        if f.xyz.iter().chain(&f.rpy).any(|v| !v.is_finite()) {
            return Err(ctx.invalid(
                element,
                &f.name,
                "has a non-finite offset",
                "write finite numbers",
            ));
        }
        let offset = pose_from_xyz_rpy(f.xyz, f.rpy);
        let (link, local_offset) = if let Some(l) = tree.link_index(&f.link) {
            (l, offset)
        } else if let Some(g) = frames.iter().find(|g| g.name == f.link) {
            (g.link, g.local_offset * offset)
        } else {
            let candidates = tree
                .links
                .iter()
                .map(|l| l.name.as_str())
                .chain(frames.iter().map(|g| g.name.as_str()));
            return Err(ctx.invalid(
                element,
                &f.link,
                format!(
                    "is attached to `{}`, which is no link or earlier frame",
                    f.link
                ),
                suggestion_fix(&f.link, candidates, "name an existing link"),
            ));
        };
        frames.push(NamedFrame {
            name: f.name.clone(),
            link,
            local_offset,
        });
    }
    Ok(frames)
}

pub(crate) fn resolve_groups(
    motors: &[Motor],
    desc: &ModelDescription,
    ctx: &DescCtx,
) -> Result<Vec<(String, Vec<usize>)>> {
    let mut groups: Vec<(String, Vec<usize>)> = Vec::new();
    for (i, g) in desc.groups.iter().enumerate() {
        let element = format!("groups[{i}] (\"{}\")", g.name);
        if groups.iter().any(|(n, _)| *n == g.name) {
            return Err(ctx.invalid(
                element,
                &g.name,
                "is declared twice",
                "give every group a unique name",
            ));
        }
        let mut members = Vec::new();
        for name in &g.members {
            let found: Vec<usize> = if let Some((_, m)) = groups.iter().find(|(n, _)| n == name) {
                m.clone()
            } else if let Some(i) = motors.iter().position(|m| &m.name == name) {
                vec![i]
            } else {
                let candidates = motors
                    .iter()
                    .map(|m| m.name.as_str())
                    .chain(groups.iter().map(|(n, _)| n.as_str()));
                return Err(ctx.invalid(
                    element,
                    name,
                    format!("member `{name}` is no motor or earlier group"),
                    suggestion_fix(name, candidates, "list motor names"),
                ));
            };
            for m in found {
                if !members.contains(&m) {
                    members.push(m);
                }
            }
        }
        groups.push((g.name.clone(), members));
    }
    Ok(groups)
}

type CollisionPairs = (Vec<DisabledCollision>, Vec<[usize; 2]>);

pub(crate) fn resolve_collision_pairs(
    tree: &Tree,
    desc: &ModelDescription,
    ctx: &DescCtx,
) -> Result<CollisionPairs> {
    let link = |name: &str, element: &str| {
        tree.link_index(name).ok_or_else(|| {
            ctx.invalid(
                element.to_string(),
                name,
                format!("`{name}` is no link of the URDF"),
                suggestion_fix(
                    name,
                    tree.links.iter().map(|l| l.name.as_str()),
                    "use link names",
                ),
            )
        })
    };
    let pair = |a: &str, b: &str, element: &str| -> Result<[usize; 2]> {
        let (i, j) = (link(a, element)?, link(b, element)?);
        if i == j {
            return Err(ctx.invalid(
                element.to_string(),
                a,
                "names the same link twice",
                "name two different links",
            ));
        }
        Ok([i.min(j), i.max(j)])
    };
    let mut disabled = Vec::new();
    for (i, d) in desc.disabled_collisions.iter().enumerate() {
        let links = pair(&d.a, &d.b, &format!("disabled_collisions[{i}]"))?;
        disabled.push(DisabledCollision {
            links,
            reason: d.reason,
        });
    }
    let mut enabled = Vec::new();
    for (i, (a, b)) in desc.enabled_collisions.iter().enumerate() {
        enabled.push(pair(a, b, &format!("enabled_collisions[{i}]"))?);
    }
    Ok((disabled, enabled))
}

/// The description's planning settings, each a positive finite number of radians.
pub(crate) fn resolve_planning(
    desc: &ModelDescription,
    ctx: &DescCtx,
) -> Result<crate::PlanningSpec> {
    let p = desc.planning;
    for (what, value) in [
        ("range", p.range),
        ("resolution", p.resolution),
        ("domain_radius", p.domain_radius),
    ] {
        if let Some(v) = value.filter(|v| !(v.is_finite() && *v > 0.0)) {
            return Err(ctx.invalid(
                format!("planning.{what}"),
                what,
                format!("{v} is not a positive finite number of radians"),
                format!(
                    "give a positive {what} in radians, or leave it out to size it by the robot"
                ),
            ));
        }
    }
    Ok(p)
}

/// `motors` with the description's `motion_limits` applied: each names a motor (with a
/// suggestion when it does not) and gives finite positive limits.
pub(crate) fn resolve_motion_limits(
    motors: &mut [Motor],
    desc: &ModelDescription,
    ctx: &DescCtx,
) -> Result<()> {
    for (name, spec) in &desc.motion_limits {
        let element = format!("motion_limits (\"{name}\")");
        let Some(motor) = motors.iter_mut().find(|m| &m.name == name) else {
            let names: Vec<String> = motors.iter().map(|m| m.name.clone()).collect();
            return Err(ctx.invalid(
                element,
                name,
                format!("limits `{name}`, which is no motor"),
                suggestion_fix(
                    name,
                    names.iter().map(String::as_str),
                    "use motor names (see `trm model-info`)",
                ),
            ));
        };
        for (what, value, slot) in [
            ("velocity", spec.velocity, &mut motor.limits.velocity),
            (
                "acceleration",
                spec.acceleration,
                &mut motor.limits.acceleration,
            ),
            ("jerk", spec.jerk, &mut motor.limits.jerk),
        ] {
            let Some(v) = value else { continue };
            if !(v.is_finite() && v > 0.0) {
                return Err(ctx.invalid(
                    element,
                    name,
                    format!("gives `{name}` a {what} limit of {v}"),
                    format!("give a finite positive {what} limit, or leave it out"),
                ));
            }
            *slot = v;
        }
    }
    Ok(())
}

pub(crate) fn resolve_postures(
    motors: &[Motor],
    desc: &ModelDescription,
    ctx: &DescCtx,
) -> Result<Vec<(String, Vec<f64>)>> {
    let mut postures: Vec<(String, Vec<f64>)> = Vec::new();
    for (i, p) in desc.postures.iter().enumerate() {
        let element = format!("postures[{i}] (\"{}\")", p.name);
        if postures.iter().any(|(n, _)| *n == p.name) {
            return Err(ctx.invalid(
                element,
                &p.name,
                "is declared twice",
                "give every posture a unique name",
            ));
        }
        let mut values: Vec<f64> = motors
            .iter()
            .map(|m| 0.0f64.clamp(m.limits.lower, m.limits.upper))
            .collect();
        for (name, &v) in &p.values {
            let Some(i) = motors.iter().position(|m| &m.name == name) else {
                return Err(ctx.invalid(
                    element,
                    name,
                    format!("sets `{name}`, which is no motor"),
                    suggestion_fix(
                        name,
                        motors.iter().map(|m| m.name.as_str()),
                        "use motor names (see `cargo xtask model-info`)",
                    ),
                ));
            };
            let l = &motors[i].limits;
            if !v.is_finite() || v < l.lower - 1e-12 || v > l.upper + 1e-12 {
                return Err(ctx.invalid(
                    element,
                    name,
                    format!(
                        "sets `{name}` to {v}, outside its limits [{}, {}]",
                        l.lower, l.upper
                    ),
                    "choose a value within the motor limits",
                ));
            }
            values[i] = v.clamp(l.lower, l.upper);
        }
        postures.push((p.name.clone(), values));
    }
    Ok(postures)
}
