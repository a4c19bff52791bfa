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
    /// Point clouds read from PLY or PCD files.
    #[serde(default)]
    pub clouds: Vec<CloudFileSpec>,
    /// Triangle meshes read from STL, OBJ or COLLADA files.
    #[serde(default)]
    pub meshes: Vec<MeshFileSpec>,
}

/// A point cloud of a [`WorldSpec`] read from a file: `(name: "scan", file: "scan.ply",
/// radius: 0.005)`; non-finite points (a camera's invalid pixels) are dropped.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CloudFileSpec {
    /// Unique name.
    pub name: String,
    /// PLY or PCD file, relative to the world file.
    pub file: String,
    /// Radius of every point, m (> 0).
    pub radius: f64,
    /// Position of the cloud's frame (the camera's, say) in the world, metres.
    #[serde(default)]
    pub xyz: [f64; 3],
    /// Orientation as URDF roll-pitch-yaw, radians.
    #[serde(default)]
    pub rpy: [f64; 3],
}

/// A triangle mesh of a [`WorldSpec`] read from a file: `(name: "bowl", file: "bowl.stl")`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MeshFileSpec {
    /// Unique name.
    pub name: String,
    /// STL, OBJ or COLLADA file, relative to the world file.
    pub file: String,
    /// Scale along each axis.
    #[serde(default = "unit_scale")]
    pub scale: [f64; 3],
    /// Position in the world, metres.
    #[serde(default)]
    pub xyz: [f64; 3],
    /// Orientation as URDF roll-pitch-yaw, radians.
    #[serde(default)]
    pub rpy: [f64; 3],
}

