//! A problem read and prepared once, then solved and checked as often as asked.

use trm_collision::{CollisionModel, World};
use trm_kinematics::RobotModel;
use trm_moveit::{MotionPlanRequest, PlanningScene};

use crate::error::MbmError;
use crate::problems::Problem;
use crate::run::TaskSpaceGoals;

/// A problem read and prepared once: its scene and request parsed, its world built and the
/// scene's allowed-collision matrix applied to the robot's collision model. Solving it
/// ([`crate::solve`]), solving it with experience and re-checking its paths
/// ([`crate::certify_path`]) read and compile nothing again.
#[derive(Debug, Clone)]
pub struct LoadedProblem {
    /// Its family, number and files (a problem made in memory: no family, its messages'
    /// origins).
    pub problem: Problem,
    /// The scene.
    pub scene: PlanningScene,
    /// The request.
    pub request: MotionPlanRequest,
    /// The scene's world.
    pub world: World,
    /// The robot's collision model with the scene's matrix applied
    /// ([`trm_moveit::AllowedCollisions::apply`]).
    pub collision: CollisionModel,
    /// The robot's collision model as given, before the scene's matrix (a planner is made
    /// with it, then takes the problem's: so that it can say which matrix checks a pair).
    pub own: CollisionModel,
    /// The scene's matrix entries that are not links of the robot (skipped).
    pub notes: Vec<String>,
    /// When `world` is the scene seen as a point cloud ([`crate::Obstacles::Cloud`]): how it
    /// was made.
    pub cloud: Option<crate::CloudBuild>,
}

impl LoadedProblem {
    /// Prepares a scene and request for `collision`'s robot.
    pub fn new(
        collision: &CollisionModel,
        scene: PlanningScene,
        request: MotionPlanRequest,
    ) -> Result<Self, MbmError> {
        let world = scene.to_world()?;
        let (applied, notes) = match &scene.allowed_collisions {
            Some(acm) => {
                let (applied, notes) = acm.apply(collision)?;
                (applied.unwrap_or_else(|| collision.clone()), notes)
            }
            None => (collision.clone(), Vec::new()),
        };
        Ok(LoadedProblem {
            problem: Problem {
                family: String::new(),
                index: 0,
                scene: scene.origin.clone(),
                request: request.origin.clone(),
            },
            scene,
            request,
            world,
            own: collision.clone(),
            collision: applied,
            notes,
            cloud: None,
        })
    }

    /// Reads `problem`'s files and prepares them for `collision`'s robot.
    pub fn load(collision: &CollisionModel, problem: &Problem) -> Result<Self, MbmError> {
        let scene = PlanningScene::load(&problem.scene)?;
        let request = MotionPlanRequest::load(&problem.request)?;
        Ok(LoadedProblem {
            problem: problem.clone(),
            ..Self::new(collision, scene, request)?
        })
    }

    /// [`LoadedProblem::load`] of every problem, in order.
    pub fn load_all(
        collision: &CollisionModel,
        problems: &[Problem],
    ) -> Result<Vec<Self>, MbmError> {
        problems.iter().map(|p| Self::load(collision, p)).collect()
    }

    /// The same problem with its joint goal posed as the task-space goal it implies
    /// ([`MotionPlanRequest::to_task_space`]).
    pub fn with_task_space(
        &self,
        robot: &RobotModel,
        goals: &TaskSpaceGoals,
    ) -> Result<Self, MbmError> {
        let request = self.request.to_task_space(
            robot,
            &goals.link,
            goals.position_tolerance,
            goals.orientation_tolerance,
        )?;
        Ok(LoadedProblem {
            request,
            ..self.clone()
        })
    }
}
