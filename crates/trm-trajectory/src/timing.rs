//! Time-optimal timing of a [`BlendedPath`] under joint velocity and acceleration limits, by
//! reachability analysis (TOPP-RA: Pham and Pham, "A new approach to time-optimal path
//! parameterization based on reachability analysis", T-RO 2018).
//!
//! The path is cut into intervals of arc length (every piece boundary and stop is a grid
//! point). On each interval the path acceleration `u = s̈` is constant, so `x = ṡ²` is linear
//! in `s`. TOPP-RA's backward pass finds, at every grid point, the interval of `x` from which
//! the motion can still come to rest at the next stop; the forward pass then takes the largest
//! `u` that keeps `x` in those sets. Each constraint is a 2-variable linear programme, solved
//! exactly by eliminating `u` (Fourier–Motzkin).
//!
//! Unlike collocation at grid points, the constraints hold over **whole intervals**: each
//! joint's `q'(s)` and `q''(s)` are bounded over the interval and every combination of those
//! bounds with the interval's two end speeds is constrained (the joint acceleration
//! `q' u + q'' ṡ²` is bilinear in them, so its extremes sit at those corners). On straight
//! pieces this is exact; on arcs it is conservative by the variation of `q'` across an
//! interval. A trajectory sampled at any rate therefore keeps every limit (to rounding).
//!
//! ```
//! use trm_trajectory::{BlendedPath, JointLimits, TimingOptions, time_optimal};
//! let path = BlendedPath::new(&[vec![0.0, 0.0], vec![1.0, 0.0], vec![1.0, 1.0]], 0.1)?;
//! let limits = JointLimits::new(vec![1.0, 1.0], vec![2.0, 2.0])?;
//! let timed = time_optimal(&path, &limits, &TimingOptions::default())?;
//! let end = timed.sample(timed.duration());
//! assert!((end.position[1] - 1.0).abs() < 1e-9 && end.velocity.iter().all(|v| v.abs() < 1e-9));
//! # Ok::<(), trm_trajectory::TrajectoryError>(())
//! ```

use crate::{BlendedPath, TrajectoryError, invalid};

/// Per-joint velocity and acceleration limits (positive, finite).
#[derive(Debug, Clone, PartialEq)]
pub struct JointLimits {
    /// Largest speed of each joint (rad/s or m/s).
    pub velocity: Vec<f64>,
    /// Largest acceleration of each joint (rad/s² or m/s²).
    pub acceleration: Vec<f64>,
}

impl JointLimits {
    /// Checked limits: as many accelerations as velocities, every one finite and positive.
    pub fn new(velocity: Vec<f64>, acceleration: Vec<f64>) -> Result<Self, TrajectoryError> {
        let limits = JointLimits {
            velocity,
            acceleration,
        };
        limits.check()?;
        Ok(limits)
    }

    /// Checks the limits (see [`JointLimits::new`]).
    pub fn check(&self) -> Result<(), TrajectoryError> {
        if self.velocity.len() != self.acceleration.len() {
            return Err(invalid(
                "limits",
                format!(
                    "{} velocities for {} accelerations: give one of each per joint",
                    self.velocity.len(),
                    self.acceleration.len()
                ),
            ));
        }
        for (what, values) in [
            ("velocity limit", &self.velocity),
            ("acceleration limit", &self.acceleration),
        ] {
            if let Some(j) = values.iter().position(|v| !(v.is_finite() && *v > 0.0)) {
                return Err(invalid(
                    what,
                    format!("{} for joint {j}: give a finite positive limit", values[j]),
                ));
            }
        }
        Ok(())
    }

    /// The limits scaled as MoveIt's requests scale them (`max_velocity_scaling_factor`,
    /// `max_acceleration_scaling_factor`, each in (0, 1]).
    pub fn scaled(&self, velocity: f64, acceleration: f64) -> Result<Self, TrajectoryError> {
        for (what, f) in [
            ("velocity scaling", velocity),
            ("acceleration scaling", acceleration),
        ] {
            if !(f > 0.0 && f <= 1.0) {
                return Err(invalid(what, format!("{f}: give a factor in (0, 1]")));
            }
        }
        JointLimits::new(
            self.velocity.iter().map(|v| v * velocity).collect(),
            self.acceleration.iter().map(|a| a * acceleration).collect(),
        )
    }
}

