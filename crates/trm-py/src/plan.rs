//! `trm.Planner`: planning through maps in a world.

use crate::*;
use trm_moveit::RequestGoal;
use trm_plan::rrt::Budget;

/// A planner for one robot, compiled once (`trm_plan::Planner`): worlds and planning scenes
/// are set on it, maps and kept paths are optional, queries go without rebuilding anything.
/// A MoveIt motion plan request (`.yaml`: start state, joint goal, group, planning time), read
/// once: `Planner.plan_request` takes it as often as wanted without reading the file again.
#[pyclass(module = "trm", frozen)]
pub(crate) struct MotionPlanRequest {
    request: trm_moveit::MotionPlanRequest,
}

#[pymethods]
impl MotionPlanRequest {
    /// Reads a request file; an error names the file, the line and the fix.
    #[staticmethod]
    fn load(path: &str) -> PyResult<Self> {
        Ok(MotionPlanRequest {
            request: trm_moveit::MotionPlanRequest::load(path).map_err(err)?,
        })
    }

    /// The planning group it asks for.
    #[getter]
    fn group(&self) -> String {
        self.request.group.clone()
    }

    /// Its `allowed_planning_time`, s (None when it gives none).
    #[getter]
    fn allowed_planning_time(&self) -> Option<f64> {
        self.request.planning_time
    }

    /// The joints its goal constrains, in its order.
    #[getter]
    fn goal_joints(&self) -> Vec<String> {
        self.request.goal.names.clone()
    }

    /// The goal's joint values, in the order of `goal_joints`.
    #[getter]
    fn goal<'py>(&self, py: Python<'py>) -> PyResult<Array<'py>> {
        let goal = &self.request.goal.positions;
        shaped(py, None, &[goal.len()], goal.clone())
    }

    /// This request with its joint goal replaced by the task-space goal it implies for `link`
    /// of `robot` (its pose at the goal: a cube of side `position_tolerance` m around its
    /// origin, `orientation_tolerance` rad about each axis, in the robot's root frame), as
    /// `trm benchmark-mbm --task-space` poses its goals.
    #[pyo3(signature = (robot, link, position_tolerance = 0.01, orientation_tolerance = 0.05))]
    fn to_task_space(
        &self,
        robot: &Robot,
        link: &str,
        position_tolerance: f64,
        orientation_tolerance: f64,
    ) -> PyResult<Self> {
        let request = self
            .request
            .to_task_space(
                &robot.model,
                link,
                position_tolerance,
                orientation_tolerance,
            )
            .map_err(err)?;
        Ok(MotionPlanRequest { request })
    }

    /// Whether its goal is a task-space goal (position and orientation constraints).
    #[getter]
    fn is_task_space(&self) -> bool {
        self.request.goal.names.is_empty() && !self.request.pose_goal.is_empty()
    }

    fn __repr__(&self) -> String {
        format!(
            "MotionPlanRequest({}, group {}, {} goal joints)",
            self.request.origin.display(),
            self.request.group,
            self.request.goal.names.len()
        )
    }
}

#[pyclass(module = "trm")]
pub(crate) struct Planner {
    planner: trm_plan::Planner,
    /// The collision model the planner was made with (a scene's matrix applies over its own).
    own: CollisionModel,
    /// The maps' spec start (map planners), the default start.
    start: Option<Vec<f64>>,
    /// The maps' task space has this many dimensions (0: no maps).
    task_dim: usize,
    /// Keep every path RRT-Connect finds as experience.
    experience: bool,
    /// How paths are timed (`set_timing`).
    timing: trm_moveit::TimingSettings,
}

