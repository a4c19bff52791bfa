//! `trm model-info [MODEL]`.

use std::path::PathBuf;

use anyhow::Result;
use trm_collision::{CollisionModel, Shape};
use trm_kinematics::srdf::Srdf;
use trm_kinematics::{JointKind, RobotModel};

use crate::support::description::{own_description, write_description};

/// Arguments of `model-info`.
#[derive(clap::Args)]
pub struct Args {
    /// A .urdf file or a .ron model description; the embedded iCub upper body when absent.
    model: Option<PathBuf>,
    /// Also list every link with its parent joint.
    #[arg(long)]
    links: bool,
    /// Also list every disabled collision pair.
    #[arg(long)]
    collisions: bool,
    /// Write every named posture as a one-point ROS 2 JointTrajectory (YAML, one document per
    /// posture) to this file.
    #[arg(long, value_name = "FILE")]
    pub ros_postures: Option<PathBuf>,
    /// Read an SRDF (MoveIt's semantic description) into the model first: its groups, group
    /// states, end effectors and disabled collision pairs join the model description's.
    #[arg(long, value_name = "FILE.srdf")]
    srdf: Option<PathBuf>,
    /// With --srdf: write the merged model description (RON, beside which the model loads
    /// again: `urdf` names the URDF relative to it).
    #[arg(long, value_name = "FILE.ron", requires = "srdf")]
    pub write_description: Option<PathBuf>,
    /// Write the model's groups, named postures and allowed-collision matrix as an SRDF that
    /// MoveIt loads.
    #[arg(long, value_name = "FILE.srdf")]
    pub write_srdf: Option<PathBuf>,
    /// Seconds a controller gets to reach each posture of --ros-postures.
    #[arg(long, default_value_t = 2.0, value_parser = crate::parse::positive)]
    posture_seconds: f64,
    #[command(flatten)]
    meshes: crate::MeshArgs,
}

/// A limit for the tables: degrees, or metres marked `m` for a prismatic joint.
fn limit(x: f64, prismatic: bool) -> String {
    match (x.is_finite(), prismatic) {
        (false, _) => format!("{x}"),
        (true, true) => format!("{x:.3} m"),
        (true, false) => format!("{:.1}", x.to_degrees()),
    }
}

fn coupling_formula(model: &RobotModel, coordinate: usize) -> String {
    let c = &model.couplings()[coordinate];
    let mut text = String::new();
    for &(m, f) in &c.terms {
        let name = &model.motors()[m].name;
        let factor = if f.abs() == 1.0 {
            String::new()
        } else {
            format!("{:.4}·", f.abs())
        };
        let sign = match (text.is_empty(), f < 0.0) {
            (true, false) => "",
            (true, true) => "-",
            (false, false) => " + ",
            (false, true) => " - ",
        };
        text = format!("{text}{sign}{factor}{name}");
    }
    if text.is_empty() {
        format!("{:.4} (constant)", c.offset)
    } else if c.offset != 0.0 {
        format!(
            "{text} {} {:.4}",
            if c.offset < 0.0 { "-" } else { "+" },
            c.offset.abs()
        )
    } else {
        text
    }
}

