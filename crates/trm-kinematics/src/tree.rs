//! The kinematic tree read from URDF: links in topological order and the joints between them.

use std::collections::HashMap;

use nalgebra::{Isometry3, Translation3, Unit, UnitQuaternion, Vector3};

use crate::error::{KinematicsError, Result, line_of_element};

/// How a joint moves its child link.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum JointKind {
    /// Rotation about the axis within limits.
    Revolute,
    /// Rotation about the axis without limits.
    Continuous,
    /// Translation along the axis within limits.
    Prismatic,
    /// No motion.
    Fixed,
}

impl JointKind {
    /// Whether the joint has a coordinate (is not fixed).
    pub fn is_movable(self) -> bool {
        self != JointKind::Fixed
    }
}

/// Position (and velocity/effort) limits of a joint, in SI units (rad, m).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Limits {
    /// Lowest position.
    pub lower: f64,
    /// Highest position.
    pub upper: f64,
    /// Largest speed (rad/s or m/s); infinite when the URDF gives none.
    pub velocity: f64,
    /// Largest effort (N·m or N); infinite when the URDF gives none.
    pub effort: f64,
    /// Largest acceleration (rad/s² or m/s²); infinite unless the model description's
    /// `motion_limits` give one (a URDF has none).
    pub acceleration: f64,
    /// Largest jerk (rad/s³ or m/s³); infinite unless the model description gives one.
    pub jerk: f64,
}

impl Limits {
    /// Whether `value` lies within `[lower, upper]`.
    pub fn contains(&self, value: f64) -> bool {
        value >= self.lower && value <= self.upper
    }

    /// Checks a value read from a file: finite and within `[lower, upper]` up to
    /// [`LIMIT_TOLERANCE`] (values written with fewer digits may round just past a limit).
    pub fn check(&self, value: f64) -> Result<(), String> {
        if !value.is_finite() {
            return Err(format!("is {value}, not a finite number"));
        }
        if value < self.lower - LIMIT_TOLERANCE || value > self.upper + LIMIT_TOLERANCE {
            return Err(format!(
                "is {value}, outside its limits [{}, {}]",
                self.lower, self.upper
            ));
        }
        Ok(())
    }
}

/// How far past a limit a value read from a file may lie and still count as inside it.
pub const LIMIT_TOLERANCE: f64 = 1e-6;

/// A link of the tree.
#[derive(Debug, Clone)]
pub struct Link {
    /// URDF name.
    pub name: String,
    /// Index of the parent link (`None` for the root).
    pub parent: Option<usize>,
    /// Index of the joint that connects the parent to this link.
    pub parent_joint: Option<usize>,
    /// The link's URDF `<collision>` elements, as written (mesh files are not opened here).
    pub collisions: Vec<urdf_rs::Collision>,
    /// The link's URDF `<visual>` elements, as written, except that a material named without a
    /// colour takes the colour of the robot-level `<material>` of that name.
    pub visuals: Vec<urdf_rs::Visual>,
    /// Line of the `<link>` element in the URDF text, when known.
    pub line: Option<usize>,
    /// Mass properties (zero mass when the URDF gives no `<inertial>`).
    pub inertial: Inertial,
}

/// A link's mass properties, in the link frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Inertial {
    /// Mass, kg.
    pub mass: f64,
    /// Centre of mass in the link frame.
    pub com: Vector3<f64>,
    /// Inertia tensor about the centre of mass, in link-frame axes.
    pub inertia: nalgebra::Matrix3<f64>,
}

impl Inertial {
    fn from_urdf(i: &urdf_rs::Inertial) -> Self {
        let pose = pose_from_xyz_rpy(i.origin.xyz.0, i.origin.rpy.0);
        let t = &i.inertia;
        let local = nalgebra::Matrix3::new(
            t.ixx, t.ixy, t.ixz, t.ixy, t.iyy, t.iyz, t.ixz, t.iyz, t.izz,
        );
        let r = pose.rotation.to_rotation_matrix();
        Inertial {
            mass: i.mass.value,
            com: pose.translation.vector,
            inertia: r.matrix() * local * r.matrix().transpose(),
        }
    }
}

/// A URDF joint `<mimic>` element: `value = multiplier · leader + offset`.
#[derive(Debug, Clone, PartialEq)]
pub struct Mimic {
    /// The joint that is followed.
    pub leader: String,
    /// Factor on the leader's value.
    pub multiplier: f64,
    /// Added offset.
    pub offset: f64,
}

