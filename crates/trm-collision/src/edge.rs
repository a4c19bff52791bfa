//! Straight edges between configurations: their length, the points at which they are checked,
//! and the raked order in which those points are visited ([`rake`]).
//!
//! Two step rules serve two callers: [`edge_steps`] cuts an edge into pieces no longer than the
//! resolution in Euclidean distance (the sampling planner's edges, as OMPL and VAMP measure
//! them), [`span_steps`] into pieces along which no coordinate moves more than the resolution
//! (a roadmap's edges).

/// Euclidean distance between configurations.
pub fn distance(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y) * (x - y))
        .sum::<f64>()
        .sqrt()
}

/// Pieces of the edge a → b no longer than `resolution` in [`distance`] (at least 1).
pub fn edge_steps(a: &[f64], b: &[f64], resolution: f64) -> usize {
    (distance(a, b) / resolution).ceil().max(1.0) as usize
}

/// Pieces of the edge a → b along which no coordinate moves more than `resolution` (at least 1).
pub fn span_steps(a: &[f64], b: &[f64], resolution: f64) -> usize {
    let span = a
        .iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max);
    (span / resolution).ceil().max(1.0) as usize
}

/// Point `s` of `steps` along a → b (`s = 0` is `a`, `s = steps` is `b`) into `q`.
pub fn edge_point(a: &[f64], b: &[f64], s: usize, steps: usize, q: &mut [f64]) {
    let u = s as f64 / steps as f64;
    for ((q, a), b) in q.iter_mut().zip(a).zip(b) {
        *q = a + u * (b - a);
    }
}

/// Whether `check` accepts the `n` points a + at(i)·(b − a), i < n, handed to it in batches of at
/// most `width` configurations (`d` values each, one after the other) and visited *raked*, as
/// VAMP validates a motion: batch k holds points k, k + m, k + 2m, … (m = ⌈n / width⌉), so the
/// first batch already spans the whole edge and an edge blocked anywhere over more than
/// 1/`width` of its length is refused by it. Stops at the first batch refused. `samples` is the
/// caller's buffer (grown to `width × d` once); `state` is handed to `check` with each batch.
///
/// # Panics
/// If `a` or `b` does not hold `d` values, or `width` is 0.
#[allow(clippy::too_many_arguments)] // the edge, its points, their batching and the check
pub fn rake<S>(
    d: usize,
    a: &[f64],
    b: &[f64],
    n: usize,
    at: impl Fn(usize) -> f64,
    width: usize,
    samples: &mut Vec<f64>,
    state: &mut S,
    mut check: impl FnMut(&[f64], &mut S) -> bool,
) -> bool {
    assert!(a.len() == d && b.len() == d, "one value per active motor");
    assert!(width > 0, "at least one sample per batch");
    let stride = n.div_ceil(width);
    samples.resize(width * d, 0.0);
    for k in 0..stride {
        let mut m = 0;
        for i in (k..n).step_by(stride) {
            let u = at(i);
            for ((q, a), b) in samples[m * d..(m + 1) * d].iter_mut().zip(a).zip(b) {
                *q = a + u * (b - a);
            }
            m += 1;
        }
        if !check(&samples[..m * d], state) {
            return false;
        }
    }
    true
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Raked: every point visited once when the edge is free; an edge blocked over more than
    /// 1/width of its length, anywhere, is refused by the first batch.
    #[test]
    fn edges_are_checked_raked() {
        let (a, b) = ([0.0], [1.0]);
        let steps = span_steps(&a, &b, 0.01);
        assert_eq!(steps, 100);
        let at = |s: usize| s as f64 / steps as f64;
        let mut seen = Vec::new();
        let all = rake(
            1,
            &a,
            &b,
            steps + 1,
            at,
            4,
            &mut Vec::new(),
            &mut (),
            |qs, _| {
                seen.extend_from_slice(qs);
                true
            },
        );
        assert!(all);
        seen.sort_by(f64::total_cmp);
        assert_eq!(seen.len(), 101);
        assert!(
            seen.iter()
                .enumerate()
                .all(|(i, v)| (v - i as f64 / 100.0).abs() < 1e-12)
        );
        let mut batches = 0;
        let blocked = !rake(
            1,
            &a,
            &b,
            steps + 1,
            at,
            4,
            &mut Vec::new(),
            &mut (),
            |qs, _| {
                batches += 1;
                qs.iter().all(|q| !(0.5..0.8).contains(q))
            },
        );
        assert!(blocked);
        assert_eq!(batches, 1);
    }

    /// The two step rules: Euclidean length and largest coordinate change.
    #[test]
    fn step_rules_measure_what_they_say() {
        let (a, b) = ([0.0, 0.0], [3.0, 4.0]);
        assert_eq!(distance(&a, &b), 5.0);
        assert_eq!(edge_steps(&a, &b, 1.0), 5);
        assert_eq!(span_steps(&a, &b, 1.0), 4);
        assert_eq!(edge_steps(&a, &a, 1.0), 1);
        let mut q = [0.0; 2];
        edge_point(&a, &b, 2, 4, &mut q);
        assert_eq!(q, [1.5, 2.0]);
    }
}
