//! `cargo xtask gen-icub`: writes models/icub_upper_body.{urdf,ron} from the official iCub URDF
//! (models/icub-visuomanip/model.urdf), its per-link collision extents and the iCub motor
//! couplings. The outputs are committed; a test checks they are up to date.

use std::collections::{BTreeMap, HashSet};
use std::fmt::Write as _;
use std::path::Path;

use anyhow::{Context, Result, bail};
use nalgebra::{UnitQuaternion, Vector3};
use trm_kinematics::CouplingSpec;

/// Links whose collision proxy is their mesh's bounding box (flat parts a capsule fits badly).
const BOX_LINKS: &[&str] = &[
    "root_link",
    "chest",
    "l_hand",
    "r_hand",
    "neck_1",
    "head",
    "l_foot",
    "r_foot",
];
/// Subtrees removed to make the upper body (the legs).
const LEG_ROOTS: &[&str] = &["l_hip_1", "r_hip_1"];
/// Simulator position limits (deg) tighter than the URDF's, from the iCub Gazebo configuration.
const SIM_LIMITS_DEG: &[(&str, f64, f64)] = &[
    ("l_shoulder_pitch", -95.0, 10.0),
    ("r_shoulder_pitch", -95.0, 10.0),
    ("l_shoulder_roll", 0.0, 160.0),
    ("r_shoulder_roll", 0.0, 160.0),
    ("neck_pitch", -30.0, 17.0),
    ("neck_yaw", -45.0, 45.0),
];
/// The nine motors of each hand: name suffix and limits (deg).
const HAND_MOTORS: [(&str, f64, f64); 9] = [
    ("hand_finger", 0.0, 60.0),
    ("thumb_oppose", 0.0, 90.0),
    ("thumb_proximal", 0.0, 90.0),
    ("thumb_distal", 0.0, 180.0),
    ("index_proximal", 0.0, 90.0),
    ("index_distal", 0.0, 180.0),
    ("middle_proximal", 0.0, 90.0),
    ("middle_distal", 0.0, 180.0),
    ("pinky", 0.0, 270.0),
];
const FINGERS: [&str; 5] = ["thumb", "index", "middle", "ring", "little"];
/// Capsules shortened at their end nearest the link origin (metres): the fitted forearm capsule
/// reaches back over the elbow hinge into the upper arm's at every elbow angle, which would
/// force the upper-arm/forearm pair out of checking; elbow_1 covers the hinge instead.
const CAPSULE_TRIMS: &[(&str, f64)] = &[("l_forearm", 0.045), ("r_forearm", 0.045)];
/// Random configurations sampled to find never/always colliding link pairs.
const ACM_SAMPLES: usize = 1_000_000;

/// One row of collision-extents.csv (link frame, metres).
struct Extents {
    aabb_min: [f64; 3],
    aabb_max: [f64; 3],
    capsule_a: [f64; 3],
    capsule_b: [f64; 3],
    capsule_r: f64,
}

fn read_extents(path: &Path) -> Result<BTreeMap<String, Extents>> {
    let text =
        std::fs::read_to_string(path).with_context(|| format!("reading {}", path.display()))?;
    let mut lines = text.lines();
    let header: Vec<&str> = lines
        .next()
        .context("empty extents file")?
        .split(',')
        .collect();
    let col = |name: &str| {
        header
            .iter()
            .position(|h| *h == name)
            .with_context(|| format!("{}: no column {name}", path.display()))
    };
    let cols = [
        "aabb_min_x",
        "aabb_min_y",
        "aabb_min_z",
        "aabb_max_x",
        "aabb_max_y",
        "aabb_max_z",
        "capsule_ax",
        "capsule_ay",
        "capsule_az",
        "capsule_bx",
        "capsule_by",
        "capsule_bz",
        "capsule_r",
    ];
    let idx: Vec<usize> = cols.iter().map(|c| col(c)).collect::<Result<_>>()?;
    let mut out = BTreeMap::new();
    for (n, line) in lines.enumerate() {
        let fields: Vec<&str> = line.split(',').collect();
        if fields.len() != header.len() {
            bail!(
                "{}:{}: expected {} fields",
                path.display(),
                n + 2,
                header.len()
            );
        }
        // primitive rows (the feet's sole boxes) carry no capsule; they become boxes
        let primitive = fields[idx[6]].is_empty();
        let v: Vec<f64> = idx
            .iter()
            .enumerate()
            .map(|(k, &i)| {
                if primitive && k >= 6 {
                    return Ok(0.0);
                }
                fields[i].parse::<f64>().with_context(|| {
                    format!("{}:{}: bad number {}", path.display(), n + 2, fields[i])
                })
            })
            .collect::<Result<_>>()?;
        out.insert(
            fields[0].to_string(),
            Extents {
                aabb_min: [v[0], v[1], v[2]],
                aabb_max: [v[3], v[4], v[5]],
                capsule_a: [v[6], v[7], v[8]],
                capsule_b: [v[9], v[10], v[11]],
                capsule_r: v[12],
            },
        );
    }
    Ok(out)
}

