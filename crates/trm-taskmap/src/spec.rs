//! Task-map specs: which hand grasps which object, where to start and how to explore (RON) —
//! what `cargo xtask explore-task-map` reads. Format: [`crate::formats::task_map_spec`]. Errors
//! name the file, the line and the field.

use std::path::{Path, PathBuf};

use serde::Deserialize;
use trm_collision::{CollisionModel, ObjectSpec, World, WorldSpec};
use trm_kinematics::RobotModel;

use crate::{ExploreOptions, Hand, Metric, TaskMap, TaskMapError, explore, find_grasp};

fn right() -> String {
    "r".into()
}

/// A task-map spec (format: [`crate::formats::task_map_spec`]).
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TaskMapSpec {
    /// A model file relative to the spec; the embedded iCub upper body when absent.
    #[serde(default)]
    pub model: Option<PathBuf>,
    /// Which iCub hand: "r" or "l".
    #[serde(default = "right")]
    pub hand: String,
    /// The object's parts in its own frame.
    pub object: Vec<ObjectSpec>,
    /// The first grasp g₀ (hand position and rotation vector in the object frame); found by
    /// random search when absent.
    #[serde(default)]
    pub start: Option<[f64; 6]>,
    /// The metric W.
    #[serde(default)]
    pub metric: Option<Metric>,
    /// RRT settings.
    #[serde(default)]
    pub explore: ExploreSpec,
    /// Random search for g₀.
    #[serde(default)]
    pub search: SearchSpec,
}

/// The RRT settings of a [`TaskMapSpec`].
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ExploreSpec {
    /// RRT iterations.
    pub iterations: usize,
    /// RRT step (in the metric's units).
    pub step: f64,
    /// Restarts from random feasible samples, for disjoint clusters.
    pub restarts: usize,
    /// Half widths of the sampling box around g₀ (m, m, m, rad, rad, rad).
    pub half_widths: [f64; 6],
    /// Seed.
    pub seed: u64,
}

impl Default for ExploreSpec {
    fn default() -> Self {
        ExploreSpec {
            iterations: 3000,
            step: 0.015,
            restarts: 300,
            half_widths: [0.1, 0.1, 0.2, 1.0, 1.0, 1.0],
            seed: 0,
        }
    }
}

/// The random search for a first grasp of a [`TaskMapSpec`].
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SearchSpec {
    /// Random hand poses tried.
    pub samples: usize,
    /// Lower corner of the hand-position box in the object frame, m.
    pub lower: [f64; 3],
    /// Upper corner, m.
    pub upper: [f64; 3],
    /// Seed.
    pub seed: u64,
}

impl Default for SearchSpec {
    fn default() -> Self {
        SearchSpec {
            samples: 5000,
            lower: [-0.15, -0.12, -0.08],
            upper: [0.05, 0.12, 0.15],
            seed: 0,
        }
    }
}

/// An explored task map with the robot and hand it was explored for.
#[derive(Debug)]
pub struct Explored {
    /// The robot.
    pub model: RobotModel,
    /// Its collision model.
    pub collision: CollisionModel,
    /// The map.
    pub map: TaskMap,
    /// The object's parts, in the object's frame.
    pub object: World,
    /// The first grasp g₀ the exploration started from.
    pub start: [f64; 6],
    /// Exploration wall time, s.
    pub seconds: f64,
}

/// Where an object stands in the robot's root frame from `(x, y, z)` or `(x, y, z, yaw)`
/// (finite numbers; yaw about z, rad).
pub fn placement(at: &[f64]) -> Result<nalgebra::Isometry3<f64>, TaskMapError> {
    if !(at.len() == 3 || at.len() == 4) || at.iter().any(|v| !v.is_finite()) {
        return Err(TaskMapError::Invalid {
            what: "object placement".into(),
            problem: format!("{at:?}: give (x, y, z) or (x, y, z, yaw), finite"),
        });
    }
    Ok(nalgebra::Isometry3::new(
        nalgebra::Vector3::new(at[0], at[1], at[2]),
        nalgebra::Vector3::z() * at.get(3).copied().unwrap_or(0.0),
    ))
}

/// A reaching motion optimised by [`Explored::reach`].
#[derive(Debug, Clone)]
pub struct Reach {
    /// The motion and its costs.
    pub motion: crate::Motion,
    /// The best cost and its joint-limit part after each iteration, the start's first.
    pub trace: Vec<(f64, f64)>,
    /// The motors it moves (torso and right arm), the others at home.
    pub active: trm_kinematics::ActiveSet,
}

impl Reach {
    /// The motion's postures as full motor vectors.
    pub fn motor_trajectory(&self) -> Vec<Vec<f64>> {
        let path = &self.motion.trajectory;
        path.iter().map(|q| self.active.to_motors(q)).collect()
    }
}