/// A joint of the tree.
#[derive(Debug, Clone)]
pub struct Joint {
    /// URDF name.
    pub name: String,
    /// Motion type.
    pub kind: JointKind,
    /// Parent link index.
    pub parent: usize,
    /// Child link index.
    pub child: usize,
    /// Pose of the joint frame in the parent link frame (URDF `<origin>`).
    pub local_origin: Isometry3<f64>,
    /// Unit axis in the joint frame.
    pub axis: Unit<Vector3<f64>>,
    /// Limits (continuous joints: ±∞ position).
    pub limits: Limits,
    /// `<mimic>`, if present.
    pub mimic: Option<Mimic>,
    /// Index in the joint-value vector (movable joints only).
    pub coordinate: Option<usize>,
}

/// A URDF link tree: links in depth-first order from the root (parents before children), the
/// joints ordered like their child links, and the movable joints numbered in that order (the
/// order Pinocchio uses).
#[derive(Debug, Clone)]
pub struct Tree {
    /// The robot name from `<robot name>`.
    pub name: String,
    /// Links; index 0 is the root.
    pub links: Vec<Link>,
    /// Joints; `joints[i].child == i + 1`.
    pub joints: Vec<Joint>,
    /// Indices into `joints` of the movable joints, in coordinate order.
    pub movable: Vec<usize>,
}

pub(crate) struct Ctx<'a> {
    pub origin: &'a str,
    pub source: Option<&'a str>,
}

impl Ctx<'_> {
    pub fn invalid(
        &self,
        tag: &str,
        name: &str,
        problem: impl Into<String>,
        fix: impl Into<String>,
    ) -> KinematicsError {
        KinematicsError::InvalidModel {
            origin: self.origin.to_string(),
            line: self.source.and_then(|s| line_of_element(s, tag, name)),
            element: format!("<{tag} name=\"{name}\">"),
            problem: problem.into(),
            fix: fix.into(),
        }
    }
}

fn check_finite(ctx: &Ctx, tag: &str, name: &str, what: &str, values: &[f64]) -> Result<()> {
    if values.iter().any(|v| !v.is_finite()) {
        return Err(ctx.invalid(
            tag,
            name,
            format!("{what} {values:?} is not finite"),
            "write finite numbers",
        ));
    }
    Ok(())
}

/// The six numbers of a URDF `<origin>`.
fn pose_numbers(p: &urdf_rs::Pose) -> [f64; 6] {
    [p.xyz[0], p.xyz[1], p.xyz[2], p.rpy[0], p.rpy[1], p.rpy[2]]
}

/// The sizes of a URDF `<geometry>` (a mesh's scale).
fn geometry_numbers(g: &urdf_rs::Geometry) -> Vec<f64> {
    match g {
        urdf_rs::Geometry::Box { size } => size.to_vec(),
        urdf_rs::Geometry::Cylinder { radius, length }
        | urdf_rs::Geometry::Capsule { radius, length } => vec![*radius, *length],
        urdf_rs::Geometry::Sphere { radius } => vec![*radius],
        urdf_rs::Geometry::Mesh { scale, .. } => scale.as_ref().map_or(Vec::new(), |s| s.to_vec()),
    }
}

/// Each link's index in the document, the robot given at least one link and names unique.
fn link_index<'a>(robot: &'a urdf_rs::Robot, ctx: &Ctx) -> Result<HashMap<&'a str, usize>> {
    if robot.links.is_empty() {
        return Err(ctx.invalid(
            "robot",
            &robot.name,
            "has no <link>",
            "add at least one <link>",
        ));
    }
    let mut link_index: HashMap<&str, usize> = HashMap::new();
    for (i, l) in robot.links.iter().enumerate() {
        if link_index.insert(l.name.as_str(), i).is_some() {
            return Err(ctx.invalid(
                "link",
                &l.name,
                "is defined twice",
                "give every <link> a unique name",
            ));
        }
    }
    Ok(link_index)
}

/// Every link's numbers finite (inertia, origins, geometry) and its mass ≥ 0.
fn check_links(robot: &urdf_rs::Robot, ctx: &Ctx) -> Result<()> {
    for l in &robot.links {
        let i = &l.inertial;
        let t = &i.inertia;
        check_finite(
            ctx,
            "link",
            &l.name,
            "inertial",
            &[i.mass.value, t.ixx, t.ixy, t.ixz, t.iyy, t.iyz, t.izz],
        )?;
        check_finite(
            ctx,
            "link",
            &l.name,
            "inertial origin",
            &pose_numbers(&i.origin),
        )?;
        let shapes = (l
            .collision
            .iter()
            .map(|c| ("collision", &c.origin, &c.geometry)))
        .chain(l.visual.iter().map(|v| ("visual", &v.origin, &v.geometry)));
        for (what, origin, geometry) in shapes {
            check_finite(
                ctx,
                "link",
                &l.name,
                &format!("{what} origin"),
                &pose_numbers(origin),
            )?;
            // (sizes are checked where shapes are made: trm-collision)
            let size = geometry_numbers(geometry);
            check_finite(ctx, "link", &l.name, &format!("{what} geometry"), &size)?;
        }
        if i.mass.value < 0.0 {
            return Err(ctx.invalid(
                "link",
                &l.name,
                format!("mass {} is negative", i.mass.value),
                "give a mass ≥ 0 in kg",
            ));
        }
    }
    Ok(())
}

