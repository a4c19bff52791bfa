//! The cloud's grid against brute force, its vector instructions against the plain loops.

use super::super::model::Ball;
use super::*;
use crate::{CollisionModel, Shape, World};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// Every query finds the nearest point within its range, as a scan of all points does,
/// on clouds of every shape: a plane, a cluster, a line, a single point, wide and sparse.
#[test]
fn nearest_within_range_is_the_brute_force_nearest() {
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    for case in 0..60 {
        let n = [1, 7, 300, 5000][case % 4];
        let spread: [f32; 3] = match case % 5 {
            0 => [1.0, 1.0, 0.0],
            1 => [0.1, 0.1, 0.1],
            2 => [2.0, 0.0, 0.0],
            3 => [30.0, 30.0, 5.0],
            _ => [0.6, 0.8, 1.2],
        };
        let points: Vec<[f32; 3]> = (0..n)
            .map(|_| std::array::from_fn(|k| rng.random_range(-0.5..=0.5) * spread[k] + 0.3))
            .collect();
        let cell = rng.random_range(0.005..0.2);
        let (near, far) = (rng.random_range(0.0..4.0), rng.random_range(0.0..20.0));
        let grid = CloudGrid::new(&points, cell, near * cell, far * cell);
        assert_eq!(grid.len(), n);
        for _ in 0..200 {
            let p: [f32; 3] =
                std::array::from_fn(|k| rng.random_range(-0.7..=0.7) * (spread[k] + 0.2) + 0.3);
            let range = rng.random_range(0.0..0.3);
            let brute = points
                .iter()
                .map(|q| (0..3).map(|k| (q[k] - p[k]) * (q[k] - p[k])).sum::<f32>())
                .fold(f32::INFINITY, f32::min);
            let found = grid.nearest2(p, range, 0.0);
            let clearance = grid.clearance(p);
            // a lane the witness settles has a point within its sphere
            let c = p.map(|v| F([v; FAST_LANES]));
            if grid.holding::<false>(&c, range, 1) != 0 {
                assert!(brute < range * range, "case {case}: {p:?} holds none");
            }
            assert!(
                clearance * clearance <= brute,
                "case {case}: clearance {clearance}, nearest {}",
                brute.sqrt()
            );
            if brute <= range * range {
                assert_eq!(found, brute, "case {case}: {p:?} range {range}");
            } else {
                assert!(found >= brute, "case {case}: {found} < {brute}");
            }
        }
    }
}

/// Near the points a cell's clearance is the distance from the cell to the points about
/// it (less than a cell short of a query's own distance, on average), and far from them it
/// still grows up to `far`: a transform of occupied cells alone is short by √3 cells.
#[test]
fn clearances_are_tight_near_the_points_and_reach_far() {
    let mut rng = ChaCha8Rng::seed_from_u64(12);
    // a board of points 2 cm apart, as a thinned camera cloud gives it, and a small cell
    let points: Vec<[f32; 3]> = (0..40)
        .flat_map(|i| (0..30).map(move |j| [0.02 * i as f32, 0.02 * j as f32, 0.5]))
        .chain([[0.4, 0.3, 0.0], [0.4, 0.3, 1.0]])
        .collect();
    let (cell, near, far) = (0.02, 0.08, 0.3);
    let grid = CloudGrid::new(&points, cell, near, far);
    // the grid's own cell: coarser than asked where the cells would be too many
    let (cell, diagonal) = (grid.cell, 3f32.sqrt() * grid.cell);
    let (mut short, mut count) = (0.0, 0);
    for _ in 0..4000 {
        let p: [f32; 3] = [
            rng.random_range(0.0..0.8),
            rng.random_range(0.0..0.6),
            rng.random_range(0.0..1.0),
        ];
        let nearest = points
            .iter()
            .map(|q| (0..3).map(|k| (q[k] - p[k]).powi(2)).sum::<f32>())
            .fold(f32::INFINITY, f32::min)
            .sqrt();
        let clearance = grid.clearance(p);
        assert!(clearance <= nearest, "{p:?}: {clearance} > {nearest}");
        if nearest < near {
            short += nearest - clearance;
            count += 1;
        } else if nearest < far - 2.0 * diagonal {
            let lost = nearest - clearance;
            assert!(lost <= 2.0 * diagonal, "{p:?}: {clearance} for {nearest}");
        }
    }
    let short = short / count as f32;
    assert!(
        count > 500 && short < 0.75 * cell,
        "{count} near: {short} short on average"
    );
    // within a cell of the board, a sphere of two cells holds a point by its cell's witness
    // alone
    let (mut held, mut tried) = (0, 0);
    for _ in 0..1000 {
        let p = [
            rng.random_range(0.0..0.78),
            rng.random_range(0.0..0.58),
            0.5 + rng.random_range(-1.0..1.0) * cell,
        ];
        let c = p.map(|v| F([v; FAST_LANES]));
        held += grid.holding::<false>(&c, 2.0 * cell, 1).count_ones();
        tried += 1;
    }
    assert!(held * 10 > tried * 9, "{held} of {tried} held by a witness");
}