/// Largest turn of the path's tangent (rad) within one grid interval on an arc: the
/// interval bounds of the derivatives, and so the timing's conservatism, shrink with it.
const MAX_TURN: f64 = 0.03;

/// Settings of [`time_optimal`].
#[derive(Debug, Clone, PartialEq)]
pub struct TimingOptions {
    /// Grid intervals over the whole path (more: closer to the continuous optimum, slower);
    /// every piece gets at least [`TimingOptions::min_per_piece`].
    pub intervals: usize,
    /// Least number of intervals per piece of the path.
    pub min_per_piece: usize,
}

impl Default for TimingOptions {
    fn default() -> Self {
        TimingOptions {
            intervals: 200,
            min_per_piece: 4,
        }
    }
}

/// A path timed by [`time_optimal`]: grid of arc lengths with `ṡ²` and the constant `s̈` of
/// each interval.
#[derive(Debug, Clone, PartialEq)]
pub struct TimedPath {
    path: BlendedPath,
    /// Grid arc lengths.
    s: Vec<f64>,
    /// `ṡ²` at each grid point.
    x: Vec<f64>,
    /// `s̈` on each interval.
    u: Vec<f64>,
    /// Time at each grid point.
    t: Vec<f64>,
}

/// One instant of a timed path: joint positions, velocities and accelerations.
#[derive(Debug, Clone, PartialEq)]
pub struct Sample {
    /// Time (s).
    pub time: f64,
    /// Joint positions.
    pub position: Vec<f64>,
    /// Joint velocities.
    pub velocity: Vec<f64>,
    /// Joint accelerations.
    pub acceleration: Vec<f64>,
}

impl TimedPath {
    /// Total time (s).
    pub fn duration(&self) -> f64 {
        self.t.last().copied().unwrap_or(0.0)
    }

    /// The path it times.
    pub fn path(&self) -> &BlendedPath {
        &self.path
    }

    /// Arc length and path speed `ṡ` at time `t` (clamped to `[0, duration]`), with the
    /// interval's path acceleration.
    pub fn progress(&self, t: f64) -> (f64, f64, f64) {
        if self.u.is_empty() {
            return (0.0, 0.0, 0.0);
        }
        let t = t.clamp(0.0, self.duration());
        let i = (self.t.partition_point(|&a| a <= t).max(1) - 1).min(self.u.len() - 1);
        let tau = t - self.t[i];
        let (v0, u) = (self.x[i].sqrt(), self.u[i]);
        let speed = (v0 + u * tau).max(0.0);
        let s = (self.s[i] + v0 * tau + 0.5 * u * tau * tau).clamp(self.s[i], self.s[i + 1]);
        (s, speed, u)
    }

    /// Positions, velocities and accelerations at time `t` (clamped to `[0, duration]`).
    pub fn sample(&self, t: f64) -> Sample {
        let n = self.path.dim();
        let (s, speed, u) = self.progress(t);
        let mut out = Sample {
            time: t.clamp(0.0, self.duration()),
            position: vec![0.0; n],
            velocity: vec![0.0; n],
            acceleration: vec![0.0; n],
        };
        let mut ddq = vec![0.0; n];
        self.path
            .evaluate(s, &mut out.position, &mut out.velocity, &mut ddq);
        for ((v, a), dd) in out.velocity.iter_mut().zip(&mut out.acceleration).zip(&ddq) {
            let dq = *v;
            *v = dq * speed;
            *a = dq * u + dd * speed * speed;
        }
        out
    }

    /// Samples every `period` seconds from 0, and the end (so the last sample is at rest at
    /// the goal). `period` must be finite and positive.
    pub fn sampled(&self, period: f64) -> Result<Vec<Sample>, TrajectoryError> {
        sample_every(self.duration(), period, |t| self.sample(t))
    }
}

