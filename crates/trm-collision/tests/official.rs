//! The official iCub URDFs, whose collision geometry is STL (and COLLADA) meshes.
//!
//! The meshes are not in the repository (18 MB, from the `icub-models` package on PyPI):
//! `.ci/run` installs them and sets `TRM_ICUB_MESHES` to the directory that holds `iCub/`.
//! Without it, the mesh test says so and checks only that the missing meshes are reported.

use trm_collision::{AcmSettings, CollisionError, CollisionModel, CollisionOptions, generate_acm};

fn meshes() -> Option<std::path::PathBuf> {
    let dir = std::path::PathBuf::from(std::env::var_os("TRM_ICUB_MESHES")?);
    assert!(dir.join("iCub/meshes").is_dir(), "TRM_ICUB_MESHES={} holds no iCub/meshes", dir.display());
    Some(dir)
}

#[test]
fn without_mesh_paths_the_official_urdf_reports_the_missing_mesh() {
    let robot = trm_models::icub_official();
    let e = CollisionModel::new(&robot).unwrap_err();
    assert!(matches!(e, CollisionError::MeshNotFound { .. }), "{e}");
    let text = e.to_string();
    assert!(text.contains("package://iCub/meshes/") && text.contains("--package-path"), "{text}");
}

#[test]
fn the_official_urdfs_with_their_meshes_can_be_collision_checked() {
    let Some(dir) = meshes() else {
        eprintln!("TRM_ICUB_MESHES is not set: skipping the mesh check (see .ci/run)");
        return;
    };
    let options = CollisionOptions {
        package_paths: vec![dir],
        ..Default::default()
    };
    // iCubGenova04's meshes are all in icub-models; the visuomanip hands' COLLADA meshes are not.
    for robot in [trm_models::icub_genova04()] {
        let collision = CollisionModel::with_options(&robot, &options).unwrap();
        assert!(collision.bodies().len() >= 39, "{}", collision.bodies().len());
        // A generated matrix leaves the zero posture free, and random postures are classified
        // the same way by every query.
        let report = generate_acm(
            &collision,
            &AcmSettings {
                samples: 300,
                ..Default::default()
            },
        )
        .unwrap();
        let checked = collision.with_acm(report.acm).unwrap();
        let mut poses = robot.pose_buffer();
        let mut placed = checked.placed_bodies();
        robot
            .forward_motors(&robot.neutral_motors(), &mut poses)
            .unwrap();
        checked.place(&poses, &mut placed);
        assert_eq!(checked.count_self(&placed), 0);
        assert!(checked.min_self_distance(&placed).unwrap().distance > 0.0);
    }
}
