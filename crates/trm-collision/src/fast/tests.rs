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

/// A shipped model (`models/…`): its robot, exact collision model and screen.
fn shipped(file: &str) -> (trm_kinematics::RobotModel, CollisionModel, FastModel) {
    let file = format!("{}/../../models/{file}", env!("CARGO_MANIFEST_DIR"));
    let robot = trm_kinematics::RobotModel::load(&file).unwrap();
    let collision = CollisionModel::new(&robot).unwrap();
    let model = FastModel::new(&collision).unwrap();
    (robot, collision, model)
}

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
    let (robot, _, model) = shipped("panda-mbm/panda_spherized.ron");
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
            place_balls::<false>(&model, block.lanes(), gp.a, &mut scratch);
            place_balls::<false>(&model, block.lanes(), gp.b, &mut scratch);
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
    let (robot, collision, model) = shipped("panda-mbm/panda.ron");
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
            place_balls::<false>(&model, block.lanes(), gp.a, &mut scratch);
            place_balls::<false>(&model, block.lanes(), gp.b, &mut scratch);
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

/// The solids' kernels ([`super::solid`]) never call a pair clear that touches nor colliding
/// that is apart, by parry's distance (an independent implementation in `f64`), on pairs of
/// every kind moved onto contact by bisection and then off it by a few tolerances either way,
/// half of them with parallel axes (the separating-axis and closest-point degeneracies); and
/// beyond ten tolerances of contact they leave almost nothing uncertain (but overlapping boxes
/// with parallel edges, which the exact check decides when no point of one is found inside the
/// other).
#[test]
fn solid_kernels_are_sound_at_contact() {
    use super::lanes::Flags;
    use super::solid::{Placed, Solid, SolidPair, box_box, round_box, round_round};
    use crate::model::Body;
    use nalgebra::{Isometry3, Translation3, UnitQuaternion, UnitVector3};
    use parry3d_f64::query;

    let avx2 = is_x86_feature_detected!("avx2") && is_x86_feature_detected!("fma");

    let shapes = [
        Shape::Sphere { radius: 0.05 },
        Shape::Capsule {
            radius: 0.04,
            length: 0.2,
        },
        Shape::Box {
            size: [0.1, 0.25, 0.15],
        },
        Shape::Box {
            size: [0.02, 0.3, 0.05],
        },
        Shape::Capsule {
            radius: 0.01,
            length: 0.4,
        },
    ];
    let m = 2.5e-5f32;
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    let (mut far_lanes, mut far_uncertain) = (0usize, 0usize);
    // lanes certainly clear, certainly colliding
    let mut decided = [0usize; 2];
    let place = |shape: &Shape, pose: &Isometry3<f64>, placed: &mut Placed, l: usize| {
        let at = |p: nalgebra::Point3<f64>| to_f32(p.coords);
        let slots: [[f32; 3]; 4] = match shape {
            Shape::Box { .. } => {
                let r = pose.rotation.to_rotation_matrix();
                let c = |k: usize| to_f32(r.matrix().column(k).into_owned());
                [to_f32(pose.translation.vector), c(0), c(1), c(2)]
            }
            Shape::Capsule { length, .. } => [
                at(pose * nalgebra::Point3::new(0.0, 0.0, -0.5 * length)),
                at(pose * nalgebra::Point3::new(0.0, 0.0, 0.5 * length)),
                [0.0; 3],
                [0.0; 3],
            ],
            _ => [
                to_f32(pose.translation.vector),
                to_f32(pose.translation.vector),
                [0.0; 3],
                [0.0; 3],
            ],
        };
        for (slot, v) in placed.iter_mut().zip(slots) {
            for k in 0..3 {
                slot[k].0[l] = v[k];
            }
        }
    };
    for (i, a) in shapes.iter().enumerate() {
        for b in &shapes[i..] {
            let body = |shape: &Shape| Body {
                name: "b".into(),
                link: 0,
                shape: shape.clone(),
                local: Isometry3::identity(),
            };
            let solids = [Solid::of(&body(a)).unwrap(), Solid::of(&body(b)).unwrap()];
            let pair = SolidPair::new(&solids, 0, 1);
            let (first, second) = if pair.a == 0 { (a, b) } else { (b, a) };
            let tol = m * pair.scale;
            // boxes as convex hulls of their corners: parry's box–box distance jumps from 0 to
            // the boxes' gap where their axes are parallel (parry3d 0.x), its hull distance
            // (GJK) does not
            let truth_shape = |shape: &Shape| match shape {
                Shape::Box { size } => {
                    let h = size.map(|s| 0.5 * s);
                    let corners: Vec<nalgebra::Point3<f64>> = (0..8)
                        .map(|k| {
                            let sign = |bit: usize| if k >> bit & 1 == 0 { -1.0 } else { 1.0 };
                            nalgebra::Point3::new(sign(0) * h[0], sign(1) * h[1], sign(2) * h[2])
                        })
                        .collect();
                    parry3d_f64::shape::SharedShape::convex_hull(&corners).unwrap()
                }
                _ => shape.to_parry().unwrap().1,
            };
            let (pa_shape, pb_shape) = (truth_shape(first), truth_shape(second));
            for trial in 0..300 {
                let rot = |rng: &mut ChaCha8Rng| {
                    UnitQuaternion::from_euler_angles(
                        rng.random_range(-3.2..3.2),
                        rng.random_range(-3.2..3.2),
                        rng.random_range(-3.2..3.2),
                    )
                };
                let ra = rot(&mut rng);
                // half the trials: the same axes (or a quarter turn about one of them)
                let rb = match trial % 4 {
                    0 => ra,
                    1 => {
                        ra * UnitQuaternion::from_euler_angles(
                            0.0,
                            0.0,
                            std::f64::consts::FRAC_PI_2,
                        )
                    }
                    _ => rot(&mut rng),
                };
                let center = nalgebra::Vector3::new(
                    rng.random_range(-0.5..0.5),
                    rng.random_range(-0.5..0.5),
                    rng.random_range(-0.5..0.5),
                );
                let dir = UnitVector3::new_normalize(nalgebra::Vector3::new(
                    rng.random_range(-1.0..1.0),
                    rng.random_range(-1.0..1.0),
                    rng.random_range(-1.0..1.0),
                ));
                let pose_a = Isometry3::from_parts(Translation3::from(center), ra);
                let pose_b = |lambda: f64| {
                    Isometry3::from_parts(
                        Translation3::from(center + dir.into_inner() * lambda),
                        rb,
                    )
                };
                let distance = |lambda: f64| {
                    query::distance(&pose_a, &*pa_shape, &pose_b(lambda), &*pb_shape).unwrap()
                };
                // bisect onto contact: touching at 0, apart at 2
                let (mut lo, mut hi) = (0.0, 2.0);
                for _ in 0..60 {
                    let mid = 0.5 * (lo + hi);
                    if distance(mid) > 0.0 {
                        hi = mid
                    } else {
                        lo = mid
                    }
                }
                let t = f64::from(tol);
                let offsets = [
                    -10.0 * t,
                    -3.0 * t,
                    -t,
                    -0.2 * t,
                    0.2 * t,
                    t,
                    3.0 * t,
                    10.0 * t,
                ];
                let offsets = if trial % 2 == 0 {
                    offsets
                } else {
                    offsets.map(|o| o * 40.0)
                };
                let signed = |lambda: f64| {
                    let (pb_pose, d) = (pose_b(lambda), distance(lambda));
                    if d > 0.0 {
                        return d;
                    }
                    query::contact(&pose_a, &*pa_shape, &pb_pose, &*pb_shape, 0.0)
                        .unwrap()
                        .map_or(0.0, |c| c.dist)
                };
                fn kernel<const AVX: bool>(
                    (first, second): (&Solid, &Solid),
                    pa: &Placed,
                    pb: &Placed,
                    tol: f32,
                ) -> (Flags, Flags) {
                    match (first, second) {
                        (
                            Solid::Round { a, b, radius },
                            Solid::Round {
                                a: c,
                                b: d,
                                radius: r,
                            },
                        ) => round_round::<AVX>(pa, (*a, *b, *radius), pb, (*c, *d, *r), tol),
                        (Solid::Round { a, b, radius }, Solid::Box { half, .. }) => {
                            round_box::<AVX>(pa, (*a, *b, *radius), pb, *half, tol, true)
                        }
                        (Solid::Box { half, .. }, Solid::Box { half: other, .. }) => {
                            box_box::<AVX>(pa, *half, pb, *other, tol)
                        }
                        _ => unreachable!(),
                    }
                }
                let kernel = |avx: bool, pa: &Placed, pb: &Placed| {
                    let solids = (&solids[pair.a as usize], &solids[pair.b as usize]);
                    if avx {
                        kernel::<true>(solids, pa, pb, tol)
                    } else {
                        kernel::<false>(solids, pa, pb, tol)
                    }
                };
                let (mut pa, mut pb): (Placed, Placed) = Default::default();
                let (mut apart, mut depth) = ([false; FAST_LANES], [0.0; FAST_LANES]);
                for (l, &o) in offsets.iter().enumerate() {
                    // `o` along the normal direction of separation, roughly: along `dir`
                    let lambda = hi + o;
                    place(first, &pose_a, &mut pa, l);
                    place(second, &pose_b(lambda), &mut pb, l);
                    apart[l] = distance(lambda) > 0.0;
                    depth[l] = signed(lambda);
                }
                let (hit, close) = kernel(false, &pa, &pb);
                if avx2 {
                    // the AVX2 compilation answers as the portable one
                    let (avx_hit, avx_close) = kernel(true, &pa, &pb);
                    assert_eq!(
                        (avx_hit.0, avx_close.0),
                        (hit.0, close.0),
                        "AVX2 and portable"
                    );
                }
                for l in 0..FAST_LANES {
                    let what = format!(
                        "{} and {}, trial {trial}, offset {}",
                        first.kind(),
                        second.kind(),
                        offsets[l]
                    );
                    if hit.0[l] != 0 {
                        assert!(!apart[l], "{what}: called colliding, apart");
                    }
                    if close.0[l] == 0 {
                        assert!(apart[l], "{what}: called clear, touching");
                    }
                    // overlapping boxes whose edges are parallel are left to the exact check
                    // unless a point of one lies inside the other (a cross axis vanishes)
                    let parallel_boxes =
                        trial % 4 < 2 && first.kind() == "box" && second.kind() == "box";
                    if depth[l].abs() >= 10.0 * t && !(parallel_boxes && depth[l] < 0.0) {
                        let uncertain = usize::from(close.0[l] != 0 && hit.0[l] == 0);
                        far_lanes += 1;
                        far_uncertain += uncertain;
                        decided[usize::from(hit.0[l] != 0)] += 1 - uncertain;
                    }
                }
            }
        }
    }
    eprintln!("{far_uncertain} of {far_lanes} far lanes uncertain; {decided:?} clear, colliding");
    assert!(
        decided.iter().all(|&n| n * 4 > far_lanes),
        "{decided:?}: a test of both answers"
    );
    assert!(
        far_uncertain * 200 <= far_lanes,
        "{far_uncertain} of {far_lanes} lanes beyond ten tolerances of contact left uncertain"
    );
}