/// `sample` every `period` seconds from 0 over `duration`, and at the end, where the motion is
/// at rest (velocity exactly 0: the last interval's speed rounds to a few 1e-17).
pub(crate) fn sample_every(
    duration: f64,
    period: f64,
    sample: impl Fn(f64) -> Sample,
) -> Result<Vec<Sample>, TrajectoryError> {
    if !(period.is_finite() && period > 0.0) {
        return Err(invalid(
            "sample period",
            format!("{period} s: give a finite positive period"),
        ));
    }
    let count = (duration / period).floor() as usize;
    let mut out: Vec<Sample> = (0..=count).map(|k| sample(k as f64 * period)).collect();
    if out.last().is_none_or(|l| l.time < duration - 1e-12) {
        out.push(sample(duration));
    }
    if let Some(last) = out.last_mut() {
        last.velocity.iter_mut().for_each(|v| *v = 0.0);
    }
    Ok(out)
}

/// One linear constraint `a·u + b·x ≤ c` on an interval's path acceleration `u` and start
/// `x = ṡ²`, scaled so that `a` is -1, 0 or 1 (the bound on `u` is then `a (c − b x)`, no
/// division in the passes).
#[derive(Debug, Clone, Copy)]
struct Row {
    a: f64,
    b: f64,
    c: f64,
}

impl Row {
    fn new(a: f64, b: f64, c: f64) -> Row {
        if a == 0.0 {
            Row { a, b, c }
        } else {
            let scale = 1.0 / a.abs();
            Row {
                a: a.signum(),
                b: b * scale,
                c: c * scale,
            }
        }
    }
}

/// The time-optimal timing of `path` under `limits`, starting and ending at rest and
/// stopping at every corner the path keeps as a point. Errors: limits that do not fit the
/// path's joints or are invalid.
pub fn time_optimal(
    path: &BlendedPath,
    limits: &JointLimits,
    options: &TimingOptions,
) -> Result<TimedPath, TrajectoryError> {
    limits.check()?;
    if limits.velocity.len() != path.dim() {
        return Err(invalid(
            "limits",
            format!(
                "{} joints limited, the path moves {}: give one limit per joint",
                limits.velocity.len(),
                path.dim()
            ),
        ));
    }
    let s = grid(path, options);
    let n = s.len() - 1;
    let stops = path.stops();
    let at_stop = |v: f64| {
        stops
            .iter()
            .any(|&p| (p - v).abs() <= 1e-12 * path.length().max(1.0))
    };
    // constraints of each interval, independent of the controllable sets: interval i's rows
    // are rows[starts[i]..starts[i + 1]]
    let mut rows: Vec<Row> = Vec::new();
    let mut starts = Vec::with_capacity(n + 1);
    let mut bounds = Vec::new();
    for i in 0..n {
        starts.push(rows.len());
        path.derivative_bounds(s[i], s[i + 1], &mut bounds);
        interval_rows(&bounds, limits, s[i + 1] - s[i], &mut rows);
    }
    starts.push(rows.len());
    let rows_of = |i: usize| &rows[starts[i]..starts[i + 1]];
    // backward pass: controllable sets [0, hi] of x at every grid point (rest is always
    // controllable: x = 0, u = 0 meets every row and reaches rest at the next point)
    let mut sets = vec![(0.0, 0.0); n + 1];
    for i in (0..n).rev() {
        let reach = Row::new(2.0 * (s[i + 1] - s[i]), 1.0, sets[i + 1].1);
        sets[i] = if at_stop(s[i]) {
            (0.0, 0.0)
        } else {
            (0.0, largest_x(rows_of(i), reach))
        };
    }
    // forward pass: greatest path acceleration that stays controllable
    let mut x = vec![0.0; n + 1];
    let mut u = vec![0.0; n];
    for i in 0..n {
        let delta = s[i + 1] - s[i];
        let (lo, hi) = sets[i + 1];
        let mut top = (hi - x[i]) / (2.0 * delta);
        let mut bottom = (lo - x[i]) / (2.0 * delta);
        for r in rows_of(i) {
            let limit = r.a * (r.c - r.b * x[i]);
            if r.a > 0.0 {
                top = top.min(limit);
            } else if r.a < 0.0 {
                bottom = bottom.max(limit);
            }
        }
        u[i] = top.max(bottom);
        x[i + 1] = (x[i] + 2.0 * delta * u[i]).clamp(lo, hi);
        // the clamp only absorbs rounding: keep u consistent with the x reached
        u[i] = (x[i + 1] - x[i]) / (2.0 * delta);
    }
    let mut t = Vec::with_capacity(n + 1);
    t.push(0.0);
    for i in 0..n {
        let speeds = x[i].sqrt() + x[i + 1].sqrt();
        let dt = 2.0 * (s[i + 1] - s[i]) / speeds;
        if !(dt.is_finite() && dt >= 0.0) {
            return Err(invalid(
                "path",
                format!(
                    "no motion fits the limits at arc length {:.6}: report this with the \
                     waypoints and limits",
                    s[i]
                ),
            ));
        }
        t.push(t[i] + dt);
    }
    Ok(TimedPath {
        path: path.clone(),
        s,
        x,
        u,
        t,
    })
}