fn f(x: f64) -> String {
    // Shortest representation that reads back to the same f64; tidy signed zeros.
    if x == 0.0 { "0".into() } else { format!("{x}") }
}

fn v3(v: [f64; 3]) -> String {
    format!("{} {} {}", f(v[0]), f(v[1]), f(v[2]))
}

fn round6(x: f64) -> f64 {
    (x * 1e6).round() / 1e6
}

fn collision_xml(link: &str, e: &Extents) -> String {
    let (xyz, rpy, geometry);
    if BOX_LINKS.contains(&link) {
        let c: Vec<f64> = (0..3)
            .map(|i| round6((e.aabb_min[i] + e.aabb_max[i]) / 2.0))
            .collect();
        let s: Vec<f64> = (0..3)
            .map(|i| round6(e.aabb_max[i] - e.aabb_min[i]))
            .collect();
        xyz = [c[0], c[1], c[2]];
        rpy = [0.0; 3];
        geometry = format!("<box size=\"{}\"/>", v3([s[0], s[1], s[2]]));
    } else {
        let (mut a, mut b) = (Vector3::from(e.capsule_a), Vector3::from(e.capsule_b));
        if let Some((_, trim)) = CAPSULE_TRIMS.iter().find(|(l, _)| *l == link) {
            if a.norm() > b.norm() {
                std::mem::swap(&mut a, &mut b);
            }
            a += (b - a).normalize() * *trim;
        }
        let d = b - a;
        let c = (a + b) / 2.0;
        xyz = [round6(c.x), round6(c.y), round6(c.z)];
        if d.norm() < 1e-9 {
            rpy = [0.0; 3];
            geometry = format!("<sphere radius=\"{}\"/>", f(e.capsule_r));
        } else {
            let q = UnitQuaternion::rotation_between(&Vector3::z(), &d).unwrap_or_else(|| {
                UnitQuaternion::from_axis_angle(&Vector3::x_axis(), std::f64::consts::PI)
            });
            let (r, p, y) = q.euler_angles();
            rpy = [round6(r), round6(p), round6(y)];
            geometry = format!(
                "<capsule radius=\"{}\" length=\"{}\"/>",
                f(e.capsule_r),
                f(round6(d.norm()))
            );
        }
    }
    format!(
        "    <collision>\n      <origin xyz=\"{}\" rpy=\"{}\"/>\n      <geometry>\n        {geometry}\n      </geometry>\n    </collision>\n",
        v3(xyz),
        v3(rpy)
    )
}