/// A world compiled after another takes what did not change (a cloud's grid shared, not built
/// again) and is otherwise the world compiled afresh: moved, added, removed and reshaped
/// objects, a renamed one, and a world rebuilt in another order.
#[test]
fn a_world_compiled_after_another_is_the_world_compiled_afresh() {
    let (_, _, model) = shipped("panda-mbm/panda_spherized.ron");
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    let board = Shape::Box {
        size: [0.6, 0.8, 0.02],
    };
    let cloud = Shape::Points {
        points: board.surface_samples(2000, &mut rng),
        radius: 0.003,
    };
    let tetra = Shape::Mesh {
        vertices: vec![[0.0; 3], [0.2, 0.0, 0.0], [0.0, 0.2, 0.0], [0.0, 0.0, 0.2]],
        triangles: vec![[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]],
    };
    let at = |x: f64, y: f64, z: f64| nalgebra::Isometry3::translation(x, y, z);
    let mut before = World::new();
    before
        .add("scan", cloud.clone(), at(0.5, 0.0, 0.3))
        .unwrap();
    before
        .add("bowl", tetra.clone(), at(0.4, 0.3, 0.4))
        .unwrap();
    before
        .add("crate", board.clone(), at(0.6, -0.3, 0.2))
        .unwrap();
    before
        .add("ball", Shape::Sphere { radius: 0.05 }, at(0.3, 0.2, 0.6))
        .unwrap();
    let compiled = model.world(&before);
    let same = |a: &FastWorld, b: &FastWorld| {
        format!(
            "{:?} {:?} {:?} {:?} {:?}",
            a.objects, a.original, a.compiled_of, a.margin, a.limits
        ) == format!(
            "{:?} {:?} {:?} {:?} {:?}",
            b.objects, b.original, b.compiled_of, b.margin, b.limits
        ) && a.clouds.len() == b.clouds.len()
            && a.clouds
                .iter()
                .zip(&b.clouds)
                .all(|(x, y)| format!("{x:?}") == format!("{y:?}"))
    };
    let mut changes: Vec<(&str, World)> = Vec::new();
    let mut moved = before.clone();
    moved.set_pose("crate", at(0.65, -0.3, 0.25)).unwrap();
    changes.push(("a box moved", moved));
    let mut removed = before.clone();
    removed.remove("ball").unwrap();
    changes.push(("a ball removed", removed));
    let mut added = before.clone();
    added
        .add(
            "cup",
            Shape::Cylinder {
                radius: 0.04,
                length: 0.1,
            },
            at(0.5, 0.1, 0.5),
        )
        .unwrap();
    changes.push(("a cylinder added", added));
    let mut reshaped = World::new();
    for o in before.objects() {
        let shape = match o.name() {
            "scan" => Shape::Points {
                points: board.surface_samples(2000, &mut rng),
                radius: 0.003,
            },
            _ => o.shape().clone(),
        };
        reshaped.add(o.name(), shape, *o.pose()).unwrap();
    }
    changes.push(("a new scan", reshaped));
    let mut renamed = World::new();
    for o in before.objects().iter().rev() {
        let name = if o.name() == "bowl" { "dish" } else { o.name() };
        renamed.add(name, o.shape().clone(), *o.pose()).unwrap();
    }
    changes.push(("reordered, the mesh renamed", renamed));
    for (what, world) in &changes {
        let after = model.world_after(world, &before, &compiled);
        assert!(same(&after, &model.world(world)), "{what}");
    }
    // an unchanged cloud's grid is shared, not built again; a new scan's is its own
    let scan_grid = |w: &FastWorld, world: &World| {
        let k = w.compiled_of[world.index("scan").unwrap()] as usize;
        match w.objects[k] {
            Object::Cloud { index, .. } => std::sync::Arc::clone(&w.clouds[index as usize]),
            _ => panic!("the scan is a cloud"),
        }
    };
    let original = scan_grid(&compiled, &before);
    let moved = model.world_after(&changes[0].1, &before, &compiled);
    assert!(std::sync::Arc::ptr_eq(
        &original,
        &scan_grid(&moved, &changes[0].1)
    ));
    let rescanned = model.world_after(&changes[3].1, &before, &compiled);
    assert!(!std::sync::Arc::ptr_eq(
        &original,
        &scan_grid(&rescanned, &changes[3].1)
    ));
}