/// Grid of arc lengths: every piece boundary and stop, each piece cut into intervals of about
/// `length / options.intervals` (at least `options.min_per_piece`).
fn grid(path: &BlendedPath, options: &TimingOptions) -> Vec<f64> {
    let breaks = path.breaks();
    let step = path.length() / options.intervals.max(1) as f64;
    let mut s = vec![0.0];
    for w in breaks.windows(2) {
        let len = w[1] - w[0];
        // arcs: at most MAX_TURN of tangent turn per interval (the bounds stay tight)
        let by_turn = (path.turn(w[0], w[1]) / MAX_TURN).ceil() as usize;
        let count = ((len / step).ceil() as usize)
            .max(options.min_per_piece.max(1))
            .max(by_turn);
        for k in 1..=count {
            s.push(if k == count {
                w[1]
            } else {
                w[0] + len * k as f64 / count as f64
            });
        }
    }
    s.dedup();
    s
}

/// The constraints of one interval of length `delta`, with `bounds` of each joint's
/// `(q'min, q'max, q''min, q''max)` over it, appended to `rows`: speed within limits at both ends
/// (`x_end = x + 2 δ u`), and for the worst corners of the derivative bounds, acceleration
/// `q' u + q'' ṡ²` within limits at both ends.
fn interval_rows(bounds: &[[f64; 4]], limits: &JointLimits, delta: f64, rows: &mut Vec<Row>) {
    let mut speed_cap = f64::INFINITY;
    let mut line_cap = f64::INFINITY;
    for (j, b) in bounds.iter().enumerate() {
        let p = b[0].abs().max(b[1].abs());
        if p > 0.0 {
            speed_cap = speed_cap.min((limits.velocity[j] / p).powi(2));
        }
        let a = limits.acceleration[j];
        if b[2] == 0.0 && b[3] == 0.0 {
            // a straight piece: |q'| u ≤ a, one bound on u
            if p > 0.0 {
                line_cap = line_cap.min(a / p);
            }
            continue;
        }
        // p u + c x' ≤ a with x' = ṡ² ≥ 0 is worst at c = q''max, and −a ≤ p u + c x' at
        // c = q''min; either sign of u makes either bound of p the worst: both kept
        for &p in &[b[0], b[1]] {
            for (sign, c) in [(1.0, b[3]), (-1.0, b[2])] {
                // at the start: p u + c x; at the end: (p + 2δc) u + c x
                for pu in [p, p + 2.0 * delta * c] {
                    if pu == 0.0 && c == 0.0 {
                        continue;
                    }
                    rows.push(Row::new(sign * pu, sign * c, a));
                }
            }
        }
    }
    if line_cap.is_finite() {
        rows.push(Row::new(1.0, 0.0, line_cap));
        rows.push(Row::new(-1.0, 0.0, line_cap));
    }
    if speed_cap.is_finite() {
        rows.push(Row::new(0.0, 1.0, speed_cap));
        rows.push(Row::new(2.0 * delta, 1.0, speed_cap));
    }
    rows.push(Row::new(0.0, -1.0, 0.0));
    rows.push(Row::new(-2.0 * delta, -1.0, 0.0));
}

