//! Collision queries of the 41-DOF iCub from precomputed poses (forward kinematics excluded).
//! Targets: ≤ 3 µs for the self-collision count (median, one core), the early-exit check faster.

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use std::hint::black_box;
use trm_benches::random_configurations;
use trm_collision::{CollisionModel, PlacedBodies, World};
use trm_kinematics::PoseBuffer;

/// specs/worlds/table.ron: a table in front of the robot with three boxes on and above it.
fn table_world() -> World {
    World::from_ron(
        include_str!("../../specs/worlds/table.ron"),
        "specs/worlds/table.ron",
    )
    .expect("valid world")
}

/// The table's objects as convex hulls (a box's eight corners) and its top as two triangles:
/// the iCub's capsules against hulls and a triangle mesh.
fn hull_world() -> World {
    let table = table_world();
    let mut world = World::new();
    for object in table.objects() {
        let trm_collision::Shape::Box { size } = object.shape() else {
            unreachable!("the table world holds boxes")
        };
        let h = size.map(|s| 0.5 * s);
        let corners = (0..8)
            .map(|k| std::array::from_fn(|a| if k >> a & 1 == 1 { h[a] } else { -h[a] }))
            .collect();
        let pose = *object.pose();
        let name = object.name();
        world
            .add(name, trm_collision::Shape::Convex { points: corners }, pose)
            .expect("a hull of a box");
        if name == "table" {
            let top = |x: f64, y: f64| [x * h[0], y * h[1], h[2]];
            let mesh = trm_collision::Shape::Mesh {
                vertices: vec![
                    top(-1.0, -1.0),
                    top(1.0, -1.0),
                    top(1.0, 1.0),
                    top(-1.0, 1.0),
                ],
                triangles: vec![[0, 1, 2], [0, 2, 3]],
            };
            world.add("table_top", mesh, pose).expect("two triangles");
        }
    }
    world
}

fn collision(c: &mut Criterion) {
    let robot = trm_models::icub_upper_body();
    let model = CollisionModel::new(&robot).expect("shipped model");
    let active = robot.all_active();
    let configurations = random_configurations(&active, 64, 11);
    let poses: Vec<PoseBuffer> = configurations
        .iter()
        .map(|q| {
            let mut p = robot.pose_buffer();
            active.forward(q, &mut p).expect("within bounds");
            p
        })
        .collect();
    let mut home = robot.pose_buffer();
    robot
        .forward_motors(robot.posture("home").expect("home"), &mut home)
        .expect("home");
    let world = table_world();
    let mut placed: PlacedBodies = model.placed_bodies();
    let colliding = poses
        .iter()
        .filter(|p| {
            model.place(p, &mut placed);
            model.count_self(&placed) > 0
        })
        .count();
    eprintln!(
        "{} bodies, {} checked link pairs; {colliding}/64 random configurations self-collide",
        model.bodies().len(),
        model.num_checked_link_pairs()
    );

    let mut group = c.benchmark_group("collision_icub_41");
    group.bench_function(BenchmarkId::new("place_and_count_self", "home"), |b| {
        b.iter(|| {
            model.place(black_box(&home), &mut placed);
            black_box(model.count_self(&placed))
        })
    });
    let mut k = 0;
    let mut cycle = || {
        k = (k + 1) % poses.len();
        &poses[k]
    };
    group.bench_function(BenchmarkId::new("place", "random"), |b| {
        b.iter(|| {
            model.place(black_box(cycle()), &mut placed);
            black_box(placed.len())
        })
    });
    group.bench_function(BenchmarkId::new("place_and_count_self", "random"), |b| {
        b.iter(|| {
            model.place(black_box(cycle()), &mut placed);
            black_box(model.count_self(&placed))
        })
    });
    group.bench_function(BenchmarkId::new("place_and_any_self", "random"), |b| {
        b.iter(|| {
            model.place(black_box(cycle()), &mut placed);
            black_box(model.any_self_collision(&placed))
        })
    });
    group.bench_function(
        BenchmarkId::new("place_and_count_world", "random_table_3_boxes"),
        |b| {
            b.iter(|| {
                model.place(black_box(cycle()), &mut placed);
                black_box(model.count_world(&placed, &world))
            })
        },
    );
    group.bench_function(
        BenchmarkId::new("place_and_count_both", "random_table_3_boxes"),
        |b| {
            b.iter(|| {
                model.place(black_box(cycle()), &mut placed);
                black_box(model.count(&placed, &world).total())
            })
        },
    );
    let hulls = hull_world();
    group.bench_function(
        BenchmarkId::new("place_and_count_world", "random_table_hulls_and_mesh"),
        |b| {
            b.iter(|| {
                model.place(black_box(cycle()), &mut placed);
                black_box(model.count_world(&placed, &hulls))
            })
        },
    );
    group.bench_function(
        BenchmarkId::new("place_and_is_colliding", "random_table_3_boxes"),
        |b| {
            b.iter(|| {
                model.place(black_box(cycle()), &mut placed);
                black_box(model.is_colliding(&placed, &world))
            })
        },
    );
    group.finish();
}

criterion_group!(benches, collision);
criterion_main!(benches);