/// Lanes outside `live` never decide the live ones: blocks whose dead lanes hold colliding
/// configurations and whose live lanes hold random ones, among boxes, a sphere and a capsule,
/// on a model of capsules and boxes (the iCub) and one of mesh hulls (the Panda). A live lane
/// is reported colliding only where the exact model says so, and when no lane is reported
/// colliding every live lane the exact model finds colliding is left uncertain, never clear.
#[test]
fn dead_lanes_never_decide_live_ones() {
    let at = |x: f64, y: f64, z: f64| nalgebra::Isometry3::translation(x, y, z);
    for (file, seed, reach) in [
        ("icub_upper_body.ron", 21, 0.3),
        ("panda-mbm/panda.ron", 22, 0.5),
    ] {
        let (robot, collision, model) = shipped(file);
        let active = robot.all_active();
        let mut world = World::new();
        let plate = Shape::Box {
            size: [0.3, 0.3, 0.02],
        };
        world.add("plate", plate, at(reach, 0.0, 0.2)).unwrap();
        let post = Shape::Box {
            size: [0.04, 0.04, 0.5],
        };
        world.add("post", post, at(0.0, reach, 0.3)).unwrap();
        world
            .add(
                "ball",
                Shape::Sphere { radius: 0.06 },
                at(reach, -reach, 0.4),
            )
            .unwrap();
        let rod = Shape::Capsule {
            radius: 0.02,
            length: 0.4,
        };
        world.add("rod", rod, at(-reach, 0.0, 0.3)).unwrap();
        let (mut pose, mut placed) = (robot.pose_buffer(), collision.placed_bodies());
        let mut colliding = |q: &[f64]| {
            active.forward(q, &mut pose).unwrap();
            collision.place(&pose, &mut placed);
            collision.is_colliding(&placed, &world)
        };
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let hits: Vec<Vec<f64>> = std::iter::repeat_with(|| active.random(&mut rng))
            .filter(|q| colliding(q))
            .take(64)
            .collect();
        let (mut block, mut scratch) = (robot.pose_block(), model.scratch());
        let fast_world = model.world(&world);
        let mut live_hits = 0;
        for round in 0..1000 {
            let live: LaneMask = (1 << (1 + round % (FAST_LANES - 1))) - 1;
            let qs: Vec<Vec<f64>> = (0..FAST_LANES)
                .map(|l| match live & (1 << l) {
                    0 => hits[(round + l) % hits.len()].clone(),
                    _ => active.random(&mut rng),
                })
                .collect();
            active.forward_block_unchecked(&qs.concat(), &mut block);
            let verdict = model.check(block.lanes(), live, &fast_world, &mut scratch);
            let truth: LaneMask = (0..FAST_LANES)
                .filter(|&l| live & (1 << l) != 0 && colliding(&qs[l]))
                .fold(0, |m, l| m | (1 << l));
            live_hits += truth.count_ones();
            assert_eq!(
                verdict.colliding & !truth,
                0,
                "{file}: a free lane reported colliding"
            );
            if verdict.colliding == 0 {
                assert_eq!(
                    truth & !verdict.uncertain,
                    0,
                    "{file}: a colliding live lane cleared"
                );
            }
        }
        assert!(
            live_hits > 30,
            "{file}: {live_hits} colliding live lanes: too few to test"
        );
    }
}

