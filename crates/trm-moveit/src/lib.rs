//! MoveIt's planning inputs as YAML (the ROS message layout MotionBenchMaker and
//! `moveit_msgs` tools write): a `PlanningScene` (world collision objects made of box, sphere
//! and cylinder primitives, the allowed-collision matrix, the robot state) and a
//! `MotionPlanRequest` (start state, joint-space goal, group, planning time).
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
//! [x, y, z, w]` or `{x:, y:, z:, w:}`. Meshes, planes, cones and attached objects are refused
//! with the object named (trm's worlds hold convex primitives). Every error names the file and
//! the line.

mod error;
mod reader;
mod request;
mod scene;
pub mod yaml;

use std::path::Path;

use trm_collision::World;

pub use error::{MoveItError, Result};
pub use request::{JointGoal, JointState, MotionPlanRequest, motors_from_state};
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
