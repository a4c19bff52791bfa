//! Python bindings of trm (the `trm` package; this is its extension module `trm._trm`).
//!
//! NumPy arrays in and out, batch-first: a configuration is an `(n,)` array, a batch an
//! `(N, n)` one, and results gain the leading `N` axis. Long calls release the GIL; errors
//! become `trm.TrmError` (a `ValueError`) carrying trm's located messages.

mod cost;

use numpy::ndarray::{ArrayD, IxDyn};
use numpy::{IntoPyArray, PyArrayDyn, PyArrayMethods, PyReadonlyArrayDyn, PyUntypedArrayMethods};
use pyo3::create_exception;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use trm_collision::{CollisionModel, Shape, World};
use trm_kinematics::nalgebra::{Isometry3, Matrix3xX, Matrix6xX, Translation3, UnitQuaternion};
use trm_kinematics::{ActiveSet, RobotModel};

create_exception!(
    _trm,
    TrmError,
    PyValueError,
    "An error from trm: the message names the file, the place and the fix."
);

/// Any trm error as a `TrmError` with its full message.
fn err(e: impl std::fmt::Display) -> PyErr {
    TrmError::new_err(e.to_string())
}

/// `obj` as a C-contiguous float64 array (lists and other sequences are converted).
fn float_array<'py>(obj: &Bound<'py, PyAny>) -> PyResult<PyReadonlyArrayDyn<'py, f64>> {
    // the common case without a call into Python: already a contiguous float64 array
    if let Ok(a) = obj.extract::<PyReadonlyArrayDyn<'py, f64>>()
        && a.is_c_contiguous()
    {
        return Ok(a);
    }
    let np = obj.py().import("numpy")?;
    let a = np
        .call_method1("ascontiguousarray", (obj, "float64"))
        .map_err(|e| err(format!("expected numbers: {e}")))?;
    a.extract::<PyReadonlyArrayDyn<'py, f64>>()
        .map_err(|e| err(format!("expected a float array: {e}")))
}

/// A configuration `(n,)` or a batch `(N, n)`: the values, row by row, and `Some(N)` for a batch.
fn configurations(
    obj: &Bound<'_, PyAny>,
    n: usize,
    what: &str,
) -> PyResult<(Vec<f64>, Option<usize>)> {
    let a = float_array(obj)?;
    let shape = a.shape().to_vec();
    let batch = match shape.as_slice() {
        [m] if *m == n => None,
        [rows, m] if *m == n => Some(*rows),
        _ => {
            return Err(err(format!(
                "{what}: shape {shape:?}; expected ({n},) or (N, {n}) ({n} values per configuration)"
            )));
        }
    };
    let values = a.as_slice().map_err(err)?.to_vec();
    if let Some(i) = values.iter().position(|v| !v.is_finite()) {
        return Err(err(format!(
            "{what}: value #{i} is {}; give finite numbers",
            values[i]
        )));
    }
    Ok((values, batch))
}

/// A float64 NumPy array of any shape.
type Array<'py> = Bound<'py, PyArrayDyn<f64>>;

/// A flat array shaped `shape`, with the batch axis in front when there is one.
fn shaped<'py>(
    py: Python<'py>,
    batch: Option<usize>,
    shape: &[usize],
    data: Vec<f64>,
) -> PyResult<Array<'py>> {
    let full: Vec<usize> = batch.into_iter().chain(shape.iter().copied()).collect();
    Ok(ArrayD::from_shape_vec(IxDyn(&full), data)
        .map_err(err)?
        .into_pyarray(py))
}

/// The result of the one configuration (a model without motors has none).
fn first<T: Copy>(values: &[T]) -> PyResult<T> {
    values
        .first()
        .copied()
        .ok_or_else(|| err("no configuration: the model has no motors"))
}

/// One number per configuration: the number itself for one configuration, an `(N,)` array for
/// a batch.
fn numbers(py: Python<'_>, batch: Option<usize>, values: Vec<f64>) -> PyResult<Py<PyAny>> {
    Ok(match batch {
        None => first(&values)?.into_pyobject(py)?.into_any().unbind(),
        Some(_) => shaped(py, batch, &[], values)?.into_any().unbind(),
    })
}

/// One flag per configuration: a bool for one configuration, a list of bools for a batch.
fn flags(py: Python<'_>, batch: Option<usize>, values: Vec<bool>) -> PyResult<Py<PyAny>> {
    Ok(match batch {
        None => first(&values)?
            .into_pyobject(py)?
            .to_owned()
            .into_any()
            .unbind(),
        Some(_) => PyList::new(py, values)?.into_any().unbind(),
    })
}

/// 4 × 4 homogeneous matrix, row-major, into `out` (16 values).
fn write_matrix(pose: &Isometry3<f64>, out: &mut [f64]) {
    let r = pose.rotation.to_rotation_matrix();
    let t = &pose.translation.vector;
    for i in 0..3 {
        out[4 * i..4 * i + 3].copy_from_slice(&[r[(i, 0)], r[(i, 1)], r[(i, 2)]]);
        out[4 * i + 3] = t[i];
    }
    out[12..].copy_from_slice(&[0.0, 0.0, 0.0, 1.0]);
}

/// 4 × 4 homogeneous matrix, row-major, appended to `out`.
fn matrix(pose: &Isometry3<f64>, out: &mut Vec<f64>) {
    let start = out.len();
    out.resize(start + 16, 0.0);
    write_matrix(pose, &mut out[start..]);
}

/// A pose from a position and URDF roll-pitch-yaw.
fn pose(xyz: [f64; 3], rpy: [f64; 3]) -> Isometry3<f64> {
    Isometry3::from_parts(
        Translation3::new(xyz[0], xyz[1], xyz[2]),
        UnitQuaternion::from_euler_angles(rpy[0], rpy[1], rpy[2]),
    )
}

/// A robot model: links, motors (with couplings and limits), named frames, groups and postures.
#[pyclass(module = "trm")]
#[derive(Clone)]
struct Robot {
    model: RobotModel,
}