/// Per link: its parent joint (none for the root) and its child joints.
type Joined = (Vec<Option<usize>>, Vec<Vec<usize>>);

/// Each link's parent joint and each link's child joints, every joint joining two defined,
/// different links, each link the child of one joint at most.
fn connect(robot: &urdf_rs::Robot, link_index: &HashMap<&str, usize>, ctx: &Ctx) -> Result<Joined> {
    let mut joint_names: HashMap<&str, ()> = HashMap::new();
    let mut parent_of: Vec<Option<usize>> = vec![None; robot.links.len()];
    let mut children: Vec<Vec<usize>> = vec![Vec::new(); robot.links.len()];
    for (j, joint) in robot.joints.iter().enumerate() {
        if joint_names.insert(joint.name.as_str(), ()).is_some() {
            return Err(ctx.invalid(
                "joint",
                &joint.name,
                "is defined twice",
                "give every <joint> a unique name",
            ));
        }
        let find = |link: &str, role: &str| {
            link_index.get(link).copied().ok_or_else(|| {
                let near = trm_io::closest_names(link, robot.links.iter().map(|l| l.name.as_str()));
                ctx.invalid(
                    "joint",
                    &joint.name,
                    format!("its {role} link `{link}` is not defined"),
                    if near.is_empty() {
                        format!("add <link name=\"{link}\"/> or correct the <{role}> element")
                    } else {
                        format!(
                            "did you mean `{}`? otherwise add <link name=\"{link}\"/>",
                            near.join("`, `")
                        )
                    },
                )
            })
        };
        let parent = find(&joint.parent.link, "parent")?;
        let child = find(&joint.child.link, "child")?;
        if parent == child {
            return Err(ctx.invalid(
                "joint",
                &joint.name,
                "connects a link to itself",
                "use two different links",
            ));
        }
        if let Some(previous) = parent_of[child] {
            return Err(ctx.invalid(
                "joint",
                &joint.name,
                format!(
                    "link `{}` already has parent joint `{}`; a URDF must be a tree",
                    joint.child.link, robot.joints[previous].name
                ),
                "remove one of the two joints (closed chains are not supported)",
            ));
        }
        parent_of[child] = Some(j);
        children[parent].push(j);
    }
    Ok((parent_of, children))
}

/// The links in depth-first pre-order from the one root (children in document order); an
/// error when there is no single root or a link is unreachable.
fn depth_first(
    robot: &urdf_rs::Robot,
    link_index: &HashMap<&str, usize>,
    parent_of: &[Option<usize>],
    children: &[Vec<usize>],
    ctx: &Ctx,
) -> Result<Vec<usize>> {
    let roots: Vec<usize> = (0..robot.links.len())
        .filter(|&i| parent_of[i].is_none())
        .collect();
    if roots.len() != 1 {
        let names: Vec<&str> = roots
            .iter()
            .map(|&i| robot.links[i].name.as_str())
            .collect();
        return Err(if roots.is_empty() {
            ctx.invalid(
                "robot",
                &robot.name,
                "has no root link: the joints form a cycle",
                "break the cycle",
            )
        } else {
            ctx.invalid(
                "robot",
                &robot.name,
                format!("has {} root links ({}); a URDF tree has exactly one", roots.len(), names.join(", ")),
                "connect the extra roots to the tree with joints (a <fixed> joint if they do not move)",
            )
        });
    }
    // Depth-first pre-order, children in document order.
    let mut order: Vec<usize> = Vec::with_capacity(robot.links.len());
    let mut stack = vec![roots[0]];
    while let Some(l) = stack.pop() {
        order.push(l);
        for &j in children[l].iter().rev() {
            stack.push(link_index[robot.joints[j].child.link.as_str()]);
        }
    }
    if order.len() != robot.links.len() {
        let reached: std::collections::HashSet<usize> = order.iter().copied().collect();
        let lost = (0..robot.links.len())
            .find(|i| !reached.contains(i))
            .unwrap_or(0);
        return Err(ctx.invalid(
            "link",
            &robot.links[lost].name,
            "is part of a cycle of joints, unreachable from the root",
            "break the cycle",
        ));
    }
    Ok(order)
}