impl Explored {
    /// The paper's reaching motion (Section III) of the iCub's right hand (torso and right arm
    /// moving, from the home posture) to grasp this map's object placed at `object` in
    /// `world`, toward `goal` (this map, or one grasp of it), with the default settings.
    pub fn reach_problem<'a>(
        &'a self,
        active: &'a trm_kinematics::ActiveSet,
        world: &'a World,
        object: nalgebra::Isometry3<f64>,
        goal: crate::MotionGoal<'a>,
    ) -> Result<crate::ReachProblem<'a>, TaskMapError> {
        let grasp_axis =
            crate::grasp_axis(&self.map, &self.object).ok_or_else(|| TaskMapError::Invalid {
                what: "task map".into(),
                problem:
                    "gives no grasp axis: it is empty or its object has no capsule, cylinder or box"
                        .into(),
            })?;
        Ok(crate::ReachProblem {
            active,
            collision: &self.collision,
            world,
            hand: self.model.frame_id("r_hand")?,
            grasp_axis,
            object,
            start: active.from_motors(self.model.posture("home")?),
            goal,
            settings: crate::MotionOptions::default(),
        })
    }

    /// The reaching motion of `trm reach-grasp`: this map's object placed at `object` in
    /// `world`, the right hand optimised for `iterations` iRprop− steps toward the whole map
    /// (or, with `exact`, the map's grasp nearest the object's centre).
    pub fn reach(
        &self,
        world: &World,
        object: nalgebra::Isometry3<f64>,
        exact: bool,
        iterations: usize,
    ) -> Result<Reach, TaskMapError> {
        if iterations == 0 {
            return Err(TaskMapError::Invalid {
                what: "iterations".into(),
                problem: "0: give at least 1".into(),
            });
        }
        let active = self.reaching_set()?;
        let centre = self
            .map
            .center_grasp()
            .ok_or_else(|| TaskMapError::Invalid {
                what: "task map".into(),
                problem: "is empty: explore it with more points".into(),
            })?;
        let goal = if exact {
            crate::MotionGoal::Target(centre)
        } else {
            crate::MotionGoal::Map(&self.map)
        };
        let (motion, trace) = self
            .reach_problem(&active, world, object, goal)?
            .optimize(iterations);
        Ok(Reach {
            motion,
            trace,
            active,
        })
    }

    /// The active set the reaching motions move: torso and right arm, the rest at home.
    pub fn reaching_set(&self) -> Result<trm_kinematics::ActiveSet, TaskMapError> {
        Ok(self
            .model
            .active_set(&["torso", "right_arm"], self.model.posture("home")?)?)
    }
}

/// A spec with where it came from (for errors and relative paths).
#[derive(Debug, Clone)]
pub struct LoadedTaskMapSpec {
    /// The spec.
    pub spec: TaskMapSpec,
    /// Its origin (file name or `<string>`).
    pub origin: String,
    /// Its text, for locating errors.
    pub text: String,
    /// The directory relative paths start from.
    pub base: PathBuf,
}

impl TaskMapSpec {
    /// Reads a spec file.
    pub fn load(path: impl AsRef<Path>) -> Result<LoadedTaskMapSpec, TaskMapError> {
        let path = path.as_ref();
        let text = trm_io::read_input(path).map_err(|source| {
            TaskMapError::MapFile(trm_io::FileError::Io {
                path: path.to_path_buf(),
                source,
            })
        })?;
        let base = path.parent().map(PathBuf::from).unwrap_or_default();
        Self::from_ron(&text, &path.display().to_string(), &base)
    }

    /// Parses and checks spec text; `origin` names it in errors, `base` resolves the model path.
    ///
    /// ```
    /// use trm_taskmap::TaskMapSpec;
    /// let text = "(object: [(name: \"stick\", shape: Capsule(radius: 0.02, length: 0.3))],\n explore: (step: -1.0))";
    /// let e = TaskMapSpec::from_ron(text, "stick.ron", ".".as_ref()).unwrap_err().to_string();
    /// assert!(e.starts_with("stick.ron:2:12: explore.step:"), "{e}");
    /// ```
    pub fn from_ron(
        text: &str,
        origin: &str,
        base: &Path,
    ) -> Result<LoadedTaskMapSpec, TaskMapError> {
        let spec: TaskMapSpec = ron::from_str(text)
            .map_err(|e| TaskMapError::Spec(Box::new(trm_io::SpecError::from_ron(&e, origin))))?;
        let loaded = LoadedTaskMapSpec {
            spec,
            origin: origin.to_string(),
            text: text.to_string(),
            base: base.to_path_buf(),
        };
        loaded.check()?;
        Ok(loaded)
    }
}

