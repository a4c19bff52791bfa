//! The world around the robot: named convex objects with poses, addable, movable and removable
//! at run time, and loadable from RON.

use std::path::Path;

use nalgebra::Isometry3;
use serde::{Deserialize, Serialize};
use trm_kinematics::pose_from_xyz_rpy;

use crate::error::{CollisionError, Result, unknown};
use crate::shape::{Compiled, Placed, Shape};

/// An object of the world.
#[derive(Debug, Clone)]
pub struct WorldObject {
    name: String,
    shape: Shape,
    pose: Isometry3<f64>,
    pub(crate) compiled: Compiled,
    pub(crate) placed: Placed,
}

impl WorldObject {
    /// Unique name.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// Shape, in the object frame.
    pub fn shape(&self) -> &Shape {
        &self.shape
    }

    /// Pose of the object frame in the world.
    pub fn pose(&self) -> &Isometry3<f64> {
        &self.pose
    }

    /// The smallest axis-aligned box enclosing the object.
    pub fn tight_box(&self) -> parry3d_f64::bounding_volume::Aabb {
        self.compiled.tight_box(&self.placed)
    }

    /// An axis-aligned box enclosing the object (through its bounding sphere).
    pub fn bounding_box(&self) -> parry3d_f64::bounding_volume::Aabb {
        self.placed.bounding_box()
    }
}

/// Named objects around the robot, in the world frame (the robot's root link).
#[derive(Debug, Clone, Default)]
pub struct World {
    objects: Vec<WorldObject>,
}

/// A world as written in RON: `(objects: [(name: "table", shape: Box(size: (0.8, 1.2, 0.05)),
/// xyz: (-0.4, 0, -0.1))])`.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WorldSpec {
    /// The objects.
    #[serde(default)]
    pub objects: Vec<ObjectSpec>,
}

/// One object of a [`WorldSpec`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ObjectSpec {
    /// Unique name.
    pub name: String,
    /// Shape.
    pub shape: Shape,
    /// Position in the world, metres.
    #[serde(default)]
    pub xyz: [f64; 3],
    /// Orientation as URDF roll-pitch-yaw, radians.
    #[serde(default)]
    pub rpy: [f64; 3],
}

fn check_pose(what: &str, pose: &Isometry3<f64>) -> Result<()> {
    let finite = pose.translation.vector.iter().all(|v| v.is_finite())
        && pose.rotation.coords.iter().all(|v| v.is_finite());
    if finite {
        Ok(())
    } else {
        Err(CollisionError::InvalidValue {
            what: what.to_string(),
            problem: "the pose is not finite".into(),
        })
    }
}

impl World {
    /// An empty world.
    pub fn new() -> Self {
        Self::default()
    }

    /// Builds a world from parsed RON data; `origin` names the source in errors.
    pub fn from_spec(spec: &WorldSpec, origin: &str) -> Result<Self> {
        Self::build(spec, origin, None)
    }

    /// Builds a world from RON data parsed out of `text`, where its object list sits at field
    /// path `at` (`"objects"` in a world file, `"world.objects"` inside a task spec), so that an
    /// error names the line of the object it is about.
    pub fn from_spec_in(spec: &WorldSpec, origin: &str, text: &str, at: &str) -> Result<Self> {
        Self::build(spec, origin, Some((text, at)))
    }

    fn build(spec: &WorldSpec, origin: &str, located: Option<(&str, &str)>) -> Result<Self> {
        let mut world = World::new();
        for (i, o) in spec.objects.iter().enumerate() {
            let path = format!("{}[{i}]", located.map_or("objects", |(_, at)| at));
            let line = located
                .and_then(|(text, _)| trm_io::locate_ron_path(text, &path))
                .map(|(line, _)| line);
            let element = format!("{path} (\"{}\")", o.name);
            world
                .add(&o.name, o.shape.clone(), pose_from_xyz_rpy(o.xyz, o.rpy))
                .map_err(|e| match e {
                    CollisionError::InvalidShape { problem, fix, .. } => {
                        CollisionError::InvalidShape {
                            origin: origin.to_string(),
                            line,
                            element: element.clone(),
                            problem,
                            fix,
                        }
                    }
                    // in a file, the API's hint (move it with set_pose) is no help
                    CollisionError::DuplicateObject(name) => CollisionError::InvalidShape {
                        origin: origin.to_string(),
                        line,
                        element: element.clone(),
                        problem: format!("`{name}` names an earlier object too"),
                        fix: "give every object its own name".into(),
                    },
                    other => CollisionError::InvalidShape {
                        origin: origin.to_string(),
                        line,
                        element: element.clone(),
                        problem: other.to_string(),
                        fix: "give every object a unique name, a finite pose and a valid shape"
                            .into(),
                    },
                })?;
        }
        Ok(world)
    }

    /// Parses a RON world; `origin` names the source in errors.
    pub fn from_ron(text: &str, origin: &str) -> Result<Self> {
        let spec: WorldSpec = ron::from_str(text).map_err(|e| {
            let p = trm_io::explain_ron_error(&e);
            CollisionError::MalformedWorld {
                origin: origin.to_string(),
                line: p.line,
                column: p.column,
                message: p.message(),
            }
        })?;
        Self::from_spec_in(&spec, origin, text, "objects")
    }

    /// Reads a RON world file.
    pub fn load(path: impl AsRef<Path>) -> Result<Self> {
        let path = path.as_ref();
        let text = trm_io::read_input(path).map_err(|source| CollisionError::Io {
            path: path.to_path_buf(),
            source,
        })?;
        Self::from_ron(&text, &path.display().to_string())
    }