/// The pose a URDF `<origin xyz rpy>` describes (R = Rz(yaw)·Ry(pitch)·Rx(roll)).
pub fn pose_from_xyz_rpy(xyz: [f64; 3], rpy: [f64; 3]) -> Isometry3<f64> {
    Isometry3::from_parts(
        Translation3::new(xyz[0], xyz[1], xyz[2]),
        UnitQuaternion::from_euler_angles(rpy[0], rpy[1], rpy[2]),
    )
}

impl Tree {
    /// Builds and validates the tree. `source` (the URDF text), when given, lets errors name lines.
    pub(crate) fn from_urdf(robot: &urdf_rs::Robot, ctx: &Ctx) -> Result<Tree> {
        let link_index = link_index(robot, ctx)?;
        check_links(robot, ctx)?;
        let (parent_of, children) = connect(robot, &link_index, ctx)?;
        let order = depth_first(robot, &link_index, &parent_of, &children, ctx)?;
        let mut new_index = vec![0usize; robot.links.len()];
        for (new, &old) in order.iter().enumerate() {
            new_index[old] = new;
        }
        let mut links = Vec::with_capacity(order.len());
        let mut joints = Vec::with_capacity(order.len() - 1);
        let mut movable = Vec::new();
        for (new, &old) in order.iter().enumerate() {
            let parent_joint = parent_of[old].map(|j| &robot.joints[j]);
            links.push(Link {
                name: robot.links[old].name.clone(),
                parent: parent_joint.map(|j| new_index[link_index[j.parent.link.as_str()]]),
                parent_joint: parent_joint.map(|_| new - 1),
                collisions: robot.links[old].collision.clone(),
                visuals: visuals_of(robot, &robot.links[old]),
                line: ctx
                    .source
                    .and_then(|src| line_of_element(src, "link", &robot.links[old].name)),
                inertial: Inertial::from_urdf(&robot.links[old].inertial),
            });
            if let Some(uj) = parent_joint {
                let mut joint =
                    convert_joint(uj, new_index[link_index[uj.parent.link.as_str()]], new, ctx)?;
                if joint.kind.is_movable() {
                    joint.coordinate = Some(movable.len());
                    movable.push(joints.len());
                }
                joints.push(joint);
            }
        }
        let tree = Tree {
            name: robot.name.clone(),
            links,
            joints,
            movable,
        };
        tree.check_mimics(ctx)?;
        Ok(tree)
    }

    fn check_mimics(&self, ctx: &Ctx) -> Result<()> {
        for joint in &self.joints {
            let Some(mimic) = &joint.mimic else { continue };
            let Some(leader) = self.joints.iter().find(|j| j.name == mimic.leader) else {
                let near = trm_io::closest_names(
                    &mimic.leader,
                    self.joints.iter().map(|j| j.name.as_str()),
                );
                return Err(ctx.invalid(
                    "joint",
                    &joint.name,
                    format!("<mimic joint=\"{}\"> names no joint", mimic.leader),
                    if near.is_empty() {
                        "name an existing joint".into()
                    } else {
                        format!("did you mean `{}`?", near.join("`, `"))
                    },
                ));
            };
            if !leader.kind.is_movable() {
                return Err(ctx.invalid(
                    "joint",
                    &joint.name,
                    format!("mimics the fixed joint `{}`", leader.name),
                    "mimic a movable joint",
                ));
            }
            if leader.mimic.is_some() {
                return Err(ctx.invalid(
                    "joint",
                    &joint.name,
                    format!(
                        "mimics `{}`, which itself mimics another joint",
                        leader.name
                    ),
                    "make every mimic joint follow an independent joint",
                ));
            }
        }
        Ok(())
    }

    /// Index of the link called `name`.
    pub fn link_index(&self, name: &str) -> Option<usize> {
        self.links.iter().position(|l| l.name == name)
    }

    /// Index (into `joints`) of the joint called `name`.
    pub fn joint_index(&self, name: &str) -> Option<usize> {
        self.joints.iter().position(|j| j.name == name)
    }

    /// The link `link` is rigidly attached to: its nearest ancestor (itself included) whose
    /// parent joint is movable, or the root, and `link`'s pose in that link's frame, the same
    /// in every configuration (the fixed joints' origins between them). Panics for an index
    /// past the links.
    pub fn rigid_ancestor(&self, link: usize) -> (usize, Isometry3<f64>) {
        let mut at = link;
        let mut offset = Isometry3::identity();
        while at > 0 {
            let joint = &self.joints[at - 1];
            if joint.kind != JointKind::Fixed {
                break;
            }
            offset = joint.local_origin * offset;
            at = joint.parent;
        }
        (at, offset)
    }
}

