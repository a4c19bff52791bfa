//! What a world change blocks: the indexed search finds exactly what checking every node and
//! edge finds, over many random changes (objects added near the map, the table moved, removed).

use std::path::Path;

use rand::{RngExt, SeedableRng};
use trm_collision::{Shape, World};
use trm_kinematics::nalgebra::{Isometry3, Translation3, UnitQuaternion};
use trm_roadmap::{
    BlockIndex, BuildOptions, Builder, LiveMap, RepairOptions, blocked_exhaustive, connect,
};
use trm_tasks::Problem;

/// The reach problem and a map of `points` points, connected to 6 neighbours.
fn reach_map(points: usize) -> (Problem, trm_roadmap::Roadmap) {
    let problem =
        Problem::load(Path::new(env!("CARGO_MANIFEST_DIR")).join("../../specs/reach.ron")).unwrap();
    let mut map = Builder::new(
        &problem,
        &BuildOptions {
            points: Some(points),
            ..Default::default()
        },
    )
    .run(|_| {})
    .unwrap();
    connect(&mut map, &problem.objective, 6, 0.05).unwrap();
    (problem, map)
}

#[test]
fn indexed_blocking_equals_the_exhaustive_check_on_random_world_changes() {
    let (problem, map) = reach_map(60);
    let objective = &problem.objective;
    let index = BlockIndex::new(&map, objective).unwrap();
    // the map's own world blocks nothing
    let own = index.blocked(&map, objective, objective.world()).unwrap();
    assert!(own.nodes.is_empty() && own.edges.is_empty() && own.changed.is_empty());
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(11);
    let (mut worlds_blocking, mut nodes, mut edges) = (0, 0, 0);
    for case in 0..80 {
        let mut world: World = objective.world().clone();
        match case % 4 {
            // the table moved up or sideways
            0 => {
                let table = *world.object("table").unwrap().pose();
                let shift = Translation3::new(
                    rng.random_range(-0.1..0.1),
                    rng.random_range(-0.1..0.1),
                    rng.random_range(0.0..0.2),
                );
                world.set_pose("table", shift * table).unwrap();
            }
            // the table gone, and maybe an object instead
            1 => {
                world.remove("table").unwrap();
            }
            _ => {}
        }
        for k in 0..rng.random_range(case % 4 / 2..3) {
            let near = &map.points[rng.random_range(0..map.points.len())].t;
            let centre = Translation3::new(
                near[0] + rng.random_range(-0.12..0.12),
                near[1] + rng.random_range(-0.12..0.12),
                near[2] + rng.random_range(-0.12..0.12),
            );
            let turn = UnitQuaternion::from_euler_angles(
                rng.random_range(-3.0..3.0),
                rng.random_range(-3.0..3.0),
                rng.random_range(-3.0..3.0),
            );
            let size = rng.random_range(0.01..0.1);
            let shape = match k % 3 {
                0 => Shape::Box {
                    size: [size, 2.0 * size, size],
                },
                1 => Shape::Sphere { radius: size },
                _ => Shape::Capsule {
                    radius: size / 2.0,
                    length: size,
                },
            };
            world
                .add(
                    &format!("thing{k}"),
                    shape,
                    Isometry3::from_parts(centre, turn),
                )
                .unwrap();
        }
        let indexed = index.blocked(&map, objective, &world).unwrap();
        let exhaustive = blocked_exhaustive(&map, objective, &world).unwrap();
        assert_eq!(indexed, exhaustive, "world change {case}");
        if !indexed.nodes.is_empty() || !indexed.edges.is_empty() {
            worlds_blocking += 1;
        }
        nodes += indexed.nodes.len();
        edges += indexed.edges.len();
    }
    eprintln!("{worlds_blocking} of 80 changes blocked something: {nodes} nodes, {edges} edges");
    assert!(worlds_blocking >= 20 && nodes > 0 && edges > 0);
}

