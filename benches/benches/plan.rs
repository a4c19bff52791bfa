//! Planning queries on a 400-point reach map (built once, seeded): in the map's own world, and
//! after a box the map did not know about is added (every node and edge unchecked again).
//! Target: well under 10 ms per query.

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use std::hint::black_box;
use trm_collision::{Shape, World};
use trm_kinematics::nalgebra::Isometry3;
use trm_plan::{Goal, PlanOptions, Planner};
use trm_roadmap::{BuildOptions, Builder, connect};
use trm_tasks::Problem;

fn plan(c: &mut Criterion) {
    let path = format!("{}/../specs/reach.ron", env!("CARGO_MANIFEST_DIR"));
    let problem = Problem::load(&path).expect("shipped spec");
    let mut map = Builder::new(
        &problem,
        &BuildOptions {
            points: Some(400),
            ..Default::default()
        },
    )
    .run(|_| {})
    .expect("map");
    connect(&mut map, &problem.objective, 8, 0.05).unwrap();
    let goals: Vec<Goal> = (0..16)
        .map(|k| Goal::TaskPoint {
            t: map.points[(k * 97) % map.points.len()].t.clone(),
            tolerance: 0.03,
        })
        .collect();
    // the query through the map (the exact finish at the goal point is NGIK, timed elsewhere)
    let options = PlanOptions {
        exact_goal: false,
        ..Default::default()
    };
    let mut group = c.benchmark_group("plan_reach_400");
    let mut world: World = problem.objective.world().clone();
    world
        .add(
            "new_box",
            Shape::Box {
                size: [0.08, 0.06, 0.16],
            },
            Isometry3::translation(-0.3, 0.08, -0.04),
        )
        .expect("valid box");
    let mut k = 0;
    for (name, new_world) in [("map_world", None), ("new_box_all_unchecked", Some(&world))] {
        group.bench_function(BenchmarkId::new("query", name), |b| {
            b.iter(|| {
                let mut planner = Planner::new(&problem.objective, &[&map]).expect("compatible");
                if let Some(w) = new_world {
                    planner.set_world(w.clone());
                }
                k = (k + 1) % goals.len();
                black_box(
                    planner
                        .plan(&problem.start, &goals[k], &options)
                        .ok()
                        .map(|p| p.stats.length),
                )
            })
        });
    }
    group.finish();
}

criterion_group!(benches, plan);
criterion_main!(benches);
