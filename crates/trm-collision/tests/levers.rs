//! Lever arms bound real motion: on trm's Panda, VAMP's spherized Panda and the iCub upper body
//! (coupled motors), no body sphere's centre moves farther between two configurations than
//! `Levers::displacement` of their difference allows, and some come close to it.

use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use trm_collision::{CollisionModel, Levers};
use trm_kinematics::RobotModel;

fn check(file: &str) {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../models")
        .join(file);
    let robot = RobotModel::load(path).unwrap();
    let collision = CollisionModel::new(&robot).unwrap();
    let active = robot.all_active();
    let levers = Levers::new(&collision, &active).unwrap();
    assert!(levers.max_reach() > 0.0, "{file}");
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    let (mut a, mut b) = (robot.pose_buffer(), robot.pose_buffer());
    let mut tightest = 0.0f64;
    for _ in 0..300 {
        let q = active.random(&mut rng);
        // a short step and a long one
        let scale = if rng.random_range(0..2) == 0 {
            0.05
        } else {
            1.0
        };
        let dq: Vec<f64> = (0..q.len())
            .map(|_| scale * rng.random_range(-1.0..1.0))
            .collect();
        let r: Vec<f64> = q.iter().zip(&dq).map(|(x, d)| x + d).collect();
        active.forward(&q, &mut a).unwrap();
        active.forward(&r, &mut b).unwrap();
        let bound = levers.displacement(&dq);
        for (k, body) in collision.bodies().iter().enumerate() {
            for s in collision.enclosing_spheres(k) {
                let (pa, pb) = (
                    a.poses()[body.link] * s.center,
                    b.poses()[body.link] * s.center,
                );
                let moved = (pb - pa).norm();
                assert!(
                    moved <= bound * (1.0 + 1e-9) + 1e-12,
                    "{file}: {} moved {moved} m, bound {bound} m",
                    body.name
                );
                tightest = tightest.max(moved / bound);
            }
        }
    }
    // the bound is not vacuous: some step moves a sphere by a fair share of it
    assert!(tightest > 0.3, "{file}: at most {tightest} of the bound");
}

#[test]
fn levers_bound_trm_panda() {
    check("panda/panda.ron");
}

#[test]
fn levers_bound_vamp_panda() {
    check("panda-mbm/panda_spherized.ron");
}

#[test]
fn levers_bound_the_icub_upper_body() {
    check("icub_upper_body.ron");
}