impl Robot {
    fn all(&self) -> ActiveSet {
        self.model.all_active()
    }

    /// Forward kinematics of each configuration in `q` (all motors), then `f` appends its
    /// values (`shape` of them, row-major); the array gains the batch axis for a batch.
    fn per_configuration<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        shape: &[usize],
        mut f: impl FnMut(&ActiveSet, &trm_kinematics::PoseBuffer, &mut Vec<f64>),
    ) -> PyResult<Array<'py>> {
        let n = self.dof();
        let (values, batch) = configurations(q, n, "q")?;
        let active = self.all();
        let mut poses = self.model.pose_buffer();
        let mut out = Vec::new();
        for row in values.chunks(n.max(1)) {
            active.forward(row, &mut poses).map_err(err)?;
            f(&active, &poses, &mut out);
        }
        shaped(py, batch, shape, out)
    }
}

#[pymethods]
impl Robot {
    /// The embedded 41-motor iCub upper body (official URDF, CC-BY-SA-4.0, with collision
    /// capsules and motor couplings).
    #[staticmethod]
    fn icub() -> Self {
        Robot {
            model: trm_models::icub_upper_body(),
        }
    }

    /// A robot from a `.urdf` file or a `.ron` model description.
    #[staticmethod]
    fn load(path: &str) -> PyResult<Self> {
        Ok(Robot {
            model: RobotModel::load(path).map_err(err)?,
        })
    }

    /// The model's name.
    #[getter]
    fn name(&self) -> String {
        self.model.name().to_string()
    }

    /// Motor names (the columns of every configuration).
    #[getter]
    fn motor_names(&self) -> Vec<String> {
        self.model.motors().iter().map(|m| m.name.clone()).collect()
    }

    /// Number of motors.
    #[getter]
    fn dof(&self) -> usize {
        self.model.motors().len()
    }

    /// Lower motor limits, `(n,)`.
    #[getter]
    fn lower<'py>(&self, py: Python<'py>) -> PyResult<Array<'py>> {
        let (l, _) = self.all().bounds();
        shaped(py, None, &[l.len()], l)
    }

    /// Upper motor limits, `(n,)`.
    #[getter]
    fn upper<'py>(&self, py: Python<'py>) -> PyResult<Array<'py>> {
        let (_, u) = self.all().bounds();
        shaped(py, None, &[u.len()], u)
    }

    /// Link names (the link axis of `fk`).
    #[getter]
    fn link_names(&self) -> Vec<String> {
        self.model
            .tree()
            .links
            .iter()
            .map(|l| l.name.clone())
            .collect()
    }

    /// Names of every frame (links and named frames).
    #[getter]
    fn frame_names(&self) -> Vec<String> {
        self.model.frame_names().map(str::to_string).collect()
    }

    /// Motor groups: name → motor indices.
    #[getter]
    fn groups(&self) -> Vec<(String, Vec<usize>)> {
        self.model
            .groups()
            .map(|(n, m)| (n.to_string(), m.to_vec()))
            .collect()
    }

    /// Names of the named postures.
    #[getter]
    fn posture_names(&self) -> Vec<String> {
        self.model.posture_names().map(str::to_string).collect()
    }

    /// A named posture (all motors), `(n,)`.
    fn posture<'py>(&self, py: Python<'py>, name: &str) -> PyResult<Array<'py>> {
        let p = self.model.posture(name).map_err(err)?.to_vec();
        shaped(py, None, &[p.len()], p)
    }

    /// World poses of every link as 4 × 4 matrices: `(links, 4, 4)`, or `(N, links, 4, 4)` for
    /// a batch of configurations `(N, n)`.
    fn fk<'py>(&self, py: Python<'py>, q: &Bound<'py, PyAny>) -> PyResult<Array<'py>> {
        use rayon::prelude::*;
        let n = self.dof().max(1);
        let (values, batch) = configurations(q, n, "q")?;
        let links = self.model.num_links();
        let full: Vec<usize> = batch.into_iter().chain([links, 4, 4]).collect();
        let out = PyArrayDyn::<f64>::zeros(py, IxDyn(&full), false);
        {
            let mut rw = out.readwrite();
            let slice = rw.as_slice_mut().map_err(err)?;
            let per = links * 16;
            let fill = |poses: &mut trm_kinematics::PoseBuffer, (o, row): (&mut [f64], &[f64])| {
                self.model
                    .forward_motors(row, poses)
                    .map_err(|e| e.to_string())?;
                for (m, p) in o.chunks_mut(16).zip(poses.poses()) {
                    write_matrix(p, m);
                }
                Ok::<(), String>(())
            };
            // large batches over trm's threads without the GIL; a few configurations on the
            // calling thread (releasing the GIL costs more than they take)
            if values.len() / n >= 64 {
                py.detach(|| {
                    slice
                        .par_chunks_mut(per)
                        .zip(values.par_chunks(n))
                        .try_for_each_init(|| self.model.pose_buffer(), fill)
                })
            } else {
                let mut poses = self.model.pose_buffer();
                slice
                    .chunks_mut(per)
                    .zip(values.chunks(n))
                    .try_for_each(|c| fill(&mut poses, c))
            }
            .map_err(err)?;
        }
        Ok(out)
    }

    /// The world pose of one frame (link or named frame): `(4, 4)` or `(N, 4, 4)`.
    fn frame_pose<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        frame: &str,
    ) -> PyResult<Array<'py>> {
        let id = self.model.frame_id(frame).map_err(err)?;
        self.per_configuration(py, q, &[4, 4], |_, poses, out| matrix(poses.pose(id), out))
    }

    /// The 6 × n geometric Jacobian of a frame with respect to all motors (rows: linear then
    /// angular velocity, world axes; Pinocchio's LOCAL_WORLD_ALIGNED): `(6, n)` or `(N, 6, n)`.
    fn jacobian<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        frame: &str,
    ) -> PyResult<Array<'py>> {
        let id = self.model.frame_id(frame).map_err(err)?;
        let n = self.dof();
        let mut jac = Matrix6xX::zeros(n);
        self.per_configuration(py, q, &[6, n], |active, poses, out| {
            active.jacobian(poses, id, &mut jac);
            out.extend(jac.transpose().iter());
        })
    }

    /// Total mass and centre of mass: `(mass, (3,))`, or `(mass, (N, 3))` for a batch.
    fn center_of_mass<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
    ) -> PyResult<(f64, Array<'py>)> {
        let mut mass = 0.0;
        let centres = self.per_configuration(py, q, &[3], |active, poses, out| {
            let (m, c) = active.center_of_mass(poses);
            mass = m;
            out.extend_from_slice(c.coords.as_slice());
        })?;
        Ok((mass, centres))
    }

    /// The 3 × n Jacobian of the centre of mass: `(3, n)` or `(N, 3, n)`.
    fn com_jacobian<'py>(&self, py: Python<'py>, q: &Bound<'py, PyAny>) -> PyResult<Array<'py>> {
        let n = self.dof();
        let mut jac = Matrix3xX::zeros(n);
        self.per_configuration(py, q, &[3, n], |active, poses, out| {
            active.com_jacobian(poses, &mut jac);
            out.extend(jac.transpose().iter());
        })
    }

    fn __repr__(&self) -> String {
        format!(
            "Robot({:?}: {} motors, {} links, {} frames)",
            self.model.name(),
            self.model.motors().len(),
            self.model.num_links(),
            self.model.num_frames()
        )
    }
}

