//! Whole-body motion specs in RON (format: [`crate::formats::motion_spec`]).
//! [`MotionSpec::load`] reads a file and checks every name and number, with errors that name the
//! file, line and field and say how to fix them.

use std::collections::BTreeMap;
use std::path::Path;

use crate::WholeBodyError;
use serde::{Deserialize, Serialize};
use trm_collision::{Shape, WorldSpec};
use trm_io::closest_names;
use trm_kinematics::RobotModel;

use crate::Result;

/// A whole-body motion: robot, contacts, phases with their keyframe postures, the parametrised
/// centre-of-mass trajectory, the controller, the constraints and the optimisation settings.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MotionSpec {
    /// `icub_sagittal` (embedded) or a `.ron`/`.urdf` model path relative to the spec.
    pub model: String,
    /// Frames at the centres of the soles (z along the sole normal, x towards the toes); both
    /// feet stay flat on the ground. The ground frame lies midway between them, x forward, z up.
    pub feet: (String, String),
    /// Sole length (along the frame's x) and width, metres.
    pub sole: (f64, f64),
    /// The conservative support polygon is the feet's, shrunk by this margin (metres) on every side.
    pub support_margin: f64,
    /// Objects around the robot, in the ground frame (x forward, y left, z up); the robot must
    /// not collide with them, except the seat's contact links while the seat supports it.
    #[serde(default)]
    pub world: WorldSpec,
    /// The seat (a box of `world`) and the links resting on it; `None` without a seat.
    #[serde(default)]
    pub seat: Option<SeatSpec>,
    /// A hand (frame) that reaches a target during one phase; `None` for no reach.
    #[serde(default)]
    pub reach: Option<ReachSpec>,
    /// Start posture, degrees, by motor name (motors left out: 0 clamped into limits).
    #[serde(deserialize_with = "trm_io::unique_names")]
    pub start: BTreeMap<String, f64>,
    /// The phases, in order; each ends at a keyframe posture.
    pub phases: Vec<PhaseSpec>,
    /// Number of free RBFs per centre-of-mass component and of the time law (the paper: 5).
    pub rbfs: usize,
    /// Control step, seconds (the paper: 0.01).
    pub dt: f64,
    /// Controller gains.
    pub controller: ControllerSpec,
    /// Constraint limits beyond the model's.
    pub limits: LimitsSpec,
    /// Weights of the cost terms (the paper: 1.3, 1, 3).
    pub weights: WeightsSpec,
    /// Optimisation settings.
    pub optimiser: OptimizerSpec,
    /// The hand-tuned reference trajectory the results are normalised by.
    pub hand_tuned: TrajectorySpec,
}

/// The seat.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SeatSpec {
    /// Name of a box in `world`.
    pub object: String,
    /// Links that rest on the seat while it supports the robot (contact, not collision).
    pub contacts: Vec<String>,
}

/// A reaching task: the frame's origin moves along a minimum-jerk line from where it is at the
/// phase's start to `target` at the phase's end (x and z; y is free), as a task below the
/// centre of mass and above the posture.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ReachSpec {
    /// A link or named frame of the model (e.g. `l_palm_center`).
    pub frame: String,
    /// Target (x, z) in the ground frame, metres.
    pub target: (f64, f64),
    /// The phase (by name) during which the hand reaches.
    pub phase: String,
    /// Feedback gain, 1/s.
    pub gain: f64,
    /// The final distance to the target must stay below this (a constraint), metres.
    pub tolerance: f64,
}

/// Who carries the robot during a phase.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum Support {
    /// The feet alone.
    Feet,
    /// The feet and the seat.
    FeetAndSeat,
}

