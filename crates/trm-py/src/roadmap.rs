//! `trm.Roadmap`: maps built, loaded and inspected.

use crate::*;

/// A task-relevant roadmap: postures that cover a task space, and collision-free edges.
#[pyclass(module = "trm")]
#[derive(Clone)]
pub(crate) struct Roadmap {
    pub(crate) map: trm_roadmap::Roadmap,
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
        let problem = trm_tasks::Problem::load_with(spec, &trm_taskmap::loaders()).map_err(err)?;
        let options = trm_roadmap::BuildOptions {
            points,
            seed,
            searches,
            edge_resolution,
            ..Default::default()
        };
        let map = py
            .detach(|| {
                trm_roadmap::Builder::new(&problem, &options)
                    .connected()
                    .run(|_| {})
            })
            .map_err(err)?;
        Ok(Roadmap { map })
    }

    /// The map repaired for `world` (a `World`, e.g. a MoveIt scene), as `trm repair-map`: what
    /// the world blocks is parked, lost task-space cells are grown again and connected.
    /// Returns `(repaired map, report)`, the report a dict: blocked, restored and added nodes
    /// and edges, lost and restored cells, why growing stopped, seconds per phase.
    fn repair(&self, py: Python<'_>, world: &PyWorld) -> PyResult<(Roadmap, Py<PyAny>)> {
        let problem = self
            .map
            .problem_with(&trm_taskmap::loaders())
            .map_err(err)?;
        let options = trm_roadmap::RepairOptions::default();
        let (map, report) = py
            .detach(|| trm_roadmap::repair(&self.map, &problem, &world.world, &options))
            .map_err(err)?;
        Ok((Roadmap { map }, to_python(py, &report)?))
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

    /// Points, edges, components, extent, spacing, coverage and mean cost (`trm map-info`).
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