/// Runs a scenario (RON: objects that move, appear and vanish, goals that change; see
/// specs/scenarios/) on `roadmap`, as `trm scenario`: each step invalidates what the world
/// blocks, repairs within a budget (`repair_evaluations` cost evaluations, reproducible; else
/// `repair_ms` milliseconds) and replans. Returns a dict: `steps` (a dict per step: t,
/// blocked, restored, added, seconds, action, goal, goal_error, hit, nodes, edges, parked
/// nodes and edges), `times` `(T,)` and `positions` `(T, motors)`, the robot's motion.
#[pyfunction]
#[pyo3(signature = (scenario, roadmap, repair_evaluations = None, repair_ms = 40.0))]
pub(crate) fn run_scenario<'py>(
    py: Python<'py>,
    scenario: &str,
    roadmap: &Roadmap,
    repair_evaluations: Option<u64>,
    repair_ms: f64,
) -> PyResult<Bound<'py, PyDict>> {
    if !(repair_ms.is_finite() && repair_ms > 0.0) {
        return Err(err(format!(
            "repair_ms {repair_ms}: give a finite number of milliseconds above 0"
        )));
    }
    let spec = trm_plan::Scenario::load(scenario).map_err(err)?;
    let problem = roadmap
        .map
        .problem_with(&trm_taskmap::loaders())
        .map_err(err)?;
    let options = trm_plan::ScenarioOptions {
        repair_seconds: repair_evaluations.is_none().then_some(repair_ms / 1e3),
        repair_evaluations,
        ..Default::default()
    };
    let run = py
        .detach(|| trm_plan::run_scenario(&roadmap.map, &problem, &spec, &options))
        .map_err(err)?;
    let d = PyDict::new(py);
    d.set_item("steps", to_python(py, &run.steps)?)?;
    let times = run.motion.times.clone();
    let motors = run.motion.positions.first().map_or(0, Vec::len);
    let positions: Vec<f64> = run.motion.positions.concat();
    d.set_item("times", shaped(py, None, &[times.len()], times)?)?;
    d.set_item(
        "positions",
        shaped(py, None, &[run.motion.positions.len(), motors], positions)?,
    )?;
    Ok(d)
}

