//! Self-collision checking of the official iCubGenova04 URDF on its meshes' convex hulls
//! against the same URDF with proxies fitted by `trm_collision::fit` (issue target: ≥ 5×
//! faster). Needs the official meshes: `TRM_ICUB_MESHES=<dir holding iCub/>` (as `.ci/run`
//! installs them from PyPI's icub-models); without it the bench says so and does nothing.

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use std::hint::black_box;
use trm_benches::random_configurations;
use trm_collision::fit::fit;
use trm_collision::{CollisionModel, CollisionOptions};
use trm_kinematics::PoseBuffer;

fn proxies(c: &mut Criterion) {
    let Some(dir) = std::env::var_os("TRM_ICUB_MESHES") else {
        eprintln!("TRM_ICUB_MESHES is not set: nothing to bench (see the file's documentation)");
        return;
    };
    let robot = trm_models::icub_genova04();
    let options = CollisionOptions {
        package_paths: vec![dir.into()],
        ..Default::default()
    };
    let hulls = CollisionModel::with_options(&robot, &options).expect("the official meshes");
    // the same bodies, each link's hulls replaced by its fitted primitive
    let mut bodies = Vec::new();
    for l in 0..robot.tree().links.len() {
        let points = hulls.link_mesh_points(l);
        let first = hulls.bodies().iter().find(|b| b.link == l);
        if let (Some(first), Some(f)) = (first, fit(&points)) {
            let best = f.best().clone();
            let mut body = first.clone();
            body.shape = best.shape;
            body.local = best.pose;
            bodies.push(body);
        }
    }
    // the same allowed-collision matrix: the same pairs are checked
    let fitted =
        CollisionModel::from_bodies(&robot, bodies, hulls.acm().clone()).expect("fitted bodies");
    let active = robot.all_active();
    let poses: Vec<PoseBuffer> = random_configurations(&active, 64, 5)
        .iter()
        .map(|q| {
            let mut p = robot.pose_buffer();
            active.forward(q, &mut p).expect("within bounds");
            p
        })
        .collect();
    let mut group = c.benchmark_group("icub_genova04_self_collision");
    for (name, model) in [("convex_hulls", &hulls), ("fitted_proxies", &fitted)] {
        let mut placed = model.placed_bodies();
        let mut k = 0;
        group.bench_function(BenchmarkId::new("place_and_count_self", name), |b| {
            b.iter(|| {
                k = (k + 1) % poses.len();
                model.place(black_box(&poses[k]), &mut placed);
                black_box(model.count_self(&placed))
            })
        });
    }
    group.finish();
}

criterion_group!(benches, proxies);
criterion_main!(benches);
