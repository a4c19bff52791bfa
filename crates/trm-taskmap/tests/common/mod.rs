//! Fixtures shared by the task-map tests.

use trm_collision::{Shape, World};
use trm_kinematics::nalgebra::Isometry3;

/// A world holding one stick: a capsule 30 cm long, 2 cm in radius, along z at the origin.
pub fn stick() -> World {
    let mut w = World::new();
    w.add(
        "stick",
        Shape::Capsule {
            radius: 0.02,
            length: 0.3,
        },
        Isometry3::identity(),
    )
    .unwrap();
    w
}