/// The proxy URDF text: the upper body, or with `legs` the whole robot.
fn proxy_urdf(
    robot: &urdf_rs::Robot,
    extents: &BTreeMap<String, Extents>,
    legs: bool,
) -> Result<String> {
    // Links kept: everything reachable from root_link, without the leg subtrees unless `legs`.
    let mut kept: HashSet<&str> = HashSet::from(["root_link"]);
    let mut changed = true;
    while changed {
        changed = false;
        for j in &robot.joints {
            if kept.contains(j.parent.link.as_str())
                && (legs || !LEG_ROOTS.contains(&j.child.link.as_str()))
                && kept.insert(&j.child.link)
            {
                changed = true;
            }
        }
    }
    let (what, name, legs_note) = if legs {
        (
            "whole iCub (legs, torso, arms, hands, neck, eyes)",
            "icub_full_body",
            "legs kept",
        )
    } else {
        (
            "iCub upper body (torso, arms, hands, neck, eyes)",
            "icub_upper_body",
            "legs removed",
        )
    };
    let mut s = String::new();
    s.push_str("<?xml version=\"1.0\"?>\n");
    s.push_str("<!-- GENERATED by `cargo xtask gen-icub`; do not edit by hand.\n");
    let _ = writeln!(
        s,
        "     {what} from the official iCubGazeboV2_5_visuomanip URDF"
    );
    s.push_str("     (robotology/icub-models, CC-BY-SA-4.0, (c) Istituto Italiano di Tecnologia; see models/icub-visuomanip/NOTICE.md).\n");
    let _ = writeln!(
        s,
        "     Kinematics and inertials unchanged; {legs_note}; collision meshes replaced by primitives enclosing them"
    );
    s.push_str("     (capsules, or boxes for flat parts); arm and neck limits narrowed to the simulator's. Licence: CC-BY-SA-4.0. -->\n");
    let _ = writeln!(s, "<robot name=\"{name}\">");
    for link in robot
        .links
        .iter()
        .filter(|l| kept.contains(l.name.as_str()))
    {
        let _ = writeln!(s, "  <link name=\"{}\">", link.name);
        let i = &link.inertial;
        if i.mass.value > 0.0 {
            let _ = writeln!(
                s,
                "    <inertial>\n      <origin xyz=\"{}\" rpy=\"{}\"/>\n      <mass value=\"{}\"/>",
                v3(*i.origin.xyz),
                v3(*i.origin.rpy),
                f(i.mass.value)
            );
            let t = &i.inertia;
            let _ = writeln!(
                s,
                "      <inertia ixx=\"{}\" ixy=\"{}\" ixz=\"{}\" iyy=\"{}\" iyz=\"{}\" izz=\"{}\"/>\n    </inertial>",
                f(t.ixx),
                f(t.ixy),
                f(t.ixz),
                f(t.iyy),
                f(t.iyz),
                f(t.izz)
            );
        }
        if !link.collision.is_empty() {
            let e = extents
                .get(&link.name)
                .with_context(|| format!("no collision extents for link {}", link.name))?;
            s.push_str(&collision_xml(&link.name, e));
        }
        s.push_str("  </link>\n");
    }
    for j in robot
        .joints
        .iter()
        .filter(|j| kept.contains(j.parent.link.as_str()) && kept.contains(j.child.link.as_str()))
    {
        let kind = match j.joint_type {
            urdf_rs::JointType::Revolute => "revolute",
            urdf_rs::JointType::Fixed => "fixed",
            ref other => bail!("joint {} has unexpected type {other:?}", j.name),
        };
        let _ = writeln!(s, "  <joint name=\"{}\" type=\"{kind}\">", j.name);
        let _ = writeln!(
            s,
            "    <origin xyz=\"{}\" rpy=\"{}\"/>",
            v3(*j.origin.xyz),
            v3(*j.origin.rpy)
        );
        let _ = writeln!(
            s,
            "    <parent link=\"{}\"/>\n    <child link=\"{}\"/>",
            j.parent.link, j.child.link
        );
        if kind == "revolute" {
            let _ = writeln!(s, "    <axis xyz=\"{}\"/>", v3(*j.axis.xyz));
            let (mut lower, mut upper) = (j.limit.lower, j.limit.upper);
            if let Some(&(_, lo, hi)) = SIM_LIMITS_DEG.iter().find(|(n, _, _)| *n == j.name) {
                lower = lower.max(lo.to_radians());
                upper = upper.min(hi.to_radians());
            }
            let _ = writeln!(
                s,
                "    <limit lower=\"{}\" upper=\"{}\" effort=\"{}\" velocity=\"{}\"/>",
                f(lower),
                f(upper),
                f(j.limit.effort),
                f(j.limit.velocity)
            );
        }
        s.push_str("  </joint>\n");
    }
    s.push_str("</robot>\n");
    Ok(s)
}