#[pymethods]
impl Planner {
    /// A planner for `source`: a `Robot` (no maps; RRT-Connect and kept paths answer), or a
    /// `Roadmap` or list of them (their spec's robot, motors, costs and task space), in `world`
    /// (none: empty, or the maps' own). For a robot, `joints` are the motors it moves (their
    /// names, or a group's name; all motors when absent), `posture` holds the others (every
    /// motor's value; the `home` posture, else 0 within the limits, when absent), `collision`
    /// its collision model (the robot's own when absent); or `request`, a MoveIt motion plan
    /// request (`.yaml`), says both: its goal's joints move, the other motors stay where its
    /// start state puts them. With `experience=True` every path RRT-Connect finds is kept and
    /// later queries plan through them.
    #[new]
    #[pyo3(signature = (source, world = None, *, joints = None, posture = None, request = None, collision = None, experience = false))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        source: &Bound<'_, PyAny>,
        world: Option<&PyWorld>,
        joints: Option<&Bound<'_, PyAny>>,
        posture: Option<&Bound<'_, PyAny>>,
        request: Option<&str>,
        collision: Option<PyRef<'_, Collision>>,
        experience: bool,
    ) -> PyResult<Self> {
        if let Ok(robot) = source.extract::<PyRef<'_, Robot>>() {
            let model = &robot.model;
            if request.is_some() && (joints.is_some() || posture.is_some()) {
                return Err(err(
                    "request: give it alone, or joints and posture (a request says both)",
                ));
            }
            // motor names or groups' names
            let names: Vec<String> = match joints {
                None => model.motor_names(),
                Some(j) => match j.extract::<String>() {
                    Ok(group) => vec![group],
                    Err(_) => j
                        .extract::<Vec<String>>()
                        .map_err(|_| err("joints: give a list of motor names or a group's name"))?,
                },
            };
            let fixed = match posture {
                Some(p) => configurations(p, model.motors().len(), "posture")?.0,
                None => model.home_motors(),
            };
            let active = match request {
                Some(path) => trm_moveit::MotionPlanRequest::load(path)
                    .and_then(|r| r.active_set(model, &fixed))
                    .map_err(err)?,
                None => model.active_set(&names, &fixed).map_err(err)?,
            };
            let collision = match collision {
                Some(c) => c.model.clone(),
                None => CollisionModel::new(model).map_err(err)?,
            };
            let world = world.map(|w| w.world.clone()).unwrap_or_default();
            let objective = trm_tasks::Objective::new(active, collision, world);
            return Ok(Planner {
                planner: trm_plan::Planner::new(&objective, &[]).map_err(err)?,
                own: objective.collision().clone(),
                start: None,
                task_dim: 0,
                experience,
                timing: Default::default(),
            });
        }
        if joints.is_some() || posture.is_some() || request.is_some() || collision.is_some() {
            return Err(err(
                "joints, posture, request and collision are a robot planner's: a map planner takes its maps' spec",
            ));
        }
        let maps: Vec<trm_roadmap::Roadmap> = match source.extract::<PyRef<'_, Roadmap>>() {
            Ok(m) => vec![m.map.clone()],
            Err(_) => source
                .extract::<Vec<PyRef<'_, Roadmap>>>()
                .map_err(|_| err("give a Robot, a Roadmap or a list of Roadmaps"))?
                .iter()
                .map(|m| m.map.clone())
                .collect(),
        };
        let first = maps.first().ok_or_else(|| err("give at least one map"))?;
        let problem = first.problem_with(&trm_taskmap::loaders()).map_err(err)?;
        let refs: Vec<&trm_roadmap::Roadmap> = maps.iter().collect();
        let mut planner = trm_plan::Planner::new(&problem.objective, &refs).map_err(err)?;
        if let Some(w) = world {
            planner.set_world(w.world.clone());
        }
        Ok(Planner {
            own: problem.objective.collision().clone(),
            planner,
            start: Some(problem.start.clone()),
            task_dim: problem.objective.task().map_or(0, |t| t.dim()),
            experience,
            timing: Default::default(),
        })
    }

    /// The current world (a copy: set it again after changing it).
    #[getter]
    fn get_world(&self) -> PyWorld {
        PyWorld {
            world: self.planner.world().clone(),
        }
    }

    /// Replaces the world; the robot is not compiled again, kept paths are checked again
    /// lazily.
    #[setter]
    fn set_world(&mut self, world: &PyWorld) {
        self.planner.set_world(world.world.clone());
    }

    /// Attaches a map built for the same moving motors, in any world: its nodes and edges are
    /// checked in the current world when a search first wants them. A query between two
    /// configurations is answered by RRT-Connect when it needs no more than its first samples
    /// (as without the map), else through the map when it joins them, else by RRT-Connect
    /// going on. Returns the number of nodes added.
    fn add_map(&mut self, map: &Roadmap) -> PyResult<usize> {
        self.planner.add_map(&map.map).map_err(err)
    }

    /// Sets a world file as the current world: RON, or a MoveIt planning scene (`.yaml`), whose
    /// allowed-collision matrix then applies over the planner's own and whose attached
    /// collision objects the robot then holds (the collision checks are made again only when
    /// the matrix or the held objects change). Returns notes on the matrix's entries that are
    /// not links of the robot.
    fn load_scene(&mut self, py: Python<'_>, path: &str) -> PyResult<Vec<String>> {
        let scene = trm_moveit::load_scene(path, &self.own).map_err(err)?;
        let planner = &mut self.planner;
        py.detach(|| scene.apply_to(planner)).map_err(err)
    }

    /// The names of the motors the planner moves (the order of its configurations' values).
    #[getter]
    fn joint_names(&self) -> Vec<String> {
        self.planner.active().names().map(str::to_string).collect()
    }

    /// Nodes of the planner's graph: map nodes and kept waypoints.
    #[getter]
    fn num_nodes(&self) -> usize {
        self.planner.num_nodes()
    }

    /// Whether the configuration `q` (the moved motors' values) is collision-free in the
    /// current world.
    fn is_free(&mut self, q: &Bound<'_, PyAny>) -> PyResult<bool> {
        let q = configurations(q, self.planner.active().len(), "q")?.0;
        Ok(self.planner.is_free(&q))
    }

    /// Keeps a path (an `(W, joints)` array, free in the current world) as experience: later
    /// queries plan through it. Returns the number of nodes added.
    fn add_path(&mut self, path: &Bound<'_, PyAny>) -> PyResult<usize> {
        let n = self.planner.active().len();
        let (values, _) = configurations(path, n, "path")?;
        let rows: Vec<Vec<f64>> = values.chunks(n.max(1)).map(<[f64]>::to_vec).collect();
        self.planner.add_path(&rows).map_err(err)
    }

    /// The kept paths, in the order they were kept: one `(W, joints)` array each.
    fn kept_paths<'py>(&self, py: Python<'py>) -> PyResult<Vec<Array<'py>>> {
        let n = self.planner.active().len();
        self.planner
            .kept_paths()
            .into_iter()
            .map(|path| shaped(py, Some(path.len()), &[n], path.concat()))
            .collect()
    }

    /// Forgets every kept path (the attached maps stay): later queries plan as a planner
    /// given no experience does, the robot and the world not compiled again.
    fn forget_paths(&mut self) {
        self.planner.forget_paths();
    }

    /// Writes the kept paths to `path` (a versioned JSON file: the moved motors' names and
    /// every path's waypoints), atomically.
    fn save_experience(&self, path: &str) -> PyResult<()> {
        self.planner.save_experience(path).map_err(err)
    }

    /// Keeps the paths of a file `save_experience` wrote (checked in the current world when a
    /// search wants them); a file of other motors is refused whole. Returns the number of
    /// paths kept.
    fn load_experience(&mut self, path: &str) -> PyResult<usize> {
        self.planner.load_experience(path).map_err(err)
    }

    /// How the next plans are timed: time-optimal within the joints' velocity and
    /// acceleration limits (the robot's; `joint_limits`, a MoveIt `joint_limits.yaml`, replaces
    /// them; `velocity` and `acceleration` where neither gives one), each scaled by its factor
    /// in (0, 1] (when absent: a request's `max_*_scaling_factor` in `plan_request`, else the
    /// `joint_limits` file's default, else 1 — as `trm plan` resolves them), corners cut by
    /// blends of at most `max_deviation` rad that are collision-checked (0: stop at every
    /// waypoint), sampled every `sample_period` s. With `jerk_limited=True` the jerk is limited
    /// too (`joint_limits`' `max_jerk`, the model's, else `jerk` rad/s³) and the motion stops
    /// at every waypoint (a double-S profile per segment, no blends).
    #[pyo3(signature = (*, velocity_scaling = None, acceleration_scaling = None, max_deviation = 0.2, sample_period = 0.01, velocity = 1.0, acceleration = 1.0, joint_limits = None, jerk_limited = false, jerk = 10.0))]
    #[allow(clippy::too_many_arguments)]
    fn set_timing(
        &mut self,
        velocity_scaling: Option<f64>,
        acceleration_scaling: Option<f64>,
        max_deviation: f64,
        sample_period: f64,
        velocity: f64,
        acceleration: f64,
        joint_limits: Option<&str>,
        jerk_limited: bool,
        jerk: f64,
    ) -> PyResult<()> {
        let joint_limits = match joint_limits {
            Some(path) => Some(trm_moveit::JointLimitsFile::load(path).map_err(err)?),
            None => None,
        };
        let settings = trm_moveit::TimingSettings {
            timing: trm_plan::Timing {
                default_velocity: velocity,
                default_acceleration: acceleration,
                default_jerk: jerk,
                jerk_limited,
                max_deviation,
                sample_period,
                ..Default::default()
            },
            joint_limits,
            velocity_scaling,
            acceleration_scaling,
        };
        let timing = settings.timing(None);
        timing.joint_limits(self.planner.active()).map_err(err)?;
        self.timing = settings;
        Ok(())
    }

    /// Plans from `start` (the moved motors' values; a map planner's spec start when absent)
    /// to `to`: a posture (the moved motors' values; RRT-Connect through the kept paths, within
    /// `max_seconds` and `max_samples`, steps of at most `range` rad, edges checked every
    /// `resolution` rad; both sized by the robot's lever arms unless given) or, for a map
    /// planner, a task point (a map node within `tolerance`, then with `exact` NGIK to the
    /// point itself). `posture` says which; by default a posture for a robot planner and a
    /// task point for a map planner. With `certified`, a posture goal's path is proved free in
    /// continuous motion (segments that cannot be proved planned again with proved edges).
    /// `smoothing` rounds of corner cutting follow the shortcut (VAMP's simplifier; 0: the
    /// greedy shortcut only). The GIL is released while planning.
    ///
    /// Returns a dict: `times (T,)`, `positions`, `velocities` and `accelerations` `(T, motors)`
    /// (every motor, sampled as `set_timing` says), `motor_names`, `waypoints (W, joints)` (the moved motors), `task_path` (map
    /// planners), `length` (rad), `seconds`, and for posture goals `source` (`straight`,
    /// `graph`, `retrieved` or `sampled`), `checks` and `samples`. With `out` (a `.csv` path)
    /// the trajectory is also written as `trm plan --out` writes it (CSV, JSON, a ROS 2
    /// JointTrajectory `.ros.yaml`, a MoveIt MotionPlanResponse `.response.yaml`), the
    /// files listed under `files`. With `timed=False` (posture goals) the path is not timed
    /// (no `times`, `positions`, `velocities`, `accelerations`, `motor_names`, `task_path`):
    /// planning alone, as MoveIt's planners and VAMP return paths (timing a MotionBenchMaker
    /// Panda path time-optimally costs about 1.5× its planning).
    #[pyo3(signature = (to, start = None, *, tolerance = 0.03, posture = None, exact = true, seed = 0, max_seconds = None, max_samples = 1_000_000, resolution = None, range = None, certified = false, smoothing = trm_plan::rrt::SMOOTHING_ROUNDS, timed = true, out = None))]
    #[allow(clippy::too_many_arguments)]
    fn plan<'py>(
        &mut self,
        py: Python<'py>,
        to: &Bound<'py, PyAny>,
        start: Option<&Bound<'py, PyAny>>,
        tolerance: f64,
        posture: Option<bool>,
        exact: bool,
        seed: u64,
        max_seconds: Option<f64>,
        max_samples: usize,
        resolution: Option<f64>,
        range: Option<f64>,
        certified: bool,
        smoothing: usize,
        timed: bool,
        out: Option<std::path::PathBuf>,
    ) -> PyResult<Bound<'py, PyDict>> {
        check_out(out.as_deref(), timed)?;
        let dim = self.planner.active().len();
        let from = match (start, &self.start) {
            (Some(s), _) => configurations(s, dim, "start")?.0,
            (None, Some(home)) => home.clone(),
            (None, None) => return Err(err("start: give the moved motors' values to start from")),
        };
        let target = float_array(to)?.as_slice().map_err(err)?.to_vec();
        let posture = posture.unwrap_or(self.task_dim == 0);
        if !posture && self.task_dim == 0 {
            return Err(err(
                "to: a task point needs a map planner (its task space); give a posture (posture=True)",
            ));
        }
        if !posture && !timed {
            return Err(err(
                "timed=False: a task point's motion is timed as it is planned; give timed=True",
            ));
        }
        let d = PyDict::new(py);
        let planned = if posture {
            if target.len() != dim {
                return Err(err(format!(
                    "to: the goal configuration has {} values; the planner moves {dim} motors ({})",
                    target.len(),
                    self.joint_names().join(", ")
                )));
            }
            let budget = Budget {
                seed,
                max_seconds,
                max_samples,
                resolution,
                range,
                certified,
                smoothing,
            };
            let timing = timed.then(|| self.timing.timing(None));
            self.connect(py, &d, from, RequestGoal::Joints(target), &budget, timing)?
        } else {
            let goal = trm_plan::Goal::TaskPoint {
                t: target,
                tolerance,
            };
            let options = trm_plan::PlanOptions {
                seed,
                exact_goal: exact,
                timing: self.timing.timing(None),
                ..Default::default()
            };
            let planner = &mut self.planner;
            let planned = py
                .detach(|| planner.plan(&from, &goal, &options))
                .map_err(err)?;
            (
                Some(planned.trajectory),
                planned.waypoints,
                planned.stats.length,
                planned.stats.seconds,
            )
        };
        let group = self.joint_names().join(",");
        self.write(&d, &planned, &group, out.as_deref())?;
        self.fill(py, d, planned)
    }

    /// Plans a MoveIt motion plan request (a `MotionPlanRequest`, or a `.yaml` file read on
    /// each call: its start state and its joint goal for the motors the planner moves, or its
    /// task-space goal, met by IK for a collision-free configuration first; its
    /// `allowed_planning_time` as the budget unless `max_seconds`), in the current world; load
    /// its scene first (`load_scene`). Objects its start state holds are held from then on
    /// (beside the scene's). Returns what `plan` returns; `timed` and `out` as for `plan` (the
    /// response names the request's group).
    #[pyo3(signature = (request, *, seed = 0, max_seconds = None, max_samples = 1_000_000, resolution = None, range = None, certified = false, smoothing = trm_plan::rrt::SMOOTHING_ROUNDS, timed = true, out = None))]
    #[allow(clippy::too_many_arguments)]
    fn plan_request<'py>(
        &mut self,
        py: Python<'py>,
        request: &Bound<'py, PyAny>,
        seed: u64,
        max_seconds: Option<f64>,
        max_samples: usize,
        resolution: Option<f64>,
        range: Option<f64>,
        certified: bool,
        smoothing: usize,
        timed: bool,
        out: Option<std::path::PathBuf>,
    ) -> PyResult<Bound<'py, PyDict>> {
        check_out(out.as_deref(), timed)?;
        let read;
        let request = match request.cast::<MotionPlanRequest>() {
            Ok(r) => &r.get().request,
            Err(_) => {
                let path: String = request
                    .extract()
                    .map_err(|_| err("request: give a MotionPlanRequest or a .yaml path"))?;
                read = trm_moveit::MotionPlanRequest::load(&path).map_err(err)?;
                &read
            }
        };
        request.hold_on(&mut self.planner).map_err(err)?;
        let (start, goal) = request.query(self.planner.active()).map_err(err)?;
        let budget = Budget {
            seed,
            max_seconds: max_seconds.or(request.planning_time),
            max_samples,
            resolution,
            range,
            certified,
            smoothing,
        };
        let d = PyDict::new(py);
        let timing = timed.then(|| self.timing.timing(Some(request)));
        let planned = self.connect(py, &d, start, goal, &budget, timing)?;
        self.write(&d, &planned, &request.group, out.as_deref())?;
        self.fill(py, d, planned)
    }

    /// Holds an object: the objects of `shapes` (a World, its poses read in `link`'s frame)
    /// move with `link` and are checked against the world and the robot's other links except
    /// `touch_links` (the fingers holding it). Maps and kept paths are checked again for the
    /// robot's new shape when a search wants them.
    #[pyo3(signature = (name, link, shapes, touch_links = Vec::new()))]
    fn attach(
        &mut self,
        name: &str,
        link: &str,
        shapes: &PyWorld,
        touch_links: Vec<String>,
    ) -> PyResult<()> {
        let object = trm_collision::AttachedObject {
            name: name.to_string(),
            link: link.to_string(),
            shapes: (shapes.world.objects().iter())
                .map(|o| (o.shape().clone(), *o.pose()))
                .collect(),
            touch_links,
        };
        self.planner.attach(object).map_err(err)
    }

    /// Puts down the held object `name`.
    fn detach(&mut self, name: &str) -> PyResult<()> {
        self.planner.detach(name).map_err(err)
    }

    /// The names of the objects the robot holds.
    #[getter]
    fn attached(&self) -> Vec<String> {
        self.planner
            .attached()
            .iter()
            .map(|o| o.name.clone())
            .collect()
    }

    fn __repr__(&self) -> String {
        format!(
            "Planner(moves {} motors, {} graph nodes, {} world objects)",
            self.planner.active().len(),
            self.planner.num_nodes(),
            self.planner.world().len()
        )
    }
}

