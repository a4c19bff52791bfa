//! The collision model of a robot: one body per URDF `<collision>` element, the allowed-collision
//! matrix, and the flat list of body pairs the queries walk.

use parry3d_f64::bounding_volume::Aabb;
use std::path::{Path, PathBuf};
use std::sync::{Arc, OnceLock};

use nalgebra::{Isometry3, Point3};
use trm_kinematics::{PoseBuffer, RobotModel, pose_from_xyz_rpy};

use crate::acm::AllowedCollisionMatrix;
use crate::cull::Culling;
use crate::error::{CollisionError, Result, unknown};
use crate::mesh::{convex_hull_of_mesh, resolve_mesh};
use crate::placed::{BodyPair, PlacedBodies};
use crate::shape::{Compiled, Placed, Shape};

/// How to turn a URDF's `<collision>` elements into bodies.
#[derive(Debug, Clone, Default)]
pub struct CollisionOptions {
    /// Directories searched for `package://NAME/...` mesh URIs (like `ROS_PACKAGE_PATH`).
    pub package_paths: Vec<PathBuf>,
    /// Directory relative mesh paths are resolved against; by default the URDF's directory
    /// when the model was loaded from a file.
    pub urdf_dir: Option<PathBuf>,
}

impl CollisionOptions {
    /// Options that search `package_paths`, then the directories of the `ROS_PACKAGE_PATH`
    /// environment variable, as ROS resolves `package://` URIs.
    pub fn with_ros_package_path(package_paths: Vec<PathBuf>) -> Self {
        let mut package_paths = package_paths;
        if let Some(ros) = std::env::var_os("ROS_PACKAGE_PATH") {
            package_paths.extend(std::env::split_paths(&ros));
        }
        CollisionOptions {
            package_paths,
            ..Default::default()
        }
    }

    /// Where the mesh `uri` of `robot`'s URDF is: searched in these package paths, then the
    /// description's, relative to [`CollisionOptions::urdf_dir`] or else the URDF's directory
    /// ([`crate::mesh::mesh_candidates`]); on failure, every path tried.
    pub fn find_mesh(&self, robot: &RobotModel, uri: &str) -> Result<PathBuf, Vec<PathBuf>> {
        let urdf_dir = self.urdf_dir.clone().or_else(|| link_dir(robot.origin()));
        let package_paths: Vec<PathBuf> = self
            .package_paths
            .iter()
            .chain(robot.package_paths())
            .cloned()
            .collect();
        resolve_mesh(uri, urdf_dir.as_deref(), &package_paths)
    }
}

/// One collision body: a convex shape rigidly attached to a link.
#[derive(Debug, Clone, PartialEq)]
pub struct Body {
    /// Unique name: the link name, or `link#k` for the k-th of several elements of one link.
    pub name: String,
    /// Index of the link in [`trm_kinematics::Tree::links`].
    pub link: usize,
    /// The shape, in its own frame.
    pub shape: Shape,
    /// Pose of the shape frame in the link frame.
    pub local: Isometry3<f64>,
}

/// How a model was made from another ([`CollisionModel::padded`],
/// [`CollisionModel::only_pairs`]).
#[derive(Debug, PartialEq)]
enum Derived {
    /// Padded by a margin, without some link pairs.
    Padded(f64, Vec<[usize; 2]>),
    /// With only some link pairs.
    Only(Vec<[usize; 2]>),
}

#[derive(Debug)]
struct Inner {
    robot: RobotModel,
    bodies: Vec<Body>,
    compiled: Vec<Compiled>,
    acm: AllowedCollisionMatrix,
    pairs: Vec<BodyPair>,
    link_pairs: usize,
    culling: Culling,
    /// What the models made from this one keep.
    kept: Kept,
    /// The model compiled for single-precision checks ([`crate::fast::FastModel::of`]).
    fast: OnceLock<Arc<crate::fast::FastModel>>,
    /// The models made from it so far ([`CollisionModel::padded`],
    /// [`CollisionModel::only_pairs`]), by how they were made.
    derived: std::sync::Mutex<Vec<(Derived, CollisionModel)>>,
}

