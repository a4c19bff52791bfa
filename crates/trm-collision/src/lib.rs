//! Self- and world-collision checking for trm robot models.
//!
//! A [`CollisionModel`] turns every URDF `<collision>` element of a
//! [`RobotModel`](trm_kinematics::RobotModel) into a convex body (boxes, cylinders, spheres,
//! capsules; meshes become their convex hull) and skips the link pairs its
//! [`AllowedCollisionMatrix`] disables. Per configuration: forward kinematics into a
//! [`PoseBuffer`](trm_kinematics::PoseBuffer), [`CollisionModel::place`], then count, test or
//! measure — without allocating:
//!
//! ```
//! use trm_collision::{CollisionModel, Shape, World};
//! use trm_kinematics::nalgebra::Isometry3;
//!
//! let robot = trm_models::icub_upper_body();
//! let collision = CollisionModel::new(&robot)?;
//! let mut poses = robot.pose_buffer();
//! robot.forward_motors(robot.posture("home")?, &mut poses)?;
//! let mut placed = collision.placed_bodies();
//! collision.place(&poses, &mut placed);
//! assert_eq!(collision.count_self(&placed), 0);
//!
//! let mut world = World::new();
//! world.add("table", Shape::Box { size: [0.6, 1.0, 0.05] }, Isometry3::translation(-0.3, 0.0, 0.0))?;
//! assert!(collision.count_world(&placed, &world) > 0); // the table cuts through the torso
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! Round shapes (spheres, capsules) are tested analytically (segment distance minus radii);
//! everything else goes through parry. Every pair test starts with a bounding-sphere reject;
//! boxes add their slabs. [`Shape::enclosing_spheres`] gives a sphere model of any shape (a few
//! spheres that enclose it, tighter than one).
//! [`generate_acm`] builds the matrix as MoveIt's setup assistant does.
//!
//! A [`World`] holds those shapes and what cameras and CAD give: point clouds
//! ([`Shape::Points`], read from PLY and PCD files; [`thin_points`] thins them,
//! [`CollisionModel::points_off_robot`] drops the robot's own points) and triangle meshes
//! ([`Shape::Mesh`]). A robot holds objects ([`CollisionModel::with_attached`],
//! [`AttachedObject`]): they move with their link and are checked against everything but their
//! touch links.
//!
//! For sphere models (VAMP's spherized URDFs, or [`fit::urdf_with_spheres`]),
//! [`fast::FastChecker`] checks eight configurations at once in single precision, deferring the
//! few within rounding distance of contact to the exact check, so its answers are the exact
//! model's; mesh hulls go through spheres that enclose them exactly
//! ([`fit::fit_convex_spheres`]), the lanes they leave uncertain decided by the hulls pair by
//! pair (the planner uses it for both).
//!
//! [`WorldChecker`] is what planners use: it checks configurations and straight edges
//! ([`edge`]) of one robot in one world, on the screen where the model compiles to it and
//! through the exact model otherwise, and counts what it checked. [`Certifier`] proves straight
//! motions free in continuous motion (lever-arm bounds on exact distances, [`certify`]), for
//! verifying paths independently of the planner that made them; [`prove::Prover`] proves them
//! fast, for planners, on the screen with the robot padded ([`CollisionModel::padded`]), the
//! certifier deciding only what comes within millimetres of contact.

mod acm;
mod attached;
mod batch;
pub mod certify;
mod checker;
mod cull;
pub mod edge;
mod error;
pub mod fast;
pub mod fit;
mod generate;
mod levers;
pub mod mesh;
mod model;
mod placed;
mod points;
pub mod prove;
mod query;
mod shape;
mod world;

pub use acm::AllowedCollisionMatrix;
pub use attached::AttachedObject;
pub use batch::PlacedBatch;
pub use certify::{Certificate, Certifier, Contact, PathCertificate};
pub use checker::WorldChecker;
pub use error::{CollisionError, Result};
pub use generate::{AcmOptions, AcmReport, generate_acm};
pub use levers::Levers;
pub use model::{Body, CollisionModel, CollisionOptions};
/// Axis-aligned boxes (parry's), as [`PlacedBodies::bounding_box`] and
/// [`WorldObject::bounding_box`] return them.
pub use parry3d_f64::bounding_volume::Aabb;
pub use placed::PlacedBodies;
pub use points::thin_points;
pub use query::{CollidingPair, CollisionCount, NearPair, Other, PairDistance};
pub use shape::{CONVEX_SPHERES, Shape, ShapeProblem, Sphere};
pub use trm_kinematics::DisableReason;
pub use world::{CloudFileSpec, MeshFileSpec, ObjectSpec, World, WorldObject, WorldSpec};

/// The file formats this crate reads and writes.
pub mod formats {
    #[doc = include_str!("../docs/world.md")]
    pub mod world {}
}