/// Clearance tables decide only what the exact model says: on the Panda's mesh hulls, the
/// wrist pairs (the forearm against the last link, the hand and the fingers, moved by joints 6
/// and 7 alone) get tables, and on the Fetch's the shoulder against the upper arm (moved by a
/// limited joint and one that turns a whole turn, given a turn more in half the lanes); in 40 000 random configurations every lane a table
/// calls free is one where the exact model finds the pair's bodies apart, every lane it calls
/// colliding one where some of them touch; the tables decide most lanes (a table whose angles
/// were read wrongly would decide few, or wrongly; the Fetch's table is all free, so there its
/// reading of a whole-turn joint's angle, whatever the quaternion's sign, is what is tested).
#[test]
fn clearance_tables_decide_only_what_the_exact_model_says() {
    for (file, least_tables) in [("panda-mbm/panda.ron", 4), ("fetch-mbm/fetch.ron", 1)] {
        let (robot, collision, model) = shipped(file);
        assert!(
            model.tables.len() >= least_tables,
            "{file}: {} tables",
            model.tables.len()
        );
        let active = robot.all_active();
        let (mut block, mut pose) = (robot.pose_block(), robot.pose_buffer());
        let mut placed = collision.placed_bodies();
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        let (mut decided, mut hits, mut looked) = (0, 0, 0);
        for _ in 0..40_000 / FAST_LANES {
            let mut qs: Vec<Vec<f64>> = (0..FAST_LANES).map(|_| active.random(&mut rng)).collect();
            // a joint that turns a whole turn, a turn further in half the lanes: the same
            // rotation, the opposite quaternion
            for (l, q) in qs.iter_mut().enumerate() {
                for (i, v) in q.iter_mut().enumerate() {
                    let limits = &robot.joint(i).limits;
                    if l % 2 == 1 && limits.upper - limits.lower > 6.0 {
                        *v += std::f64::consts::TAU;
                    }
                }
            }
            active.forward_block_unchecked(&qs.concat(), &mut block);
            for gp in &model.group_pairs {
                let Some(t) = gp.table else { continue };
                let mut angles = super::table::Angles::new(model.readers.len());
                let (free, hit) = model.tables[t as usize].lookup(
                    &model.readers,
                    &mut angles,
                    block.lanes(),
                    ALL_LANES,
                );
                assert_eq!(free & hit, 0);
                looked += FAST_LANES;
                decided += (free | hit).count_ones() as usize;
                hits += hit.count_ones() as usize;
                for l in (0..FAST_LANES).filter(|l| (free | hit) & (1 << l) != 0) {
                    active.forward(&qs[l], &mut pose).unwrap();
                    collision.place(&pose, &mut placed);
                    let touch = gp
                        .bodies
                        .iter()
                        .any(|&(a, b)| collision.bodies_touch(&placed, a as usize, b as usize));
                    assert_eq!(
                        touch,
                        hit & (1 << l) != 0,
                        "{file}: a table called the pair {} at {:?}",
                        if touch { "free" } else { "colliding" },
                        qs[l]
                    );
                }
            }
        }
        assert!(model.tables.iter().all(|t| t.decided()[0] > 0.5), "{file}");
        assert!(
            decided * 20 > looked * 19,
            "{file}: tables decided {decided} of {looked} lanes ({hits} colliding)"
        );
        if file.starts_with("panda") {
            assert!(
                hits * 50 > looked,
                "{file}: {hits} of {looked} lanes colliding"
            );
        }
    }
}

