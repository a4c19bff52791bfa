//! SRDF, the semantic robot description MoveIt's setup assistant writes beside a URDF: read
//! into a model description (groups → motor groups, group states → named postures, end
//! effectors → named frames, disabled collisions → the allowed-collision matrix) and written
//! from a model (its groups, postures and disabled pairs), so that MoveIt and trm share one
//! description of a robot.
//!
//! ```no_run
//! use trm_kinematics::{RobotModel, srdf::Srdf};
//! let robot = RobotModel::load("panda.urdf")?;
//! let srdf = Srdf::load("panda.srdf")?;
//! let (description, report) = srdf.to_description(&robot, &Default::default())?;
//! let robot = robot.with_description(&description, None)?;
//! println!("{report}");
//! # Ok::<(), trm_kinematics::KinematicsError>(())
//! ```
//!
//! Read: `<group>` (`<joint>`, `<link>`, `<chain>`, `<group>` members), `<group_state>`,
//! `<end_effector>`, `<disable_collisions>`, `<virtual_joint>`, `<passive_joint>`; other
//! elements (sphere approximations, …) are skipped. A name the URDF does not have is an error
//! naming the file, the line and the closest names.

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::Path;

use crate::description::{
    DisableReason, DisabledCollisionSpec, FrameSpec, GroupSpec, ModelDescription, PostureSpec,
};
use crate::error::{KinematicsError, Result};
use crate::model::RobotModel;
use trm_io::closest_names;

/// A group: its members as the SRDF lists them.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SrdfGroup {
    /// Name.
    pub name: String,
    /// `<joint name>` members.
    pub joints: Vec<String>,
    /// `<link name>` members (the group holds the joints above them).
    pub links: Vec<String>,
    /// `<chain base_link tip_link>` members (the joints between them).
    pub chains: Vec<(String, String)>,
    /// `<group name>` members (subgroups).
    pub subgroups: Vec<String>,
    /// Line of the element.
    pub line: usize,
}

/// A named posture of a group: joint values.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct GroupState {
    /// Name.
    pub name: String,
    /// The group it belongs to.
    pub group: String,
    /// Joint values, rad or m.
    pub values: BTreeMap<String, f64>,
    /// Joints given several coordinates (a floating or planar virtual joint's pose), with the
    /// line of each.
    pub multi: Vec<(String, Vec<f64>, usize)>,
    /// Line of the element.
    pub line: usize,
}

/// An end effector: a named frame at its parent link.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct EndEffector {
    /// Name.
    pub name: String,
    /// The link it is attached to.
    pub parent_link: String,
    /// The group of the end effector's own joints.
    pub group: String,
    /// The group it is attached to, if given.
    pub parent_group: Option<String>,
    /// Line of the element.
    pub line: usize,
}

/// How the robot's root is attached to the world.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct VirtualJoint {
    /// Name.
    pub name: String,
    /// `fixed`, `floating` or `planar`.
    pub kind: String,
    /// The world frame's name.
    pub parent_frame: String,
    /// The robot's root link.
    pub child_link: String,
    /// Line of the element.
    pub line: usize,
}

/// An SRDF document; see the module documentation.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Srdf {
    /// Where it came from (a file name, or `<string>`).
    pub origin: String,
    /// The robot's name (it must be the URDF's).
    pub robot: String,
    /// Line of the `<robot>` element.
    pub robot_line: usize,
    /// Virtual joints.
    pub virtual_joints: Vec<VirtualJoint>,
    /// Groups, in document order.
    pub groups: Vec<SrdfGroup>,
    /// Group states.
    pub group_states: Vec<GroupState>,
    /// End effectors.
    pub end_effectors: Vec<EndEffector>,
    /// Disabled link pairs with their reasons, and the line of each.
    pub disabled: Vec<(DisabledCollisionSpec, usize)>,
    /// Passive joints.
    pub passive_joints: Vec<String>,
    /// What the reader skipped, and why (MoveIt warns about the same and goes on).
    pub notes: Vec<String>,
}