/// Obstacles: boxes, spheres, capsules, cylinders at poses (root frame).
#[pyclass(name = "World", module = "trm")]
#[derive(Clone, Default)]
struct PyWorld {
    world: World,
}

#[pymethods]
impl PyWorld {
    /// An empty world.
    #[new]
    fn new() -> Self {
        Self::default()
    }

    /// A world from a RON file (`(objects: [(name: "table", shape: Box(size: (…)), xyz: (…))])`) or a MoveIt planning scene (`.yaml`).
    #[staticmethod]
    fn load(path: &str) -> PyResult<Self> {
        Ok(PyWorld {
            world: trm_plan::moveit::load_world(path).map_err(err)?,
        })
    }

    /// Adds a box of full side lengths `size` at `xyz`, turned by URDF `rpy`.
    #[pyo3(signature = (name, size, xyz, rpy = [0.0; 3]))]
    fn add_box(
        &mut self,
        name: &str,
        size: [f64; 3],
        xyz: [f64; 3],
        rpy: [f64; 3],
    ) -> PyResult<()> {
        self.add(name, Shape::Box { size }, xyz, rpy)
    }

    /// Adds a sphere.
    fn add_sphere(&mut self, name: &str, radius: f64, xyz: [f64; 3]) -> PyResult<()> {
        self.add(name, Shape::Sphere { radius }, xyz, [0.0; 3])
    }

    /// Adds a capsule along its z axis (`length` between the cap centres).
    #[pyo3(signature = (name, radius, length, xyz, rpy = [0.0; 3]))]
    fn add_capsule(
        &mut self,
        name: &str,
        radius: f64,
        length: f64,
        xyz: [f64; 3],
        rpy: [f64; 3],
    ) -> PyResult<()> {
        self.add(name, Shape::Capsule { radius, length }, xyz, rpy)
    }

    /// Adds a cylinder along its z axis.
    #[pyo3(signature = (name, radius, length, xyz, rpy = [0.0; 3]))]
    fn add_cylinder(
        &mut self,
        name: &str,
        radius: f64,
        length: f64,
        xyz: [f64; 3],
        rpy: [f64; 3],
    ) -> PyResult<()> {
        self.add(name, Shape::Cylinder { radius, length }, xyz, rpy)
    }

    /// Moves an object.
    #[pyo3(signature = (name, xyz, rpy = [0.0; 3]))]
    fn set_pose(&mut self, name: &str, xyz: [f64; 3], rpy: [f64; 3]) -> PyResult<()> {
        self.world.set_pose(name, pose(xyz, rpy)).map_err(err)
    }

    /// Removes an object.
    fn remove(&mut self, name: &str) -> PyResult<()> {
        self.world.remove(name).map(drop).map_err(err)
    }

    /// Object names.
    #[getter]
    fn names(&self) -> Vec<String> {
        self.world
            .objects()
            .iter()
            .map(|o| o.name().to_string())
            .collect()
    }

    fn __len__(&self) -> usize {
        self.world.len()
    }
}

impl PyWorld {
    fn add(&mut self, name: &str, shape: Shape, xyz: [f64; 3], rpy: [f64; 3]) -> PyResult<()> {
        self.world
            .add(name, shape, pose(xyz, rpy))
            .map(drop)
            .map_err(err)
    }
}

/// A robot's collision model (its bodies and allowed-collision matrix): counts, checks, pairs
/// and distances, against itself and a world.
#[pyclass(name = "CollisionModel", module = "trm")]
struct Collision {
    robot: RobotModel,
    model: CollisionModel,
}

impl Collision {
    /// The configurations in `q` placed one by one (without the GIL), `f` on each against
    /// `world` (none: empty); the results and `Some(N)` for a batch.
    fn map<T: Send>(
        &self,
        py: Python<'_>,
        q: &Bound<'_, PyAny>,
        world: Option<&PyWorld>,
        f: impl Fn(&trm_collision::PlacedBodies, &World) -> T + Sync,
    ) -> PyResult<(Vec<T>, Option<usize>)> {
        let empty = World::new();
        let w = world.map_or(&empty, |w| &w.world);
        let (values, batch) = configurations(q, self.robot.motors().len(), "q")?;
        let out = py.detach(|| self.each(&values, |p| f(p, w))).map_err(err)?;
        Ok((out, batch))
    }