/// What a model hands on to the models made from it ([`CollisionModel::with_acm`],
/// [`CollisionModel::with_attached`]).
#[derive(Debug, Clone, Default)]
pub(crate) struct Kept {
    /// Objects the robot holds, their bodies among the model's bodies.
    pub(crate) attached: Vec<crate::AttachedObject>,
    /// Every body's [`CollisionModel::enclosing_spheres`] and
    /// [`CollisionModel::inscribed_spheres`], fitted on first use and shared (fitting a
    /// mesh's cells takes milliseconds).
    pub(crate) spheres: Arc<SphereSets>,
    /// Where meshes were searched for.
    pub(crate) options: CollisionOptions,
}

/// Per body, its spheres in its link's frame, each set fitted on first use.
#[derive(Debug, Default)]
pub(crate) struct SphereSets {
    enclosing: OnceLock<Vec<Vec<crate::Sphere>>>,
    inscribed: OnceLock<Vec<Vec<crate::Sphere>>>,
}

/// The collision geometry of a robot with its allowed-collision matrix. Cheap to clone,
/// `Send + Sync`. Build it once, then per configuration: forward kinematics into a
/// [`PoseBuffer`], [`CollisionModel::place`] into a [`PlacedBodies`], then query.
#[derive(Debug, Clone)]
pub struct CollisionModel {
    inner: Arc<Inner>,
}

fn link_dir(origin: &str) -> Option<PathBuf> {
    let path = Path::new(origin);
    path.is_file()
        .then(|| path.parent().map(Path::to_path_buf))
        .flatten()
}

impl CollisionModel {
    /// The smallest axis-aligned boxes enclosing each body of `placed` (placed by this model),
    /// in body order: tighter than [`PlacedBodies::body_boxes`], a little dearer.
    pub fn tight_boxes<'a>(&'a self, placed: &'a PlacedBodies) -> impl Iterator<Item = Aabb> + 'a {
        self.inner
            .compiled
            .iter()
            .zip(&placed.placed)
            .map(|(c, p)| c.tight_box(p))
    }

    /// The vertices of link `link`'s mesh bodies (their convex hulls), in the link frame: what
    /// [`crate::fit::fit`] fits proxies to. Empty for a link without meshes.
    pub fn link_mesh_points(&self, link: usize) -> Vec<nalgebra::Point3<f64>> {
        self.bodies()
            .iter()
            .filter(|b| b.link == link)
            .flat_map(|b| match &b.shape {
                Shape::Convex { points } => points
                    .iter()
                    .map(|v| b.local * nalgebra::Point3::new(v[0], v[1], v[2]))
                    .collect(),
                _ => Vec::new(),
            })
            .collect()
    }

    /// Bodies from the URDF's `<collision>` elements and the allowed-collision matrix of the
    /// model description ([`AllowedCollisionMatrix::from_model`]); meshes are found relative to
    /// the URDF, in the description's `package_paths` and in `ROS_PACKAGE_PATH`.
    pub fn new(robot: &RobotModel) -> Result<Self> {
        Self::with_options(robot, &CollisionOptions::with_ros_package_path(Vec::new()))
    }

    /// As [`CollisionModel::new`], `package://` meshes searched in `package_paths` first (then
    /// the description's, then `ROS_PACKAGE_PATH`): what every `--package-path` flag and
    /// Python's `package_paths=` give.
    pub fn with_package_paths(robot: &RobotModel, package_paths: Vec<PathBuf>) -> Result<Self> {
        Self::with_options(
            robot,
            &CollisionOptions::with_ros_package_path(package_paths),
        )
    }