/// What [`Srdf::to_description`] took over and what it left out.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SrdfReport {
    /// Groups, postures, frames and disabled pairs taken over.
    pub counts: [usize; 4],
    /// What was not taken over, and why.
    pub notes: Vec<String>,
}

impl std::fmt::Display for SrdfReport {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let [g, p, e, d] = self.counts;
        write!(
            f,
            "{g} groups, {p} named postures, {e} end-effector frames, {d} disabled link pairs"
        )?;
        for n in &self.notes {
            write!(f, "\n  note: {n}")?;
        }
        Ok(())
    }
}

/// The URDF's names an SRDF is checked against: its links and joints (located errors with
/// the nearest names), and the motors driving each joint.
struct Names<'a> {
    origin: &'a str,
    robot: &'a RobotModel,
    tree: &'a crate::Tree,
    links: Vec<&'a str>,
    joints: Vec<&'a str>,
    /// The movable joints, in coupling order.
    movable: Vec<&'a str>,
}

/// Per SRDF group, its URDF joints (`None` when it includes a group only the model
/// description defines).
type GroupJoints<'s> = BTreeMap<&'s str, Option<Vec<usize>>>;

impl<'a> Names<'a> {
    fn new(robot: &'a RobotModel, origin: &'a str) -> Self {
        let tree = robot.tree();
        Names {
            origin,
            robot,
            tree,
            links: tree.links.iter().map(|l| l.name.as_str()).collect(),
            joints: tree.joints.iter().map(|j| j.name.as_str()).collect(),
            movable: robot.joint_names().collect(),
        }
    }

    /// Index of link `name` (named on SRDF line `line`).
    fn link(&self, name: &str, line: usize) -> Result<usize> {
        self.links.iter().position(|l| *l == name).ok_or_else(|| {
            error(
                self.origin,
                line,
                format!("link `{name}` is not in the URDF"),
                did_you_mean(name, self.links.iter().copied(), "link"),
            )
        })
    }

    /// Index of joint `name` (named on SRDF line `line`).
    fn joint(&self, name: &str, line: usize) -> Result<usize> {
        self.joints.iter().position(|j| *j == name).ok_or_else(|| {
            error(
                self.origin,
                line,
                format!("joint `{name}` is not in the URDF"),
                did_you_mean(name, self.joints.iter().copied(), "joint"),
            )
        })
    }

    /// The motors driving tree joint `j` (none for fixed joints).
    fn motors_of(&self, j: usize) -> Vec<String> {
        let Some(k) = self
            .movable
            .iter()
            .position(|m| *m == self.tree.joints[j].name)
        else {
            return Vec::new();
        };
        self.robot.couplings()[k]
            .terms
            .iter()
            .map(|&(m, _)| self.robot.motors()[m].name.clone())
            .collect()
    }
}

fn error(
    origin: &str,
    line: usize,
    problem: impl Into<String>,
    fix: impl Into<String>,
) -> KinematicsError {
    KinematicsError::InvalidModel {
        origin: origin.to_string(),
        line: Some(line),
        element: "srdf".into(),
        problem: problem.into(),
        fix: fix.into(),
    }
}

/// The fix for an unknown `name` among `candidates`: the closest names, or where to look.
fn did_you_mean<'a>(
    name: &str,
    candidates: impl IntoIterator<Item = &'a str>,
    kind: &str,
) -> String {
    let close = closest_names(name, candidates);
    if close.is_empty() {
        format!("use a {kind} of the URDF")
    } else {
        format!(
            "did you mean {}?",
            close
                .iter()
                .map(|c| format!("`{c}`"))
                .collect::<Vec<_>>()
                .join(", ")
        )
    }
}

/// An SRDF document being read: element lines and attributes with located errors.
struct Reader<'a, 'input> {
    doc: &'a roxmltree::Document<'input>,
    origin: &'a str,
}

impl Reader<'_, '_> {
    /// The line an element starts on.
    fn line(&self, n: roxmltree::Node) -> usize {
        self.doc.text_pos_at(n.range().start).row as usize
    }