/// The couplings of the hands' joints to their motors (as the iCub simulator couples them) and
/// of the eyes' pan joints to version and vergence.
fn write_couplings(s: &mut String) {
    let deg20 = 20f64.to_radians();
    for side in ["l", "r"] {
        let row = |finger: &str, k: u32, terms: &[(&str, f64)], offset: f64| CouplingSpec {
            joint: format!("{side}_hand_{finger}_{k}_joint"),
            motors: terms
                .iter()
                .map(|(name, factor)| (format!("{side}_{name}"), *factor))
                .collect(),
            offset,
        };
        let mut rows = vec![
            row("thumb", 0, &[("thumb_oppose", 1.0)], 0.0),
            row("thumb", 1, &[("thumb_proximal", 1.0)], 0.0),
            row("thumb", 2, &[("thumb_distal", 0.5)], 0.0),
            row("thumb", 3, &[("thumb_distal", 0.5)], 0.0),
            row("index", 0, &[("hand_finger", 1.0 / 3.0)], -deg20),
            row("index", 1, &[("index_proximal", 1.0)], 0.0),
            row("index", 2, &[("index_distal", 0.5)], 0.0),
            row("index", 3, &[("index_distal", 0.5)], 0.0),
            row("middle", 0, &[], 0.0),
            row("middle", 1, &[("middle_proximal", 1.0)], 0.0),
            row("middle", 2, &[("middle_distal", 0.5)], 0.0),
            row("middle", 3, &[("middle_distal", 0.5)], 0.0),
        ];
        for finger in ["ring", "little"] {
            rows.push(row(finger, 0, &[("hand_finger", -1.0 / 3.0)], deg20));
            for k in 1..=3 {
                rows.push(row(finger, k, &[("pinky", 1.0 / 3.0)], 0.0));
            }
        }
        for CouplingSpec {
            joint,
            motors,
            offset,
        } in rows
        {
            let terms: Vec<String> = motors
                .iter()
                .map(|(n, k)| format!("(\"{n}\", {})", f(*k)))
                .collect();
            let offset = if offset == 0.0 {
                String::new()
            } else {
                format!(", offset: {}", f(offset))
            };
            let _ = writeln!(
                s,
                "        (joint: \"{joint}\", motors: [{}]{offset}),",
                terms.join(", ")
            );
        }
    }
    s.push_str("        (joint: \"l_eye_pan_joint\", motors: [(\"eyes_version\", 1), (\"eyes_vergence\", 0.5)]),\n");
    s.push_str("        (joint: \"r_eye_pan_joint\", motors: [(\"eyes_version\", 1), (\"eyes_vergence\", -0.5)]),\n");
}

/// The named frames: palm centres, fingertips (the end of each distal capsule), the cameras'
/// optical axes and the gaze between the eyes.
fn write_frames(s: &mut String, extents: &BTreeMap<String, Extents>) -> Result<()> {
    for side in ["l", "r"] {
        let palm = extents
            .get(&format!("{side}_hand"))
            .context("no palm extents")?;
        let c: Vec<f64> = (0..3)
            .map(|i| round6((palm.aabb_min[i] + palm.aabb_max[i]) / 2.0))
            .collect();
        let _ = writeln!(
            s,
            "        // centre of the palm's bounding box, axes of {side}_hand"
        );
        let _ = writeln!(
            s,
            "        (name: \"{side}_palm_center\", link: \"{side}_hand\", xyz: ({}, {}, {})),",
            f(c[0]),
            f(c[1]),
            f(c[2])
        );
        for finger in FINGERS {
            let link = format!("{side}_hand_{finger}_3");
            let e = extents
                .get(&link)
                .with_context(|| format!("no extents for {link}"))?;
            let (a, b) = (Vector3::from(e.capsule_a), Vector3::from(e.capsule_b));
            let (near, far) = if a.norm() < b.norm() { (a, b) } else { (b, a) };
            let tip = far + (far - near).normalize() * e.capsule_r;
            let _ = writeln!(
                s,
                "        (name: \"{side}_{finger}_fingertip\", link: \"{link}\", xyz: ({}, {}, {})),",
                f(round6(tip.x)),
                f(round6(tip.y)),
                f(round6(tip.z))
            );
        }
        let _ = writeln!(
            s,
            "        (name: \"{side}_gaze\", link: \"{side}_eye\"), // z: optical axis of the {side} camera"
        );
    }
    s.push_str("        // between the eyes, z forward at zero version\n");
    s.push_str(
        "        (name: \"gaze\", link: \"eyes_tilt_frame\", rpy: (0, -1.5707963267948966, 0)),\n",
    );
    Ok(())
}

