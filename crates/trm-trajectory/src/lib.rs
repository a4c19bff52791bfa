//! Trajectory parametrisations for trajectory optimisation, after Modugno, Nava, Pucci, Nori,
//! Oriolo and Ivaldi, "Safe trajectory optimization for whole-body motion of humanoids"
//! (Section III-C):
//!
//! * [`RbfTrajectory`]: one trajectory component as a normalised radial-basis-function network
//!   y(t) = Σ w_k ψ_k(t) / Σ ψ_k(t), ψ_k(t) = exp(−½((t − μ_k)/σ_k)²) with fixed centres and
//!   widths (eq. 21), extended with one basis function per waypoint whose weights are solved so
//!   that the trajectory passes *exactly* through the waypoints whatever the free weights are
//!   (eq. 22–24) — the optimiser only sees the free weights;
//! * [`TimeLaw`]: a monotone map from time to phase, s(0) = 0, s(T) = 1, from an RBF network of
//!   log-speeds, so that an optimiser can also shape how fast the motion runs.
//!
//! and the timing of paths a robot can execute:
//!
//! * [`BlendedPath`]: waypoints joined by straight lines whose corners are cut by circular
//!   blends of bounded deviation;
//! * [`time_optimal`]: its time-optimal timing under joint velocity and acceleration limits
//!   ([`JointLimits`]) by reachability analysis (TOPP-RA), with constraints that hold over
//!   whole grid intervals, so the [`TimedPath`] sampled at any rate keeps the limits;
//! * [`jerk_limited`]: a motion that also keeps jerk limits, stopping at every waypoint with a
//!   double-S profile per segment ([`StopAndGo`]).
//!
//! ```
//! use trm_trajectory::RbfTrajectory;
//! // 5 free RBFs over [0, 4.5] s, passing through 0.1 at t = 0 and 0.5 at t = 4.5
//! let traj = RbfTrajectory::new(0.0, 4.5, 5, &[(0.0, 0.1), (4.5, 0.5)])?;
//! let y = traj.evaluate(&[0.3, -0.2, 0.8, 0.1, 0.4], 0.0)?;
//! assert!((y - 0.1).abs() < 1e-12);
//! # Ok::<(), trm_trajectory::TrajectoryError>(())
//! ```

use nalgebra::{DMatrix, DVector};
use thiserror::Error;

mod jerk;
mod path;
mod timing;

pub use jerk::{StopAndGo, jerk_limited};
pub use path::BlendedPath;
pub use timing::{JointLimits, Sample, TimedPath, TimingOptions, time_optimal};

/// Bad settings or inputs.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum TrajectoryError {
    /// An invalid setting.
    #[error("invalid {what}: {problem}")]
    Invalid {
        /// The setting.
        what: &'static str,
        /// What is wrong.
        problem: String,
    },
}

fn invalid(what: &'static str, problem: impl Into<String>) -> TrajectoryError {
    TrajectoryError::Invalid {
        what,
        problem: problem.into(),
    }
}

/// Gaussian basis functions with fixed centres and widths.
#[derive(Debug, Clone, PartialEq)]
pub struct Basis {
    /// Centres μ_k.
    pub centers: Vec<f64>,
    /// Widths σ_k.
    pub widths: Vec<f64>,
}

impl Basis {
    /// `n` centres evenly spread over [t0, t1] (inclusive), each with width = spacing.
    pub fn even(t0: f64, t1: f64, n: usize) -> Self {
        let spacing = if n > 1 {
            (t1 - t0) / (n - 1) as f64
        } else {
            (t1 - t0).max(1e-9)
        };
        Basis {
            centers: (0..n)
                .map(|k| {
                    if n > 1 {
                        t0 + spacing * k as f64
                    } else {
                        (t0 + t1) / 2.0
                    }
                })
                .collect(),
            widths: vec![spacing.max(1e-9); n],
        }
    }

    /// ψ_k(t).
    #[inline]
    pub fn value(&self, k: usize, t: f64) -> f64 {
        let z = (t - self.centers[k]) / self.widths[k];
        (-0.5 * z * z).exp()
    }

    /// Number of functions.
    pub fn len(&self) -> usize {
        self.centers.len()
    }

    /// True without functions.
    pub fn is_empty(&self) -> bool {
        self.centers.is_empty()
    }
}

/// A trajectory component through fixed waypoints (eq. 22): free RBFs plus one RBF per
/// waypoint, normalised by the sum of all of them.
#[derive(Debug, Clone, PartialEq)]
pub struct RbfTrajectory {
    free: Basis,
    waypoint_basis: Basis,
    waypoints: Vec<(f64, f64)>,
    /// LU-free: the waypoint system A (n_wp × n_wp), A[j][l] = ψ^c_l(μ^c_j), kept inverted.
    a_inverse: DMatrix<f64>,
}