    /// An attribute the element must have.
    fn attr(&self, n: roxmltree::Node, a: &str) -> Result<String> {
        n.attribute(a).map(str::to_string).ok_or_else(|| {
            error(
                self.origin,
                self.line(n),
                format!("<{}> has no `{a}` attribute", n.tag_name().name()),
                format!("give <{}> its `{a}`", n.tag_name().name()),
            )
        })
    }

    /// A `<group>` and its members; elements that are no members noted and skipped.
    fn group(&self, n: roxmltree::Node, notes: &mut Vec<String>) -> Result<SrdfGroup> {
        let (attr, line) = (|n, a| self.attr(n, a), |n| self.line(n));
        let mut g = SrdfGroup {
            name: attr(n, "name")?,
            line: line(n),
            ..Default::default()
        };
        for m in n.children().filter(|m| m.is_element()) {
            match m.tag_name().name() {
                        "joint" => g.joints.push(attr(m, "name")?),
                        "link" => g.links.push(attr(m, "name")?),
                        "chain" => g.chains.push((attr(m, "base_link")?, attr(m, "tip_link")?)),
                        "group" => g.subgroups.push(attr(m, "name")?),
                        // MoveIt's reader skips other elements (SRDFs in the wild put
                        // <passive_joint> there); so does trm, saying so
                        other => notes.push(format!(
                            "line {}: <{other}> in group `{}` skipped (a group holds <joint>, <link>, <chain> and <group> members)",
                            line(m),
                            g.name
                        )),
                    }
        }
        Ok(g)
    }

    /// A `<group_state>`: one finite value per joint (several for a multi-coordinate joint).
    fn group_state(&self, n: roxmltree::Node) -> Result<GroupState> {
        let (attr, line, origin) = (|n, a| self.attr(n, a), |n| self.line(n), self.origin);
        let mut s = GroupState {
            name: attr(n, "name")?,
            group: attr(n, "group")?,
            line: line(n),
            ..Default::default()
        };
        for j in n.children().filter(|j| j.has_tag_name("joint")) {
            let name = attr(j, "name")?;
            let text = attr(j, "value")?;
            // a joint with several coordinates lists them space-separated
            let values: Option<Vec<f64>> = text
                .split_whitespace()
                .map(|v| v.parse().ok().filter(|v: &f64| v.is_finite()))
                .collect();
            let value = match values.as_deref() {
                Some([v]) => *v,
                Some(many) if many.len() > 1 => {
                    s.multi.push((name.clone(), many.to_vec(), line(j)));
                    continue;
                }
                _ => {
                    return Err(error(
                        origin,
                        line(j),
                        format!(
                            "group state `{}`: joint `{name}` has value `{text}`",
                            s.name
                        ),
                        "give finite numbers (rad or m), space-separated for a joint with several coordinates",
                    ));
                }
            };
            if s.values.insert(name.clone(), value).is_some() {
                return Err(error(
                    origin,
                    line(j),
                    format!("group state `{}` gives joint `{name}` twice", s.name),
                    "give each joint once",
                ));
            }
        }
        Ok(s)
    }
}