    /// As [`CollisionModel::new`], with mesh search paths (searched before the description's
    /// `package_paths`; `ROS_PACKAGE_PATH` only as `options` give it).
    pub fn with_options(robot: &RobotModel, options: &CollisionOptions) -> Result<Self> {
        let bodies = bodies_from_urdf(robot, options)?;
        let has = has_geometry(robot.num_links(), &bodies);
        let acm = AllowedCollisionMatrix::from_model(robot, &has);
        let kept = Kept {
            options: options.clone(),
            ..Kept::default()
        };
        Self::build(robot, bodies, acm, kept)
    }

    /// Where the model's meshes were searched for (the options it was built with; the
    /// defaults for [`CollisionModel::from_bodies`]): the URDF's other meshes, its visuals
    /// say, are found the same way.
    pub fn options(&self) -> &CollisionOptions {
        &self.inner.kept.options
    }

    /// A collision model from bodies of your own (e.g. simplified proxies) and a matrix.
    pub fn from_bodies(
        robot: &RobotModel,
        bodies: Vec<Body>,
        acm: AllowedCollisionMatrix,
    ) -> Result<Self> {
        Self::build(robot, bodies, acm, Kept::default())
    }

    /// [`CollisionModel::from_bodies`] with what a model carries over to the models made
    /// from it: the objects it holds (their bodies among `bodies`), the bodies' spheres
    /// (fitted or still to fit) and its mesh search options.
    pub(crate) fn build(
        robot: &RobotModel,
        mut bodies: Vec<Body>,
        acm: AllowedCollisionMatrix,
        kept: Kept,
    ) -> Result<Self> {
        let attached = &kept.attached;
        if acm.num_links() != robot.num_links() {
            return Err(CollisionError::InvalidValue {
                what: "allowed-collision matrix".into(),
                problem: format!(
                    "covers {} links but the robot has {}",
                    acm.num_links(),
                    robot.num_links()
                ),
            });
        }
        bodies.sort_by_key(|b| b.link);
        let mut compiled = Vec::with_capacity(bodies.len());
        for (i, b) in bodies.iter().enumerate() {
            if b.link >= robot.num_links() {
                return Err(CollisionError::InvalidValue {
                    what: format!("body `{}`", b.name),
                    problem: format!("link index {} out of range", b.link),
                });
            }
            if bodies[..i].iter().any(|o| o.name == b.name) {
                return Err(CollisionError::InvalidValue {
                    what: format!("body `{}`", b.name),
                    problem: "the name is used twice".into(),
                });
            }
            let element = format!("body `{}`", b.name);
            if !b.shape.is_convex() {
                return Err(CollisionError::InvalidShape {
                    origin: robot.origin().to_string(),
                    line: None,
                    element,
                    problem: format!("a link's body cannot be a {}", b.shape.kind()),
                    fix: "give links convex bodies (a mesh's convex hull: Shape::Convex); point \
                          clouds and triangle meshes are world objects"
                        .into(),
                });
            }
            compiled.push(b.shape.compile(&b.local).ok_or_else(|| {
                let p = b
                    .shape
                    .check()
                    .err()
                    .unwrap_or_else(|| crate::ShapeProblem {
                        problem: "unusable shape".into(),
                        fix: "use another shape".into(),
                    });
                CollisionError::InvalidShape {
                    origin: robot.origin().to_string(),
                    line: None,
                    element,
                    problem: p.problem,
                    fix: p.fix,
                }
            })?);
        }
        // a held object's bodies are checked against every other link but its touch links,
        // whatever the matrix says of its holding link (as MoveIt checks attached objects)
        let touching: Vec<Option<Vec<usize>>> = bodies
            .iter()
            .map(|b| {
                let o = attached.iter().find(|o| o.holds(&b.name))?;
                let mut links = o.touch_link_indices(robot.tree());
                links.push(b.link);
                Some(links)
            })
            .collect();
        let checked = |i: usize, j: usize| match (&touching[i], &touching[j]) {
            (Some(exempt), _) if !exempt.contains(&bodies[j].link) => true,
            (_, Some(exempt)) if !exempt.contains(&bodies[i].link) => true,
            (None, None) => acm.is_checked(bodies[i].link, bodies[j].link),
            _ => false,
        };
        let (pairs, link_pairs) = body_pairs(&bodies, checked);
        let links: Vec<usize> = bodies.iter().map(|b| b.link).collect();
        let culling = Culling::new(robot.tree(), &links, &compiled, &pairs);
        Ok(CollisionModel {
            inner: Arc::new(Inner {
                robot: robot.clone(),
                bodies,
                compiled,
                acm,
                pairs,
                link_pairs,
                culling,
                kept,
                fast: OnceLock::new(),
                derived: Default::default(),
            }),
        })
    }