impl LoadedTaskMapSpec {
    fn err(&self, field: &str, problem: impl Into<String>, fix: impl Into<String>) -> TaskMapError {
        TaskMapError::Spec(Box::new(trm_io::SpecError::at(
            &self.text,
            &self.origin,
            field,
            problem,
            fix,
        )))
    }

    fn check(&self) -> Result<(), TaskMapError> {
        let s = &self.spec;
        if s.hand != "r" && s.hand != "l" {
            return Err(self.err(
                "hand",
                format!("{:?} is no iCub hand", s.hand),
                "write \"r\" or \"l\"",
            ));
        }
        if s.object.is_empty() {
            return Err(self.err("object", "the object has no parts", "add at least one part"));
        }
        let e = &s.explore;
        if !(e.step.is_finite() && e.step > 0.0) {
            return Err(self.err(
                "explore.step",
                format!("{} is not a positive step", e.step),
                "give a positive step",
            ));
        }
        if let Some(k) = e
            .half_widths
            .iter()
            .position(|w| !(w.is_finite() && *w > 0.0))
        {
            return Err(self.err(
                &format!("explore.half_widths[{k}]"),
                "must be positive",
                "give positive half widths",
            ));
        }
        for (field, n, lo) in [
            ("explore.iterations", e.iterations, 1),
            ("explore.restarts", e.restarts, 0),
            ("search.samples", s.search.samples, 1),
        ] {
            if !(lo..=100_000_000).contains(&n) {
                return Err(self.err(
                    field,
                    format!("{n} is not in {lo}..=100000000"),
                    "give a count in that range",
                ));
            }
        }
        let q = &s.search;
        if let Some(k) = (0..3).find(|&k| {
            !(q.lower[k].is_finite() && q.upper[k].is_finite() && q.lower[k] < q.upper[k])
        }) {
            return Err(self.err(
                &format!("search.lower[{k}]"),
                format!("lower {} is not below upper {}", q.lower[k], q.upper[k]),
                "give a box with lower < upper on every axis",
            ));
        }
        if let Some(g) = &s.start {
            if g.iter().any(|v| !v.is_finite()) {
                return Err(self.err("start", "holds a non-finite value", "write finite numbers"));
            }
        }
        if let Some(m) = &s.metric {
            for (field, w) in [("position", m.position), ("orientation", m.orientation)] {
                if !(w.is_finite() && w > 0.0) {
                    return Err(self.err(
                        &format!("metric.{field}"),
                        format!("{w} is not a positive weight (a degenerate metric)"),
                        "give a positive finite weight",
                    ));
                }
            }
        }
        self.object()?;
        Ok(())
    }

    /// The object as a world of its parts, checked like a world file.
    fn object(&self) -> Result<World, TaskMapError> {
        World::from_spec_in(
            &WorldSpec {
                objects: self.spec.object.clone(),
                ..WorldSpec::default()
            },
            &self.origin,
            &self.text,
            "object",
        )
        .map_err(|e| self.err("object", e.to_string(), "fix the object's parts"))
    }

    /// Loads the robot, finds the first grasp if the spec gives none, and explores the map.
    pub fn explore(&self) -> Result<Explored, TaskMapError> {
        let s = &self.spec;
        let model = match &s.model {
            None => trm_models::icub_upper_body(),
            Some(m) => trm_models::load(&m.to_string_lossy(), &self.base)?,
        };
        let collision = CollisionModel::new(&model)?;
        let hand = Hand::icub(&model, &collision, &s.hand)?;
        let object = self.object()?;
        let start = match s.start {
            Some(g) => g,
            None => {
                let q = &s.search;
                find_grasp(&hand, &object, q.lower, q.upper, q.samples, q.seed)
                    .map(|(g, _)| g)
                    .ok_or_else(|| {
                        self.err(
                            "search",
                            format!(
                                "no grasp found in {} random hand poses: the hand cannot grasp this object anywhere in the search box",
                                q.samples
                            ),
                            "widen the search box, raise samples, or give `start`",
                        )
                    })?
            }
        };
        let e = &s.explore;
        let settings = ExploreOptions {
            iterations: e.iterations,
            step: e.step,
            restarts: e.restarts,
            seed: e.seed,
            ..ExploreOptions::around(start, e.half_widths)
        };
        let started = std::time::Instant::now();
        let map = explore(&[start], &settings, &s.metric.unwrap_or_default(), |g| {
            hand.quality(&object, g)
        })?;
        Ok(Explored {
            seconds: started.elapsed().as_secs_f64(),
            model,
            collision,
            map,
            object,
            start,
        })
    }
}