/// One phase of the motion.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PhaseSpec {
    /// A name for reports.
    pub name: String,
    /// End time, seconds, of the optimised motion (the hand-tuned one has its own).
    pub end: f64,
    /// Contacts carrying the robot.
    pub support: Support,
    /// Motors held still (e.g. the legs while seated).
    #[serde(default)]
    pub locked: Vec<String>,
    /// Keyframe posture reached at the phase's end (posture task), degrees by motor name;
    /// motors left out keep the previous keyframe's value.
    #[serde(deserialize_with = "trm_io::unique_names")]
    pub keyframe: BTreeMap<String, f64>,
}

/// Gains of the differential-IK controller.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ControllerSpec {
    /// Centre-of-mass feedback gain, 1/s.
    pub com_gain: f64,
    /// Posture feedback gain in the null space, 1/s.
    pub posture_gain: f64,
    /// Damping of the least-squares inverse, metres.
    pub damping: f64,
    /// Time constant (s) of the first-order low-pass filter between the IK's joint velocities
    /// and the joints (the actuators' response); 0 = none. Without it the joint velocities
    /// jump when a phase unlocks motors, and so would the ZMP.
    #[serde(default)]
    pub smoothing: f64,
}

/// Constraint limits.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LimitsSpec {
    /// Velocity limits, rad/s, by motor (overriding or completing the model's).
    #[serde(default)]
    #[serde(deserialize_with = "trm_io::unique_names")]
    pub velocity: BTreeMap<String, f64>,
    /// Static torque limits per joint, N·m, by motor (every motor needs one).
    #[serde(deserialize_with = "trm_io::unique_names")]
    pub torque: BTreeMap<String, f64>,
    /// Check self-collision along the motion.
    #[serde(default = "yes")]
    pub self_collision: bool,
}

fn yes() -> bool {
    true
}

/// Weights of φ_co's terms.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WeightsSpec {
    /// Centre-of-mass tracking error (w₁).
    pub com_error: f64,
    /// Effort, Σ τ² (w₂).
    pub effort: f64,
    /// Backward motion (w₃).
    pub backward: f64,
    /// Normaliser of the backward penalty, metres (b_max).
    pub backward_max: f64,
}

/// Optimisation settings.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OptimizerSpec {
    /// Rollouts of the unconstrained bootstrap (the paper: 500).
    pub bootstrap_rollouts: u64,
    /// Rollouts of the constrained search (the paper: 500).
    pub rollouts: u64,
    /// Initial step size (the paper's exploration rate 0.1), in parameter units.
    pub exploration: f64,
    /// Start parameters (x fractions, z fractions, time-law log-speeds); all 0 when left out
    /// (a straight-line blend at constant speed).
    #[serde(default)]
    pub start: Option<Vec<f64>>,
}

/// A trajectory given by hand: phase end times and parameters.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TrajectorySpec {
    /// End time of every phase, seconds.
    pub ends: Vec<f64>,
    /// Parameters: `rbfs` x fractions, `rbfs` z fractions, `rbfs` time-law log-speeds.
    pub params: Vec<f64>,
}

/// The most control steps a rollout may simulate (duration / dt).
pub const MAX_STEPS: usize = 1_000_000;

/// The most control steps a whole optimisation may simulate (rollouts × duration / dt): 30×
/// the stand-up spec's 1.65 million.
pub const MAX_TOTAL_STEPS: u64 = 50_000_000;

/// A located spec error from a field, a problem and its fix.
pub(crate) type SpecErr<'a> = dyn Fn(&str, String, &str) -> WholeBodyError + 'a;

impl MotionSpec {
    /// Reads and checks a spec file.
    pub fn load(path: impl AsRef<Path>) -> Result<(Self, String)> {
        let path = path.as_ref();
        let text = trm_io::read_input(path).map_err(|source| WholeBodyError::Io {
            path: path.to_path_buf(),
            source,
        })?;
        let spec = Self::from_ron(&text, &path.display().to_string())?;
        Ok((spec, text))
    }