fn unit_scale() -> [f64; 3] {
    [1.0; 3]
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

/// An error for a sphere's centre or radius that is not finite, or a negative radius.
pub(crate) fn check_sphere(centre: &[f64; 3], radius: f64) -> Result<()> {
    if let Some(i) = centre.iter().position(|v| !v.is_finite()) {
        return Err(CollisionError::InvalidValue {
            what: format!("coordinate {i} of a sphere's centre"),
            problem: format!("is {}, not a finite number", centre[i]),
        });
    }
    if !(radius.is_finite() && radius >= 0.0) {
        return Err(CollisionError::InvalidValue {
            what: "a sphere's radius".into(),
            problem: format!("is {radius}; give a finite radius of 0 or more, in metres"),
        });
    }
    Ok(())
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
        // files beside the world file (an origin that is not a path: the working directory)
        let dir = Path::new(origin).parent().unwrap_or(Path::new(""));
        let at = located.map_or("objects", |(_, at)| at);
        let lists = at.strip_suffix("objects").unwrap_or("");
        let from_files = (spec.clouds.iter().enumerate())
            .map(|(i, c)| {
                let shape = trm_io::read_points(&dir.join(&c.file)).map(|f| Shape::Points {
                    points: f.points,
                    radius: c.radius,
                });
                (
                    format!("{lists}clouds[{i}]"),
                    &c.name,
                    &c.file,
                    shape,
                    c.xyz,
                    c.rpy,
                )
            })
            .chain(spec.meshes.iter().enumerate().map(|(i, m)| {
                let shape = crate::mesh::triangles_of_mesh(&dir.join(&m.file), m.scale).map(
                    |(vertices, triangles)| Shape::Mesh {
                        vertices,
                        triangles,
                    },
                );
                (
                    format!("{lists}meshes[{i}]"),
                    &m.name,
                    &m.file,
                    shape,
                    m.xyz,
                    m.rpy,
                )
            }));
        let objects = spec.objects.iter().enumerate().map(|(i, o)| {
            let shape = Ok(o.shape.clone());
            (format!("{at}[{i}]"), &o.name, &o.name, shape, o.xyz, o.rpy)
        });
        for (path, name, file, shape, xyz, rpy) in objects.chain(from_files) {
            let line = located
                .and_then(|(text, _)| trm_io::locate_ron_path(text, &path))
                .map(|(line, _)| line);
            let element = format!("{path} (\"{name}\")");
            let shape = shape.map_err(|problem| CollisionError::InvalidShape {
                origin: origin.to_string(),
                line,
                element: element.clone(),
                problem: format!("{}: {problem}", dir.join(file).display()),
                fix: "give a readable file, relative to the world file".into(),
            })?;
            world
                .add(name, shape, pose_from_xyz_rpy(xyz, rpy))
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

    /// The world as RON data (point clouds and meshes written out in full, as objects).
    pub fn to_spec(&self) -> WorldSpec {
        WorldSpec {
            clouds: Vec::new(),
            meshes: Vec::new(),
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

    /// The first object (index) that a ball of radius `radius` at `centre` touches or
    /// overlaps, measured exactly in `f64` (a point cloud's points as balls of its radius);
    /// `None` when it touches none. A radius of 0 asks about a point. An error for a centre
    /// or radius that is not finite, or a negative radius.
    pub fn sphere_touches(&self, centre: [f64; 3], radius: f64) -> Result<Option<usize>> {
        check_sphere(&centre, radius)?;
        Ok(self.sphere_touches_unchecked(centre, radius))
    }

    /// [`World::sphere_touches`] without its checks: a centre or radius that is not finite
    /// gives a meaningless answer (never a panic).
    pub fn sphere_touches_unchecked(&self, centre: [f64; 3], radius: f64) -> Option<usize> {
        let c = nalgebra::Point3::from(centre);
        let ball = Compiled {
            center: c,
            bound: radius,
            geometry: crate::shape::Geometry::Round { a: c, b: c, radius },
        };
        let mut placed = Placed::default();
        ball.place(&Isometry3::identity(), &mut placed);
        self.objects.iter().position(|o| {
            !crate::shape::bounds_apart(&placed, &o.placed)
                && crate::shape::intersects(&ball, &placed, &o.compiled, &o.placed)
        })
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

    /// Point clouds and meshes come from files beside the world file; a cloud and a mesh round
    /// trip through RON inline; a missing or malformed file names the entry, its line and the
    /// file.
    #[test]
    fn clouds_and_meshes_load_from_files_beside_the_world() {
        let dir = std::env::temp_dir().join(format!("trm-world-files-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let ply = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nend_header\n0 0 0\n0.1 0 0\nnan 0 0\n";
        std::fs::write(dir.join("scan.ply"), ply).unwrap();
        let mut stl = String::from("solid t\n");
        for f in [[0, 1, 2], [0, 2, 3]] {
            let v = [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 1]];
            stl.push_str("facet normal 0 0 0\n outer loop\n");
            for i in f {
                stl.push_str(&format!(" vertex {} {} {}\n", v[i][0], v[i][1], v[i][2]));
            }
            stl.push_str(" endloop\nendfacet\n");
        }
        stl.push_str("endsolid t\n");
        std::fs::write(dir.join("fold.stl"), stl).unwrap();
        let text = r#"(
    clouds: [(name: "scan", file: "scan.ply", radius: 0.01, xyz: (0.5, 0.0, 0.2))],
    meshes: [(name: "fold", file: "fold.stl", scale: (0.5, 0.5, 0.5))],
)"#;
        let path = dir.join("world.ron");
        std::fs::write(&path, text).unwrap();
        let world = World::load(&path).unwrap();
        let Shape::Points { points, radius } = world.object("scan").unwrap().shape() else {
            panic!("a cloud");
        };
        assert_eq!((points.len(), *radius), (2, 0.01));
        let Shape::Mesh { triangles, .. } = world.object("fold").unwrap().shape() else {
            panic!("a mesh");
        };
        assert_eq!(triangles.len(), 2);
        let again = World::from_spec(&world.to_spec(), "again").unwrap();
        assert_eq!(
            again.object("scan").unwrap().shape(),
            world.object("scan").unwrap().shape()
        );
        let missing = text.replace("fold.stl", "gone.stl");
        std::fs::write(&path, missing).unwrap();
        let e = World::load(&path).unwrap_err().to_string();
        assert!(
            e.contains(":3: meshes[0] (\"fold\")") && e.contains("gone.stl"),
            "{e}"
        );
        for (from, to, says) in [
            (
                "radius: 0.01",
                "radius: -0.01",
                "points radius -0.01 is not a positive",
            ),
            (
                "radius: 0.01",
                "radius: 0.0",
                "points radius 0 is not a positive",
            ),
            (
                "radius: 0.01",
                "radius: inf",
                "not a positive finite number",
            ),
            (
                "name: \"fold\"",
                "name: \"scan\"",
                "names an earlier object too",
            ),
            ("file: \"fold.stl\"", "file: \".\"", "meshes[0]"),
            (
                "scale: (0.5, 0.5, 0.5)",
                "scale: (1e9, 1, 1)",
                "more than 1000 m",
            ),
        ] {
            std::fs::write(&path, text.replace(from, to)).unwrap();
            let e = World::load(&path).unwrap_err().to_string();
            assert!(e.contains(says) && e.contains("world.ron:"), "{to}: {e}");
        }
        std::fs::write(dir.join("scan.ply"), "ply\nformat ascii 1.0\n").unwrap();
        std::fs::write(&path, text).unwrap();
        let e = World::load(&path).unwrap_err().to_string();
        assert!(
            e.contains(":2: clouds[0] (\"scan\")") && e.contains("never ends"),
            "{e}"
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
