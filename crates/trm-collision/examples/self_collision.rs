//! Self-collision of the 41-DOF iCub: the home posture, then 1000 seeded random postures —
//! how many collide, the most common colliding pair, and the minimum self-distance at home.
//!
//! `cargo run -p trm-collision --example self_collision`

use rand::{RngExt, SeedableRng};
use trm_collision::{CollisionError, CollisionModel, World};

fn main() -> Result<(), CollisionError> {
    let robot = trm_models::icub_upper_body();
    let collision = CollisionModel::new(&robot)?;
    let mut poses = robot.pose_buffer();
    let mut placed = collision.placed_bodies();
    let home = robot.posture("home")?.to_vec();
    robot.forward_motors(&home, &mut poses)?;
    collision.place(&poses, &mut placed);
    println!(
        "home: {} colliding link pairs, minimum self-distance {:.4} m",
        collision.count_self(&placed),
        collision
            .min_self_distance(&placed)
            .map_or(f64::INFINITY, |p| p.distance)
    );
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(0);
    let mut colliding = 0;
    let mut pairs = std::collections::BTreeMap::<String, usize>::new();
    let world = World::new();
    for _ in 0..1000 {
        let q: Vec<f64> = robot
            .motors()
            .iter()
            .map(|m| m.limits.lower + rng.random::<f64>() * (m.limits.upper - m.limits.lower))
            .collect();
        robot.forward_motors(&q, &mut poses)?;
        collision.place(&poses, &mut placed);
        if collision.is_colliding(&placed, &world) {
            colliding += 1;
            for p in collision.colliding_pairs(&placed, &world) {
                let bodies = collision.bodies();
                *pairs
                    .entry(format!(
                        "{} – {}",
                        bodies[p.body_index].name, bodies[p.other_index].name
                    ))
                    .or_default() += 1;
            }
        }
    }
    let top = pairs.iter().max_by_key(|(_, n)| **n);
    println!("random postures: {colliding} of 1000 collide; most common pair: {top:?}");
    Ok(())
}
