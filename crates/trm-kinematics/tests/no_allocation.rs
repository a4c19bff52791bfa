//! Forward kinematics does not allocate: a counting global allocator sees no allocation during
//! thousands of FK passes (checked and unchecked, motor and joint inputs).

// A global allocator can only be written with `unsafe`; it forwards to the system allocator.
#![allow(unsafe_code)]

use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering};

struct Counting;

static ALLOCATIONS: AtomicUsize = AtomicUsize::new(0);

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
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
    let path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../models/icub_upper_body.ron");
    let model = trm_kinematics::RobotModel::load(path).unwrap();
    let all = model.all_active();
    let arm = model
        .active_set(&["right_arm"], model.posture("home").unwrap())
        .unwrap();
    let mut buffer = model.pose_buffer();
    let mut q41 = model.posture("home").unwrap().to_vec();
    let mut q7 = arm.from_motors(&q41);
    let mut joints = vec![0.1; model.num_joints()];
    let before = ALLOCATIONS.load(Ordering::Relaxed);
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
    let after = ALLOCATIONS.load(Ordering::Relaxed);
    assert_eq!(after - before, 0, "FK allocated {} times", after - before);
}
