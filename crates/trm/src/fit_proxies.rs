//! `trm fit-proxies MODEL.urdf [--package-path DIR] [--out FILE.urdf] [--compare MODEL]`:
//! a sphere, capsule or box fitted around each link's collision meshes (`trm_collision::fit`),
//! with the volume against the meshes' convex hulls; optionally the URDF with the meshes
//! replaced by the fitted primitives, and a comparison with another model's primitives.

use std::fmt::Write as _;
use std::path::PathBuf;

use anyhow::{Context, Result};
use trm_collision::CollisionModel;
use trm_collision::fit::{fit_model, fit_model_spheres, urdf_with_proxies, urdf_with_spheres};

/// Arguments of `fit-proxies`.
#[derive(clap::Args)]
pub struct Args {
    /// The URDF whose `<collision>` meshes are fitted.
    model: PathBuf,
    #[command(flatten)]
    meshes: crate::MeshArgs,
    /// Write the URDF with each meshed link's collisions replaced by its fitted primitive.
    #[arg(long, value_name = "FILE.urdf")]
    pub out: Option<PathBuf>,
    /// Another model of the same robot (e.g. hand-made proxies) whose primitives' volumes are
    /// compared link by link.
    #[arg(long, value_name = "MODEL", conflicts_with = "spheres")]
    compare: Option<PathBuf>,
    /// Fit up to N spheres per link instead of one primitive (a sphere model, as VAMP's
    /// spherized URDFs): every point of the convex hull of the link's bodies enclosed.
    #[arg(long, value_name = "N", value_parser = crate::parse::count(1, 1000))]
    spheres: Option<usize>,
}

/// Fits sphere sets, prints the table, writes the URDF when asked.
fn run_spheres(args: &Args, collision: &CollisionModel, count: usize) -> Result<()> {
    let sets =
        fit_model_spheres(collision, count).with_context(|| args.model.display().to_string())?;
    println!(
        "{:<24} {:>9} {:>8} {:>12} {:>10}",
        "link", "hull cm³", "spheres", "spheres cm³", "ratio"
    );
    let (mut hull, mut volume, mut total) = (0.0, 0.0, 0);
    for s in &sets {
        hull += s.hull;
        volume += s.volume;
        total += s.spheres.len();
        println!(
            "{:<24} {:>9.1} {:>8} {:>12.1} {:>10.2}",
            s.link,
            s.hull * 1e6,
            s.spheres.len(),
            s.volume * 1e6,
            s.volume / s.hull.max(1e-12)
        );
    }
    println!(
        "{} links, {total} spheres: {:.1} cm³ of spheres (overlaps counted twice) against hulls {:.1} cm³ ({:.2}×); every point of every hull within a sphere",
        sets.len(),
        volume * 1e6,
        hull * 1e6,
        volume / hull.max(1e-12),
    );
    if let Some(out) = &args.out {
        let text = std::fs::read_to_string(&args.model)
            .with_context(|| format!("reading {}", args.model.display()))?;
        let urdf = urdf_with_spheres(&text, &args.model.display().to_string(), &sets)?;
        crate::write_atomic(out, urdf.as_bytes())?;
        println!("wrote {} ({total} spheres)", out.display());
    }
    Ok(())
}

