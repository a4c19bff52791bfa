//! The hot path does not allocate: a counting global allocator sees no allocation during
//! thousands of forward-kinematics passes (checked and unchecked, motor and joint inputs) and
//! collision queries (placing bodies, self and world counts, early-exit checks, distances), and
//! optimiser generations (ask/tell) after the first.
//! It lives here, in the crate that depends on every library, so one allocator covers them all.

// A global allocator can only be written with `unsafe`; it forwards to the system allocator.
#![allow(unsafe_code)]

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

struct Counting;

thread_local! {
    /// Allocations made by this thread (tests run on parallel threads).
    static ALLOCATIONS: Cell<usize> = const { Cell::new(0) };
}

fn allocations() -> usize {
    ALLOCATIONS.with(Cell::get)
}

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        ALLOCATIONS.with(|n| n.set(n.get() + 1));
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

#[test]
fn forward_kinematics_never_allocates() {
    let model = trm_models::icub_upper_body();
    let all = model.all_active();
    let arm = model
        .active_set(&["right_arm"], model.posture("home").unwrap())
        .unwrap();
    let mut buffer = model.pose_buffer();
    let mut q41 = model.posture("home").unwrap().to_vec();
    let mut q7 = arm.from_motors(&q41);
    let mut joints = vec![0.1; model.num_joints()];
    let before = allocations();
    for k in 0..2000 {
        let x = k as f64 * 1e-4;
        q41[5] = x;
        q7[3] = x;
        joints[7] = x;
        all.forward(&q41, &mut buffer).unwrap();
        all.forward_unchecked(&q41, &mut buffer);
        arm.forward(&q7, &mut buffer).unwrap();
        model.forward_joints(&joints, &mut buffer).unwrap();
        model.forward_motors(&q41, &mut buffer).unwrap();
    }
    let after = allocations();
    assert_eq!(after - before, 0, "FK allocated {} times", after - before);
    // four configurations at once
    let mut batch = model.pose_batch();
    let mut q4 = q41.repeat(trm_kinematics::LANES);
    let mut joints4 = joints.repeat(trm_kinematics::LANES);
    let before = allocations();
    for k in 0..500 {
        q4[50] = k as f64 * 1e-4;
        joints4[70] = k as f64 * 1e-4;
        all.forward_batch(&q4, &mut batch).unwrap();
        all.forward_batch_unchecked(&q4, &mut batch);
        model.forward_motors_batch(&q4, &mut batch).unwrap();
        model.forward_joints_batch(&joints4, &mut batch).unwrap();
    }
    let after = allocations();
    assert_eq!(
        after - before,
        0,
        "batched FK allocated {} times",
        after - before
    );
}

#[test]
fn collision_queries_never_allocate() {
    let model = trm_models::icub_upper_body();
    let collision = trm_collision::CollisionModel::new(&model).unwrap();
    let world =
        trm_collision::World::from_ron(include_str!("../../specs/worlds/table.ron"), "table.ron")
            .unwrap();
    let mut buffer = model.pose_buffer();
    let mut placed = collision.placed_bodies();
    let mut q = model.posture("home").unwrap().to_vec();
    let elbow = model.motor_index("r_elbow").unwrap();
    let (hand, table) = (collision.body_index("r_hand").unwrap(), 0);
    let mut total = 0usize;
    let before = allocations();
    for k in 0..2000 {
        q[elbow] = 0.3 + k as f64 * 7e-4;
        model.forward_motors(&q, &mut buffer).unwrap();
        collision.place(&buffer, &mut placed);
        total += collision.count_self(&placed);
        total += collision.count(&placed, &world).total();
        total += usize::from(collision.is_colliding(&placed, &world));
        total += usize::from(collision.any_self_collision(&placed));
        let d = collision.min_self_distance(&placed).unwrap().distance
            + collision.object_distance(&placed, hand, &world, table);
        total += usize::from(d > 0.0);
    }
    let after = allocations();
    assert!(total > 0);
    assert_eq!(
        after - before,
        0,
        "collision queries allocated {} times",
        after - before
    );
}

#[test]
fn optimiser_generations_never_allocate() {
    use rand::SeedableRng;
    let start = trm_optim::Start::new(vec![0.3; 12], 0.2).with_stop(trm_optim::StopOptions {
        tol_x: None,
        tol_fun: None,
        ..Default::default()
    });
    // Our own buffers are reused everywhere. The exceptions are inside nalgebra: its matrix
    // products (through matrixmultiply) allocate packing buffers, one per product (xNES makes
    // 8–9 per generation, CMA-ES 3), and CMA-ES's eigendecomposition allocates its result.
    for (algo, products) in [
        ("xnes", 10), // 8–9 products, plus squarings of larger exponentials
        ("snes", 0),
        ("oneplusone", 0),
        ("sir", 0),
        ("sird", 0),
        ("mh", 0),
        ("simplex", 0),
    ] {
        let mut o = trm_optim::by_name(algo, &start, None).unwrap();
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(1);
        let mut fitness = vec![0.0; 400];
        let mut step = |o: &mut Box<dyn trm_optim::Optimizer + Send>, fitness: &mut Vec<f64>| {
            let n = {
                let xs = o.ask(&mut rng);
                for (f, x) in fitness.iter_mut().zip(xs) {
                    *f = x.iter().map(|v| v * v).sum();
                }
                xs.len()
            };
            o.tell(&fitness[..n]).unwrap();
            let _ = o.stop();
        };
        for _ in 0..3 {
            step(&mut o, &mut fitness);
        }
        let before = allocations();
        for _ in 0..200 {
            step(&mut o, &mut fitness);
        }
        let after = allocations();
        // `stop()` returns a Vec of reasons: empty while running, so no allocation
        assert!(
            after - before <= 200 * products,
            "{algo} allocated {} times in 200 generations",
            after - before
        );
    }
}

#[test]
fn batched_objective_evaluations_never_allocate() {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../specs/table_iii/posture1.ron"
    );
    let mut problem = trm_tasks::Problem::load(path).unwrap();
    let population = trm_benches::random_configurations(problem.objective.active(), 30, 5);
    for noise in [false, true] {
        if noise {
            problem.objective.set_noise(4, 0.05, 1).unwrap();
        }
        let objective = &problem.objective;
        let mut scratch = objective.scratch();
        let mut out = vec![0.0; population.len()];
        // the first call sizes the noise buffers
        objective.eval_batch(&population, &mut scratch, &mut out);
        let before = allocations();
        for _ in 0..50 {
            objective.eval_batch(&population, &mut scratch, &mut out);
        }
        let after = allocations();
        assert!(out.iter().all(|v| v.is_finite()));
        assert_eq!(after - before, 0, "eval_batch (noise {noise}) allocated");
    }
}