/// `link`'s visuals, each material named without a colour given the robot-level one's.
fn visuals_of(robot: &urdf_rs::Robot, link: &urdf_rs::Link) -> Vec<urdf_rs::Visual> {
    let mut visuals = link.visual.clone();
    for m in visuals.iter_mut().filter_map(|v| v.material.as_mut()) {
        if m.color.is_none() && m.texture.is_none() {
            if let Some(global) = robot.materials.iter().find(|g| g.name == m.name) {
                m.color.clone_from(&global.color);
                m.texture.clone_from(&global.texture);
            }
        }
    }
    visuals
}

fn convert_joint(uj: &urdf_rs::Joint, parent: usize, child: usize, ctx: &Ctx) -> Result<Joint> {
    let name = uj.name.as_str();
    let kind = match &uj.joint_type {
        urdf_rs::JointType::Revolute => JointKind::Revolute,
        urdf_rs::JointType::Continuous => JointKind::Continuous,
        urdf_rs::JointType::Prismatic => JointKind::Prismatic,
        urdf_rs::JointType::Fixed => JointKind::Fixed,
        other => {
            return Err(ctx.invalid(
                "joint",
                name,
                format!("has type {other:?}, which trm does not support"),
                "use revolute, continuous, prismatic or fixed joints (model a floating base by locating the root link in the world instead)",
            ));
        }
    };
    let xyz = *uj.origin.xyz;
    let rpy = *uj.origin.rpy;
    check_finite(ctx, "joint", name, "<origin xyz>", &xyz)?;
    check_finite(ctx, "joint", name, "<origin rpy>", &rpy)?;
    let axis_raw = *uj.axis.xyz;
    check_finite(ctx, "joint", name, "<axis xyz>", &axis_raw)?;
    let axis_vec = Vector3::from(axis_raw);
    let axis = if kind.is_movable() {
        if axis_vec.norm() < 1e-12 {
            return Err(ctx.invalid(
                "joint",
                name,
                "has a zero <axis>",
                "give a non-zero axis, e.g. <axis xyz=\"0 0 1\"/>",
            ));
        }
        Unit::new_normalize(axis_vec)
    } else {
        Vector3::z_axis()
    };
    let l = &uj.limit;
    let (lower, upper) = match kind {
        JointKind::Continuous => (f64::NEG_INFINITY, f64::INFINITY),
        JointKind::Fixed => (0.0, 0.0),
        _ => {
            check_finite(
                ctx,
                "joint",
                name,
                "<limit lower upper>",
                &[l.lower, l.upper],
            )?;
            if l.lower > l.upper {
                return Err(ctx.invalid(
                    "joint",
                    name,
                    format!(
                        "<limit lower=\"{}\" upper=\"{}\">: lower is above upper",
                        l.lower, l.upper
                    ),
                    "swap the two values",
                ));
            }
            (l.lower, l.upper)
        }
    };
    if l.velocity.is_nan() || l.effort.is_nan() || l.velocity < 0.0 || l.effort < 0.0 {
        return Err(ctx.invalid(
            "joint",
            name,
            format!(
                "<limit velocity=\"{}\" effort=\"{}\"> must be non-negative numbers",
                l.velocity, l.effort
            ),
            "write non-negative velocity and effort limits",
        ));
    }
    let positive_or_inf = |v: f64| if v > 0.0 { v } else { f64::INFINITY };
    let mimic = match &uj.mimic {
        Some(m) if kind.is_movable() => {
            let multiplier = m.multiplier.unwrap_or(1.0);
            let offset = m.offset.unwrap_or(0.0);
            check_finite(
                ctx,
                "joint",
                name,
                "<mimic multiplier offset>",
                &[multiplier, offset],
            )?;
            Some(Mimic {
                leader: m.joint.clone(),
                multiplier,
                offset,
            })
        }
        _ => None,
    };
    Ok(Joint {
        name: name.to_string(),
        kind,
        parent,
        child,
        local_origin: pose_from_xyz_rpy(xyz, rpy),
        axis,
        limits: Limits {
            lower,
            upper,
            velocity: positive_or_inf(l.velocity),
            effort: positive_or_inf(l.effort),
            acceleration: f64::INFINITY,
            jerk: f64::INFINITY,
        },
        mimic,
        coordinate: None,
    })
}