    /// The same bodies with another allowed-collision matrix.
    pub fn with_acm(&self, acm: AllowedCollisionMatrix) -> Result<Self> {
        Self::build(
            &self.inner.robot,
            self.inner.bodies.clone(),
            acm,
            self.inner.kept.clone(),
        )
    }

    /// The robot.
    pub fn robot(&self) -> &RobotModel {
        &self.inner.robot
    }

    /// The bodies, sorted by link.
    pub fn bodies(&self) -> &[Body] {
        &self.inner.bodies
    }

    /// The spheres enclosing body `body` completely ([`crate::Shape::enclosing_spheres`]) in
    /// its link's frame: a sphere model of the robot, e.g. for sphere-based planners. Every
    /// body's are fitted on the first call, then kept.
    ///
    /// # Panics
    /// If `body` is out of range.
    pub fn enclosing_spheres(&self, body: usize) -> &[crate::Sphere] {
        let all = self
            .inner
            .kept
            .spheres
            .enclosing
            .get_or_init(|| self.in_link_frames(crate::Shape::enclosing_spheres));
        &all[body]
    }

    /// Spheres wholly inside body `body` ([`crate::Shape::inscribed_spheres`]) in its link's
    /// frame: whatever touches one touches the body. Every body's are fitted on the first
    /// call, then kept.
    ///
    /// # Panics
    /// If `body` is out of range.
    pub fn inscribed_spheres(&self, body: usize) -> &[crate::Sphere] {
        let all = self
            .inner
            .kept
            .spheres
            .inscribed
            .get_or_init(|| self.in_link_frames(crate::Shape::inscribed_spheres));
        &all[body]
    }

    /// `spheres` of every body's shape, moved into its link's frame.
    fn in_link_frames(
        &self,
        spheres: impl Fn(&crate::Shape) -> Vec<crate::Sphere>,
    ) -> Vec<Vec<crate::Sphere>> {
        self.inner
            .bodies
            .iter()
            .map(|b| {
                let mut spheres = spheres(&b.shape);
                for s in &mut spheres {
                    s.center = b.local * s.center;
                }
                spheres
            })
            .collect()
    }

    /// Index of the body with this name.
    pub fn body_index(&self, name: &str) -> Result<usize> {
        self.inner
            .bodies
            .iter()
            .position(|b| b.name == name)
            .ok_or_else(|| {
                unknown(
                    "collision body",
                    name,
                    self.inner.bodies.iter().map(|b| b.name.as_str()),
                )
            })
    }

    /// The allowed-collision matrix in use.
    pub fn acm(&self) -> &AllowedCollisionMatrix {
        &self.inner.acm
    }

    /// Per link: whether it has at least one body.
    pub fn has_geometry(&self) -> Vec<bool> {
        has_geometry(self.inner.robot.num_links(), &self.inner.bodies)
    }

    /// Number of link pairs self-collision checking tests.
    pub fn num_checked_link_pairs(&self) -> usize {
        self.inner.link_pairs
    }

    /// Number of body pairs self-collision checking tests.
    pub fn num_checked_body_pairs(&self) -> usize {
        self.inner.pairs.len()
    }