    /// Parses a spec (numbers and structure; names are checked against the model by
    /// [`MotionSpec::check_names`]).
    pub fn from_ron(text: &str, origin: &str) -> Result<Self> {
        let spec: MotionSpec = ron::from_str(text)
            .map_err(|e| WholeBodyError::Spec(Box::new(trm_io::SpecError::from_ron(&e, origin))))?;
        spec.check(text, origin)?;
        Ok(spec)
    }

    /// Checks the numbers and structure (what [`MotionSpec::from_ron`] checks), errors located
    /// in `text`: for a spec changed after parsing, e.g. its budgets replaced.
    pub fn check(&self, text: &str, origin: &str) -> Result<()> {
        let err = |field: &str, problem: String, fix: &str| {
            WholeBodyError::spec(text, origin, field, problem, fix)
        };
        self.check_numbers(&err)?;
        self.check_phases(&err)?;
        self.check_sizes(&err)?;
        self.check_parameters(&err)?;
        self.check_supports(&err)
    }

    /// Gains, sizes and weights in range; a support polygon left inside the margin.
    fn check_numbers(&self, err: &SpecErr<'_>) -> Result<()> {
        let positive = [
            ("dt", self.dt),
            ("sole[0]", self.sole.0),
            ("sole[1]", self.sole.1),
            ("controller.com_gain", self.controller.com_gain),
            ("controller.damping", self.controller.damping),
            ("optimiser.exploration", self.optimiser.exploration),
            ("weights.backward_max", self.weights.backward_max),
        ];
        for (field, v) in positive {
            if !(v.is_finite() && v > 0.0) {
                return Err(err(
                    field,
                    format!("must be positive and finite, got {v}"),
                    "give a positive number",
                ));
            }
        }
        let w = &self.weights;
        let non_negative = [
            ("support_margin", self.support_margin),
            ("controller.posture_gain", self.controller.posture_gain),
            ("controller.smoothing", self.controller.smoothing),
            ("weights.com_error", w.com_error),
            ("weights.effort", w.effort),
            ("weights.backward", w.backward),
        ];
        for (field, v) in non_negative {
            if !(v.is_finite() && v >= 0.0) {
                return Err(err(
                    field,
                    format!("must be ≥ 0 and finite, got {v}"),
                    "give a non-negative number",
                ));
            }
        }
        if 2.0 * self.support_margin >= self.sole.0.min(self.sole.1) {
            return Err(err(
                "support_margin",
                "leaves no support polygon".into(),
                "use a margin below half the sole width",
            ));
        }
        if self.rbfs == 0 {
            return Err(err(
                "rbfs",
                "need at least one RBF".into(),
                "the paper uses 5",
            ));
        }
        Ok(())
    }

    /// Phases: at least one, ends increasing, names unique.
    fn check_phases(&self, err: &SpecErr<'_>) -> Result<()> {
        if self.phases.is_empty() {
            return Err(err("phases", "no phase".into(), "add at least one phase"));
        }
        let ends: Vec<f64> = self.phases.iter().map(|p| p.end).collect();
        check_ends(&ends).map_err(|p| err("phases", p, "phase ends must increase from > 0"))?;
        for (i, p) in self.phases.iter().enumerate() {
            if self.phases[..i].iter().any(|q| q.name == p.name) {
                return Err(err(
                    &format!("phases[{i}].name"),
                    format!("`{}` names two phases", p.name),
                    "give every phase its own name",
                ));
            }
        }
        Ok(())
    }

