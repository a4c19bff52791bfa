//! The screen's AVX kernels against the portable code, and its k-DOPs.

use super::avx;
use super::kdop::*;
use super::lanes::*;
use super::model::*;
use super::outcome::*;
use super::walk::*;
use super::world::*;
use super::*;
use crate::{CollisionModel, Shape, World};
use nalgebra::{Point3, Vector3};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// The written-out AVX distances ([`avx`]) are the portable ones up to rounding, for every
/// kind of object, points inside and outside (where the CPU has AVX2 and FMA).
#[test]
fn avx_distances_are_the_portable_ones() {
    if !(is_x86_feature_detected!("avx2") && is_x86_feature_detected!("fma")) {
        return;
    }
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    let mut v = || rng.random_range(-0.5f32..0.5);
    let pose = nalgebra::Isometry3::new(Vector3::new(0.1, -0.2, 0.3), Vector3::new(0.4, -0.7, 1.1));
    let axes = inverse_axes(&pose);
    let center = to_f32(pose.translation.vector);
    let objects = [
        Object::Round {
            a: [0.1, 0.0, -0.1],
            b: [0.1, 0.0, -0.1],
            radius: 0.05,
        },
        Object::Round {
            a: [-0.2, 0.1, 0.0],
            b: [0.2, -0.1, 0.1],
            radius: 0.05,
        },
        Object::Box {
            center,
            axes,
            half: [0.2, 0.1, 0.05],
        },
        Object::Cylinder {
            center,
            axes,
            radius: 0.1,
            half: 0.2,
        },
        Object::Bounded {
            center,
            radius: 0.3,
        },
    ];
    for object in &objects {
        for _ in 0..200 {
            let c = [0; 3].map(|_| F(std::array::from_fn(|_| v())));
            let want = object.distance2(&c);
            // SAFETY: the CPU has AVX2 and FMA (checked above)
            #[allow(unsafe_code)]
            let got: [f32; FAST_LANES] = unsafe {
                std::mem::transmute::<std::arch::x86_64::__m256, [f32; FAST_LANES]>(avx::distance2(
                    object, &c,
                ))
            };
            for l in 0..FAST_LANES {
                let (w, g) = (want.0[l], got[l]);
                assert!((w - g).abs() <= 1e-6 * (1.0 + w), "{object:?}: {w} vs {g}");
            }
            let (r, m) = (0.05, 1e-3);
            let reach = object.reach(r);
            // SAFETY: as above
            #[allow(unsafe_code)]
            let (near, contact) = unsafe {
                let mut contact = Contact::default();
                avx::test(object, &mut contact, &c, reach, m);
                (avx::near(object, &c, reach * reach), contact)
            };
            let mut portable = Contact::default();
            object.test::<false>(&mut portable, &c, r, m);
            for l in 0..FAST_LANES {
                // lanes at the limits within rounding may go either way
                let w = want.0[l];
                let at = |limit: f32| (w - limit * limit).abs() <= 1e-6;
                if !at(reach) {
                    assert_eq!(near >> l & 1 == 1, w <= reach * reach, "{object:?}");
                }
                if !at(reach + m) && !at((reach - m).max(0.0)) {
                    assert_eq!(contact.close.0[l], portable.close.0[l], "{object:?}");
                    assert_eq!(contact.hit.0[l], portable.hit.0[l], "{object:?}");
                }
            }
        }
    }
}

