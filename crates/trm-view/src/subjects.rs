//! Scenes of trm's subjects, built in one place for the `trm` tool and Python: a task spec's
//! robot and world, roadmaps and planned motions.

use trm_kinematics::ActiveSet;
use trm_roadmap::Roadmap;
use trm_tasks::Problem;

use crate::{Result, Scene};

/// The first three components of a task vector (zeros where it has fewer), for drawing.
pub fn point3(v: &[f64]) -> [f64; 3] {
    [
        v.first().copied().unwrap_or(0.0),
        v.get(1).copied().unwrap_or(0.0),
        v.get(2).copied().unwrap_or(0.0),
    ]
}

impl Scene {
    /// A task spec's robot and world at its start posture (frame 0).
    pub fn of_problem(problem: &Problem, title: &str) -> Result<Scene> {
        let mut scene = Scene::new(title, problem.objective.collision());
        scene.set_world(problem.objective.world());
        scene.add_frame(0.0, &problem.objective.active().to_motors(&problem.start))?;
        Ok(scene)
    }

    /// Adds a roadmap: its points (task vectors' first three components), costs, edges and
    /// postures (`active` turns its active values into motor values).
    pub fn add_roadmap(&mut self, map: &Roadmap, active: &ActiveSet) -> Result<()> {
        let postures: Vec<Vec<f64>> = map.points.iter().map(|p| active.to_motors(&p.q)).collect();
        self.set_map(
            map.points.iter().map(|p| point3(&p.t)).collect(),
            map.points.iter().map(|p| p.cost).collect(),
            &postures,
            map.edges.iter().map(|&(a, b, _)| [a, b]).collect(),
        )
    }
}
