//! Scenes of trm's subjects, built in one place for the `trm` tool and Python: a task spec's
//! robot and world, roadmaps, planned motions and scenario runs (objects moving, map nodes
//! parked per frame).

use trm_kinematics::ActiveSet;
use trm_plan::ScenarioRun;
use trm_roadmap::Roadmap;
use trm_tasks::Problem;

use crate::{FrameMap, Result, Scene, ViewError};

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

    /// A scenario run (`trm_plan::run_scenario` on `problem`'s map): the robot's motion, every
    /// object that ever appears posed per frame (absent while it is not there), the map with the
    /// nodes and edges parked at each step, and the task-space path.
    pub fn of_scenario(problem: &Problem, run: &ScenarioRun) -> Result<Scene> {
        let mut scene = Scene::of_problem(problem, "scenario")?;
        scene.frames.clear();
        for (t, q) in run.motion.times.iter().zip(&run.motion.positions) {
            scene.add_frame(*t, q)?;
        }
        let mut all = run
            .worlds
            .last()
            .cloned()
            .unwrap_or_else(|| problem.objective.world().clone());
        for w in &run.worlds {
            for o in w.objects() {
                if all.object(o.name()).is_err() {
                    all.add(o.name(), o.shape().clone(), *o.pose())
                        .map_err(|e| ViewError::Invalid {
                            what: format!("scenario object `{}`", o.name()),
                            problem: e.to_string(),
                        })?;
                }
            }
        }
        scene.set_world(&all);
        scene.add_roadmap(&run.map, problem.objective.active())?;
        for (frame, (step, world)) in scene
            .frames
            .iter_mut()
            .zip(run.steps.iter().zip(&run.worlds))
        {
            frame.world = Some(
                all.objects()
                    .iter()
                    .map(|o| world.object(o.name()).ok().map(|p| crate::pose(p.pose())))
                    .collect(),
            );
            frame.map = Some(FrameMap {
                nodes: step.nodes,
                edges: step.edges,
                blocked: step.parked_nodes.clone(),
                blocked_edges: step.parked_edges.clone(),
            });
        }
        scene.set_path(run.motion.task_path.iter().map(|p| point3(p)).collect());
        Ok(scene)
    }
}