/// The written-out AVX pair tests give the portable ones' lane masks, on the spherized
/// Panda's link pairs in random blocks of configurations.
#[test]
fn avx_pair_contacts_are_the_portable_ones() {
    if !(is_x86_feature_detected!("avx2") && is_x86_feature_detected!("fma")) {
        return;
    }
    let file = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../models/panda-mbm/panda_spherized.ron"
    );
    let robot = trm_kinematics::RobotModel::load(file).unwrap();
    let model = FastModel::new(&CollisionModel::new(&robot).unwrap()).unwrap();
    let active = robot.all_active();
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    let (mut block, mut scratch) = (robot.pose_block(), model.scratch());
    let world = model.world(&World::new());
    let mut contacts = 0;
    for _ in 0..200 {
        let qs: Vec<f64> = (0..FAST_LANES)
            .flat_map(|_| active.random(&mut rng))
            .collect();
        active.forward_block_unchecked(&qs, &mut block);
        place::<false>(&model, block.lanes(), &mut scratch);
        for gp in &model.group_pairs {
            place_balls::<false>(&model, gp.a, &mut scratch);
            place_balls::<false>(&model, gp.b, &mut scratch);
            let avx = pair_contacts::<true>(&model, gp, &scratch, &world);
            assert_eq!(avx, pair_contacts::<false>(&model, gp, &scratch, &world));
            contacts += usize::from(avx.0 != 0);
        }
    }
    assert!(
        contacts > 100,
        "{contacts} pairs in contact: the test saw too few"
    );
}

/// The k-DOP screen: every hull point lies within each link's slabs, and a sphere it
/// clears is clear of the hulls, as GJK finds; the AVX code clears the same lanes.
#[test]
fn kdop_slabs_hold_the_hulls_and_clear_only_what_is_clear() {
    let file = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../models/panda-mbm/panda.ron"
    );
    let robot = trm_kinematics::RobotModel::load(file).unwrap();
    let collision = CollisionModel::new(&robot).unwrap();
    let model = FastModel::new(&collision).unwrap();
    for group in &model.groups {
        let kdop = group.kdop.expect("every Panda link is a hull");
        for &b in &group.bodies {
            let body = &collision.bodies()[b as usize];
            let Shape::Convex { points } = &body.shape else {
                panic!("a hull")
            };
            for p in points {
                let p = body.local * Point3::from(*p);
                for (n, &[lo, hi]) in KDOP.iter().zip(&kdop) {
                    let s = f64::from(n[0]) * p.x + f64::from(n[1]) * p.y + f64::from(n[2]) * p.z;
                    assert!(
                        f64::from(lo) <= s && s <= f64::from(hi),
                        "{s} not in [{lo}, {hi}]"
                    );
                }
            }
        }
    }
    let active = robot.all_active();
    let mut rng = ChaCha8Rng::seed_from_u64(9);
    let (mut block, mut scratch) = (robot.pose_block(), model.scratch());
    let (mut pose, mut placed) = (robot.pose_buffer(), collision.placed_bodies());
    let world = model.world(&World::new());
    let avx = is_x86_feature_detected!("avx2") && is_x86_feature_detected!("fma");
    let (mut cleared, mut close) = (0, 0);
    for _ in 0..100 {
        let qs: Vec<f64> = (0..FAST_LANES)
            .flat_map(|_| active.random(&mut rng))
            .collect();
        active.forward_block_unchecked(&qs, &mut block);
        place::<false>(&model, block.lanes(), &mut scratch);
        for gp in &model.group_pairs {
            place_balls::<false>(&model, gp.a, &mut scratch);
            place_balls::<false>(&model, gp.b, &mut scratch);
            let (_, near) = pair_contacts::<false>(&model, gp, &scratch, &world);
            let m = world.margin;
            let clear = kdop_clear::<false>(&model, gp.a, gp.b, &scratch, m);
            if avx {
                assert_eq!(clear, kdop_clear::<true>(&model, gp.a, gp.b, &scratch, m));
            }
            close += near.count_ones();
            for l in 0..FAST_LANES {
                if clear & near & (1 << l) == 0 {
                    continue;
                }
                cleared += 1;
                let q = &qs[l * active.len()..(l + 1) * active.len()];
                active.forward(q, &mut pose).unwrap();
                collision.place(&pose, &mut placed);
                for &(a, b) in &gp.bodies {
                    assert!(!collision.bodies_touch(&placed, a as usize, b as usize));
                }
            }
        }
    }
    assert!(
        cleared > 10 && cleared < close,
        "{cleared} of {close} close lanes cleared"
    );
}