/// Prints the report.
pub fn run(args: &Args) -> Result<()> {
    let mut model = crate::load_model(args.model.as_deref())?;
    if let Some(path) = &args.srdf {
        let srdf = Srdf::load(path)?;
        let (description, report) =
            srdf.to_description(&model, &own_description(args.model.as_deref())?)?;
        model = model.with_description(&description, None)?;
        println!("from {}: {report}", path.display());
        if let Some(out) = &args.write_description {
            write_description(&description, args.model.as_deref(), out)?;
        }
    }
    if let Some(out) = &args.write_srdf {
        let collision = args.meshes.collision_model(&model)?;
        let disabled = collision.acm().to_spec(&model, |_| true);
        let srdf = Srdf::from_model(&model, &disabled);
        crate::write_atomic(out, srdf.to_xml().as_bytes())?;
        println!(
            "wrote {} ({} groups, {} group states, {} disabled link pairs)",
            out.display(),
            srdf.groups.len(),
            srdf.group_states.len(),
            srdf.disabled.len()
        );
    }
    if let Some(out) = &args.ros_postures {
        let yaml = trm_kinematics::ros::named_postures_yaml(&model, args.posture_seconds)?;
        crate::write_atomic(out, yaml.as_bytes())?;
        println!(
            "wrote {} ({} named postures)",
            out.display(),
            model.posture_names().count()
        );
    }
    let tree = model.tree();
    let fixed = tree.joints.len() - model.num_joints();
    println!("model `{}` from {}", model.name(), model.origin());
    println!(
        "  {} links, {} joints ({} movable, {} fixed), {} motors, {} named frames",
        model.num_links(),
        tree.joints.len(),
        model.num_joints(),
        fixed,
        model.motors().len(),
        model.named_frames().len()
    );
    println!("  root (world frame): {}", tree.links[0].name);

    print_motors(&model);
    print_joints(&model);
    if args.links {
        println!("\nlinks ({}), parent joint → link:", model.num_links());
        for link in &tree.links {
            match link.parent_joint {
                Some(j) => println!(
                    "  {:<28} ← {} ({})",
                    link.name, tree.joints[j].name, tree.links[tree.joints[j].parent].name
                ),
                None => println!("  {:<28} (root)", link.name),
            }
        }
    } else {
        println!("\nlinks: {} (list them with --links)", model.num_links());
    }

    if !model.named_frames().is_empty() {
        println!("\nnamed frames ({}):", model.named_frames().len());
        for f in model.named_frames() {
            let t = f.local_offset.translation.vector;
            let (r, p, y) = f.local_offset.rotation.euler_angles();
            println!(
                "  {:<22} on {:<22} xyz ({:.4}, {:.4}, {:.4})  rpy ({:.4}, {:.4}, {:.4})",
                f.name, tree.links[f.link].name, t.x, t.y, t.z, r, p, y
            );
        }
    }
    let groups: Vec<_> = model.groups().collect();
    if !groups.is_empty() {
        println!("\ngroups:");
        for (name, members) in groups {
            let names: Vec<&str> = members
                .iter()
                .map(|&m| model.motors()[m].name.as_str())
                .collect();
            println!("  {name:<12} ({:>2}) {}", members.len(), names.join(" "));
        }
    }
    let postures: Vec<&str> = model.posture_names().collect();
    if !postures.is_empty() {
        println!("\npostures: {}", postures.join(", "));
    }
    match args.meshes.collision_model(&model) {
        Ok(collision) => {
            print_collision(&collision, args.collisions);
            print_planning(&model, &collision);
        }
        Err(e) => println!("\ncollision bodies: cannot be built: {e:#}"),
    }
    Ok(())
}

/// RRT-Connect's settings when planning for all motors and for each group (what `trm plan`,
/// `benchmark-mbm` and Python's planner use unless told otherwise): the model description's
/// `planning` where it gives them, else sized by the bodies' lever arms
/// ([`RrtOptions::for_robot`]).
fn print_planning(model: &RobotModel, collision: &CollisionModel) {
    use trm_plan::rrt::{CHECK_TRAVEL, DOMAIN_RADIUS, RrtOptions, STEP_MOTORS, STEP_TRAVEL};
    let mut sets = vec![("all motors".to_string(), Ok(model.all_active()))];
    for (name, _) in model.groups() {
        sets.push((
            name.into(),
            model.active_set(&[name], &model.neutral_motors()),
        ));
    }
    let width = sets.iter().map(|(name, _)| name.len()).max().unwrap_or(0);
    let own = model.planning();
    println!(
        "\nplanning (RRT-Connect's step, its edges' resolution and first dynamic-domain radius; \
         the largest lever: the farthest a body point moves per unit step of the motors):"
    );
    for (name, active) in sets {
        let sized = active.map_err(anyhow::Error::from).and_then(|active| {
            let levers = trm_collision::Levers::new(collision, &active)?;
            let options = RrtOptions::for_robot(collision, &active)?;
            Ok((active.len(), levers.max_reach(), options))
        });
        match sized {
            Ok((motors, lever, o)) => println!(
                "  {name:<width$} ({motors:>2}) range {:.3} rad, resolution 1/{:.1} rad, domains \
                 {:.2} rad; largest lever {lever:.2} m/rad{}",
                o.range,
                1.0 / o.resolution,
                o.domain_radius,
                if lever > 0.0 {
                    ""
                } else {
                    " (no body moves: the defaults)"
                }
            ),
            Err(e) => println!("  {name:<width$} cannot be sized: {e:#}"),
        }
    }
    let given: Vec<&str> = [
        ("range", own.range.is_some()),
        ("resolution", own.resolution.is_some()),
        ("domain_radius", own.domain_radius.is_some()),
    ]
    .into_iter()
    .filter_map(|(name, set)| set.then_some(name))
    .collect();
    if !given.is_empty() {
        println!("  (the model description sets {})", given.join(", "));
    }
    if given.len() < 3 {
        println!(
            "  (sized by the lever arms: range {STEP_TRAVEL} m / lever · √({STEP_MOTORS} / \
             motors), resolution {CHECK_TRAVEL} m / lever, domains {DOMAIN_RADIUS} rad · √(motors / \
             {STEP_MOTORS}); fix them in the model description: `planning: (range: Some(…), \
             resolution: Some(…), domain_radius: Some(…))`)"
        );
    }
}

