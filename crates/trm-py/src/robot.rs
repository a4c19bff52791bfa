//! `trm.Robot`: models, kinematics and derivatives.

use crate::*;

/// A robot model: links, motors (with couplings and limits), named frames, groups and postures.
#[pyclass(module = "trm")]
#[derive(Clone)]
pub(crate) struct Robot {
    pub(crate) model: RobotModel,
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
        self.model.motor_names()
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
