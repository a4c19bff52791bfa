//! Objects the robot holds — MoveIt's attached collision objects: shapes fixed to a link, moved
//! with it, checked against the world and the robot's other links, except the links allowed to
//! touch them (the gripper's fingers) and the link holding them.

use nalgebra::Isometry3;

use crate::error::{CollisionError, Result, unknown};
use crate::model::{Body, CollisionModel};
use crate::shape::Shape;

/// An object the robot holds.
#[derive(Debug, Clone, PartialEq)]
pub struct AttachedObject {
    /// Unique name; its bodies are named after it (`name`, or `name/k` for the k-th of
    /// several shapes).
    pub name: String,
    /// The link holding it.
    pub link: String,
    /// Its shapes (convex: a point cloud or a mesh cannot be held), each at its pose in the
    /// link's frame.
    pub shapes: Vec<(Shape, Isometry3<f64>)>,
    /// Links it may touch (the fingers holding it): not checked against it. The link holding
    /// it never is.
    pub touch_links: Vec<String>,
}

impl AttachedObject {
    /// The names of its bodies, in the order of its shapes.
    pub fn body_names(&self) -> Vec<String> {
        match self.shapes.len() {
            1 => vec![self.name.clone()],
            n => (0..n).map(|k| format!("{}/{k}", self.name)).collect(),
        }
    }

    /// Whether the body named `body` is one of its bodies.
    pub fn holds(&self, body: &str) -> bool {
        body == self.name
            || body
                .strip_prefix(self.name.as_str())
                .and_then(|rest| rest.strip_prefix('/'))
                .is_some_and(|k| k.parse::<usize>().is_ok())
    }

    /// Indices of its touch links (names checked when attached).
    pub(crate) fn touch_link_indices(&self, tree: &trm_kinematics::Tree) -> Vec<usize> {
        self.touch_links
            .iter()
            .filter_map(|l| tree.link_index(l))
            .collect()
    }
}

impl CollisionModel {
    /// This model with `object` held too: its shapes become bodies of its link, checked against
    /// the world and every other link the link is checked against, except its touch links.
    /// Cheap next to building the model (fitted spheres are kept); compile planners again.
    ///
    /// Errors name what is wrong: an unknown link or touch link (with the nearest names), a
    /// name already held or taken by a body, no shapes, a pose that is not finite, a shape that
    /// is invalid or not convex.
    pub fn with_attached(&self, object: AttachedObject) -> Result<Self> {
        let tree = self.robot().tree();
        let link_names = || tree.links.iter().map(|l| l.name.as_str());
        let link = tree
            .link_index(&object.link)
            .ok_or_else(|| unknown("link", &object.link, link_names()))?;
        for touch in &object.touch_links {
            if tree.link_index(touch).is_none() {
                return Err(unknown("touch link", touch, link_names()));
            }
        }
        let what = format!("held object `{}`", object.name);
        if object.name.trim().is_empty() || object.name.chars().any(char::is_control) {
            return Err(CollisionError::InvalidValue {
                what,
                problem: "a name must hold a visible character and no control characters".into(),
            });
        }
        if object.shapes.is_empty() {
            return Err(CollisionError::InvalidValue {
                what,
                problem: "it has no shape: give at least one".into(),
            });
        }
        if let Some(k) = (object.shapes.iter()).position(|(_, p)| {
            !(p.translation.vector.iter().chain(p.rotation.coords.iter())).all(|v| v.is_finite())
        }) {
            return Err(CollisionError::InvalidValue {
                what,
                problem: format!("the pose of shape {k} is not finite: give finite poses"),
            });
        }
        let names = object.body_names();
        if let Some(taken) = names.iter().find(|n| self.body_index(n).is_ok()) {
            return Err(CollisionError::InvalidValue {
                what,
                problem: format!(
                    "`{taken}` already names a body (detach the object first, or rename it)"
                ),
            });
        }
        let mut bodies = self.bodies().to_vec();
        for (name, (shape, local)) in names.into_iter().zip(&object.shapes) {
            bodies.push(Body {
                name,
                link,
                shape: shape.clone(),
                local: *local,
            });
        }
        let mut attached = self.attached().to_vec();
        attached.push(object);
        self.holding(bodies, attached)
    }

    /// This model without the held object `name` (an unknown name is an error with the nearest
    /// held names).
    pub fn without_attached(&self, name: &str) -> Result<Self> {
        let held = self.attached();
        let Some(k) = held.iter().position(|o| o.name == name) else {
            return Err(unknown(
                "held object",
                name,
                held.iter().map(|o| o.name.as_str()),
            ));
        };
        let object = &held[k];
        let bodies = (self.bodies().iter())
            .filter(|b| !object.holds(&b.name))
            .cloned()
            .collect();
        let mut attached = held.to_vec();
        attached.remove(k);
        self.holding(bodies, attached)
    }
}