impl RbfTrajectory {
    /// `free` evenly spread RBFs over [t0, t1] and the waypoints `(time, value)`; waypoint RBFs
    /// sit at the waypoint times with the free RBFs' width.
    pub fn new(
        t0: f64,
        t1: f64,
        free: usize,
        waypoints: &[(f64, f64)],
    ) -> Result<Self, TrajectoryError> {
        if !(t0.is_finite() && t1.is_finite() && t1 > t0) {
            return Err(invalid(
                "time span",
                format!("[{t0}, {t1}] is empty or not finite"),
            ));
        }
        if free == 0 {
            return Err(invalid("free RBFs", "need at least one"));
        }
        let basis = Basis::even(t0, t1, free);
        let width = basis.widths[0];
        Self::with_basis(basis, waypoints, width)
    }

    /// Custom free basis; waypoint RBFs get `waypoint_width`.
    pub fn with_basis(
        free: Basis,
        waypoints: &[(f64, f64)],
        waypoint_width: f64,
    ) -> Result<Self, TrajectoryError> {
        if free
            .widths
            .iter()
            .chain(std::iter::once(&waypoint_width))
            .any(|w| !(w.is_finite() && *w > 0.0))
        {
            return Err(invalid("widths", "must be positive and finite"));
        }
        if waypoints
            .iter()
            .any(|(t, v)| !t.is_finite() || !v.is_finite())
        {
            return Err(invalid("waypoints", "must be finite"));
        }
        for (i, a) in waypoints.iter().enumerate() {
            if waypoints[..i].iter().any(|b| b.0 == a.0) {
                return Err(invalid(
                    "waypoints",
                    format!("two waypoints at t = {}", a.0),
                ));
            }
        }
        let n = waypoints.len();
        let waypoint_basis = Basis {
            centers: waypoints.iter().map(|w| w.0).collect(),
            widths: vec![waypoint_width; n],
        };
        let a = DMatrix::from_fn(n, n, |j, l| waypoint_basis.value(l, waypoints[j].0));
        let a_inverse = a.try_inverse().ok_or_else(|| {
            invalid(
                "waypoints",
                "the waypoint system is singular (waypoints too close for the width)",
            )
        })?;
        Ok(RbfTrajectory {
            free,
            waypoint_basis,
            waypoints: waypoints.to_vec(),
            a_inverse,
        })
    }

    /// Number of free weights (the optimisation parameters).
    pub fn num_weights(&self) -> usize {
        self.free.len()
    }

    /// The waypoint weights π^c that make the trajectory pass through every waypoint for the
    /// free weights π^f (eq. 23–24: A π^c = b, b_j = f_j S(μ^c_j) − Σ_k π^f_k ψ_k(μ^c_j), where
    /// S is the sum of all basis functions — the condition y(μ^c_j) = f_j solved for π^c; the
    /// paper's printed b garbles this expression).
    pub fn waypoint_weights(&self, free: &[f64]) -> Result<Vec<f64>, TrajectoryError> {
        if free.len() != self.free.len() {
            return Err(invalid(
                "free weights",
                format!("{} values for {} RBFs", free.len(), self.free.len()),
            ));
        }
        let b = DVector::from_iterator(
            self.waypoints.len(),
            self.waypoints.iter().map(|&(t, f)| {
                let free_part: f64 = (0..self.free.len())
                    .map(|k| free[k] * self.free.value(k, t))
                    .sum();
                f * self.sum(t) - free_part
            }),
        );
        Ok((&self.a_inverse * b).iter().copied().collect())
    }

    fn sum(&self, t: f64) -> f64 {
        (0..self.free.len())
            .map(|k| self.free.value(k, t))
            .sum::<f64>()
            + (0..self.waypoint_basis.len())
                .map(|k| self.waypoint_basis.value(k, t))
                .sum::<f64>()
    }

    /// y(t) for the free weights.
    pub fn evaluate(&self, free: &[f64], t: f64) -> Result<f64, TrajectoryError> {
        let c = self.waypoint_weights(free)?;
        Ok(self.evaluate_with(free, &c, t))
    }

    /// y(t) given both weight sets (avoids re-solving when sampling many times).
    pub fn evaluate_with(&self, free: &[f64], waypoint_weights: &[f64], t: f64) -> f64 {
        let numerator: f64 = (0..self.free.len())
            .map(|k| free[k] * self.free.value(k, t))
            .sum::<f64>()
            + (0..self.waypoint_basis.len())
                .map(|k| waypoint_weights[k] * self.waypoint_basis.value(k, t))
                .sum::<f64>();
        numerator / self.sum(t)
    }

    /// The trajectory sampled at `times`.
    pub fn sample(&self, free: &[f64], times: &[f64]) -> Result<Vec<f64>, TrajectoryError> {
        let c = self.waypoint_weights(free)?;
        Ok(times
            .iter()
            .map(|&t| self.evaluate_with(free, &c, t))
            .collect())
    }
}