/// A frame holding [`FRAME_CULL_GROUPS`] groups or more (a gripper's fingers fixed to the
/// wrist) is walked behind the sphere enclosing them: the screen still answers as the exact
/// model does, configuration by configuration and block by block, among every primitive.
#[test]
fn groups_behind_their_frames_sphere_answer_as_the_exact_model_does() {
    let (mut links, mut joints) = (String::new(), String::new());
    for k in 0..FRAME_CULL_GROUPS {
        let a = k as f64 * std::f64::consts::TAU / FRAME_CULL_GROUPS as f64;
        let (x, y) = (0.06 * a.cos(), 0.06 * a.sin());
        links += &format!(
            r#"<link name="g{k}"><collision><origin xyz="{x} {y} 0.08"/><geometry><sphere radius="0.02"/></geometry></collision></link>"#
        );
        joints += &format!(
            r#"<joint name="f{k}" type="fixed"><parent link="wrist"/><child link="g{k}"/></joint>"#
        );
    }
    let limit = r#"<limit lower="-2.5" upper="2.5" effort="1" velocity="1"/>"#;
    let urdf = format!(
        r#"<robot name="gripper_arm">
          <link name="base"/>
          <link name="upper"><collision><origin xyz="0 0 0.2"/><geometry><sphere radius="0.05"/></geometry></collision></link>
          <link name="fore"><collision><origin xyz="0 0 0.2"/><geometry><sphere radius="0.04"/></geometry></collision></link>
          <link name="wrist"><collision><geometry><sphere radius="0.03"/></geometry></collision></link>
          {links}
          <joint name="j1" type="revolute"><parent link="base"/><child link="upper"/><axis xyz="0 0 1"/>{limit}</joint>
          <joint name="j2" type="revolute"><parent link="upper"/><child link="fore"/><origin xyz="0 0 0.4"/><axis xyz="0 1 0"/>{limit}</joint>
          <joint name="j3" type="revolute"><parent link="fore"/><child link="wrist"/><origin xyz="0 0 0.4"/><axis xyz="0 1 0"/>{limit}</joint>
          {joints}
        </robot>"#
    );
    let robot = trm_kinematics::RobotModel::from_urdf_str(&urdf, "<gripper arm>").unwrap();
    let collision = CollisionModel::new(&robot).unwrap();
    let active = robot.all_active();
    let mut checker = FastChecker::new(&collision, active.clone()).unwrap();
    assert_eq!(
        checker.model().frame_balls.len(),
        1,
        "the wrist's fingers share a cull"
    );
    let at = |x: f64, y: f64, z: f64| nalgebra::Isometry3::translation(x, y, z);
    let mut world = World::new();
    let plate = Shape::Box {
        size: [0.5, 0.5, 0.02],
    };
    world.add("plate", plate, at(0.4, 0.0, 0.45)).unwrap();
    let ball = Shape::Sphere { radius: 0.12 };
    world.add("ball", ball, at(-0.25, 0.25, 0.75)).unwrap();
    let rod = Shape::Capsule {
        radius: 0.02,
        length: 0.4,
    };
    world.add("rod", rod, at(0.0, -0.4, 0.5)).unwrap();
    let can = Shape::Cylinder {
        radius: 0.05,
        length: 0.2,
    };
    world.add("can", can, at(-0.3, -0.2, 0.4)).unwrap();
    let fast_world = checker.model().world(&world);
    let (mut pose, mut placed) = (robot.pose_buffer(), collision.placed_bodies());
    let mut rng = ChaCha8Rng::seed_from_u64(31);
    let qs: Vec<Vec<f64>> = (0..4000).map(|_| active.random(&mut rng)).collect();
    let mut truth = Vec::with_capacity(qs.len());
    for q in &qs {
        active.forward(q, &mut pose).unwrap();
        collision.place(&pose, &mut placed);
        truth.push(!collision.is_colliding(&placed, &world));
    }
    let free = truth.iter().filter(|&&f| f).count();
    assert!(
        free > 400 && free < 3600,
        "{free} of 4000: a test of both answers"
    );
    for (q, &expected) in qs.iter().zip(&truth) {
        assert_eq!(
            checker.all_free(q, &world, &fast_world).unwrap(),
            expected,
            "{q:?}"
        );
    }
    for (block, expected) in qs.chunks(FAST_LANES).zip(truth.chunks(FAST_LANES)) {
        let expected = expected.iter().all(|&f| f);
        let found = checker.all_free_unchecked(&block.concat(), &world, &fast_world);
        assert_eq!(found, expected, "{block:?}");
    }
}

