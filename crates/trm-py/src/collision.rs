//! `trm.World` and `trm.CollisionModel`: worlds (RON or MoveIt scenes) and collision queries.

use crate::*;

/// Obstacles: boxes, spheres, capsules, cylinders, point clouds and triangle meshes at poses
/// (root frame).
#[pyclass(name = "World", module = "trm")]
#[derive(Clone, Default)]
pub(crate) struct PyWorld {
    pub(crate) world: World,
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
            world: trm_moveit::load_world(path).map_err(err)?,
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

    /// Adds a point cloud: `points` an (N, 3) array in the cloud's frame (a camera's, placed at
    /// `xyz`, `rpy`), each point a ball of `radius`. Rows with a NaN or infinite coordinate
    /// (invalid pixels) are dropped; returns how many points were kept.
    #[pyo3(signature = (name, points, radius, xyz = [0.0; 3], rpy = [0.0; 3]))]
    fn add_points(
        &mut self,
        name: &str,
        points: &Bound<'_, PyAny>,
        radius: f64,
        xyz: [f64; 3],
        rpy: [f64; 3],
    ) -> PyResult<usize> {
        let points: Vec<[f64; 3]> = rows3(points, "points")?
            .into_iter()
            .filter(|p| p.iter().all(|v| v.is_finite()))
            .collect();
        let kept = points.len();
        self.add(name, Shape::Points { points, radius }, xyz, rpy)?;
        Ok(kept)
    }

    /// Adds a triangle mesh (its surface, concave parts included): `vertices` an (N, 3) array,
    /// `triangles` an (M, 3) array of vertex indices.
    #[pyo3(signature = (name, vertices, triangles, xyz = [0.0; 3], rpy = [0.0; 3]))]
    fn add_mesh(
        &mut self,
        name: &str,
        vertices: &Bound<'_, PyAny>,
        triangles: Vec<[u32; 3]>,
        xyz: [f64; 3],
        rpy: [f64; 3],
    ) -> PyResult<()> {
        let vertices = rows3(vertices, "vertices")?;
        let shape = Shape::Mesh {
            vertices,
            triangles,
        };
        self.add(name, shape, xyz, rpy)
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

    /// Per sphere of radius `radius` (m) centred on a row of `centres` (an (N, 3) array): the
    /// name of an object it touches or overlaps, measured exactly (a point cloud's points as
    /// balls of its radius), or None. A radius of 0 asks about points.
    fn touching(
        &self,
        py: Python<'_>,
        centres: &Bound<'_, PyAny>,
        radius: f64,
    ) -> PyResult<Vec<Option<String>>> {
        let centres = rows3(centres, "centres")?;
        let found = py.detach(|| {
            centres
                .iter()
                .enumerate()
                .map(|(row, c)| {
                    self.world
                        .sphere_touches(*c, radius)
                        .map_err(|e| format!("centres row {row}: {e}"))
                })
                .collect::<Result<Vec<_>, _>>()
        });
        let objects = self.world.objects();
        Ok(found
            .map_err(err)?
            .into_iter()
            .map(|o| o.map(|i| objects[i].name().to_string()))
            .collect())
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

/// The rows of an (N, 3) array.
fn rows3(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<Vec<[f64; 3]>> {
    let a = float_array(obj)?;
    match a.shape() {
        [_, 3] => Ok(a
            .as_slice()
            .map_err(err)?
            .chunks_exact(3)
            .map(|r| [r[0], r[1], r[2]])
            .collect()),
        shape => Err(err(format!("{what}: shape {shape:?}; expected (N, 3)"))),
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
pub(crate) struct Collision {
    pub(crate) robot: RobotModel,
    pub(crate) model: CollisionModel,
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
    /// The collision model of `robot` (its capsules and boxes, or meshes as convex hulls);
    /// `package://` meshes are looked for in `package_paths`, then ROS_PACKAGE_PATH, as
    /// `--package-path` does for `trm`.
    #[new]
    #[pyo3(signature = (robot, package_paths = Vec::new()))]
    fn new(robot: &Robot, package_paths: Vec<std::path::PathBuf>) -> PyResult<Self> {
        Ok(Collision {
            model: CollisionModel::with_package_paths(&robot.model, package_paths).map_err(err)?,
            robot: robot.model.clone(),
        })
    }

    /// The allowed-collision matrix MoveIt's setup assistant would generate for this model, as
    /// `trm gen-acm`: pairs adjacent in the tree, colliding in the default posture (`posture`,
    /// else `home`), never colliding or colliding in at least `always_fraction` of `samples`
    /// seeded random configurations. Returns the disabled link pairs as
    /// `(link, link, reason)`.
    #[pyo3(signature = (samples = 1_000_000, seed = 0, always_fraction = 0.95, posture = None))]
    fn generate_acm(
        &self,
        py: Python<'_>,
        samples: usize,
        seed: u64,
        always_fraction: f64,
        posture: Option<String>,
    ) -> PyResult<Vec<(String, String, String)>> {
        let default_posture = match posture {
            Some(name) => Some(self.robot.posture(&name).map_err(err)?.to_vec()),
            None => None,
        };
        let options = trm_collision::AcmOptions {
            samples,
            seed,
            always_fraction,
            default_posture,
        };
        let report = py
            .detach(|| trm_collision::generate_acm(&self.model, &options))
            .map_err(err)?;
        let links = &self.robot.tree().links;
        Ok(report
            .acm
            .disabled_pairs()
            .map(|([a, b], reason)| {
                (
                    links[a].name.clone(),
                    links[b].name.clone(),
                    reason.as_str().to_string(),
                )
            })
            .collect())
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