    /// Runs `f` on every configuration placed.
    fn each<T>(
        &self,
        values: &[f64],
        mut f: impl FnMut(&trm_collision::PlacedBodies) -> T,
    ) -> Result<Vec<T>, String> {
        let n = self.robot.motors().len().max(1);
        let mut poses = self.robot.pose_buffer();
        let mut placed = self.model.placed_bodies();
        values
            .chunks(n)
            .map(|row| {
                self.robot
                    .forward_motors(row, &mut poses)
                    .map_err(|e| e.to_string())?;
                self.model.place(&poses, &mut placed);
                Ok(f(&placed))
            })
            .collect()
    }
}

#[pymethods]
impl Collision {
    /// The collision model of `robot` (its capsules and boxes, or meshes as convex hulls).
    #[new]
    fn new(robot: &Robot) -> PyResult<Self> {
        Ok(Collision {
            model: CollisionModel::new(&robot.model).map_err(err)?,
            robot: robot.model.clone(),
        })
    }

    /// Body names.
    #[getter]
    fn body_names(&self) -> Vec<String> {
        self.model.bodies().iter().map(|b| b.name.clone()).collect()
    }

    /// Colliding link pairs (self plus world): an int, or `(N,)` for a batch.
    #[pyo3(signature = (q, world = None))]
    fn count<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        world: Option<&PyWorld>,
    ) -> PyResult<Py<PyAny>> {
        let (counts, batch) =
            self.map(py, q, world, |p, w| self.model.count(p, w).total() as f64)?;
        match batch {
            None => Ok((first(&counts)? as usize)
                .into_pyobject(py)?
                .into_any()
                .unbind()),
            Some(_) => numbers(py, batch, counts),
        }
    }

    /// Whether anything collides (early exit): a bool, or a bool list for a batch.
    #[pyo3(signature = (q, world = None))]
    fn is_colliding<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        world: Option<&PyWorld>,
    ) -> PyResult<Py<PyAny>> {
        let (hits, batch) = self.map(py, q, world, |p, w| self.model.is_colliding(p, w))?;
        flags(py, batch, hits)
    }

    /// The colliding pairs of one configuration: `[(body, other, signed distance)]`.
    #[pyo3(signature = (q, world = None))]
    fn colliding_pairs(
        &self,
        q: &Bound<'_, PyAny>,
        world: Option<&PyWorld>,
    ) -> PyResult<Vec<(String, String, f64)>> {
        let empty = World::new();
        let w = world.map_or(&empty, |w| &w.world);
        let (values, batch) = configurations(q, self.robot.motors().len(), "q")?;
        if batch.is_some() {
            return Err(err("colliding_pairs takes one configuration (n,)"));
        }
        let pairs = self
            .each(&values, |p| self.model.colliding_pairs(p, w))
            .map_err(err)?;
        Ok(pairs
            .into_iter()
            .flatten()
            .map(|p| {
                let other = match p.other {
                    trm_collision::Other::Body(b) | trm_collision::Other::Object(b) => b,
                };
                (p.body, other, p.distance)
            })
            .collect())
    }

    /// The smallest signed distance between checked body pairs (negative when penetrating): a
    /// float, or `(N,)` for a batch.
    fn min_distance<'py>(&self, py: Python<'py>, q: &Bound<'py, PyAny>) -> PyResult<Py<PyAny>> {
        let (d, batch) = self.map(py, q, None, |p, _| {
            self.model
                .min_self_distance(p)
                .map_or(f64::INFINITY, |d| d.distance)
        })?;
        numbers(py, batch, d)
    }
}

/// A task spec loaded with its robot: the objective (costs, task function, collision), the
/// active motors and the start.
#[pyclass(module = "trm")]
struct Problem {
    problem: trm_tasks::Problem,
    /// The error slots of the costs added from Python.
    python_costs: Vec<std::sync::Arc<std::sync::Mutex<Option<String>>>>,
}

impl Problem {
    /// The first error a Python cost raised since the last call, as a `TrmError` (the slots
    /// are cleared for the next call).
    fn python_cost_error(&self) -> PyResult<()> {
        for slot in &self.python_costs {
            if let Some(e) = slot.lock().ok().and_then(|mut s| s.take()) {
                return Err(err(e));
            }
        }
        Ok(())
    }
}

#[pymethods]
impl Problem {
    /// Loads a RON spec (e.g. `specs/reach.ron`).
    #[staticmethod]
    fn load(path: &str) -> PyResult<Self> {
        Ok(Problem {
            problem: trm_tasks::Problem::load(path).map_err(err)?,
            python_costs: Vec::new(),
        })
    }

    /// Adds a cost written in Python: `weight · function(q, frames)`, where `q` is a batch of
    /// candidates' active values `(N, d)` and `frames` a dict of the named frames' world poses
    /// `(N, 4, 4)`; it returns `(N,)` finite costs ≥ 0. NGIK calls it once per batch of
    /// candidates, taking the GIL for that call only. An exception, a wrong shape or a bad value
    /// is raised as a `TrmError` naming the cost when `solve` or `cost` returns.
    #[pyo3(signature = (function, weight = 1.0, label = None, frames = Vec::new()))]
    fn add_cost(
        &mut self,
        function: Py<PyAny>,
        weight: f64,
        label: Option<String>,
        frames: Vec<String>,
    ) -> PyResult<()> {
        let label = label.unwrap_or_else(|| format!("python cost {}", self.python_costs.len()));
        let frames = frames
            .into_iter()
            .map(|name| {
                let id = self
                    .problem
                    .robot
                    .frame_id(&name)
                    .map_err(|e| err(format!("add_cost `{label}`: frames: {e}")))?;
                Ok((name, id))
            })
            .collect::<PyResult<Vec<_>>>()?;
        let error = std::sync::Arc::new(std::sync::Mutex::new(None));
        let term = cost::PythonCost {
            function,
            label,
            frames,
            error: error.clone(),
        };
        self.problem
            .objective
            .add(weight, Box::new(term))
            .map_err(err)?;
        self.python_costs.push(error);
        Ok(())
    }