/// Each compiled object's distance from the world's origin, by which the world walk stops
/// early, is a lower bound of the exact one (nalgebra, `f64`) and within 0.1 mm of it, for
/// boxes, cylinders, capsules and spheres in random poses and for a box holding the origin;
/// the objects are in ascending order of it.
#[test]
fn objects_lie_no_nearer_the_origin_than_their_walk_takes_them() {
    use nalgebra::{Isometry3, UnitQuaternion};
    let (_, _, model) = shipped("panda-mbm/panda_spherized.ron");
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    let mut world = World::new();
    let mut exact = Vec::new();
    for i in 0..200 {
        let t = Vector3::from_fn(|_, _| rng.random_range(-1.5..1.5));
        let axis = Vector3::from_fn(|_, _| rng.random_range(-1.0..1.0));
        let rotation = UnitQuaternion::from_scaled_axis(axis);
        let pose = Isometry3::from_parts(t.into(), rotation);
        // the origin in the object's frame
        let p = pose.inverse_transform_point(&Point3::origin()).coords;
        let (a, b, c) = (
            rng.random_range(0.01..0.6),
            rng.random_range(0.01..0.6),
            rng.random_range(0.01..0.6),
        );
        let (shape, d) = match i % 5 {
            0 => {
                let half = Vector3::new(a, b, c);
                let out = p.abs() - half;
                (
                    Shape::Box {
                        size: [2.0 * a, 2.0 * b, 2.0 * c],
                    },
                    out.sup(&Vector3::zeros()).norm(),
                )
            }
            1 => {
                let radial = (p.x.hypot(p.y) - a).max(0.0);
                let axial = (p.z.abs() - b).max(0.0);
                (
                    Shape::Cylinder {
                        radius: a,
                        length: 2.0 * b,
                    },
                    radial.hypot(axial),
                )
            }
            2 => {
                let z = p.z.clamp(-b, b);
                let d = (p - Vector3::new(0.0, 0.0, z)).norm() - a;
                (
                    Shape::Capsule {
                        radius: a,
                        length: 2.0 * b,
                    },
                    d.max(0.0),
                )
            }
            3 => (Shape::Sphere { radius: a }, (p.norm() - a).max(0.0)),
            // a box about the origin
            _ => {
                let pose = Isometry3::translation(0.1 * a, -0.1 * b, 0.1 * c);
                world
                    .add(&format!("o{i}"), Shape::Box { size: [1.0; 3] }, pose)
                    .unwrap();
                exact.push(0.0);
                continue;
            }
        };
        world.add(&format!("o{i}"), shape, pose).unwrap();
        exact.push(d);
    }
    let compiled = model.world(&world);
    assert!(compiled.from_origin.windows(2).all(|w| w[0] <= w[1]));
    for (k, &o) in compiled.original.iter().enumerate() {
        let (bound, d) = (f64::from(compiled.from_origin[k]), exact[o as usize]);
        assert!(
            bound <= d && bound >= d - 1e-4,
            "object {o}: {bound} against {d}"
        );
    }
}