/// A repaired map is collision-free in the new world under the exhaustive check, records that
/// world, and covers about what a rebuild in the new world covers; repairing it again for the
/// same world changes nothing.
#[test]
fn a_repaired_map_is_valid_in_the_new_world_and_covers_like_a_rebuild() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let problem = Problem::load(root.join("specs/reach.ron")).unwrap();
    let points = 150;
    let options = BuildOptions {
        points: Some(points),
        ..Default::default()
    };
    let mut map = Builder::new(&problem, &options).run(|_| {}).unwrap();
    connect(&mut map, &problem.objective, 8, 0.05).unwrap();
    let world = World::load(root.join("specs/worlds/reach_with_box.ron")).unwrap();
    let (repaired, report) =
        trm_roadmap::repair(&map, &problem, &world, &RepairOptions::default()).unwrap();
    eprintln!("{report:?}");
    assert!(report.blocked_nodes > 0 && report.added_nodes > 0);
    assert_eq!(
        repaired.points.len(),
        points - report.blocked_nodes + report.added_nodes
    );
    let parked = repaired.parked.as_ref().expect("blocked nodes are parked");
    assert_eq!(parked.points.len(), report.blocked_nodes);
    // valid in the new world: nothing blocked under the exhaustive check
    let again = repaired.problem().unwrap();
    assert!(again.objective.world().object("new_box").is_ok());
    let check = blocked_exhaustive(&repaired, &again.objective, &world).unwrap();
    assert!(
        check.nodes.is_empty() && check.edges.is_empty(),
        "{check:?}"
    );
    assert!(
        repaired
            .edges
            .iter()
            .all(|&(a, b, _)| a < b && b < repaired.points.len())
    );
    // a rebuild in the new world, to the same number of points
    let text = problem.text.replace(
        "world: (objects: [",
        "world: (objects: [\n        (name: \"new_box\", shape: Box(size: (0.08, 0.06, 0.16)), xyz: (-0.3, 0.08, -0.04)),",
    );
    let rebuilt_problem = Problem::from_ron(&text, &problem.origin, &root.join("specs")).unwrap();
    let started = std::time::Instant::now();
    let rebuilt = Builder::new(&rebuilt_problem, &options)
        .run(|_| {})
        .unwrap();
    eprintln!("rebuild {:.2} s", started.elapsed().as_secs_f64());
    let (ours, theirs) = (repaired.occupied_cells(), rebuilt.occupied_cells());
    eprintln!(
        "occupied cells: repaired {ours}, rebuilt {theirs}, before {}",
        map.occupied_cells()
    );
    assert!(ours as f64 >= 0.95 * theirs as f64, "{ours} vs {theirs}");
    // the same world again: nothing to do
    let (twice, report) =
        trm_roadmap::repair(&repaired, &again, &world, &RepairOptions::default()).unwrap();
    assert_eq!(report.blocked_nodes, 0);
    assert_eq!(twice.points, repaired.points);
    // the box gone: every parked node and edge comes back without a search
    let (back, report) = trm_roadmap::repair(
        &repaired,
        &again,
        problem.objective.world(),
        &RepairOptions::default(),
    )
    .unwrap();
    eprintln!("{report:?}");
    assert_eq!(report.restored_nodes, parked.points.len());
    assert_eq!((report.blocked_nodes, report.added_nodes), (0, 0));
    assert!(back.parked.is_none());
    for p in &map.points {
        assert!(back.points.contains(p), "an original node came back");
    }
    let position = |p: &trm_roadmap::MapPoint| back.points.iter().position(|b| b == p).unwrap();
    let edges: std::collections::BTreeSet<(usize, usize)> =
        back.edges.iter().map(|&(a, b, _)| (a, b)).collect();
    for &(a, b, _) in &map.edges {
        let (a, b) = (position(&map.points[a]), position(&map.points[b]));
        assert!(
            edges.contains(&(a.min(b), a.max(b))),
            "an original edge came back"
        );
    }
}

/// A live map's blocked flags stay exactly those of the exhaustive check over a sequence of
/// worlds: a box sliding through the map, a ball appearing and going, the table moving; and a
/// repair under an evaluation budget adds only clear nodes and edges.
#[test]
fn a_live_map_tracks_a_moving_world_exactly() {
    let (problem, map) = reach_map(80);
    let objective = &problem.objective;
    let mut live = LiveMap::new(&map, &problem).unwrap();
    let (mut parked_max, mut freed) = (0, 0);
    for step in 0..24 {
        let mut world = objective.world().clone();
        let x = -0.45 + 0.02 * step as f64;
        world
            .add(
                "box",
                Shape::Box {
                    size: [0.08, 0.06, 0.16],
                },
                Isometry3::translation(x, 0.1, -0.04),
            )
            .unwrap();
        if (6..14).contains(&step) {
            world
                .add(
                    "ball",
                    Shape::Sphere { radius: 0.05 },
                    Isometry3::translation(-0.25, 0.2, 0.05),
                )
                .unwrap();
        }
        if step >= 18 {
            world
                .set_pose("table", Isometry3::translation(-0.4, 0.0, -0.1))
                .unwrap();
        }
        let changes = live.set_world(world.clone()).unwrap();
        freed += changes.freed_nodes.len();
        if step % 6 == 5 {
            let report = live
                .repair(&RepairOptions {
                    evaluations: Some(20_000),
                    refill: false,
                    ..Default::default()
                })
                .unwrap();
            eprintln!("step {step}: {report:?}");
        }
        let all = live.all();
        let exhaustive = blocked_exhaustive(all, objective, &world).unwrap();
        let flagged: Vec<usize> = (0..all.points.len())
            .filter(|&i| live.is_blocked(i))
            .collect();
        assert_eq!(flagged, exhaustive.nodes, "nodes at step {step}");
        let current = live.map();
        let check = blocked_exhaustive(&current, objective, &world).unwrap();
        assert!(
            check.nodes.is_empty() && check.edges.is_empty(),
            "step {step}: {check:?}"
        );
        parked_max = parked_max.max(live.parked_nodes());
    }
    eprintln!("at most {parked_max} parked, {freed} freed");
    assert!(parked_max > 0 && freed > 0);
}