    /// A scratch buffer for [`CollisionModel::place`].
    pub fn placed_bodies(&self) -> PlacedBodies {
        PlacedBodies {
            placed: vec![Placed::default(); self.inner.bodies.len()],
            origins: vec![Point3::origin(); self.inner.culling.origin_links.len()],
        }
    }

    /// Moves every body to the world pose of its link (no allocation).
    ///
    /// # Panics
    /// If the buffers do not belong to this model (wrong lengths).
    pub fn place(&self, poses: &PoseBuffer, out: &mut PlacedBodies) {
        let links = poses.poses();
        for ((b, c), p) in self
            .inner
            .bodies
            .iter()
            .zip(&self.inner.compiled)
            .zip(out.placed.iter_mut())
        {
            c.place(&links[b.link], p);
        }
        for (o, &l) in out.origins.iter_mut().zip(&self.inner.culling.origin_links) {
            *o = links[l as usize].translation.vector.into();
        }
    }

    /// Moves body `body` alone to the world pose of its link (the others keep their places).
    pub(crate) fn place_body(&self, poses: &PoseBuffer, body: usize, out: &mut PlacedBodies) {
        let b = &self.inner.bodies[body];
        self.inner.compiled[body].place(&poses.poses()[b.link], &mut out.placed[body]);
    }

    /// Whether `active` moves this model's robot (an error naming both robots otherwise).
    pub fn check_active(&self, active: &trm_kinematics::ActiveSet) -> Result<()> {
        let robot = self.robot();
        if active.model().num_frames() != robot.num_frames()
            || active.model().name() != robot.name()
        {
            return Err(CollisionError::InvalidValue {
                what: format!("active set of `{}`", active.model().name()),
                problem: format!("belongs to another robot than `{}`", robot.name()),
            });
        }
        Ok(())
    }

    /// The objects the robot holds ([`CollisionModel::with_attached`]).
    pub fn attached(&self) -> &[crate::AttachedObject] {
        &self.inner.kept.attached
    }

    /// Sphere sets for `bodies`: those already fitted for this model's bodies of the same
    /// name kept, the others fitted on first use with the rest.
    pub(crate) fn carried_spheres(&self, bodies: &[Body]) -> Arc<SphereSets> {
        let carry = |old: &OnceLock<Vec<Vec<crate::Sphere>>>,
                     fit: fn(&crate::Shape) -> Vec<crate::Sphere>| {
            let cell = OnceLock::new();
            if let Some(old) = old.get() {
                let sets = bodies
                    .iter()
                    .map(|b| match self.body_index(&b.name) {
                        Ok(i) if self.inner.bodies[i].shape == b.shape => old[i].clone(),
                        _ => {
                            let mut spheres = fit(&b.shape);
                            for s in &mut spheres {
                                s.center = b.local * s.center;
                            }
                            spheres
                        }
                    })
                    .collect();
                let _ = cell.set(sets);
            }
            cell
        };
        let spheres = &self.inner.kept.spheres;
        Arc::new(SphereSets {
            enclosing: carry(&spheres.enclosing, crate::Shape::enclosing_spheres),
            inscribed: carry(&spheres.inscribed, crate::Shape::inscribed_spheres),
        })
    }

    /// The robot's own bodies' model with `attached` objects held (their bodies among
    /// `bodies`).
    pub(crate) fn holding(
        &self,
        mut bodies: Vec<Body>,
        attached: Vec<crate::AttachedObject>,
    ) -> Result<Self> {
        // in the order the model keeps them (by link), so that the spheres carried over line
        // up with the bodies
        bodies.sort_by_key(|b| b.link);
        let kept = Kept {
            attached,
            spheres: self.carried_spheres(&bodies),
            options: self.inner.kept.options.clone(),
        };
        let acm = self.inner.acm.clone();
        Self::build(&self.inner.robot, bodies, acm, kept)
    }