/// Each compiled object's enclosing box, the world walk's first test of a link against it,
/// holds the object (its extent along each world axis, exact in `f64`) and is within 0.1 mm of
/// it, for boxes, cylinders, capsules and spheres in random poses.
#[test]
fn enclosing_boxes_hold_their_objects() {
    use nalgebra::{Isometry3, UnitQuaternion};
    let (_, _, model) = shipped("panda-mbm/panda_spherized.ron");
    let mut rng = ChaCha8Rng::seed_from_u64(12);
    let mut world = World::new();
    let mut poses = Vec::new();
    for i in 0..200 {
        let t = Vector3::from_fn(|_, _| rng.random_range(-1.5..1.5));
        let axis = Vector3::from_fn(|_, _| rng.random_range(-1.0..1.0));
        let pose = Isometry3::from_parts(t.into(), UnitQuaternion::from_scaled_axis(axis));
        let (a, b, c) = (
            rng.random_range(0.01..0.6),
            rng.random_range(0.01..0.6),
            rng.random_range(0.01..0.6),
        );
        let shape = match i % 4 {
            0 => Shape::Box {
                size: [2.0 * a, 2.0 * b, 2.0 * c],
            },
            1 => Shape::Cylinder {
                radius: a,
                length: 2.0 * b,
            },
            2 => Shape::Capsule {
                radius: a,
                length: 2.0 * b,
            },
            _ => Shape::Sphere { radius: a },
        };
        world.add(&format!("o{i}"), shape, pose).unwrap();
        poses.push((pose, [a, b, c]));
    }
    let compiled = model.world(&world);
    for (k, &o) in compiled.original.iter().enumerate() {
        let (centre, half) = compiled.boxes[k];
        let (pose, [a, b, c]) = poses[o as usize];
        let r = pose.rotation.to_rotation_matrix();
        let r = r.matrix();
        // the object's half extent along world axis i
        let extent = |i: usize| -> f64 {
            let z = r[(i, 2)].abs();
            match o % 4 {
                0 => r[(i, 0)].abs() * a + r[(i, 1)].abs() * b + z * c,
                1 => z * b + a * (1.0 - z * z).max(0.0).sqrt(),
                2 => z * b + a,
                _ => a,
            }
        };
        for i in 0..3 {
            let (exact, half) = (extent(i), f64::from(half[i]));
            let off = (f64::from(centre[i]) - pose.translation.vector[i]).abs();
            assert!(
                off + exact <= half && half <= exact + 1e-4,
                "object {o}, axis {i}: half {half} off by {off} against {exact}"
            );
        }
    }
}