    /// RBF and rollout counts, the hand-tuned ends, and the control steps a run takes, bounded.
    fn check_sizes(&self, err: &SpecErr<'_>) -> Result<()> {
        let ends: Vec<f64> = self.phases.iter().map(|p| p.end).collect();
        if self.rbfs > 1000 {
            return Err(err(
                "rbfs",
                format!("{} RBFs", self.rbfs),
                "give at most 1000 (the paper uses 5)",
            ));
        }
        for (field, n) in [
            (
                "optimiser.bootstrap_rollouts",
                self.optimiser.bootstrap_rollouts,
            ),
            ("optimiser.rollouts", self.optimiser.rollouts),
        ] {
            if n > 10_000_000 {
                return Err(err(field, format!("{n} rollouts"), "give at most 10000000"));
            }
        }
        check_ends(&self.hand_tuned.ends)
            .map_err(|p| err("hand_tuned.ends", p, "ends must increase from > 0"))?;
        if self.hand_tuned.ends.len() != self.phases.len() {
            return Err(err(
                "hand_tuned.ends",
                format!(
                    "{} ends for {} phases",
                    self.hand_tuned.ends.len(),
                    self.phases.len()
                ),
                "give one end time per phase",
            ));
        }
        // every rollout simulates duration / dt control steps; the optimiser runs
        // bootstrap_rollouts + rollouts of them, and the hand-tuned motion once
        let duration = ends
            .iter()
            .chain(&self.hand_tuned.ends)
            .fold(0.0f64, |a, &b| a.max(b));
        let steps = duration / self.dt;
        if steps > MAX_STEPS as f64 {
            return Err(err(
                "dt",
                format!(
                    "{duration} s in steps of {} s is {steps:.3e} control steps",
                    self.dt
                ),
                &format!(
                    "give a time step that makes at most {MAX_STEPS} steps per rollout (the paper uses 0.01 s)"
                ),
            ));
        }
        let rollouts = self.optimiser.bootstrap_rollouts + self.optimiser.rollouts + 1;
        let total = steps * rollouts as f64;
        if total > MAX_TOTAL_STEPS as f64 {
            return Err(err(
                "dt",
                format!(
                    "{rollouts} rollouts of {steps:.3e} control steps ({duration} s in steps of {} s) are {total:.3e} steps in all",
                    self.dt
                ),
                &format!(
                    "give a larger time step or fewer rollouts: at most {MAX_TOTAL_STEPS} steps in all (the paper: 0.01 s, 1000 rollouts)"
                ),
            ));
        }
        Ok(())
    }

    /// The hand-tuned and start parameters: 3 × rbfs finite values each.
    fn check_parameters(&self, err: &SpecErr<'_>) -> Result<()> {
        let n = 3 * self.rbfs;
        let params = std::iter::once(("hand_tuned.params", Some(&self.hand_tuned.params))).chain(
            std::iter::once(("optimiser.start", self.optimiser.start.as_ref())),
        );
        for (field, p) in params {
            if let Some(p) = p {
                if p.len() != n || p.iter().any(|v| !v.is_finite()) {
                    return Err(err(
                        field,
                        format!("{} values (all finite) needed, got {}", n, p.len()),
                        "give rbfs x fractions, rbfs z fractions and rbfs time-law log-speeds",
                    ));
                }
            }
        }
        Ok(())
    }

    /// The seat (an axis-aligned box of the world, present when a phase sits) and the reach.
    fn check_supports(&self, err: &SpecErr<'_>) -> Result<()> {
        if let Some(seat) = &self.seat {
            match self.world.objects.iter().find(|o| o.name == seat.object) {
                Some(o) if matches!(o.shape, Shape::Box { .. }) && o.rpy == [0.0; 3] => {}
                _ => {
                    return Err(err(
                        "seat.object",
                        format!("`{}` is not an axis-aligned box of `world`", seat.object),
                        "name a `Box` object of `world` with rpy (0, 0, 0)",
                    ));
                }
            }
        }
        if self.seat.is_none()
            && self
                .phases
                .iter()
                .any(|p| p.support == Support::FeetAndSeat)
        {
            return Err(err(
                "phases",
                "a phase is supported by a seat but there is no seat".into(),
                "add `seat: Some((object: ..., contacts: [...]))` or use `support: Feet`",
            ));
        }
        if let Some(r) = &self.reach {
            if !self.phases.iter().any(|p| p.name == r.phase) {
                let names: Vec<&str> = self.phases.iter().map(|p| p.name.as_str()).collect();
                return Err(err(
                    "reach.phase",
                    format!("no phase named `{}`", r.phase),
                    &format!("use one of `{}`", names.join("`, `")),
                ));
            }
            let ok = [r.gain, r.tolerance]
                .iter()
                .all(|v| v.is_finite() && *v > 0.0)
                && r.target.0.is_finite()
                && r.target.1.is_finite();
            if !ok {
                return Err(err(
                    "reach",
                    "gain and tolerance must be positive, the target finite".into(),
                    "fix the reach numbers",
                ));
            }
        }
        Ok(())
    }