/// The largest `x ≥ 0` for which some `u` meets every row (0 when only rest does). The rows
/// bounding `u` from above (`a > 0`) and below (`a < 0`) give a concave gap
/// `g(x) = min upper(x) − max lower(x)`; from the largest `x` the `u`-free rows allow, each step
/// moves to where the two active rows meet, which for a concave piecewise-linear `g` reaches
/// its largest root from the right in finitely many steps. Where rounding stalls the steps
/// short of a feasible `x` (rows of very different scales), bisection finishes below it.
fn largest_x(rows: &[Row], extra: Row) -> f64 {
    let x = newton_x(rows, extra);
    if x <= 0.0 || feasible(rows, extra, x) {
        return x;
    }
    let (mut lo, mut hi) = (0.0, x);
    for _ in 0..64 {
        let mid = 0.5 * (lo + hi);
        if feasible(rows, extra, mid) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    lo
}

/// Whether some `u` meets every row at `x` (to rounding).
fn feasible(rows: &[Row], extra: Row, x: f64) -> bool {
    let (mut lower, mut upper) = (f64::NEG_INFINITY, f64::INFINITY);
    for r in rows.iter().chain(std::iter::once(&extra)) {
        let bound = r.a * (r.c - r.b * x);
        if r.a > 0.0 {
            upper = upper.min(bound);
        } else if r.a < 0.0 {
            lower = lower.max(bound);
        } else if r.b * x > r.c + 1e-12 * (1.0 + r.c.abs()) {
            return false;
        }
    }
    lower <= upper + 1e-12 * (1.0 + upper.abs() + lower.abs())
}

/// [`largest_x`]'s steps from the top.
fn newton_x(rows: &[Row], extra: Row) -> f64 {
    let all = || rows.iter().chain(std::iter::once(&extra));
    let mut x = f64::INFINITY;
    for r in all().filter(|r| r.a == 0.0) {
        if r.b > 0.0 {
            x = x.min(r.c / r.b);
        } else if r.b == 0.0 && r.c < 0.0 {
            return 0.0;
        }
    }
    if !x.is_finite() {
        // no speed cap: the rows bounding u still bound x; start far out
        x = 1e12;
    }
    for _ in 0..rows.len() + 2 {
        if x <= 0.0 {
            return 0.0;
        }
        let (mut upper, mut lower) = ((f64::INFINITY, None), (f64::NEG_INFINITY, None));
        for r in all() {
            let bound = r.a * (r.c - r.b * x);
            if r.a > 0.0 && bound < upper.0 {
                upper = (bound, Some(r));
            } else if r.a < 0.0 && bound > lower.0 {
                lower = (bound, Some(r));
            }
        }
        let (Some(p), Some(q)) = (upper.1, lower.1) else {
            return x;
        };
        if upper.0 >= lower.0 - 1e-12 * (1.0 + upper.0.abs()) {
            return x;
        }
        // where the active pair meets: k x = m (the gap of this pair falls as x grows when k > 0)
        let k = p.b * p.a - q.b * q.a;
        let m = p.c * p.a - q.c * q.a;
        if k <= 0.0 {
            return 0.0;
        }
        let next = m / k;
        if next >= x {
            return x;
        }
        if x - next <= 1e-12 * x {
            // converged to rounding: the pair's root
            return next.max(0.0);
        }
        x = next;
    }
    x.max(0.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `largest_x` against a bisection on the feasibility of `u` (an independent check).
    #[test]
    fn the_largest_feasible_speed_matches_a_bisection() {
        let mut seed = 7u64;
        let mut next = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        for _ in 0..200 {
            let mut rows: Vec<Row> = (0..12)
                .map(|_| Row::new(next() * 4.0 - 2.0, next() * 4.0 - 2.0, next() * 3.0 + 0.1))
                .collect();
            rows.push(Row::new(0.0, 1.0, 5.0));
            rows.push(Row::new(0.0, -1.0, 0.0));
            let extra = Row::new(0.3, 1.0, 2.0);
            let feasible = |x: f64| {
                let (mut lo, mut hi) = (f64::NEG_INFINITY, f64::INFINITY);
                for r in rows.iter().chain([&extra]) {
                    let v = (r.c - r.b * x) / r.a;
                    if r.a > 0.0 {
                        hi = hi.min(v);
                    } else if r.a < 0.0 {
                        lo = lo.max(v);
                    } else if r.b * x > r.c + 1e-12 {
                        return false;
                    }
                }
                lo <= hi + 1e-12
            };
            // feasible x form an interval holding 0 (every c > 0): bisect its top
            let (mut a, mut b) = (0.0, 5.0);
            if feasible(b) {
                a = b;
            }
            for _ in 0..100 {
                let m = 0.5 * (a + b);
                if feasible(m) { a = m } else { b = m }
            }
            let got = largest_x(&rows, extra);
            assert!((got - a).abs() < 1e-9, "{got} vs {a}");
        }
    }
}
