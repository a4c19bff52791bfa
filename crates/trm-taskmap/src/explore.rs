//! RRT exploration of a task map (paper Section II) with restarts for disjoint clusters.

use kiddo::{KdTree, SquaredEuclidean};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

use crate::map::{Metric, TaskMap, TaskMapError, TaskPoint};

/// Exploration settings.
#[derive(Debug, Clone, PartialEq)]
pub struct ExploreOptions {
    /// Step ε from the nearest tree node towards the sample, in metric units.
    pub step: f64,
    /// RRT iterations (one evaluation each).
    pub iterations: usize,
    /// Lower corner of the sampling box.
    pub lower: [f64; 6],
    /// Upper corner of the sampling box.
    pub upper: [f64; 6],
    /// θ: g is feasible when C(g) > θ.
    pub threshold: f64,
    /// Random probes for new clusters: a feasible probe farther than 2ε from every point
    /// starts a new tree (the paper's RRT only finds one contiguous region).
    pub restarts: usize,
    /// Seed.
    pub seed: u64,
}

impl ExploreOptions {
    /// A box of half-widths `half` around `centre`, with ε = 0.01, 2000 iterations, θ = 0,
    /// 500 restart probes, seed 0.
    pub fn around(centre: [f64; 6], half: [f64; 6]) -> Self {
        ExploreOptions {
            step: 0.01,
            iterations: 2000,
            lower: std::array::from_fn(|i| centre[i] - half[i]),
            upper: std::array::from_fn(|i| centre[i] + half[i]),
            threshold: 0.0,
            restarts: 500,
            seed: 0,
        }
    }
}

/// Explores the feasible set {g : C(g) > θ} from the feasible starts with an RRT: sample x
/// uniformly in the box, step ε from the nearest point towards x, keep the new point if it is
/// feasible (with a tree link to its origin). Restart probes are interleaved with the RRT steps.
pub fn explore(
    starts: &[[f64; 6]],
    settings: &ExploreOptions,
    metric: &Metric,
    mut evaluate: impl FnMut(&[f64; 6]) -> f64,
) -> Result<TaskMap, TaskMapError> {
    metric.check()?;
    if !(settings.step.is_finite() && settings.step > 0.0) {
        return Err(TaskMapError::Invalid {
            what: "step ε".into(),
            problem: format!("{} is not positive", settings.step),
        });
    }
    if (0..6).any(|i| {
        settings.lower[i].partial_cmp(&settings.upper[i]) == Some(std::cmp::Ordering::Greater)
            || settings.lower[i].is_nan()
            || !settings.lower[i].is_finite()
            || !settings.upper[i].is_finite()
    }) {
        return Err(TaskMapError::Invalid {
            what: "sampling box".into(),
            problem: "needs finite lower ≤ upper".into(),
        });
    }
    if starts.is_empty() {
        return Err(TaskMapError::Invalid {
            what: "starts".into(),
            problem: "give at least one feasible g₀".into(),
        });
    }
    let mut rng = ChaCha8Rng::seed_from_u64(settings.seed);
    let mut points: Vec<TaskPoint> = Vec::new();
    let mut index: KdTree<f64, 6> = KdTree::new();
    let mut evaluations = 0u64;
    let mut eval = |g: &[f64; 6], evaluations: &mut u64| {
        *evaluations += 1;
        evaluate(g)
    };
    for (k, g0) in starts.iter().enumerate() {
        if let Some(j) = starts[..k].iter().position(|s| s == g0) {
            return Err(TaskMapError::Invalid {
                what: format!("starts[{k}]"),
                problem: format!("repeats starts[{j}]; give each start once"),
            });
        }
        let value = eval(g0, &mut evaluations);
        if value.is_nan() || value <= settings.threshold {
            return Err(TaskMapError::InfeasibleStart {
                index: k,
                value,
                threshold: settings.threshold,
            });
        }
        index.add(&metric.scale(g0), points.len() as u64);
        points.push(TaskPoint {
            g: *g0,
            value,
            parent: None,
            cluster: k,
        });
    }
    let mut clusters = starts.len();
    let sample = |rng: &mut ChaCha8Rng| -> [f64; 6] {
        std::array::from_fn(|i| {
            if settings.lower[i] < settings.upper[i] {
                rng.random_range(settings.lower[i]..settings.upper[i])
            } else {
                settings.lower[i]
            }
        })
    };
    let probe_every = settings
        .iterations
        .checked_div(settings.restarts)
        .map_or(usize::MAX, |n| n.max(1));
    let mut probes = 0;
    for it in 0..settings.iterations {
        if it % probe_every == 0 && probes < settings.restarts {
            probes += 1;
            let x = sample(&mut rng);
            let nn = index.nearest_one::<SquaredEuclidean>(&metric.scale(&x));
            if nn.distance.sqrt() > 2.0 * settings.step {
                let value = eval(&x, &mut evaluations);
                if value > settings.threshold {
                    index.add(&metric.scale(&x), points.len() as u64);
                    points.push(TaskPoint {
                        g: x,
                        value,
                        parent: None,
                        cluster: clusters,
                    });
                    clusters += 1;
                }
            }
        }
        let x = sample(&mut rng);
        let nn = index.nearest_one::<SquaredEuclidean>(&metric.scale(&x));
        let (d, i) = (nn.distance.sqrt(), nn.item as usize);
        if d <= 0.0 {
            continue;
        }
        let from = points[i].g;
        let t = (settings.step / d).min(1.0);
        let g: [f64; 6] = std::array::from_fn(|k| from[k] + t * (x[k] - from[k]));
        let value = eval(&g, &mut evaluations);
        if value > settings.threshold {
            index.add(&metric.scale(&g), points.len() as u64);
            points.push(TaskPoint {
                g,
                value,
                parent: Some(i),
                cluster: points[i].cluster,
            });
        }
    }
    Ok(TaskMap::new(
        *metric,
        settings.threshold,
        points,
        evaluations,
    ))
}