    /// Checks every motor and link name against `model`, with suggestions.
    pub fn check_names(&self, model: &RobotModel, origin: &str, text: &str) -> Result<()> {
        let motors: Vec<&str> = model.motors().iter().map(|m| m.name.as_str()).collect();
        let err = |field: &str, name: &str, kind: &str, candidates: &[&str]| {
            let near = closest_names(name, candidates.iter().copied());
            WholeBodyError::spec(
                text,
                origin,
                field,
                format!("unknown {kind} `{name}`"),
                if near.is_empty() {
                    format!("use one of `{}`", candidates.join("`, `"))
                } else {
                    format!("did you mean `{}`?", near.join("`, `"))
                },
            )
        };
        let motor_maps = std::iter::once(("start".to_string(), &self.start))
            .chain(
                self.phases
                    .iter()
                    .enumerate()
                    .map(|(i, p)| (format!("phases[{i}].keyframe"), &p.keyframe)),
            )
            .chain(std::iter::once((
                "limits.velocity".to_string(),
                &self.limits.velocity,
            )))
            .chain(std::iter::once((
                "limits.torque".to_string(),
                &self.limits.torque,
            )));
        for (field, map) in motor_maps {
            for (name, v) in map {
                let at = format!("{field}.{name}");
                if !motors.contains(&name.as_str()) {
                    return Err(err(&at, name, "motor", &motors));
                }
                if !v.is_finite() {
                    return Err(WholeBodyError::spec(
                        text,
                        origin,
                        &at,
                        format!("`{name}` is {v}"),
                        "give a finite number",
                    ));
                }
            }
        }
        for (i, p) in self.phases.iter().enumerate() {
            for (j, name) in p.locked.iter().enumerate() {
                if !motors.contains(&name.as_str()) {
                    return Err(err(
                        &format!("phases[{i}].locked[{j}]"),
                        name,
                        "motor",
                        &motors,
                    ));
                }
            }
        }
        for m in &motors {
            if !self.limits.torque.contains_key(*m) {
                return Err(WholeBodyError::spec(
                    text,
                    origin,
                    "limits.torque",
                    format!("no torque limit for motor `{m}`"),
                    format!("add \"{m}\": N·m per joint"),
                ));
            }
        }
        let frames: Vec<&str> = model.frame_names().collect();
        for (i, f) in [&self.feet.0, &self.feet.1].into_iter().enumerate() {
            if model.frame_id(f).is_err() {
                return Err(err(&format!("feet[{i}]"), f, "frame", &frames));
            }
        }
        if let Some(c) = &self.seat {
            let links: Vec<&str> = model.tree().links.iter().map(|l| l.name.as_str()).collect();
            for (j, l) in c.contacts.iter().enumerate() {
                if !links.contains(&l.as_str()) {
                    return Err(err(&format!("seat.contacts[{j}]"), l, "link", &links));
                }
            }
        }
        if let Some(r) = &self.reach {
            if model.frame_id(&r.frame).is_err() {
                return Err(err("reach.frame", &r.frame, "frame", &frames));
            }
        }
        Ok(())
    }
}

fn check_ends(ends: &[f64]) -> std::result::Result<(), String> {
    let mut last = 0.0;
    for &e in ends {
        if !(e.is_finite() && e > last) {
            return Err(format!("end times {ends:?} do not increase from 0"));
        }
        last = e;
    }
    Ok(())
}