    /// The same robot with every body grown by `margin` (m, finite and positive;
    /// [`crate::Shape::grown`]) and the link pairs `unchecked` no longer checked, the same
    /// matrix otherwise and the same held objects: wherever it is free of a world, each body of
    /// this model keeps at least `margin` from every object it is checked against, and
    /// 2·`margin` from every body it is still checked against. Its spheres are this model's
    /// grown by what the bodies grow ([`crate::Shape::growth`]): nothing is fitted again. Made
    /// once per margin and pairs, then shared.
    pub fn padded(&self, margin: f64, unchecked: &[[usize; 2]]) -> Result<Self> {
        if !(margin.is_finite() && margin > 0.0) {
            return Err(CollisionError::InvalidValue {
                what: "a padding".into(),
                problem: format!("{margin} is not a positive distance (m)"),
            });
        }
        let mut acm = self.inner.acm.clone();
        for &[a, b] in unchecked {
            acm.disable(a, b, trm_kinematics::DisableReason::User);
        }
        let key = Derived::Padded(margin, unchecked.to_vec());
        self.derived(key, || self.pad(margin, acm))
    }

    /// The same model checking only the link pairs `pairs` of those it checks (and its held
    /// objects, always checked). Made once per pairs, then shared.
    pub(crate) fn only_pairs(&self, pairs: &[[usize; 2]]) -> Result<Self> {
        let mut acm = self.inner.acm.clone();
        for [a, b] in self.checked_link_pairs() {
            if !pairs.contains(&[a, b]) && !pairs.contains(&[b, a]) {
                acm.disable(a, b, trm_kinematics::DisableReason::User);
            }
        }
        let key = Derived::Only(pairs.to_vec());
        self.derived(key, || {
            let bodies = self.inner.bodies.clone();
            Self::build(&self.inner.robot, bodies, acm, self.inner.kept.clone())
        })
    }

    /// The link pairs with checked body pairs, each once.
    pub(crate) fn checked_link_pairs(&self) -> Vec<[usize; 2]> {
        let bodies = &self.inner.bodies;
        let mut out: Vec<[usize; 2]> = (self.inner.pairs.iter())
            .map(|p| [bodies[p.a as usize].link, bodies[p.b as usize].link])
            .collect();
        out.dedup();
        out
    }

    /// The model made as `key` says: the one made before, or `make`'s, kept.
    fn derived(&self, key: Derived, make: impl FnOnce() -> Result<Self>) -> Result<Self> {
        let mut made = self.inner.derived.lock().unwrap_or_else(|e| e.into_inner());
        if let Some((_, model)) = made.iter().find(|(k, _)| *k == key) {
            return Ok(model.clone());
        }
        let model = make()?;
        made.push((key, model.clone()));
        Ok(model)
    }

    /// This model's bodies grown by `margin`, checked as `acm` says.
    fn pad(&self, margin: f64, acm: AllowedCollisionMatrix) -> Result<Self> {
        let bodies: Vec<Body> = (self.bodies().iter())
            .map(|b| Body {
                shape: b.shape.grown(margin).expect("a link's bodies are convex"),
                ..b.clone()
            })
            .collect();
        let spheres = |sets: Vec<Vec<crate::Sphere>>, grown: bool| {
            let cell = OnceLock::new();
            let sets = sets.into_iter().zip(self.bodies()).map(|(mut set, b)| {
                for s in set.iter_mut().filter(|_| grown) {
                    s.radius += margin * b.shape.growth();
                }
                set
            });
            let _ = cell.set(sets.collect());
            cell
        };
        let all = |of: fn(&Self, usize) -> &[crate::Sphere]| {
            (0..bodies.len()).map(|b| of(self, b).to_vec()).collect()
        };
        let kept = Kept {
            spheres: Arc::new(SphereSets {
                // the grown bodies lie within this model's enclosing spheres grown as much, and
                // hold its inscribed ones
                enclosing: spheres(all(Self::enclosing_spheres), true),
                inscribed: spheres(all(Self::inscribed_spheres), false),
            }),
            ..self.inner.kept.clone()
        };
        Self::build(&self.inner.robot, bodies, acm, kept)
    }