impl Srdf {
    /// Parses SRDF text; `origin` names it in errors.
    pub fn parse(text: &str, origin: &str) -> Result<Self> {
        crate::check_xml_nesting(text.as_bytes(), crate::XML_NESTING_LIMIT).map_err(|e| {
            error(
                origin,
                e.line,
                format!("elements nested more than {} deep", e.limit),
                "an SRDF nests groups by name (<group name=\"…\"/> members), not by element",
            )
        })?;
        let doc = roxmltree::Document::parse(text).map_err(|e| {
            let p = e.pos();
            error(
                origin,
                p.row as usize,
                format!("not well-formed XML: {e}"),
                "write the SRDF as MoveIt's setup assistant does",
            )
        })?;
        let read = Reader { doc: &doc, origin };
        let (attr, line) = (|n, a| read.attr(n, a), |n| read.line(n));
        let root = doc.root_element();
        if root.tag_name().name() != "robot" {
            return Err(error(
                origin,
                line(root),
                format!("the root element is <{}>", root.tag_name().name()),
                "an SRDF's root element is <robot name=\"…\">",
            ));
        }
        let mut srdf = Srdf {
            origin: origin.to_string(),
            robot: attr(root, "name")?,
            robot_line: line(root),
            ..Default::default()
        };
        for n in root.children().filter(|n| n.is_element()) {
            match n.tag_name().name() {
                "virtual_joint" => srdf.virtual_joints.push(VirtualJoint {
                    name: attr(n, "name")?,
                    kind: attr(n, "type")?,
                    parent_frame: attr(n, "parent_frame")?,
                    child_link: attr(n, "child_link")?,
                    line: line(n),
                }),
                "group" => {
                    let group = read.group(n, &mut srdf.notes)?;
                    srdf.groups.push(group);
                }
                "group_state" => srdf.group_states.push(read.group_state(n)?),
                "end_effector" => srdf.end_effectors.push(EndEffector {
                    name: attr(n, "name")?,
                    parent_link: attr(n, "parent_link")?,
                    group: attr(n, "group")?,
                    parent_group: n.attribute("parent_group").map(str::to_string),
                    line: line(n),
                }),
                "disable_collisions" => {
                    let reason = match n.attribute("reason").unwrap_or("User") {
                        "Adjacent" => DisableReason::Adjacent,
                        "Default" => DisableReason::Default,
                        "Always" => DisableReason::Always,
                        "Never" => DisableReason::Never,
                        _ => DisableReason::User,
                    };
                    srdf.disabled.push((
                        DisabledCollisionSpec {
                            a: attr(n, "link1")?,
                            b: attr(n, "link2")?,
                            reason,
                        },
                        line(n),
                    ));
                }
                "passive_joint" => srdf.passive_joints.push(attr(n, "name")?),
                _ => {} // sphere approximations and other MoveIt extensions
            }
        }
        srdf.check_unique()?;
        Ok(srdf)
    }

    /// Groups, and group states within a group, each defined once.
    fn check_unique(&self) -> Result<()> {
        let origin = self.origin.as_str();
        for (k, g) in self.groups.iter().enumerate() {
            if let Some(first) = self.groups[..k].iter().find(|o| o.name == g.name) {
                return Err(error(
                    origin,
                    g.line,
                    format!(
                        "group `{}` is defined twice (first at line {})",
                        g.name, first.line
                    ),
                    "define each group once (a group can include another by <group name=\"…\"/>)",
                ));
            }
        }
        for (k, s) in self.group_states.iter().enumerate() {
            let twin = self.group_states[..k]
                .iter()
                .find(|o| o.name == s.name && o.group == s.group);
            if let Some(first) = twin {
                return Err(error(
                    origin,
                    s.line,
                    format!(
                        "group state `{}` of group `{}` is defined twice (first at line {})",
                        s.name, s.group, first.line
                    ),
                    "give each group state of a group a name of its own",
                ));
            }
        }
        Ok(())
    }

    /// Reads an SRDF file.
    pub fn load(path: impl AsRef<Path>) -> Result<Self> {
        let path = path.as_ref();
        Self::parse(&crate::error::read_text(path)?, &path.display().to_string())
    }

    /// `base` (usually the model's own description) with the SRDF's groups, group states, end
    /// effectors and disabled pairs added, checked against `robot`'s URDF; and what was taken
    /// over. Joints map to the motors that drive them (a joint coupled to several motors
    /// brings them all into a group; a group state sets only joints that are motors of their
    /// own). Groups, postures and frames the description already has keep its definition.
    pub fn to_description(
        &self,
        robot: &RobotModel,
        base: &ModelDescription,
    ) -> Result<(ModelDescription, SrdfReport)> {
        let names = Names::new(robot, &self.origin);
        if self.robot != robot.name() {
            return Err(error(
                names.origin,
                self.robot_line,
                format!(
                    "the SRDF describes robot `{}`, the URDF is robot `{}`",
                    self.robot,
                    robot.name()
                ),
                "give the SRDF of this URDF (MoveIt refuses a pair whose robot names differ)",
            ));
        }
        let mut out = base.clone();
        let mut report = SrdfReport {
            notes: self.notes.clone(),
            ..Default::default()
        };
        self.take_virtual_joints(&names, &mut report)?;
        let group_joints = self.take_groups(&names, &mut out, &mut report)?;
        self.take_group_states(&names, &group_joints, &mut out, &mut report)?;
        self.take_end_effectors(&names, &mut out, &mut report)?;
        self.take_disabled(&names, &mut out, &mut report);
        if !self.passive_joints.is_empty() {
            report.notes.push(format!(
                "{} passive joints: trm drives every joint through its motors",
                self.passive_joints.len()
            ));
        }
        Ok((out, report))
    }