/// A monotone time law s(t) on [0, T]: s(0) = 0, s(T) = 1, ds/dt ∝ exp(RBF network of
/// log-speeds), integrated on a fine grid. Zero weights give s(t) = t/T.
#[derive(Debug, Clone, PartialEq)]
pub struct TimeLaw {
    basis: Basis,
    duration: f64,
    grid: usize,
}

impl TimeLaw {
    /// `n` RBFs over [0, `duration`], integrated on `grid` intervals.
    pub fn new(duration: f64, n: usize, grid: usize) -> Result<Self, TrajectoryError> {
        if !(duration.is_finite() && duration > 0.0) || n == 0 || grid < 2 {
            return Err(invalid(
                "time law",
                "needs a positive duration, ≥ 1 RBF and ≥ 2 grid intervals",
            ));
        }
        Ok(TimeLaw {
            basis: Basis::even(0.0, duration, n),
            duration,
            grid,
        })
    }

    /// The phase at each of `times` for the log-speed weights.
    pub fn phases(&self, weights: &[f64], times: &[f64]) -> Result<Vec<f64>, TrajectoryError> {
        if weights.len() != self.basis.len() {
            return Err(invalid(
                "time-law weights",
                format!("{} values for {} RBFs", weights.len(), self.basis.len()),
            ));
        }
        let speed = |t: f64| {
            let s: f64 = (0..self.basis.len()).map(|k| self.basis.value(k, t)).sum();
            let w: f64 = (0..self.basis.len())
                .map(|k| weights[k] * self.basis.value(k, t))
                .sum();
            (w / s).exp()
        };
        // cumulative trapezoid on the grid, normalised to end at 1
        let h = self.duration / self.grid as f64;
        let mut cumulative = vec![0.0; self.grid + 1];
        for i in 1..=self.grid {
            cumulative[i] =
                cumulative[i - 1] + 0.5 * h * (speed(h * (i - 1) as f64) + speed(h * i as f64));
        }
        let total = cumulative[self.grid];
        Ok(times
            .iter()
            .map(|&t| {
                let u = (t.clamp(0.0, self.duration) / h).min(self.grid as f64);
                let i = (u.floor() as usize).min(self.grid - 1);
                let f = u - i as f64;
                (cumulative[i] + f * (cumulative[i + 1] - cumulative[i])) / total
            })
            .collect())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        #[test]
        fn waypoints_are_hit_exactly_for_any_free_weights(
            free in proptest::collection::vec(-2.0f64..2.0, 5),
            a in -1.0f64..1.0, b in -1.0f64..1.0, c in -1.0f64..1.0,
        ) {
            let traj = RbfTrajectory::new(0.0, 4.5, 5, &[(0.0, a), (1.5, b), (4.5, c)]).unwrap();
            for (t, v) in [(0.0, a), (1.5, b), (4.5, c)] {
                prop_assert!((traj.evaluate(&free, t).unwrap() - v).abs() < 1e-9);
            }
        }

        #[test]
        fn time_laws_are_monotone_from_zero_to_one(w in proptest::collection::vec(-2.0f64..2.0, 4)) {
            let law = TimeLaw::new(3.0, 4, 300).unwrap();
            let times: Vec<f64> = (0..=60).map(|i| i as f64 * 0.05).collect();
            let s = law.phases(&w, &times).unwrap();
            prop_assert!(s[0].abs() < 1e-12 && (s[60] - 1.0).abs() < 1e-12);
            prop_assert!(s.windows(2).all(|p| p[1] >= p[0]));
        }
    }

    #[test]
    fn constant_weights_give_a_constant_and_zero_log_speeds_a_linear_law() {
        let traj = RbfTrajectory::new(0.0, 1.0, 4, &[]).unwrap();
        for t in [0.0, 0.3, 0.77, 1.0] {
            assert!((traj.evaluate(&[0.7; 4], t).unwrap() - 0.7).abs() < 1e-12);
        }
        let law = TimeLaw::new(2.0, 3, 200).unwrap();
        let s = law.phases(&[0.0; 3], &[0.0, 0.5, 1.0, 2.0]).unwrap();
        assert!(
            (s[1] - 0.25).abs() < 1e-9 && (s[2] - 0.5).abs() < 1e-9 && (s[3] - 1.0).abs() < 1e-12
        );
    }

    #[test]
    fn bad_settings_are_errors() {
        assert!(RbfTrajectory::new(1.0, 1.0, 3, &[]).is_err());
        assert!(RbfTrajectory::new(0.0, 1.0, 0, &[]).is_err());
        assert!(RbfTrajectory::new(0.0, 1.0, 3, &[(0.5, 1.0), (0.5, 2.0)]).is_err());
        let traj = RbfTrajectory::new(0.0, 1.0, 3, &[(0.0, 1.0)]).unwrap();
        assert!(traj.evaluate(&[0.0; 2], 0.5).is_err());
        assert!(TimeLaw::new(0.0, 3, 10).is_err());
    }
}
