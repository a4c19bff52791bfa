//! What one configuration's checks work on: the bodies placed in the world, and the body pairs
//! a model checks.

use nalgebra::Point3;
use parry3d_f64::bounding_volume::{Aabb, BoundingVolume};

use crate::shape::Placed;

/// Two bodies to test, and where the next link pair starts (so a link pair is counted once).
#[derive(Debug, Clone, Copy)]
pub(crate) struct BodyPair {
    pub a: u32,
    pub b: u32,
    pub next: u32,
}

/// World-frame geometry of every body for one configuration (a reusable scratch buffer).
#[derive(Debug, Clone)]
pub struct PlacedBodies {
    pub(crate) placed: Vec<Placed>,
    /// World origins of the links the culling spheres are centred on.
    pub(crate) origins: Vec<Point3<f64>>,
}

impl PlacedBodies {
    /// Number of bodies.
    pub fn len(&self) -> usize {
        self.placed.len()
    }

    /// True for a robot without collision geometry.
    pub fn is_empty(&self) -> bool {
        self.placed.is_empty()
    }

    /// Axis-aligned boxes enclosing each placed body (through its bounding sphere), in body
    /// order.
    pub fn body_boxes(&self) -> impl Iterator<Item = Aabb> + '_ {
        self.placed.iter().map(Placed::bounding_box)
    }

    /// An axis-aligned box enclosing every placed body (through their bounding spheres);
    /// `None` without bodies.
    pub fn bounding_box(&self) -> Option<Aabb> {
        self.placed
            .iter()
            .map(Placed::bounding_box)
            .reduce(|a, b| a.merged(&b))
    }
}