/// The motors, their limits and the joints each drives.
fn print_motors(model: &RobotModel) {
    println!(
        "\nmotors ({}), limits in degrees (metres, marked m, for prismatic joints):",
        model.motors().len()
    );
    println!(
        "  {:>3}  {:<28} {:>9} {:>9}  drives",
        "#", "name", "lower", "upper"
    );
    for (i, m) in model.motors().iter().enumerate() {
        let driven: Vec<usize> = (model.couplings().iter().enumerate())
            .filter(|(_, c)| c.terms.iter().any(|&(k, _)| k == i))
            .map(|(j, _)| j)
            .collect();
        let prismatic = driven
            .iter()
            .any(|&j| model.joint(j).kind == JointKind::Prismatic);
        let driven: Vec<&str> = driven
            .iter()
            .map(|&j| model.joint(j).name.as_str())
            .collect();
        let driven = if driven.len() == 1 && driven[0] == m.name {
            String::from("(itself)")
        } else {
            driven.join(", ")
        };
        println!(
            "  {i:>3}  {:<28} {:>9} {:>9}  {driven}",
            m.name,
            limit(m.limits.lower, prismatic),
            limit(m.limits.upper, prismatic)
        );
    }
}

/// The movable joints, their limits and (coupled models) their values as motor formulas.
fn print_joints(model: &RobotModel) {
    println!("\nmovable joints ({}):", model.num_joints());
    println!(
        "  {:>3}  {:<28} {:<10} {:>9} {:>9}  value",
        "#", "name", "type", "lower", "upper"
    );
    for j in 0..model.num_joints() {
        let joint = model.joint(j);
        let kind = match joint.kind {
            JointKind::Revolute => "revolute",
            JointKind::Continuous => "continuous",
            JointKind::Prismatic => "prismatic",
            JointKind::Fixed => "fixed",
        };
        println!(
            "  {j:>3}  {:<28} {kind:<10} {:>9} {:>9}  {}",
            joint.name,
            limit(joint.limits.lower, joint.kind == JointKind::Prismatic),
            limit(joint.limits.upper, joint.kind == JointKind::Prismatic),
            coupling_formula(model, j)
        );
    }
    if model.is_coupled() {
        println!("  (value: the joint as a function of the motors, angles in rad)");
    }
}

fn shape_text(shape: &Shape) -> String {
    match shape {
        Shape::Sphere { radius } => format!("sphere r {radius:.4}"),
        Shape::Box { size } => format!("box {:.4} × {:.4} × {:.4}", size[0], size[1], size[2]),
        Shape::Cylinder { radius, length } => format!("cylinder r {radius:.4} l {length:.4}"),
        Shape::Capsule { radius, length } => format!("capsule r {radius:.4} l {length:.4}"),
        Shape::Convex { points } => format!("convex hull of {} points", points.len()),
        Shape::Points { points, radius } => {
            format!("{} points r {radius:.4}", points.len())
        }
        Shape::Mesh { triangles, .. } => format!("mesh of {} triangles", triangles.len()),
    }
}

fn print_collision(collision: &CollisionModel, list_pairs: bool) {
    let model = collision.robot();
    let links = &model.tree().links;
    println!("\ncollision bodies ({}):", collision.bodies().len());
    for b in collision.bodies() {
        let t = b.local.translation.vector;
        println!(
            "  {:<22} on {:<22} {:<36} at ({:.4}, {:.4}, {:.4})",
            b.name,
            links[b.link].name,
            shape_text(&b.shape),
            t.x,
            t.y,
            t.z
        );
    }
    let mut by_reason: std::collections::BTreeMap<&str, Vec<[usize; 2]>> = Default::default();
    for (pair, reason) in collision.acm().disabled_pairs() {
        by_reason.entry(reason.as_str()).or_default().push(pair);
    }
    let has = collision.has_geometry();
    let summary: Vec<String> = by_reason
        .iter()
        .map(|(r, pairs)| {
            let with_geometry = pairs.iter().filter(|[a, b]| has[*a] && has[*b]).count();
            format!("{with_geometry} {r}")
        })
        .collect();
    println!(
        "\ncollision pairs: {} link pairs checked; disabled: {} (pairs of links with bodies)",
        collision.num_checked_link_pairs(),
        summary.join(", ")
    );
    if list_pairs {
        for (reason, pairs) in &by_reason {
            for [a, b] in pairs.iter().filter(|[a, b]| has[*a] && has[*b]) {
                println!("  {reason:<8} {:<22} {}", links[*a].name, links[*b].name);
            }
        }
    } else {
        println!("  (list them with --collisions)");
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn prismatic_limits_are_shown_in_metres_and_revolute_ones_in_degrees() {
        assert_eq!(super::limit(0.2, true), "0.200 m");
        assert_eq!(super::limit(std::f64::consts::FRAC_PI_2, false), "90.0");
        assert_eq!(super::limit(f64::INFINITY, false), "inf");
    }
}