    /// Names of the active motors (the columns of `q`).
    #[getter]
    fn active_names(&self) -> Vec<String> {
        self.problem
            .objective
            .active()
            .names()
            .map(str::to_string)
            .collect()
    }

    /// The start (active values), `(d,)`.
    #[getter]
    fn start<'py>(&self, py: Python<'py>) -> PyResult<Array<'py>> {
        let s = self.problem.start.clone();
        shaped(py, None, &[s.len()], s)
    }

    /// The robot.
    #[getter]
    fn robot(&self) -> Robot {
        Robot {
            model: self.problem.robot.clone(),
        }
    }

    /// The cost of active values: a float, or `(N,)` for a batch.
    fn cost<'py>(&self, py: Python<'py>, q: &Bound<'py, PyAny>) -> PyResult<Py<PyAny>> {
        let o = &self.problem.objective;
        let (values, batch) = configurations(q, o.dim(), "q")?;
        let mut scratch = o.scratch();
        let costs: Vec<f64> = values
            .chunks(o.dim().max(1))
            .map(|row| o.eval(row, &mut scratch))
            .collect();
        self.python_cost_error()?;
        numbers(py, batch, costs)
    }

    /// Active motor limits `(lower (d,), upper (d,))`.
    #[getter]
    fn bounds<'py>(&self, py: Python<'py>) -> PyResult<(Array<'py>, Array<'py>)> {
        let (l, u) = self.problem.objective.active().bounds();
        Ok((
            shaped(py, None, &[l.len()], l)?,
            shaped(py, None, &[u.len()], u)?,
        ))
    }

    /// Free of self-collisions and of collisions with `world` (the spec's when absent): a
    /// bool, or a bool list for a batch. This is the state-validity check of planners.
    #[pyo3(signature = (q, world = None))]
    fn is_collision_free<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        world: Option<&PyWorld>,
    ) -> PyResult<Py<PyAny>> {
        let o = &self.problem.objective;
        let w = world.map_or(o.world(), |w| &w.world);
        let (values, batch) = configurations(q, o.dim(), "q")?;
        let mut scratch = o.scratch();
        let free: Vec<bool> = values
            .chunks(o.dim().max(1))
            .map(|row| o.is_collision_free_in(row, w, &mut scratch))
            .collect();
        flags(py, batch, free)
    }

    /// Clearance of active values: the smallest signed distance between checked body pairs and
    /// between bodies and `world`'s objects (the spec's world when absent), capped at `cap`
    /// metres (pairs farther apart are not measured).
    #[pyo3(signature = (q, world = None, cap = 0.5))]
    fn clearance(&self, q: &Bound<'_, PyAny>, world: Option<&PyWorld>, cap: f64) -> PyResult<f64> {
        let o = &self.problem.objective;
        let w = world.map_or(o.world(), |w| &w.world);
        let (values, batch) = configurations(q, o.dim(), "q")?;
        if batch.is_some() {
            return Err(err("clearance takes one configuration (d,)"));
        }
        let mut scratch = o.scratch();
        let poses = o.poses(&values, &mut scratch);
        let collision = o.collision();
        let mut placed = collision.placed_bodies();
        collision.place(&poses, &mut placed);
        let mut near = Vec::new();
        collision.near_pairs(&placed, w, cap, &mut near);
        Ok(near.iter().map(|p| p.distance).fold(cap, f64::min))
    }

    /// The task vector g(q) of active values (empty without a task function).
    fn task<'py>(&self, py: Python<'py>, q: &Bound<'py, PyAny>) -> PyResult<Array<'py>> {
        let o = &self.problem.objective;
        let (values, batch) = configurations(q, o.dim(), "q")?;
        if batch.is_some() {
            return Err(err("task takes one configuration (d,)"));
        }
        let t = o.task_value(&values, &mut o.scratch());
        shaped(py, None, &[t.len()], t)
    }

    /// NGIK from the start (or `start`): a dict with `q` (active), `motors` (all), `cost`,
    /// `breakdown` [(label, weight, value)], `task`, `collision_free`, `evaluations`,
    /// `seconds`. `algo`, `seed` and `max_evals` override the spec's solver.
    #[pyo3(signature = (start = None, algo = None, seed = None, max_evals = None))]
    fn solve<'py>(
        &self,
        py: Python<'py>,
        start: Option<&Bound<'py, PyAny>>,
        algo: Option<String>,
        seed: Option<u64>,
        max_evals: Option<u64>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let o = &self.problem.objective;
        let from = match start {
            Some(s) => configurations(s, o.dim(), "start")?.0,
            None => self.problem.start.clone(),
        };
        let mut solver = self.problem.spec.solver.clone();
        if let Some(a) = algo {
            solver.algo = a;
        }
        if let Some(s) = seed {
            solver.seed = s;
        }
        if let Some(m) = max_evals {
            solver.max_evaluations = m;
        }
        let s = py.detach(|| trm_tasks::solve(o, &from, &solver));
        self.python_cost_error()?;
        let s = s.map_err(err)?;
        let d = PyDict::new(py);
        d.set_item("q", shaped(py, None, &[s.q.len()], s.q.clone())?)?;
        d.set_item(
            "motors",
            shaped(py, None, &[s.motors.len()], s.motors.clone())?,
        )?;
        d.set_item("cost", s.cost)?;
        let breakdown: Vec<(String, f64, f64)> = s
            .breakdown
            .iter()
            .map(|t| (t.label.clone(), t.weight, t.value))
            .collect();
        d.set_item("breakdown", breakdown)?;
        d.set_item("task", shaped(py, None, &[s.task.len()], s.task.clone())?)?;
        d.set_item("collision_free", s.collision_free)?;
        d.set_item("evaluations", s.evaluations)?;
        d.set_item("seconds", s.wall_time.as_secs_f64())?;
        Ok(d)
    }
}

