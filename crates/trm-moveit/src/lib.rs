//! MoveIt's planning inputs as YAML (the ROS message layout MotionBenchMaker and
//! `moveit_msgs` tools write): a `PlanningScene` (world collision objects made of box, sphere
//! and cylinder primitives and triangle meshes, the allowed-collision matrix, the robot state
//! with the objects it holds) and a `MotionPlanRequest` (start state with held objects,
//! joint-space or task-space goal, group, planning time, scaling factors), and a robot's
//! `joint_limits.yaml` ([`JointLimitsFile`]).
//!
//! ```
//! use trm_moveit::PlanningScene;
//! let scene = PlanningScene::parse(
//!     "world:\n  collision_objects:\n    - id: shelf\n      primitives: [{type: box, dimensions: [1.2, 1, 0.04]}]\n      primitive_poses: [{position: [0.6, 0, 0.2], orientation: [0, 0, 0, 1]}]\n",
//!     "scene.yaml".as_ref(),
//! )?;
//! let world = scene.to_world()?;
//! assert_eq!(world.objects().len(), 1);
//! # Ok::<(), trm_moveit::MoveItError>(())
//! ```
//!
//! Each primitive becomes one world object, posed by the object's `pose` (identity when absent)
//! times its `primitive_poses` entry; an object of several primitives names them `id/0`,
//! `id/1`, …. Poses are read as `position: [x, y, z]` or `{x:, y:, z:}` and `orientation:
//! [x, y, z, w]` or `{x:, y:, z:, w:}`. Meshes (`shape_msgs/Mesh`: `vertices` and
//! `triangles`, with `mesh_poses`) become triangle meshes; a mesh may instead name a file,
//! `resource: "package://pkg/meshes/x.stl"` or a path relative to the scene, with an optional
//! `scale`. Attached collision objects (`robot_state.attached_collision_objects`, a request's
//! `start_state`) are read as [`trm_collision::AttachedObject`]s, posed in their link's frame,
//! with their touch links. Planes and cones are refused with the object named. Every error
//! names the file and the line.

mod error;
mod limits;
mod planning;
mod reader;
mod request;
mod response;
mod scene;
pub mod yaml;

use std::path::Path;

use trm_collision::{AllowedCollisionMatrix, CollisionModel, World};

pub use error::{MoveItError, Result};
pub use limits::JointLimitsFile;
pub use planning::{TimingSettings, check_trajectory_out, describe_files, trajectory_files};
pub use request::{
    JointGoal, JointState, LIMIT_SLACK, MotionPlanRequest, RequestGoal, motors_from_state,
};
pub use response::motion_plan_response_yaml;
pub use scene::{AllowedCollisions, CollisionObject, PlanningScene, Primitive};

/// A world from a file: a MoveIt planning scene (`.yaml`/`.yml`, its collision objects) or
/// trm's RON world (anything else).
pub fn load_world(path: impl AsRef<Path>) -> Result<World, MoveItError> {
    let path = path.as_ref();
    match path.extension().and_then(|e| e.to_str()) {
        Some("yaml" | "yml") => PlanningScene::load(path)?.to_world(),
        _ => Ok(World::load(path)?),
    }
}

/// A world file read for a robot: its objects and the allowed-collision matrix to check them
/// with.
#[derive(Debug, Clone)]
pub struct Scene {
    /// The objects.
    pub world: World,
    /// A MoveIt scene's matrix applied over the collision model's own
    /// ([`AllowedCollisions::over`]); the model's own for a scene without one and a RON world.
    pub acm: AllowedCollisionMatrix,
    /// The scene's matrix entries that are not links of the robot (skipped).
    pub notes: Vec<String>,
    /// What the robot holds in the scene (`robot_state.attached_collision_objects`).
    pub attached: Vec<trm_collision::AttachedObject>,
}

/// A world file (RON, or a MoveIt planning scene `.yaml`) read for `collision`'s robot: the
/// world and matrix a planner takes (`trm_plan::Planner::set_world` and `set_acm`).
pub fn load_scene(
    path: impl AsRef<Path>,
    collision: &CollisionModel,
) -> Result<Scene, MoveItError> {
    let path = path.as_ref();
    let own = || collision.acm().clone();
    match path.extension().and_then(|e| e.to_str()) {
        Some("yaml" | "yml") => {
            let scene = PlanningScene::load(path)?;
            let (acm, notes) = match &scene.allowed_collisions {
                Some(allowed) => {
                    let (acm, notes) = allowed.over(collision);
                    (acm.unwrap_or_else(own), notes)
                }
                None => (own(), Vec::new()),
            };
            Ok(Scene {
                world: scene.to_world()?,
                acm,
                notes,
                attached: scene.attached,
            })
        }
        _ => Ok(Scene {
            world: World::load(path)?,
            acm: own(),
            notes: Vec::new(),
            attached: Vec::new(),
        }),
    }
}