    /// The world as RON data.
    pub fn to_spec(&self) -> WorldSpec {
        WorldSpec {
            objects: self
                .objects
                .iter()
                .map(|o| {
                    let (r, p, y) = o.pose.rotation.euler_angles();
                    ObjectSpec {
                        name: o.name.clone(),
                        shape: o.shape.clone(),
                        xyz: o.pose.translation.vector.into(),
                        rpy: [r, p, y],
                    }
                })
                .collect(),
        }
    }

    /// Adds an object and returns its index.
    pub fn add(&mut self, name: &str, shape: Shape, pose: Isometry3<f64>) -> Result<usize> {
        if name.trim().is_empty() || name.chars().any(char::is_control) {
            return Err(CollisionError::InvalidValue {
                what: format!("world object name {name:?}"),
                problem: "a name must hold a visible character and no control characters (queries, repairs and scenarios address objects by name)".into(),
            });
        }
        if self.objects.iter().any(|o| o.name == name) {
            return Err(CollisionError::DuplicateObject(name.to_string()));
        }
        check_pose(&format!("world object `{name}`"), &pose)?;
        let compiled = shape.compile(&Isometry3::identity()).ok_or_else(|| {
            let p = shape.check().err().unwrap_or_else(|| crate::ShapeProblem {
                problem: "unusable shape".into(),
                fix: "use another shape".into(),
            });
            CollisionError::InvalidShape {
                origin: "<world>".into(),
                line: None,
                element: format!("object \"{name}\""),
                problem: p.problem,
                fix: p.fix,
            }
        })?;
        let mut placed = Placed::default();
        compiled.place(&pose, &mut placed);
        self.objects.push(WorldObject {
            name: name.to_string(),
            shape,
            pose,
            compiled,
            placed,
        });
        Ok(self.objects.len() - 1)
    }

    /// Index of the object with this name.
    pub fn index(&self, name: &str) -> Result<usize> {
        self.objects
            .iter()
            .position(|o| o.name == name)
            .ok_or_else(|| {
                unknown(
                    "world object",
                    name,
                    self.objects.iter().map(|o| o.name.as_str()),
                )
            })
    }

    /// The object with this name.
    pub fn object(&self, name: &str) -> Result<&WorldObject> {
        Ok(&self.objects[self.index(name)?])
    }

    /// Moves an object.
    pub fn set_pose(&mut self, name: &str, pose: Isometry3<f64>) -> Result<()> {
        let i = self.index(name)?;
        check_pose(&format!("world object `{name}`"), &pose)?;
        let o = &mut self.objects[i];
        o.pose = pose;
        o.compiled.place(&pose, &mut o.placed);
        Ok(())
    }

    /// Moves the object at `index` (into [`World::objects`]): the index-based form of
    /// [`World::set_pose`], for loops that move every object each step.
    pub fn set_pose_at(&mut self, index: usize, pose: Isometry3<f64>) -> Result<()> {
        let Some(o) = self.objects.get_mut(index) else {
            return Err(CollisionError::InvalidValue {
                what: "world object index".into(),
                problem: format!("{index} is beyond the {} objects", self.objects.len()),
            });
        };
        check_pose(&format!("world object `{}`", o.name), &pose)?;
        o.pose = pose;
        o.compiled.place(&pose, &mut o.placed);
        Ok(())
    }

    /// Removes an object and returns it.
    pub fn remove(&mut self, name: &str) -> Result<WorldObject> {
        let i = self.index(name)?;
        Ok(self.objects.remove(i))
    }

    /// All objects, in insertion order.
    pub fn objects(&self) -> &[WorldObject] {
        &self.objects
    }

    /// Number of objects.
    pub fn len(&self) -> usize {
        self.objects.len()
    }

    /// True when the world is empty.
    pub fn is_empty(&self) -> bool {
        self.objects.is_empty()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn worlds_round_trip_through_ron_and_reject_bad_objects() {
        let text = r#"(objects: [
            (name: "table", shape: Box(size: (0.8, 1.2, 0.05)), xyz: (-0.4, 0.0, -0.1)),
            (name: "ball", shape: Sphere(radius: 0.05), xyz: (-0.3, 0.1, 0.1), rpy: (0.0, 0.0, 1.0)),
        ])"#;
        let mut world = World::from_ron(text, "w.ron").unwrap();
        assert_eq!(world.len(), 2);
        let again = World::from_spec(&world.to_spec(), "again").unwrap();
        assert!((again.object("ball").unwrap().pose().rotation.angle() - 1.0).abs() < 1e-12);
        world
            .set_pose("ball", Isometry3::translation(1.0, 0.0, 0.0))
            .unwrap();
        assert_eq!(world.object("ball").unwrap().pose().translation.x, 1.0);
        let e = world
            .set_pose("bal", Isometry3::identity())
            .unwrap_err()
            .to_string();
        assert!(e.contains("did you mean `ball`"), "{e}");
        assert!(matches!(
            world.add(
                "table",
                Shape::Sphere { radius: 1.0 },
                Isometry3::identity()
            ),
            Err(CollisionError::DuplicateObject(_))
        ));
        let bad = r#"(objects: [(name: "b", shape: Sphere(radius: -1.0))])"#;
        let e = World::from_ron(bad, "w.ron").unwrap_err().to_string();
        assert!(
            e.starts_with("w.ron:1: objects[0] (\"b\"): sphere radius -1"),
            "{e}"
        );
        let e = World::from_ron("(objects: [(nme: \"x\")])", "w.ron")
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("w.ron:1:"), "{e}");
        world.remove("ball").unwrap();
        assert_eq!(world.len(), 1);
    }
}