/// The vector instructions' lanes near a cloud (cells' indices, gathered clearances) are
/// the plain loop's, for points inside the grid, outside it on every side, on cell
/// borders and not finite.
#[cfg(target_arch = "x86_64")]
#[test]
fn lanes_near_a_cloud_are_the_same_in_vector_instructions() {
    if !(is_x86_feature_detected!("avx2") && is_x86_feature_detected!("fma")) {
        return;
    }
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    let points: Vec<[f32; 3]> = (0..2000)
        .map(|_| std::array::from_fn(|_| rng.random_range(-0.3..0.3f32)))
        .collect();
    let grid = CloudGrid::new(&points, 0.02, 0.08, 0.3);
    let (mut flagged, mut total) = (0, 0);
    for round in 0..2000 {
        let c: [F; 3] = std::array::from_fn(|_| {
            F(std::array::from_fn(|l| match (round + l) % 23 {
                0 => f32::NAN,
                1 => f32::INFINITY,
                2 => -f32::INFINITY,
                // a cell's border
                3 => grid.origin[0] + grid.cell * rng.random_range(0..40) as f32,
                _ => rng.random_range(-1.0..1.0f32),
            }))
        });
        let reach = rng.random_range(0.0..0.05f32);
        let lanes: LaneMask = rng.random();
        let plain = grid.may_touch::<false>(&c, reach, lanes);
        assert_eq!(
            grid.may_touch::<true>(&c, reach, lanes),
            plain,
            "{c:?} {reach}"
        );
        assert_eq!(
            grid.holding::<true>(&c, reach, lanes),
            grid.holding::<false>(&c, reach, lanes),
            "{c:?} {reach}"
        );
        flagged += plain.count_ones();
        total += lanes.count_ones();
    }
    // both kinds of lanes were seen
    assert!(
        flagged > total / 20 && flagged < total * 19 / 20,
        "{flagged} of {total}"
    );
}

/// A link's spheres glanced at a point cloud in vector instructions, all at once, give the
/// lanes the plain loop gives sphere by sphere: near the board, deep in it, far from it, and
/// at places that are not finite.
#[test]
fn spheres_glance_at_a_cloud_alike_in_vector_instructions() {
    if !(is_x86_feature_detected!("avx2") && is_x86_feature_detected!("fma")) {
        return;
    }
    let file = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../models/panda-mbm/panda_spherized.ron"
    );
    let robot = trm_kinematics::RobotModel::load(file).unwrap();
    let model = FastModel::new(&CollisionModel::new(&robot).unwrap()).unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(8);
    let board = Shape::Box {
        size: [0.6, 0.8, 0.04],
    };
    let cloud = Shape::Points {
        points: board.surface_samples(3000, &mut rng),
        radius: 0.003,
    };
    let mut world = World::new();
    world
        .add(
            "scan",
            cloud,
            nalgebra::Isometry3::translation(0.5, 0.0, 0.3),
        )
        .unwrap();
    let compiled = model.world(&world);
    let object = &compiled.objects[0];
    let m = compiled.margin;
    let balls: Vec<Ball> = (0..6)
        .map(|_| Ball {
            center: [0.0; 3],
            radius: rng.random_range(0.0..0.08f32),
        })
        .collect();
    let (mut certain, mut open) = (0, 0);
    for round in 0..3000 {
        let centres: Vec<[F; 3]> = (0..balls.len())
            .map(|_| {
                std::array::from_fn(|k| {
                    F(std::array::from_fn(|l| match (round + l) % 29 {
                        0 => f32::NAN,
                        1 => f32::INFINITY,
                        // on the board's faces, within a few centimetres
                        _ => {
                            let at = [0.5, 0.0, 0.3][k];
                            let half = [0.3, 0.4, 0.02][k];
                            at + rng.random_range(-1.3 * half - 0.05..1.3 * half + 0.05)
                        }
                    }))
                })
            })
            .collect();
        let lanes: LaneMask = rng.random();
        let plain = compiled.glance_balls::<false>(object, &centres, &balls, m, lanes);
        let vector = compiled.glance_balls::<true>(object, &centres, &balls, m, lanes);
        assert_eq!(vector, plain, "round {round}");
        certain += plain.0.count_ones();
        open += plain.1.count_ones();
    }
    // lanes of both kinds were seen
    assert!(
        certain > 100 && open > certain,
        "{certain} certain, {open} open"
    );
}
