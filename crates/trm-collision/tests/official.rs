//! The official iCub URDFs, whose collision geometry is STL (and COLLADA) meshes.
//!
//! The meshes are not in the repository (18 MB, from the `icub-models` package on PyPI):
//! `.ci/run` installs them and sets `TRM_ICUB_MESHES` to the directory that holds `iCub/`.
//! Without it, the mesh test says so and checks only that the missing meshes are reported.

use trm_collision::{AcmOptions, CollisionError, CollisionModel, CollisionOptions, generate_acm};

fn meshes() -> Option<std::path::PathBuf> {
    let dir = std::path::PathBuf::from(std::env::var_os("TRM_ICUB_MESHES")?);
    assert!(
        dir.join("iCub/meshes").is_dir(),
        "TRM_ICUB_MESHES={} holds no iCub/meshes",
        dir.display()
    );
    Some(dir)
}

/// iCubGenova04 (all its meshes are in icub-models) and its collision model on the meshes in
/// `dir`.
fn genova04_with_meshes(dir: std::path::PathBuf) -> (trm_kinematics::RobotModel, CollisionModel) {
    let options = CollisionOptions {
        package_paths: vec![dir],
        ..Default::default()
    };
    let robot = trm_models::icub_genova04();
    let collision = CollisionModel::with_options(&robot, &options).unwrap();
    (robot, collision)
}

#[test]
fn without_mesh_paths_the_official_urdf_reports_the_missing_mesh() {
    let robot = trm_models::icub_official();
    let e = CollisionModel::new(&robot).unwrap_err();
    assert!(matches!(e, CollisionError::MeshNotFound { .. }), "{e}");
    let text = e.to_string();
    assert!(
        text.contains("package://iCub/meshes/") && text.contains("--package-path"),
        "{text}"
    );
}

#[test]
fn the_official_urdfs_with_their_meshes_can_be_collision_checked() {
    let Some(dir) = meshes() else {
        eprintln!("TRM_ICUB_MESHES is not set: skipping the mesh check (see .ci/run)");
        return;
    };
    // iCubGenova04's meshes are all in icub-models; the visuomanip hands' COLLADA meshes are not.
    let (robot, collision) = genova04_with_meshes(dir);
    assert!(
        collision.bodies().len() >= 39,
        "{}",
        collision.bodies().len()
    );
    // A generated matrix leaves the neutral posture free; crossing the forearms collides.
    let report = generate_acm(
        &collision,
        &AcmOptions {
            samples: 300,
            ..Default::default()
        },
    )
    .unwrap();
    let checked = collision.with_acm(report.acm).unwrap();
    let mut poses = robot.pose_buffer();
    let mut placed = checked.placed_bodies();
    let mut q = robot.neutral_motors();
    robot.forward_motors(&q, &mut poses).unwrap();
    checked.place(&poses, &mut placed);
    assert_eq!(checked.count_self(&placed), 0);
    assert!(checked.min_self_distance(&placed).unwrap().distance > 0.0);
    for side in ["l", "r"] {
        for (motor, degrees) in [
            ("shoulder_pitch", -50.0),
            ("shoulder_roll", 10.0),
            ("shoulder_yaw", 60.0),
            ("elbow", 90.0),
        ] {
            q[robot.motor_index(&format!("{side}_{motor}")).unwrap()] = f64::to_radians(degrees);
        }
    }
    robot.forward_motors(&q, &mut poses).unwrap();
    checked.place(&poses, &mut placed);
    let pairs = checked.colliding_pairs(&placed, &trm_collision::World::new());
    assert!(
        pairs
            .iter()
            .any(|p| p.body == "r_forearm"
                && p.other == trm_collision::Other::Body("l_forearm".into())),
        "{pairs:?}"
    );
}

/// Proxies fitted to the official meshes (`trm_collision::fit`) enclose every vertex of every
/// link's meshes' convex hulls.
#[test]
fn proxies_fitted_to_the_official_meshes_enclose_every_vertex() {
    let Some(dir) = meshes() else {
        eprintln!("TRM_ICUB_MESHES is not set: skipping the fitting check (see .ci/run)");
        return;
    };
    let (robot, collision) = genova04_with_meshes(dir);
    let (mut links, mut fitted, mut hulls) = (0, 0.0, 0.0);
    for l in 0..robot.tree().links.len() {
        let points = collision.link_mesh_points(l);
        if points.is_empty() {
            continue;
        }
        let fits = trm_collision::fit::fit(&points).unwrap();
        for f in [&fits.sphere, &fits.capsule, &fits.cuboid] {
            assert!(trm_collision::fit::worst_outside(f, &points) <= 1e-9);
        }
        links += 1;
        fitted += fits.best().volume;
        hulls += fits.hull_volume;
    }
    eprintln!(
        "{links} links: fitted {:.2}× the hulls' volume",
        fitted / hulls
    );
    assert!(links >= 39 && fitted / hulls < 2.0);
}