/// An ask/tell optimiser of trm-optim (xnes, cmaes, one-plus-one-cmaes, sir, sird, mh,
/// nelder-mead, …), seeded: `X = opt.ask()` gives `(λ, d)` candidates, `opt.tell(f)` their
/// values in order.
#[pyclass(module = "trm")]
struct Optimizer {
    /// The optimiser and its random stream (a mutex: Python objects may move between threads).
    inner: std::sync::Mutex<(Box<dyn trm_optim::Optimizer + Send>, ChaCha8Rng)>,
}

impl Optimizer {
    fn with<T>(&self, f: impl FnOnce(&mut dyn trm_optim::Optimizer, &mut ChaCha8Rng) -> T) -> T {
        let mut guard = self
            .inner
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner);
        let (o, rng) = &mut *guard;
        f(o.as_mut(), rng)
    }
}

#[pymethods]
impl Optimizer {
    /// `algo` at `x0` with step `sigma`; `popsize` overrides the default population, `bounds`
    /// a `(lower, upper)` box.
    #[new]
    #[pyo3(signature = (algo, x0, sigma, seed = 0, popsize = None, max_evals = None))]
    fn new(
        algo: &str,
        x0: &Bound<'_, PyAny>,
        sigma: f64,
        seed: u64,
        popsize: Option<usize>,
        max_evals: Option<u64>,
    ) -> PyResult<Self> {
        let x = float_array(x0)?;
        let mean = x.as_slice().map_err(err)?.to_vec();
        let mut start = trm_optim::Start::new(mean, sigma);
        start.stop.max_evaluations = max_evals.or(start.stop.max_evaluations);
        let inner = trm_optim::by_name(algo, &start, popsize).map_err(err)?;
        Ok(Optimizer {
            inner: std::sync::Mutex::new((inner, ChaCha8Rng::seed_from_u64(seed))),
        })
    }

    /// The next candidates, `(λ, d)`.
    fn ask<'py>(&self, py: Python<'py>) -> PyResult<Array<'py>> {
        let (rows, d, flat) = self.with(|o, rng| {
            let d = o.dim();
            let xs = o.ask(rng);
            (xs.len(), d, xs.as_slice().to_vec())
        });
        shaped(py, None, &[rows, d], flat)
    }

    /// The values of the last `ask`'s candidates, in order.
    fn tell(&self, values: &Bound<'_, PyAny>) -> PyResult<()> {
        let f = float_array(values)?;
        let f = f.as_slice().map_err(err)?;
        self.with(|o, _| o.tell(f)).map_err(err)
    }

    /// Whether a stopping rule holds.
    #[getter]
    fn done(&self) -> bool {
        self.with(|o, _| !o.stop().is_empty())
    }

    /// The stopping rules that hold, as text.
    #[getter]
    fn stop_reasons(&self) -> Vec<String> {
        self.with(|o, _| o.stop().iter().map(|r| format!("{r:?}")).collect())
    }

    /// The best point so far.
    #[getter]
    fn best_x<'py>(&self, py: Python<'py>) -> PyResult<Array<'py>> {
        let b = self.with(|o, _| o.state().best_x().to_vec());
        shaped(py, None, &[b.len()], b)
    }

    /// The best value so far.
    #[getter]
    fn best_f(&self) -> f64 {
        self.with(|o, _| o.state().best_f())
    }

    /// Evaluations told so far.
    #[getter]
    fn evaluations(&self) -> u64 {
        self.with(|o, _| o.state().evaluations())
    }

    /// The distribution's centre.
    #[getter]
    fn mean<'py>(&self, py: Python<'py>) -> PyResult<Array<'py>> {
        let m = self.with(|o, _| o.mean().to_vec());
        shaped(py, None, &[m.len()], m)
    }
}

/// A task-relevant roadmap: postures that cover a task space, and collision-free edges.
#[pyclass(module = "trm")]
#[derive(Clone)]
struct Roadmap {
    map: trm_roadmap::Roadmap,
}

#[pymethods]
impl Roadmap {
    /// Builds the map of a spec (E-TRM on trm's threads) and connects its edges, as `cargo
    /// xtask build-map` does; `points`, `seed` and `searches` override the spec's settings,
    /// `edge_resolution` is the joint step (rad) at which edges are checked.
    #[staticmethod]
    #[pyo3(signature = (spec, points = None, seed = None, searches = None, edge_resolution = 0.05))]
    fn build(
        py: Python<'_>,
        spec: &str,
        points: Option<usize>,
        seed: Option<u64>,
        searches: Option<usize>,
        edge_resolution: f64,
    ) -> PyResult<Self> {
        let problem = trm_tasks::Problem::load(spec).map_err(err)?;
        let options = trm_roadmap::BuildOptions {
            points,
            seed,
            searches,
            edge_resolution,
            ..Default::default()
        };
        let map = py
            .detach(|| trm_roadmap::build_connected(&problem, &options, |_| {}))
            .map_err(err)?;
        Ok(Roadmap { map })
    }

    /// Loads a map file.
    #[staticmethod]
    fn load(path: &str) -> PyResult<Self> {
        Ok(Roadmap {
            map: trm_roadmap::Roadmap::load(path).map_err(err)?,
        })
    }

    /// Writes the map (atomically).
    fn save(&self, path: &str) -> PyResult<()> {
        self.map.save(path).map_err(err)
    }

