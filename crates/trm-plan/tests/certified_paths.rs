//! Certified paths: proved free in continuous motion where checks at points step over a thin
//! obstacle.

use trm_collision::{Shape, World};
use trm_kinematics::nalgebra::Isometry3;
use trm_plan::Planner;
use trm_plan::rrt::RrtOptions;

/// A thin post that a coarse check steps over: planned at points only, the straight motion is
/// returned and crosses it; with certified paths, the path found is proved free in continuous
/// motion and goes around.
#[test]
fn certified_paths_do_not_cross_what_points_miss() {
    let urdf = r#"<robot name="arm">
      <link name="base"/>
      <link name="a"/>
      <link name="b"><collision><origin xyz="0.5 0 0"/><geometry><sphere radius="0.05"/></geometry></collision></link>
      <joint name="j1" type="revolute"><parent link="base"/><child link="a"/>
        <axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
      <joint name="j2" type="revolute"><parent link="a"/><child link="b"/><origin xyz="1 0 0"/>
        <axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
    </robot>"#;
    let robot = trm_kinematics::RobotModel::from_urdf_str(urdf, "<arm>").unwrap();
    let collision = trm_collision::CollisionModel::new(&robot).unwrap();
    let mut world = World::new();
    // a post of 1 cm radius where the sphere passes at j1 = 0 (x = 1.5)
    world
        .add(
            "post",
            Shape::Cylinder {
                radius: 0.01,
                length: 1.0,
            },
            Isometry3::translation(1.5, 0.0, 0.0),
        )
        .unwrap();
    let active = robot.all_active();
    let objective = trm_tasks::Objective::new(active.clone(), collision.clone(), world.clone());
    let mut planner = Planner::new(&objective, &[]).unwrap();
    let (start, goal) = ([-0.2, 0.0], [0.3, 0.0]);
    // checked every 0.25 rad and between: at j1 = -0.2, -0.075, 0.05, 0.175, 0.3 the sphere
    // (0.1 m wide) misses the post
    let coarse = RrtOptions {
        resolution: 0.25,
        ..Default::default()
    };
    let mut certifier = trm_collision::Certifier::new(&collision, &active).unwrap();
    let plain = planner.connect(&start, &goal, &coarse).unwrap();
    assert!(
        !certifier.path(&world, &plain.path).unwrap().is_free(),
        "{:?}",
        plain.path
    );
    let certified = RrtOptions {
        certified: true,
        ..coarse
    };
    let proved = planner.connect(&start, &goal, &certified).unwrap();
    assert!(proved.path.len() > 2, "{:?}", proved.path);
    assert!(certifier.path(&world, &proved.path).unwrap().is_free());
    assert_eq!(
        (
            proved.path[0].as_slice(),
            proved.path.last().unwrap().as_slice()
        ),
        (&start[..], &goal[..])
    );
}