    /// Virtual joints: on the URDF's root link; a moving one is noted (the root stays fixed).
    fn take_virtual_joints(&self, names: &Names<'_>, report: &mut SrdfReport) -> Result<()> {
        for vj in &self.virtual_joints {
            let child = names.link(&vj.child_link, vj.line)?;
            if names.tree.links[child].parent.is_some() {
                return Err(error(
                    names.origin,
                    vj.line,
                    format!(
                        "virtual joint `{}` attaches `{}`, which is not the URDF's root link",
                        vj.name, vj.child_link
                    ),
                    format!("attach the root link `{}`", names.links[0]),
                ));
            }
            if vj.kind != "fixed" {
                report.notes.push(format!(
                    "virtual joint `{}` is {}: trm keeps the root link fixed in the world frame",
                    vj.name, vj.kind
                ));
            }
        }
        Ok(())
    }

    /// Groups (after the groups they include) as motor groups of `out`, unless `out` has one
    /// of the name; the URDF joints of each (`None` for a group including one only the
    /// description defines).
    fn take_groups<'s>(
        &'s self,
        names: &Names<'_>,
        out: &mut ModelDescription,
        report: &mut SrdfReport,
    ) -> Result<GroupJoints<'s>> {
        // the URDF joints of each SRDF group (subgroups included), as MoveIt resolves them;
        // None for a group that includes one only the model description defines
        let mut group_joints: BTreeMap<&str, Option<Vec<usize>>> = BTreeMap::new();
        let mut defined: Vec<String> = out.groups.iter().map(|g| g.name.clone()).collect();
        // groups in an order where each comes after the groups it includes (as MoveIt, the
        // SRDF may name a group before defining it); what is left is an error below
        let mut left_out: Vec<String> = Vec::new();
        let mut order: Vec<&SrdfGroup> = Vec::new();
        let mut left: Vec<&SrdfGroup> = self.groups.iter().collect();
        loop {
            let known = |n: &String| defined.contains(n) || order.iter().any(|o| &o.name == n);
            let (ready, rest): (Vec<&SrdfGroup>, Vec<&SrdfGroup>) =
                left.iter().partition(|g| g.subgroups.iter().all(known));
            if ready.is_empty() {
                order.extend(rest);
                break;
            }
            order.extend(ready);
            left = rest;
        }
        for g in order {
            let mut joints: Vec<usize> = Vec::new();
            for j in &g.joints {
                joints.push(names.joint(j, g.line)?);
            }
            for l in &g.links {
                let i = names.link(l, g.line)?;
                joints.extend(names.tree.links[i].parent_joint);
            }
            for (base_link, tip) in &g.chains {
                let (b, mut t) = (names.link(base_link, g.line)?, names.link(tip, g.line)?);
                let mut chain = Vec::new();
                while t != b {
                    let (Some(j), Some(p)) =
                        (names.tree.links[t].parent_joint, names.tree.links[t].parent)
                    else {
                        return Err(error(
                            names.origin,
                            g.line,
                            format!("group `{}`: `{base_link}` is not above `{tip}`", g.name),
                            "give a chain from a link down to one of its descendants",
                        ));
                    };
                    chain.push(j);
                    t = p;
                }
                joints.extend(chain.into_iter().rev());
            }
            let mut resolved = Some(joints.clone());
            for s in &g.subgroups {
                if !defined.contains(s) && !left_out.contains(s) {
                    return Err(error(
                        names.origin,
                        g.line,
                        format!(
                            "group `{}` includes group `{s}`, which is not defined (or includes it in turn)",
                            g.name
                        ),
                        did_you_mean(s, defined.iter().map(String::as_str), "group"),
                    ));
                }
                match (&mut resolved, group_joints.get(s.as_str())) {
                    (Some(all), Some(Some(sub))) => all.extend(sub),
                    _ => resolved = None,
                }
            }
            group_joints.insert(g.name.as_str(), resolved);
            if defined.contains(&g.name) {
                report.notes.push(format!(
                    "group `{}` is also in the model description, which keeps its definition",
                    g.name
                ));
                continue;
            }
            let mut members: Vec<String> = Vec::new();
            let own_motors = joints.iter().flat_map(|&j| names.motors_of(j));
            let subgroups = g
                .subgroups
                .iter()
                .filter(|s| !left_out.contains(s))
                .cloned();
            for n in own_motors.chain(subgroups) {
                if !members.contains(&n) {
                    members.push(n);
                }
            }
            if members.is_empty() {
                report
                    .notes
                    .push(format!("group `{}` drives no motor: left out", g.name));
                left_out.push(g.name.clone());
                continue;
            }
            out.groups.push(GroupSpec {
                name: g.name.clone(),
                members,
            });
            defined.push(g.name.clone());
            report.counts[0] += 1;
        }
        Ok(group_joints)
    }

    /// Group states as postures of `out` (joints that are motors of their own), checked
    /// against their groups' joints.
    fn take_group_states(
        &self,
        names: &Names<'_>,
        group_joints: &GroupJoints<'_>,
        out: &mut ModelDescription,
        report: &mut SrdfReport,
    ) -> Result<()> {
        let motor_names: Vec<&str> = names
            .robot
            .motors()
            .iter()
            .map(|m| m.name.as_str())
            .collect();
        for s in &self.group_states {
            if !self.groups.iter().any(|g| g.name == s.group) {
                return Err(error(
                    names.origin,
                    s.line,
                    format!(
                        "group state `{}` names group `{}`, which the SRDF does not define",
                        s.name, s.group
                    ),
                    did_you_mean(
                        &s.group,
                        self.groups.iter().map(|g| g.name.as_str()),
                        "group",
                    ),
                ));
            }
            let name = if self
                .group_states
                .iter()
                .filter(|o| o.name == s.name)
                .count()
                > 1
            {
                format!("{}_{}", s.group, s.name)
            } else {
                s.name.clone()
            };
            if out.postures.iter().any(|p| p.name == name) {
                report.notes.push(format!(
                    "posture `{name}` is also in the model description, which keeps its values"
                ));
                continue;
            }
            for (j, v, line) in &s.multi {
                // a virtual joint's pose, or (Pinocchio's convention) the free-flyer `root_joint`
                // that is not in the URDF
                if self.virtual_joints.iter().any(|vj| &vj.name == j)
                    || names.robot.joint_index(j).is_err()
                {
                    report.notes.push(format!(
                        "group state `{}`: the pose of the floating root `{j}` ({} values) is left out: trm keeps the root link fixed",
                        s.name,
                        v.len()
                    ));
                } else {
                    return Err(error(
                        names.origin,
                        *line,
                        format!(
                            "group state `{}`: joint `{j}` has {} values; a URDF joint takes one",
                            s.name,
                            v.len()
                        ),
                        "give one value (several belong to a virtual joint's pose)",
                    ));
                }
            }
            let mut values = BTreeMap::new();
            for (j, v) in &s.values {
                let index = names.joint(j, s.line)?;
                if let Some(Some(members)) = group_joints.get(s.group.as_str()) {
                    if !members.contains(&index) {
                        return Err(error(
                            names.origin,
                            s.line,
                            format!(
                                "group state `{}` sets joint `{j}`, which is not in group `{}`",
                                s.name, s.group
                            ),
                            did_you_mean(
                                j,
                                members.iter().map(|&m| names.tree.joints[m].name.as_str()),
                                "joint of the group",
                            ),
                        ));
                    }
                }
                if motor_names.contains(&j.as_str()) {
                    values.insert(j.clone(), *v);
                } else {
                    report.notes.push(format!(
                        "group state `{}`: joint `{j}` is coupled or fixed, not a motor of its own: left out",
                        s.name
                    ));
                }
            }
            out.postures.push(PostureSpec { name, values });
            report.counts[1] += 1;
        }
        Ok(())
    }

    /// End effectors as frames of `out` on their parent links, unless the name is taken.
    fn take_end_effectors(
        &self,
        names: &Names<'_>,
        out: &mut ModelDescription,
        report: &mut SrdfReport,
    ) -> Result<()> {
        for e in &self.end_effectors {
            names.link(&e.parent_link, e.line)?;
            let taken = names.links.contains(&e.name.as_str())
                || names.robot.frame_names().any(|f| f == e.name)
                || out.frames.iter().any(|f| f.name == e.name);
            if taken {
                report.notes.push(format!(
                    "end effector `{}`: a link or frame of that name exists; no frame added",
                    e.name
                ));
                continue;
            }
            out.frames.push(FrameSpec {
                name: e.name.clone(),
                link: e.parent_link.clone(),
                xyz: [0.0; 3],
                rpy: [0.0; 3],
            });
            report.counts[2] += 1;
        }
        Ok(())
    }

    /// Disabled pairs into `out`'s (once each); a pair naming a link the URDF lacks is
    /// skipped and noted, as MoveIt skips it.
    fn take_disabled(
        &self,
        names: &Names<'_>,
        out: &mut ModelDescription,
        report: &mut SrdfReport,
    ) {
        for (d, line) in &self.disabled {
            // MoveIt skips a pair naming a link the URDF lacks (SRDFs written for another
            // variant of the robot, e.g. a spherized URDF); so does trm, saying so
            if let Some(missing) = [&d.a, &d.b]
                .into_iter()
                .find(|l| !names.links.contains(&l.as_str()))
            {
                report.notes.push(format!(
                    "line {line}: disabled pair ({}, {}) skipped: link `{missing}` is not in the URDF ({})",
                    d.a,
                    d.b,
                    did_you_mean(missing, names.links.iter().copied(), "link")
                ));
                continue;
            }
            let same = |x: &DisabledCollisionSpec| {
                (x.a == d.a && x.b == d.b) || (x.a == d.b && x.b == d.a)
            };
            if !out.disabled_collisions.iter().any(same) {
                out.disabled_collisions.push(d.clone());
                report.counts[3] += 1;
            }
        }
    }

    /// The SRDF of `robot`: a group per motor group (the joints its motors drive), a group
    /// `all_motors` and a group state of it per named posture (every motor's joint values
    /// through the couplings), a fixed virtual joint at the root, and `disabled` (usually the
    /// model's and the generated allowed-collision matrix) as `<disable_collisions>`.
    pub fn from_model(robot: &RobotModel, disabled: &[DisabledCollisionSpec]) -> Self {
        let movable: Vec<&str> = robot.joint_names().collect();
        let joints_of = |motors: &[usize]| -> Vec<String> {
            movable
                .iter()
                .enumerate()
                .filter(|(k, _)| {
                    robot.couplings()[*k]
                        .terms
                        .iter()
                        .any(|(m, _)| motors.contains(m))
                })
                .map(|(_, j)| j.to_string())
                .collect()
        };
        let mut groups: Vec<SrdfGroup> = robot
            .groups()
            .map(|(name, motors)| SrdfGroup {
                name: name.to_string(),
                joints: joints_of(motors),
                ..Default::default()
            })
            .collect();
        let all: Vec<usize> = (0..robot.motors().len()).collect();
        let all_joints = joints_of(&all);
        groups.push(SrdfGroup {
            name: "all_motors".into(),
            joints: all_joints.clone(),
            ..Default::default()
        });
        let mut joint_values = vec![0.0; robot.num_joints()];
        let group_states = robot
            .posture_names()
            .filter_map(|name| {
                let motors = robot.posture(name).ok()?;
                robot.motors_to_joints(motors, &mut joint_values).ok()?;
                Some(GroupState {
                    name: name.to_string(),
                    group: "all_motors".into(),
                    values: movable
                        .iter()
                        .zip(&joint_values)
                        .filter(|(j, _)| all_joints.iter().any(|a| a == *j))
                        .map(|(j, v)| (j.to_string(), *v))
                        .collect(),
                    multi: Vec::new(),
                    line: 0,
                })
            })
            .collect();
        let tree = robot.tree();
        Srdf {
            origin: robot.origin().to_string(),
            robot: robot.name().to_string(),
            robot_line: 0,
            virtual_joints: vec![VirtualJoint {
                name: "world_joint".into(),
                kind: "fixed".into(),
                parent_frame: "world".into(),
                child_link: tree.links[0].name.clone(),
                line: 0,
            }],
            groups,
            group_states,
            end_effectors: Vec::new(),
            disabled: disabled.iter().map(|d| (d.clone(), 0)).collect(),
            passive_joints: Vec::new(),
            notes: Vec::new(),
        }
    }

    /// The SRDF as XML, in the layout MoveIt's setup assistant writes.
    pub fn to_xml(&self) -> String {
        let esc = |s: &str| {
            s.replace('&', "&amp;")
                .replace('<', "&lt;")
                .replace('>', "&gt;")
                .replace('"', "&quot;")
        };
        let mut x = String::from("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n");
        let _ = writeln!(
            x,
            "<!-- Written by trm {} from {}. -->",
            env!("CARGO_PKG_VERSION"),
            esc(&self.origin)
        );
        let _ = writeln!(x, "<robot name=\"{}\">", esc(&self.robot));
        for g in &self.groups {
            let _ = writeln!(x, "    <group name=\"{}\">", esc(&g.name));
            for j in &g.joints {
                let _ = writeln!(x, "        <joint name=\"{}\"/>", esc(j));
            }
            for l in &g.links {
                let _ = writeln!(x, "        <link name=\"{}\"/>", esc(l));
            }
            for (b, t) in &g.chains {
                let _ = writeln!(
                    x,
                    "        <chain base_link=\"{}\" tip_link=\"{}\"/>",
                    esc(b),
                    esc(t)
                );
            }
            for s in &g.subgroups {
                let _ = writeln!(x, "        <group name=\"{}\"/>", esc(s));
            }
            x += "    </group>\n";
        }
        for s in &self.group_states {
            let _ = writeln!(
                x,
                "    <group_state name=\"{}\" group=\"{}\">",
                esc(&s.name),
                esc(&s.group)
            );
            for (j, v) in &s.values {
                let _ = writeln!(x, "        <joint name=\"{}\" value=\"{v}\"/>", esc(j));
            }
            x += "    </group_state>\n";
        }
        for e in &self.end_effectors {
            let parent = e
                .parent_group
                .as_ref()
                .map(|p| format!(" parent_group=\"{}\"", esc(p)))
                .unwrap_or_default();
            let _ = writeln!(
                x,
                "    <end_effector name=\"{}\" parent_link=\"{}\" group=\"{}\"{parent}/>",
                esc(&e.name),
                esc(&e.parent_link),
                esc(&e.group)
            );
        }
        for v in &self.virtual_joints {
            let _ = writeln!(
                x,
                "    <virtual_joint name=\"{}\" type=\"{}\" parent_frame=\"{}\" child_link=\"{}\"/>",
                esc(&v.name),
                esc(&v.kind),
                esc(&v.parent_frame),
                esc(&v.child_link)
            );
        }
        for p in &self.passive_joints {
            let _ = writeln!(x, "    <passive_joint name=\"{}\"/>", esc(p));
        }
        for (d, _) in &self.disabled {
            let reason = match d.reason {
                DisableReason::Adjacent => "Adjacent",
                DisableReason::Default => "Default",
                DisableReason::Always => "Always",
                DisableReason::Never => "Never",
                DisableReason::User => "User",
            };
            let _ = writeln!(
                x,
                "    <disable_collisions link1=\"{}\" link2=\"{}\" reason=\"{reason}\"/>",
                esc(&d.a),
                esc(&d.b)
            );
        }
        x += "</robot>\n";
        x
    }
}