/// The model description (motors, couplings, frames, groups, postures) text.
fn description_ron(extents: &BTreeMap<String, Extents>) -> Result<String> {
    let mut s = String::new();
    s.push_str(
        "// GENERATED by `cargo xtask gen-icub`; do not edit by hand. Format: models/README.md.\n",
    );
    s.push_str("// The 41 motors of the iCub upper body: torso 3, arms 2x7, hands 2x9, neck 3, eyes 3. Radians.\n");
    s.push_str("// Hand and eye couplings as in the iCub simulator (gz-sim couplingICubHandMk2 / couplingICubEye).\n");
    s.push_str("(\n    urdf: \"icub_upper_body.urdf\",\n    motors: [\n");
    for side in ["l", "r"] {
        for (name, lo, hi) in HAND_MOTORS {
            let _ = writeln!(
                s,
                "        (name: \"{side}_{name}\", lower: {}, upper: {}), // [{lo}, {hi}] deg",
                f(lo.to_radians()),
                f(hi.to_radians())
            );
        }
    }
    s.push_str("        (name: \"eyes_version\", lower: -0.5235987755982988, upper: 0.5235987755982988), // [-30, 30] deg\n");
    s.push_str(
        "        (name: \"eyes_vergence\", lower: 0, upper: 0.8726646259971648), // [0, 50] deg\n",
    );
    s.push_str("    ],\n    couplings: [\n");
    write_couplings(&mut s);
    s.push_str("    ],\n    frames: [\n");
    write_frames(&mut s, extents)?;
    s.push_str("    ],\n    groups: [\n");
    s.push_str(
        "        (name: \"torso\", members: [\"torso_pitch\", \"torso_roll\", \"torso_yaw\"]),\n",
    );
    for (side, word) in [("l", "left"), ("r", "right")] {
        let arm: Vec<String> = [
            "shoulder_pitch",
            "shoulder_roll",
            "shoulder_yaw",
            "elbow",
            "wrist_prosup",
            "wrist_pitch",
            "wrist_yaw",
        ]
        .iter()
        .map(|n| format!("\"{side}_{n}\""))
        .collect();
        let _ = writeln!(
            s,
            "        (name: \"{word}_arm\", members: [{}]),",
            arm.join(", ")
        );
        let hand: Vec<String> = HAND_MOTORS
            .iter()
            .map(|(n, _, _)| format!("\"{side}_{n}\""))
            .collect();
        let _ = writeln!(
            s,
            "        (name: \"{word}_hand\", members: [{}]),",
            hand.join(", ")
        );
    }
    s.push_str(
        "        (name: \"neck\", members: [\"neck_pitch\", \"neck_roll\", \"neck_yaw\"]),\n",
    );
    s.push_str("        (name: \"eyes\", members: [\"eyes_tilt\", \"eyes_version\", \"eyes_vergence\"]),\n");
    s.push_str("        (name: \"arms\", members: [\"left_arm\", \"right_arm\"]),\n");
    s.push_str("        (name: \"hands\", members: [\"left_hand\", \"right_hand\"]),\n");
    s.push_str("        (name: \"head\", members: [\"neck\", \"eyes\"]),\n");
    s.push_str("        (name: \"upper_body\", members: [\"torso\", \"left_arm\", \"left_hand\", \"right_arm\", \"right_hand\", \"neck\", \"eyes\"]),\n");
    s.push_str("    ],\n    postures: [\n");
    s.push_str("        // arms forward with bent elbows, hands open, head straight (the iCub home pose)\n        (name: \"home\", values: {\n");
    let home_deg: [(&str, f64); 6] = [
        ("shoulder_pitch", -30.0),
        ("shoulder_roll", 30.0),
        ("elbow", 45.0),
        ("hand_finger", 30.0),
        ("thumb_oppose", 30.0),
        ("thumb_proximal", 10.0),
    ];
    let mut entries: Vec<(String, f64)> = Vec::new();
    for side in ["l", "r"] {
        for (n, d) in home_deg {
            entries.push((format!("{side}_{n}"), d));
        }
    }
    entries.sort_by(|a, b| a.0.cmp(&b.0));
    for (n, d) in entries {
        let _ = writeln!(s, "            \"{n}\": {}, // {d} deg", f(d.to_radians()));
    }
    s.push_str("        }),\n        // every motor at 0 clamped into its limits\n        (name: \"zero\", values: {}),\n    ],\n");
    Ok(s)
}