    /// Where [`crate::fast::FastModel::of`] keeps this model's compilation.
    pub(crate) fn fast_cell(&self) -> &OnceLock<Arc<crate::fast::FastModel>> {
        &self.inner.fast
    }

    pub(crate) fn compiled(&self) -> &[Compiled] {
        &self.inner.compiled
    }

    pub(crate) fn pairs(&self) -> &[BodyPair] {
        &self.inner.pairs
    }

    pub(crate) fn culling(&self) -> &Culling {
        &self.inner.culling
    }
}

fn has_geometry(links: usize, bodies: &[Body]) -> Vec<bool> {
    let mut has = vec![false; links];
    for b in bodies {
        has[b.link] = true;
    }
    has
}

/// Checked body pairs grouped by link pair, and the number of link pairs.
fn body_pairs(bodies: &[Body], checked: impl Fn(usize, usize) -> bool) -> (Vec<BodyPair>, usize) {
    let mut groups: std::collections::BTreeMap<[usize; 2], Vec<(u32, u32)>> = Default::default();
    for i in 0..bodies.len() {
        for j in i + 1..bodies.len() {
            let (la, lb) = (bodies[i].link, bodies[j].link);
            if !checked(i, j) {
                continue;
            }
            groups
                .entry([la.min(lb), la.max(lb)])
                .or_default()
                .push((i as u32, j as u32));
        }
    }
    let mut pairs = Vec::new();
    for members in groups.values() {
        let next = (pairs.len() + members.len()) as u32;
        pairs.extend(members.iter().map(|&(a, b)| BodyPair { a, b, next }));
    }
    (pairs, groups.len())
}

fn bodies_from_urdf(robot: &RobotModel, options: &CollisionOptions) -> Result<Vec<Body>> {
    let mut bodies = Vec::new();
    for (index, link) in robot.tree().links.iter().enumerate() {
        let several = link.collisions.len() > 1;
        for (k, c) in link.collisions.iter().enumerate() {
            let element = if several {
                format!("<collision> {} of <link name=\"{}\">", k + 1, link.name)
            } else {
                format!("<collision> of <link name=\"{}\">", link.name)
            };
            let invalid = |problem: String, fix: String| CollisionError::InvalidShape {
                origin: robot.origin().to_string(),
                line: link.line,
                element: element.clone(),
                problem,
                fix,
            };
            let (xyz, rpy) = (c.origin.xyz.0, c.origin.rpy.0);
            if xyz.iter().chain(&rpy).any(|v| !v.is_finite()) {
                return Err(invalid(
                    "its <origin> is not finite".into(),
                    "write finite numbers".into(),
                ));
            }
            let shape = match Shape::from_urdf(&c.geometry) {
                Some(s) => s,
                None => {
                    let trm_kinematics::urdf_rs::Geometry::Mesh { filename, scale } = &c.geometry
                    else {
                        unreachable!("from_urdf converts every geometry but meshes")
                    };
                    let path = options.find_mesh(robot, filename).map_err(|tried| {
                        CollisionError::MeshNotFound {
                            origin: robot.origin().to_string(),
                            line: link.line,
                            element: element.clone(),
                            uri: filename.clone(),
                            tried,
                        }
                    })?;
                    let scale = scale.map_or([1.0; 3], |s| s.0);
                    let points = convex_hull_of_mesh(&path, scale).map_err(|message| {
                        CollisionError::MeshUnreadable {
                            path: path.clone(),
                            origin: robot.origin().to_string(),
                            element: element.clone(),
                            message,
                        }
                    })?;
                    Shape::Convex { points }
                }
            };
            shape.check().map_err(|p| invalid(p.problem, p.fix))?;
            bodies.push(Body {
                name: if several {
                    format!("{}#{}", link.name, k + 1)
                } else {
                    link.name.clone()
                },
                link: index,
                shape,
                local: pose_from_xyz_rpy(xyz, rpy),
            });
        }
    }
    Ok(bodies)
}