    /// Points, edges, components, extent, spacing, coverage and mean cost.
    fn info<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let s = self.map.summary();
        let d = PyDict::new(py);
        d.set_item("points", s.points)?;
        d.set_item("edges", s.edges)?;
        d.set_item("components", s.components)?;
        d.set_item("extent", s.extent)?;
        d.set_item("spacing", s.spacing)?;
        d.set_item("coverage", s.coverage)?;
        d.set_item("mean_cost", s.mean_cost)?;
        d.set_item("task", self.map.task.clone())?;
        d.set_item("active", self.map.active.clone())?;
        Ok(d)
    }

    /// Task vectors of the points, `(N, task dim)`.
    #[getter]
    fn tasks<'py>(&self, py: Python<'py>) -> PyResult<Array<'py>> {
        let dim = self.map.points.first().map_or(0, |p| p.t.len());
        let flat: Vec<f64> = self.map.points.iter().flat_map(|p| p.t.clone()).collect();
        shaped(py, None, &[self.map.points.len(), dim], flat)
    }

    /// Postures of the points (active values), `(N, d)`.
    #[getter]
    fn postures<'py>(&self, py: Python<'py>) -> PyResult<Array<'py>> {
        let dim = self.map.active.len();
        let flat: Vec<f64> = self.map.points.iter().flat_map(|p| p.q.clone()).collect();
        shaped(py, None, &[self.map.points.len(), dim], flat)
    }

    /// Edges `(i, j, length)`.
    #[getter]
    fn edges(&self) -> Vec<(usize, usize, f64)> {
        self.map.edges.clone()
    }

    fn __len__(&self) -> usize {
        self.map.points.len()
    }
}

/// A planner over one or several maps of the same robot and active motors, checked against a
/// world.
#[pyclass(module = "trm")]
struct Planner {
    maps: Vec<trm_roadmap::Roadmap>,
    problem: trm_tasks::Problem,
    world: Option<World>,
}

#[pymethods]
impl Planner {
    /// A planner over `maps` (a Roadmap or a list of them), in `world` (none: the maps' own).
    #[new]
    #[pyo3(signature = (maps, world = None))]
    fn new(maps: &Bound<'_, PyAny>, world: Option<&PyWorld>) -> PyResult<Self> {
        let maps: Vec<trm_roadmap::Roadmap> = match maps.extract::<PyRef<'_, Roadmap>>() {
            Ok(m) => vec![m.map.clone()],
            Err(_) => maps
                .extract::<Vec<PyRef<'_, Roadmap>>>()?
                .iter()
                .map(|m| m.map.clone())
                .collect(),
        };
        let first = maps.first().ok_or_else(|| err("give at least one map"))?;
        let problem = first.problem().map_err(err)?;
        Ok(Planner {
            problem,
            maps,
            world: world.map(|w| w.world.clone()),
        })
    }

    /// Plans from `start` (active values; the spec's start when absent) to a task point `to`
    /// (a map node within `tolerance`, then, with `exact`, NGIK to the point itself) or, with
    /// `posture=True`, to a posture (active values). Returns a dict: `times (T,)`,
    /// `positions (T, motors)`, `motor_names`, `task_path`, `length` (rad), `seconds`.
    #[pyo3(signature = (to, start = None, tolerance = 0.03, posture = false, exact = true, seed = 0))]
    #[allow(clippy::too_many_arguments)]
    fn plan<'py>(
        &self,
        py: Python<'py>,
        to: &Bound<'py, PyAny>,
        start: Option<&Bound<'py, PyAny>>,
        tolerance: f64,
        posture: bool,
        exact: bool,
        seed: u64,
    ) -> PyResult<Bound<'py, PyDict>> {
        let o = &self.problem.objective;
        let from = match start {
            Some(s) => configurations(s, o.dim(), "start")?.0,
            None => self.problem.start.clone(),
        };
        let target = float_array(to)?.as_slice().map_err(err)?.to_vec();
        let goal = if posture {
            trm_plan::Goal::Configuration(target)
        } else {
            trm_plan::Goal::TaskPoint {
                t: target,
                tolerance,
            }
        };
        let options = trm_plan::PlanOptions {
            seed,
            exact_goal: exact,
            ..Default::default()
        };
        let planned = py
            .detach(|| -> Result<trm_plan::Planned, String> {
                let refs: Vec<&trm_roadmap::Roadmap> = self.maps.iter().collect();
                let mut planner = trm_plan::Planner::new(o, &refs).map_err(|e| e.to_string())?;
                if let Some(w) = &self.world {
                    planner.set_world(w.clone());
                }
                planner
                    .plan(&from, &goal, &options)
                    .map_err(|e| e.to_string())
            })
            .map_err(err)?;
        let t = &planned.trajectory;
        let d = PyDict::new(py);
        d.set_item(
            "times",
            shaped(py, None, &[t.times.len()], t.times.clone())?,
        )?;
        let motors = t.names.len();
        let flat: Vec<f64> = t.positions.iter().flatten().copied().collect();
        d.set_item(
            "positions",
            shaped(py, None, &[t.positions.len(), motors], flat)?,
        )?;
        d.set_item("motor_names", t.names.clone())?;
        let dim = t.task_path.first().map_or(0, Vec::len);
        let tasks: Vec<f64> = t.task_path.iter().flatten().copied().collect();
        d.set_item(
            "task_path",
            shaped(py, None, &[t.task_path.len(), dim], tasks)?,
        )?;
        d.set_item("length", planned.stats.length)?;
        d.set_item("seconds", planned.stats.seconds)?;
        Ok(d)
    }
}

