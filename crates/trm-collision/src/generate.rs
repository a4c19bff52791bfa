//! Automatic allowed-collision matrices, as MoveIt's setup assistant builds them.

use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;
use trm_kinematics::DisableReason;

use crate::acm::AllowedCollisionMatrix;
use crate::error::{CollisionError, Result};
use crate::model::CollisionModel;

/// Samples drawn from one random stream (the unit of parallel work).
const SAMPLES_PER_CHUNK: usize = 4096;

/// Settings of [`generate_acm`].
#[derive(Debug, Clone, PartialEq)]
pub struct AcmOptions {
    /// Random configurations sampled uniformly within the motor limits (MoveIt uses 10 000;
    /// a 41-DOF robot needs far more before rare contacts show up, hence the default).
    pub samples: usize,
    /// Seed of the sampler (ChaCha8).
    pub seed: u64,
    /// A pair colliding in at least this fraction of the samples is disabled as `always`.
    pub always_fraction: f64,
    /// Motor values of the default posture; `None` = the model's `home` posture if it has one,
    /// else its neutral motors.
    pub default_posture: Option<Vec<f64>>,
}

impl Default for AcmOptions {
    fn default() -> Self {
        AcmOptions {
            samples: 1_000_000,
            seed: 0,
            always_fraction: 0.95,
            default_posture: None,
        }
    }
}

/// What [`generate_acm`] found.
#[derive(Debug, Clone)]
pub struct AcmReport {
    /// The new matrix.
    pub acm: AllowedCollisionMatrix,
    /// Per link pair `[a, b]` still checked: in how many samples it collided.
    pub collision_counts: Vec<([usize; 2], usize)>,
    /// Samples drawn.
    pub samples: usize,
}

/// Builds a matrix from the collision model's bodies: adjacent pairs, pairs colliding at the
/// default posture, pairs colliding in almost every and in none of `samples` random
/// configurations are disabled. Pairs the description disables by hand (`user`) stay disabled;
/// pairs it enables stay enabled. Other entries of the model's current matrix are ignored.
pub fn generate_acm(model: &CollisionModel, settings: &AcmOptions) -> Result<AcmReport> {
    let robot = model.robot();
    if !(0.0..=1.0).contains(&settings.always_fraction) {
        return Err(CollisionError::InvalidValue {
            what: "always_fraction".into(),
            problem: format!("{} is not within [0, 1]", settings.always_fraction),
        });
    }
    let mut acm = AllowedCollisionMatrix::adjacent(robot, &model.has_geometry());
    for d in robot.disabled_collisions() {
        if d.reason == DisableReason::User {
            acm.disable(d.links[0], d.links[1], DisableReason::User);
        }
    }
    acm.apply_enabled(robot);
    let forced: Vec<[usize; 2]> = robot.enabled_collisions().to_vec();
    let may_disable = |a: usize, b: usize| !forced.contains(&[a.min(b), a.max(b)]);

    let mut poses = robot.pose_buffer();
    let default = match &settings.default_posture {
        Some(q) => q.clone(),
        None => robot.home_motors(),
    };
    robot.forward_motors(&default, &mut poses)?;
    let probe = model.with_acm(acm.clone())?;
    let mut placed = probe.placed_bodies();
    probe.place(&poses, &mut placed);
    let link = |body: usize| probe.bodies()[body].link;
    for hit in probe.colliding_pair_indices(&placed) {
        let (a, b) = (link(hit[0]), link(hit[1]));
        if may_disable(a, b) {
            acm.disable(a, b, DisableReason::Default);
        }
    }

    let probe = model.with_acm(acm.clone())?;
    let n = robot.num_links();
    // Fixed-size chunks, each with its own ChaCha stream: the counts depend on the seed only,
    // not on the number of threads.
    let chunks = settings.samples.div_ceil(SAMPLES_PER_CHUNK);
    let counts = (0..chunks)
        .into_par_iter()
        .map(|chunk| -> Result<Vec<usize>> {
            let mut rng = ChaCha8Rng::seed_from_u64(settings.seed);
            rng.set_stream(chunk as u64);
            let mut counts = vec![0usize; n * n];
            let mut poses = robot.pose_buffer();
            let mut placed = probe.placed_bodies();
            let mut q = vec![0.0; robot.motors().len()];
            let todo = SAMPLES_PER_CHUNK.min(settings.samples - chunk * SAMPLES_PER_CHUNK);
            for _ in 0..todo {
                for (v, m) in q.iter_mut().zip(robot.motors()) {
                    *v = rng.random_range(m.limits.lower..=m.limits.upper);
                }
                robot.forward_motors(&q, &mut poses)?;
                probe.place(&poses, &mut placed);
                for hit in probe.colliding_pair_indices(&placed) {
                    let (a, b) = (link(hit[0]), link(hit[1]));
                    counts[a.min(b) * n + a.max(b)] += 1;
                }
            }
            Ok(counts)
        })
        .try_reduce(
            || vec![0usize; n * n],
            |mut total, part| {
                total.iter_mut().zip(part).for_each(|(t, p)| *t += p);
                Ok(total)
            },
        )?;
    let mut collision_counts = Vec::new();
    for a in 0..n {
        for b in a + 1..n {
            if !probe.acm().is_checked(a, b) || !probe.has_geometry()[a] || !probe.has_geometry()[b]
            {
                continue;
            }
            let c = counts[a * n + b];
            if may_disable(a, b) && settings.samples > 0 {
                if c == 0 {
                    acm.disable(a, b, DisableReason::Never);
                } else if c as f64 >= settings.always_fraction * settings.samples as f64 {
                    acm.disable(a, b, DisableReason::Always);
                }
            }
            collision_counts.push(([a, b], c));
        }
    }
    Ok(AcmReport {
        acm,
        collision_counts,
        samples: settings.samples,
    })
}
