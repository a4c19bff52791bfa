//! Point clouds as obstacles (VAMP's spherized Panda, an MBM-like table scene): building a
//! cloud (the world object with its exact grid — its BVH waits for a distance query — and the
//! screen's grid, for 5 000 points on a board and for a whole thinned scene) and checking
//! blocks of eight configurations among the cloud against the same scene as primitives.
//! Targets: a 5 000-point cloud builds in ≤ 0.5 ms on one core; a block among the sampled
//! scene costs no more than among its primitives. Also: the blocks' spheres as queries of
//! eight spheres ([`FastWorld::spheres_touching`](trm_collision::fast::FastWorld::spheres_touching)), exact. Also: one box moved in a world holding the
//! scene cloud and a mesh (the screen compiles again only what changed).

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use nalgebra::Isometry3;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use std::hint::black_box;
use trm_benches::{random_configurations, sampled_table_scene, table_scene};
use trm_collision::fast::{FAST_LANES, FastChecker};
use trm_collision::{CollisionModel, Shape, World};
use trm_kinematics::RobotModel;

/// A closed triangle mesh of a ball: `n` bands of latitude, `2n` of longitude.
fn ball_mesh(radius: f64, n: u32) -> Shape {
    let mut vertices = vec![[0.0, 0.0, radius], [0.0, 0.0, -radius]];
    for i in 1..n {
        let polar = std::f64::consts::PI * f64::from(i) / f64::from(n);
        for j in 0..2 * n {
            let azimuth = std::f64::consts::PI * f64::from(j) / f64::from(n);
            vertices.push([
                radius * polar.sin() * azimuth.cos(),
                radius * polar.sin() * azimuth.sin(),
                radius * polar.cos(),
            ]);
        }
    }
    let at = |i: u32, j: u32| 2 + (i - 1) * 2 * n + j % (2 * n);
    let mut triangles = Vec::new();
    for j in 0..2 * n {
        triangles.push([0, at(1, j), at(1, j + 1)]);
        triangles.push([1, at(n - 1, j + 1), at(n - 1, j)]);
        for i in 1..n - 1 {
            triangles.push([at(i, j), at(i + 1, j), at(i + 1, j + 1)]);
            triangles.push([at(i, j), at(i + 1, j + 1), at(i, j + 1)]);
        }
    }
    Shape::Mesh {
        vertices,
        triangles,
    }
}

fn clouds(c: &mut Criterion) {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../models/panda-mbm/panda_spherized.ron"
    );
    let robot = RobotModel::load(path).expect("shipped model");
    let collision = CollisionModel::new(&robot).expect("shipped model");
    let active = robot.all_active();
    let mut checker = FastChecker::new(&collision, active.clone()).expect("shipped model");
    let mut group = c.benchmark_group("clouds");
    let mut rng = ChaCha8Rng::seed_from_u64(2);
    let points = Shape::Box {
        size: [0.8, 1.2, 0.05],
    }
    .surface_samples(5000, &mut rng);
    let cloud = Shape::Points {
        points,
        radius: 0.0025,
    };
    group.bench_function(BenchmarkId::new("build_world_object", 5000), |b| {
        b.iter(|| {
            let mut world = World::new();
            world
                .add("cloud", black_box(cloud.clone()), Isometry3::identity())
                .expect("valid");
            world
        })
    });
    let mut one = World::new();
    one.add("cloud", cloud, Isometry3::identity())
        .expect("valid");
    group.bench_function(BenchmarkId::new("build_screen_grid", 5000), |b| {
        b.iter(|| checker.model().world(black_box(&one)))
    });
    // the whole scene as one cloud, as MotionBenchMaker's --cloud makes it: 10 000 points on
    // each object, thinned to 2 cm (about 6 000 points over a metre)
    let mut scene_points = Vec::new();
    for o in sampled_table_scene(10_000).objects() {
        if let Shape::Points { points, .. } = o.shape() {
            scene_points.extend(
                points
                    .iter()
                    .map(|p| <[f64; 3]>::from((o.pose() * nalgebra::Point3::from(*p)).coords)),
            );
        }
    }
    let thinned = trm_collision::thin_points(&scene_points, 0.02);
    let mut scene = World::new();
    let n = thinned.len();
    scene
        .add(
            "scene",
            Shape::Points {
                points: thinned,
                radius: 0.0025,
            },
            Isometry3::identity(),
        )
        .expect("valid");
    group.bench_function(BenchmarkId::new("build_screen_grid_scene", n), |b| {
        b.iter(|| checker.model().world(black_box(&scene)))
    });
    // a box moved in a world that also holds the sensed scene and a mesh: what the screen
    // compiles again (a world checker set to the other world, back and forth)
    let bowl = ball_mesh(0.12, 32);
    let mut busy = scene.clone();
    busy.add("bowl", bowl, Isometry3::translation(0.5, -0.3, 0.3))
        .expect("valid");
    for (name, world) in table_scene().objects().iter().map(|o| (o.name(), o)) {
        busy.add(
            &format!("{name}_solid"),
            world.shape().clone(),
            *world.pose(),
        )
        .expect("valid");
    }
    let mut moved = busy.clone();
    moved
        .set_pose("box_solid", Isometry3::translation(0.45, 0.25, 0.325))
        .expect("an object of the world");
    let mut world_checker =
        trm_collision::WorldChecker::new(&collision, &active, busy.clone()).expect("shipped");
    let mut flip = false;
    group.bench_function(BenchmarkId::new("move_one_box", busy.len()), |b| {
        b.iter(|| {
            flip = !flip;
            world_checker.set_world(black_box(if flip { moved.clone() } else { busy.clone() }));
        })
    });
    group.bench_function(BenchmarkId::new("clone_world", busy.len()), |b| {
        b.iter(|| black_box(&moved).clone())
    });
    let qs: Vec<f64> = random_configurations(&active, 8 * 256, 3).concat();
    let d = active.len();
    for (name, world) in [
        ("primitives", table_scene()),
        ("cloud_3x1000", sampled_table_scene(1000)),
        ("cloud_3x10000", sampled_table_scene(10_000)),
    ] {
        let fast = checker.model().world(&world);
        let free = qs
            .chunks(d * FAST_LANES)
            .filter(|b| checker.all_free_unchecked(b, &world, &fast))
            .count();
        eprintln!("{name}: {free} of 256 blocks free");
        group.bench_function(BenchmarkId::new("check_256_blocks", name), |b| {
            b.iter(|| {
                qs.chunks(d * FAST_LANES)
                    .filter(|b| checker.all_free_unchecked(b, &world, &fast))
                    .count()
            })
        });
    }
    // the same blocks' spheres as queries of eight (one sphere in eight configurations),
    // answered exactly
    let queries = trm_benches::sphere_queries(
        &collision,
        &active,
        &random_configurations(&active, 8 * 256, 3),
    );
    for (name, world) in [
        ("primitives", table_scene()),
        ("cloud_3x1000", sampled_table_scene(1000)),
        ("cloud_3x10000", sampled_table_scene(10_000)),
    ] {
        let fast = checker.model().world(&world);
        group.bench_function(BenchmarkId::new("sphere_queries", name), |b| {
            b.iter(|| {
                queries
                    .iter()
                    .map(|(centres, r)| fast.spheres_touching_unchecked(&world, centres, *r))
                    .fold(0u32, |n, lanes| n + lanes.count_ones())
            })
        });
    }
    group.finish();
}

criterion_group!(benches, clouds);
criterion_main!(benches);