/// Minimises `fun(x) -> float` subject to `constraints(x) -> (m,)` values (feasible where
/// every value ≤ 0) with the (1+1)-CMA-ES with constrained covariance adaptation (Arnold and
/// Hansen 2012), bootstrapped from an infeasible start by minimising the total violation first
/// (`bootstrap_budget` evaluations at most; `None`: `max_evals` covers both). `fun` is only
/// called at feasible points. Returns a dict: `x`, `f`, `evaluations`, `feasible`,
/// `bootstrap_evaluations`.
#[pyfunction]
#[pyo3(signature = (fun, constraints, x0, sigma, seed = 0, max_evals = 10_000, bootstrap_budget = None))]
#[allow(clippy::too_many_arguments)]
fn minimize_constrained<'py>(
    py: Python<'py>,
    fun: &Bound<'py, PyAny>,
    constraints: &Bound<'py, PyAny>,
    x0: &Bound<'py, PyAny>,
    sigma: f64,
    seed: u64,
    max_evals: u64,
    bootstrap_budget: Option<u64>,
) -> PyResult<Bound<'py, PyDict>> {
    let mean = float_array(x0)?.as_slice().map_err(err)?.to_vec();
    let to_array = |x: &[f64]| shaped(py, None, &[x.len()], x.to_vec());
    // the number of constraints, from one call at the start
    let m = float_array(&constraints.call1((to_array(&mean)?,))?)?.len();
    let mut start = trm_optim::Start::new(mean, sigma);
    start.stop.max_evaluations = Some(max_evals);
    let mut failure: Option<PyErr> = None;
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let report = {
        let failure = std::cell::RefCell::new(&mut failure);
        let record = |e: PyErr| {
            let mut f = failure.borrow_mut();
            if f.is_none() {
                **f = Some(e);
            }
        };
        trm_optim::minimize_constrained(
            &start,
            bootstrap_budget,
            m,
            &mut rng,
            |x| {
                let value = to_array(x)
                    .and_then(|a| fun.call1((a,)))
                    .and_then(|v| v.extract::<f64>());
                value.unwrap_or_else(|e| {
                    record(e);
                    f64::NAN
                })
            },
            |x, g| {
                let values = to_array(x)
                    .and_then(|a| constraints.call1((a,)))
                    .and_then(|v| {
                        float_array(&v).and_then(|a| Ok(a.as_slice().map_err(err)?.to_vec()))
                    });
                match values {
                    Ok(v) if v.len() == g.len() => g.copy_from_slice(&v),
                    Ok(v) => {
                        record(err(format!(
                            "constraints returned {} values, {} at the start",
                            v.len(),
                            g.len()
                        )));
                        g.fill(f64::NAN);
                    }
                    Err(e) => {
                        record(e);
                        g.fill(f64::NAN);
                    }
                }
            },
        )
        .map_err(err)?
    };
    if let Some(e) = failure {
        return Err(e);
    }
    let d = PyDict::new(py);
    d.set_item("x", to_array(&report.report.best_x)?)?;
    d.set_item("f", report.report.best_f)?;
    d.set_item("evaluations", report.report.evaluations)?;
    d.set_item("feasible", report.feasible)?;
    d.set_item("bootstrap_evaluations", report.bootstrap_evaluations)?;
    Ok(d)
}

/// Writes a self-contained 3-D page of `robot` (the same viewer as `cargo xtask view`): one
/// frame per posture in `frames` (`(n,)` or `(T, n)` motor values; the home posture, else
/// neutral, when absent) at `times` (default 0.05 s apart), `world`'s objects, and a task-space
/// `path` `(K, 3)` drawn as a line. `out` gets the page and `out` with `.json` the scene; the
/// page loads three.js from a CDN unless `bundle` names a built viewer (viewer/dist/viewer.js)
/// to inline. Returns the page's path.
#[pyfunction]
#[pyo3(signature = (robot, out, frames = None, times = None, world = None, path = None, title = "trm", bundle = None))]
#[allow(clippy::too_many_arguments)]
fn view(
    robot: &Robot,
    out: std::path::PathBuf,
    frames: Option<&Bound<'_, PyAny>>,
    times: Option<Vec<f64>>,
    world: Option<&PyWorld>,
    path: Option<&Bound<'_, PyAny>>,
    title: &str,
    bundle: Option<std::path::PathBuf>,
) -> PyResult<std::path::PathBuf> {
    let n = robot.model.motors().len();
    let postures = match frames {
        Some(f) => configurations(f, n, "frames")?.0,
        None => robot
            .model
            .posture("home")
            .map(<[f64]>::to_vec)
            .unwrap_or_else(|_| robot.model.neutral_motors()),
    };
    let count = postures.len() / n.max(1);
    let times = times.unwrap_or_else(|| (0..count).map(|k| k as f64 * 0.05).collect());
    if times.len() != count {
        return Err(err(format!(
            "times: {} values for {count} frames",
            times.len()
        )));
    }
    let collision = CollisionModel::new(&robot.model).map_err(err)?;
    let mut scene = trm_view::Scene::new(title, &collision);
    if let Some(w) = world {
        scene.set_world(&w.world);
    }
    for (t, q) in times.iter().zip(postures.chunks(n.max(1))) {
        scene.add_frame(*t, q).map_err(err)?;
    }
    if let Some(p) = path {
        let a = float_array(p)?;
        if a.ndim() != 2 || a.shape()[1] != 3 {
            return Err(err(format!("path: shape {:?}; expected (K, 3)", a.shape())));
        }
        let v = a.as_slice().map_err(err)?;
        scene.set_path(v.chunks(3).map(|c| [c[0], c[1], c[2]]).collect());
    }
    let code = match &bundle {
        Some(b) => {
            Some(std::fs::read_to_string(b).map_err(|e| err(format!("{}: {e}", b.display())))?)
        }
        None => None,
    };
    let json = out.with_extension("json");
    trm_io::write_file(&json, &scene.to_json().map_err(err)?).map_err(err)?;
    trm_io::write_file(&out, &scene.to_html(code.as_deref()).map_err(err)?).map_err(err)?;
    Ok(out)
}

/// The extension module.
#[pymodule]
fn _trm(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("TrmError", m.py().get_type::<TrmError>())?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add("ALGORITHMS", trm_optim::ALGORITHMS.to_vec())?;
    m.add_class::<Robot>()?;
    m.add_class::<PyWorld>()?;
    m.add_class::<Collision>()?;
    m.add_class::<Problem>()?;
    m.add_class::<Optimizer>()?;
    m.add_class::<Roadmap>()?;
    m.add_class::<Planner>()?;
    m.add_function(wrap_pyfunction!(view, m)?)?;
    m.add_function(wrap_pyfunction!(minimize_constrained, m)?)?;
    Ok(())
}