/// Refuses an `out` the trajectory's JSON would overwrite, before planning.
fn check_out(out: Option<&std::path::Path>, timed: bool) -> PyResult<()> {
    if out.is_some() && !timed {
        return Err(err(
            "out: the files hold a timed trajectory; give timed=True (the default) to write them",
        ));
    }
    out.map_or(Ok(()), |o| {
        trm_moveit::check_trajectory_out("out", o).map_err(err)
    })
}

/// A path: its trajectory (unless asked for the waypoints alone), the waypoints (moved
/// motors), its length (rad) and the planning time (s).
type Timed = (Option<trm_plan::Trajectory>, Vec<Vec<f64>>, f64, f64);

impl Planner {
    /// `from` joined to `goal` (a configuration or a task-space goal) by
    /// `trm_plan::Planner::connect` / `connect_to_pose` within `budget`, the GIL released;
    /// the path kept when the planner keeps experience. Sets `source`, `checks` and `samples`
    /// in `d`.
    fn connect(
        &mut self,
        py: Python<'_>,
        d: &Bound<'_, PyDict>,
        from: Vec<f64>,
        goal: RequestGoal,
        budget: &Budget,
        timing: Option<trm_plan::Timing>,
    ) -> PyResult<Timed> {
        let rrt = self.planner.rrt_options_within(budget).map_err(err)?;
        let (experience, planner) = (self.experience, &mut self.planner);
        let (found, trajectory) = py
            .detach(|| -> Result<_, trm_plan::PlanError> {
                let found = goal.connect(planner, &from, &rrt)?;
                if experience && found.source == trm_plan::Source::Sampled {
                    planner.add_path(&found.path)?;
                }
                let trajectory = timing
                    .map(|timing| planner.trajectory(&found.path, &timing))
                    .transpose()?;
                Ok((found, trajectory))
            })
            .map_err(err)?;
        d.set_item("source", found.source.name())?;
        d.set_item("checks", found.checks)?;
        d.set_item("samples", found.iterations)?;
        let length = trm_plan::rrt::path_length(&found.path);
        Ok((trajectory, found.path, length, found.seconds))
    }