/// The `disabled_collisions` section: every pair within one hand (grasp contacts are the hand's
/// own business, so fingers may close onto the palm and each other), then the pairs MoveIt's
/// rules disable (colliding at home, never or always colliding in random samples).
fn disabled_collisions(urdf: &str, ron_head: &str) -> Result<String> {
    let robot = urdf_rs::read_from_string(urdf)?;
    let with_geometry: Vec<&str> = robot
        .links
        .iter()
        .filter(|l| !l.collision.is_empty())
        .map(|l| l.name.as_str())
        .collect();
    let mut s = String::from(
        "    // Link pairs left out of collision checking (links joined by a joint are always left out).\n",
    );
    s.push_str("    // `user`: contacts within one hand; the rest from `generate_acm`");
    let _ = writeln!(s, " ({ACM_SAMPLES} random configurations, seed 0).");
    s.push_str("    disabled_collisions: [\n");
    for side in ["l", "r"] {
        let hand: Vec<&str> = with_geometry
            .iter()
            .copied()
            .filter(|l| l.starts_with(&format!("{side}_hand")))
            .collect();
        let pairs: Vec<trm_kinematics::DisabledCollisionSpec> = hand
            .iter()
            .enumerate()
            .flat_map(|(i, a)| {
                hand[i + 1..]
                    .iter()
                    .map(move |b| trm_kinematics::DisabledCollisionSpec {
                        a: a.to_string(),
                        b: b.to_string(),
                        reason: trm_kinematics::DisableReason::User,
                    })
            })
            .collect();
        s.push_str(&trm_kinematics::DisabledCollisionSpec::list_to_ron(
            &pairs, "        ",
        ));
    }
    let head = format!("{ron_head}{s}    ],\n)\n");
    let description = trm_kinematics::ModelDescription::from_ron(&head, "<generated>")?;
    let model = trm_kinematics::RobotModel::from_parts(urdf, "<generated>", &description, None)?;
    let collision = trm_collision::CollisionModel::new(&model)?;
    let report = trm_collision::generate_acm(
        &collision,
        &trm_collision::AcmOptions {
            samples: ACM_SAMPLES,
            seed: 0,
            ..Default::default()
        },
    )?;
    s.push_str(&trm_kinematics::DisabledCollisionSpec::list_to_ron(
        &report.acm.to_spec(&model, |r| {
            !matches!(
                r,
                trm_kinematics::DisableReason::Adjacent | trm_kinematics::DisableReason::User
            )
        }),
        "        ",
    ));
    s.push_str("    ],\n");
    Ok(s)
}

/// The generated texts from the files under `models/`.
pub struct Generated {
    /// models/icub_upper_body.urdf
    pub urdf: String,
    /// models/icub_upper_body.ron
    pub ron: String,
    /// models/icub_full_body.urdf (legs kept; used by models/icub_sagittal.ron)
    pub full_body_urdf: String,
}

/// The generated texts from the files under `models/`.
pub fn generate(models: &Path) -> Result<Generated> {
    let official = models.join("icub-visuomanip/model.urdf");
    let robot =
        urdf_rs::read_file(&official).with_context(|| format!("reading {}", official.display()))?;
    let extents = read_extents(&models.join("icub-visuomanip/collision-extents.csv"))?;
    let urdf = proxy_urdf(&robot, &extents, false)?;
    let full_body_urdf = proxy_urdf(&robot, &extents, true)?;
    let head = description_ron(&extents)?;
    let collisions = disabled_collisions(&urdf, &head)?;
    Ok(Generated {
        urdf,
        ron: format!("{head}{collisions})\n"),
        full_body_urdf,
    })
}

/// Writes models/icub_upper_body.{urdf,ron} (atomically) and checks they load.
pub fn run(models: &Path) -> Result<()> {
    let g = generate(models)?;
    trm::write_atomic(&models.join("icub_upper_body.urdf"), g.urdf.as_bytes())?;
    trm::write_atomic(&models.join("icub_upper_body.ron"), g.ron.as_bytes())?;
    trm::write_atomic(
        &models.join("icub_full_body.urdf"),
        g.full_body_urdf.as_bytes(),
    )?;
    let model = trm_kinematics::RobotModel::load(models.join("icub_upper_body.ron"))?;
    println!(
        "wrote {}/icub_upper_body.{{urdf,ron}}: {} links, {} joints, {} motors",
        models.display(),
        model.num_links(),
        model.num_joints(),
        model.motors().len()
    );
    Ok(())
}

#[cfg(test)]
mod tests {
    #[test]
    fn committed_icub_model_files_are_up_to_date() {
        let models = crate::models_dir();
        let g = super::generate(&models).unwrap();
        let read = |name: &str| std::fs::read_to_string(models.join(name)).unwrap();
        assert!(
            g.urdf == read("icub_upper_body.urdf")
                && g.ron == read("icub_upper_body.ron")
                && g.full_body_urdf == read("icub_full_body.urdf"),
            "models/icub_upper_body.* are stale: run `cargo xtask gen-icub`"
        );
    }
}