/// Fits every link that has meshes, prints the table, writes what was asked.
pub fn run(args: &Args) -> Result<()> {
    let model = crate::load_model(Some(&args.model))?;
    let collision = args.meshes.collision_model(&model)?;
    if let Some(count) = args.spheres {
        return run_spheres(args, &collision, count);
    }
    let fits = fit_model(&collision).with_context(|| args.model.display().to_string())?;
    let other = match &args.compare {
        Some(p) => Some(CollisionModel::new(&crate::load_model(Some(p))?)?),
        None => None,
    };
    let other_volume = |name: &str| -> Option<f64> {
        let other = other.as_ref()?;
        let l = other
            .robot()
            .tree()
            .links
            .iter()
            .position(|k| k.name == name)?;
        let v: Option<f64> = other
            .bodies()
            .iter()
            .filter(|b| b.link == l)
            .map(|b| b.shape.volume())
            .sum();
        v.filter(|v| *v > 0.0)
    };
    println!(
        "{:<24} {:>9} {:>9} {:>8} {:>9}{}",
        "link",
        "hull cm³",
        "fit cm³",
        "fit/hull",
        "primitive",
        if other.is_some() {
            "  compared cm³  compared/hull"
        } else {
            ""
        }
    );
    let (mut hull_sum, mut fit_sum, mut cmp_fit, mut cmp_other, mut tighter): (
        f64,
        f64,
        f64,
        f64,
        usize,
    ) = (0.0, 0.0, 0.0, 0.0, 0);
    for f in &fits {
        hull_sum += f.hull;
        fit_sum += f.fitted.volume;
        let mut line = format!(
            "{:<24} {:>9.1} {:>9.1} {:>8.2} {:>9}",
            f.link,
            f.hull * 1e6,
            f.fitted.volume * 1e6,
            f.fitted.volume / f.hull.max(1e-12),
            f.fitted.shape.kind()
        );
        if let Some(v) = other_volume(&f.link) {
            cmp_fit += f.fitted.volume;
            cmp_other += v;
            tighter += usize::from(f.fitted.volume < v);
            let _ = write!(line, "  {:>12.1}  {:>13.2}", v * 1e6, v / f.hull.max(1e-12));
        }
        println!("{line}");
    }
    let worst = fits
        .iter()
        .map(|f| f.worst)
        .fold(f64::NEG_INFINITY, f64::max);
    println!(
        "{} links: fitted {:.1} cm³ against hulls {:.1} cm³ ({:.2}×); every vertex enclosed: {} (largest distance outside {:.1e} m)",
        fits.len(),
        fit_sum * 1e6,
        hull_sum * 1e6,
        fit_sum / hull_sum.max(1e-12),
        if worst <= 1e-9 { "yes" } else { "NO" },
        worst.max(0.0)
    );
    if let Some(p) = &args.compare {
        println!(
            "against {} on the {} links both have: fitted {:.1} cm³, compared {:.1} cm³ ({:.2}×); the fit is tighter on {tighter}",
            p.display(),
            fits.iter()
                .filter(|f| other_volume(&f.link).is_some())
                .count(),
            cmp_fit * 1e6,
            cmp_other * 1e6,
            cmp_fit / cmp_other.max(1e-12)
        );
    }
    if let Some(out) = &args.out {
        let text = std::fs::read_to_string(&args.model)
            .with_context(|| format!("reading {}", args.model.display()))?;
        let urdf = urdf_with_proxies(&text, &args.model.display().to_string(), &fits)?;
        crate::write_atomic(out, urdf.as_bytes())?;
        println!(
            "wrote {} ({} links with fitted proxies)",
            out.display(),
            fits.len()
        );
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use trm_collision::fit::worst_outside;
    use trm_collision::{CollisionModel, CollisionOptions, Shape};
    use trm_kinematics::RobotModel;
    use trm_kinematics::nalgebra::Point3;

    /// A two-link arm whose links are a scaled mesh cube: fitted, written as a URDF with boxes,
    /// read back; the written boxes enclose every hull vertex and are that tight.
    #[test]
    fn fitted_proxies_are_written_into_the_urdf_and_enclose_the_meshes() {
        let dir = crate::test_dir("fit-proxies");
        let fixtures = crate::models_dir().join("../crates/trm-collision/tests/fixtures/meshes");
        let mesh = |scale: &str| {
            format!(
                "<collision><origin xyz=\"0.01 0 0.05\" rpy=\"0.3 0 0\"/><geometry><mesh filename=\"package://demo_pkg/meshes/cube.stl\" scale=\"{scale}\"/></geometry></collision>"
            )
        };
        let urdf = format!(
            r#"<robot name="arm">
  <link name="base">{}</link>
  <link name="tip">{}</link>
  <joint name="j" type="revolute"><parent link="base"/><child link="tip"/>
    <origin xyz="0 0 0.2"/><axis xyz="0 1 0"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
</robot>"#,
            mesh("0.1 0.2 0.05"),
            mesh("0.05 0.05 0.3")
        );
        let input = dir.join("arm.urdf");
        std::fs::write(&input, urdf).unwrap();
        let out = dir.join("arm.fitted.urdf");
        let args = super::Args {
            model: input.clone(),
            meshes: crate::MeshArgs {
                package_paths: vec![fixtures.clone()],
            },
            out: Some(out.clone()),
            compare: None,
            spheres: None,
        };
        super::run(&args).unwrap();
        let options = CollisionOptions::with_ros_package_path(vec![fixtures]);
        let meshed =
            CollisionModel::with_options(&RobotModel::load(&input).unwrap(), &options).unwrap();
        let fitted = CollisionModel::new(&RobotModel::load(&out).unwrap()).unwrap();
        assert_eq!(fitted.bodies().len(), 2);
        for (m, f) in meshed.bodies().iter().zip(fitted.bodies()) {
            let Shape::Convex { points } = &m.shape else {
                panic!("{:?}", m.shape)
            };
            let points: Vec<Point3<f64>> = points
                .iter()
                .map(|v| m.local * Point3::new(v[0], v[1], v[2]))
                .collect();
            assert_eq!(f.shape.kind(), "box", "{:?}", f.shape);
            let written = trm_collision::fit::Fitted {
                shape: f.shape.clone(),
                pose: f.local,
                volume: 0.0,
            };
            assert!(worst_outside(&written, &points) <= 0.0);
            // a box around a box: the same box, to the written precision
            assert!(worst_outside(&written, &points) > -1e-5);
        }
    }
}

#[cfg(test)]
mod committed {
    /// Runs the commands of models/NAME/NOTICE.md into a temporary directory and compares
    /// their output with the committed NAME_fitted.urdf and NAME.ron: fit-proxies on `urdf`,
    /// the SRDF into a description, and (when given) gen-acm for the proxies at `posture`.
    fn check(name: &str, urdf: &str, srdf: &str, acm: Option<(&str, usize)>) {
        let models = crate::models_dir();
        let robot = models.join(name);
        let dir = crate::test_dir(&format!("{name}-current"));
        let fitted = dir.join(format!("{name}_fitted.urdf"));
        let stale = format!("models/{name} is stale: run the commands in models/{name}/NOTICE.md");
        super::run(&super::Args {
            model: robot.join(urdf),
            meshes: crate::MeshArgs {
                package_paths: vec![robot.clone()],
            },
            out: Some(fitted.clone()),
            compare: None,
            spheres: None,
        })
        .unwrap();
        let read = |p: &std::path::Path| std::fs::read_to_string(p).unwrap();
        assert_eq!(
            read(&fitted),
            read(&robot.join(format!("{name}_fitted.urdf"))),
            "{stale}"
        );
        let description = dir.join(format!("{name}.ron"));
        // the steps after fitting read the fitted URDF just written (the same bytes)
        crate::support::description::write_srdf_description(
            &fitted,
            &robot.join(srdf),
            &description,
        )
        .unwrap();
        if let Some((posture, samples)) = acm {
            use clap::Parser;
            let path = description.to_str().unwrap();
            let samples = samples.to_string();
            let cli = crate::Cli::try_parse_from([
                "xtask",
                "gen-acm",
                path,
                "--posture",
                posture,
                "--samples",
                &samples,
                "--write-description",
                path,
            ])
            .unwrap();
            crate::dispatch(cli.command).unwrap();
        }
        // the written `urdf` field is relative to the output: compare the rest
        let body = |text: String| -> String {
            text.lines()
                .filter(|l| !l.trim_start().starts_with("urdf:") && !l.starts_with("//"))
                .collect::<Vec<_>>()
                .join("\n")
        };
        assert_eq!(
            body(read(&description)),
            body(read(&robot.join(format!("{name}.ron")))),
            "{stale}"
        );
    }

    #[test]
    fn the_committed_panda_files_are_current() {
        check(
            "panda",
            "example-robot-data/robots/panda_description/urdf/panda.urdf",
            "example-robot-data/robots/panda_description/srdf/panda.srdf",
            None,
        );
    }

    #[test]
    fn the_committed_talos_files_are_current() {
        check(
            "talos",
            "example-robot-data/robots/talos_data/robots/talos_reduced.urdf",
            "example-robot-data/robots/talos_data/srdf/talos.srdf",
            Some(("half_sitting", 20_000)),
        );
    }
}