    /// With `out`, the timed path written as `trm plan --out` writes it (for `group`), each
    /// file whole or not at all, their paths under `files` in `d`.
    fn write(
        &self,
        d: &Bound<'_, PyDict>,
        planned: &Timed,
        group: &str,
        out: Option<&std::path::Path>,
    ) -> PyResult<()> {
        let (Some(out), (Some(trajectory), _, _, seconds)) = (out, planned) else {
            return Ok(());
        };
        let robot = self.planner.active().model();
        let files = trm_moveit::trajectory_files(trajectory, robot, Some((group, *seconds)), out)
            .map_err(err)?;
        trm_io::write_files(&files).map_err(err)?;
        let paths: Vec<&std::path::Path> = files.iter().map(|(p, _)| p.as_path()).collect();
        d.set_item("files", paths)?;
        Ok(())
    }

    /// `d` filled with a timed path: `times`, `positions`, `motor_names`, `waypoints`,
    /// `task_path` (map planners), `length`, `seconds`.
    fn fill<'py>(
        &self,
        py: Python<'py>,
        d: Bound<'py, PyDict>,
        planned: Timed,
    ) -> PyResult<Bound<'py, PyDict>> {
        let dim = self.planner.active().len();
        let (trajectory, waypoints, length, seconds) = planned;
        let rows = waypoints.len();
        d.set_item(
            "waypoints",
            shaped(py, None, &[rows, dim], waypoints.concat())?,
        )?;
        if let Some(t) = trajectory {
            d.set_item("times", shaped(py, None, &[t.times.len()], t.times)?)?;
            let motors = t.names.len();
            for (key, rows) in [
                ("positions", &t.positions),
                ("velocities", &t.velocities),
                ("accelerations", &t.accelerations),
            ] {
                if key == "positions" || rows.len() == t.positions.len() {
                    let flat: Vec<f64> = rows.iter().flatten().copied().collect();
                    d.set_item(key, shaped(py, None, &[rows.len(), motors], flat)?)?;
                }
            }
            d.set_item("motor_names", t.names)?;
            if self.task_dim > 0 {
                let tasks: Vec<f64> = t.task_path.iter().flatten().copied().collect();
                d.set_item(
                    "task_path",
                    shaped(py, None, &[t.task_path.len(), self.task_dim], tasks)?,
                )?;
            }
        }
        d.set_item("length", length)?;
        d.set_item("seconds", seconds)?;
        Ok(d)
    }
}
