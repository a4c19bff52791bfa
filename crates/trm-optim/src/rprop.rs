//! iRprop− (Igel and Hüsken, "Improving the Rprop learning algorithm", 2000; Riedmiller and
//! Braun 1993): gradient descent with one step size per parameter, grown while the gradient's
//! sign holds and shrunk when it flips — only the sign of the gradient is used, which makes it
//! robust to badly scaled or numerically estimated gradients. The task-maps paper optimises its
//! attractor points with it.

use serde::{Deserialize, Serialize};

use crate::error::{Result, invalid};

/// iRprop− settings.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct RpropOptions {
    /// Initial step per parameter.
    pub initial_step: f64,
    /// Growth factor η⁺ (> 1).
    pub increase: f64,
    /// Shrink factor η⁻ (in (0, 1)).
    pub decrease: f64,
    /// Smallest step.
    pub min_step: f64,
    /// Largest step.
    pub max_step: f64,
}

impl Default for RpropOptions {
    fn default() -> Self {
        RpropOptions {
            initial_step: 0.1,
            increase: 1.2,
            decrease: 0.5,
            min_step: 1e-9,
            max_step: 50.0,
        }
    }
}

/// The iRprop− state: call [`Rprop::step`] with the gradient at [`Rprop::x`].
#[derive(Debug, Clone)]
pub struct Rprop {
    options: RpropOptions,
    x: Vec<f64>,
    steps: Vec<f64>,
    previous: Vec<f64>,
}

impl Rprop {
    /// Starts at `x0`.
    pub fn new(x0: &[f64], options: &RpropOptions) -> Result<Self> {
        let o = options;
        if !(o.increase > 1.0 && o.decrease > 0.0 && o.decrease < 1.0) {
            return Err(invalid(
                "rprop factors",
                "need increase > 1 and 0 < decrease < 1",
            ));
        }
        if !(o.min_step > 0.0 && o.min_step <= o.initial_step && o.initial_step <= o.max_step) {
            return Err(invalid(
                "rprop steps",
                "need 0 < min_step ≤ initial_step ≤ max_step",
            ));
        }
        if x0.iter().any(|v| !v.is_finite()) {
            return Err(invalid("rprop start", "not finite"));
        }
        Ok(Rprop {
            options: options.clone(),
            x: x0.to_vec(),
            steps: vec![options.initial_step; x0.len()],
            previous: vec![0.0; x0.len()],
        })
    }

    /// The current point.
    pub fn x(&self) -> &[f64] {
        &self.x
    }

    /// The current step sizes.
    pub fn steps(&self) -> &[f64] {
        &self.steps
    }

    /// One update with the gradient at [`Rprop::x`]; non-finite components are treated as 0.
    pub fn step(&mut self, gradient: &[f64]) -> &[f64] {
        let o = &self.options;
        for i in 0..self.x.len() {
            let mut g = gradient.get(i).copied().unwrap_or(0.0);
            if !g.is_finite() {
                g = 0.0;
            }
            let s = g * self.previous[i];
            if s > 0.0 {
                self.steps[i] = (self.steps[i] * o.increase).min(o.max_step);
            } else if s < 0.0 {
                self.steps[i] = (self.steps[i] * o.decrease).max(o.min_step);
                g = 0.0; // iRprop−: forget the gradient after a sign change
            }
            self.x[i] -= g.signum() * self.steps[i] * f64::from(u8::from(g != 0.0));
            self.previous[i] = g;
        }
        &self.x
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rprop_minimises_rosenbrock_from_its_gradient() {
        let f = |x: &[f64]| 100.0 * (x[1] - x[0] * x[0]).powi(2) + (1.0 - x[0]).powi(2);
        let grad = |x: &[f64]| {
            vec![
                -400.0 * x[0] * (x[1] - x[0] * x[0]) - 2.0 * (1.0 - x[0]),
                200.0 * (x[1] - x[0] * x[0]),
            ]
        };
        let mut r = Rprop::new(&[-1.2, 1.0], &RpropOptions::default()).unwrap();
        for _ in 0..20_000 {
            let g = grad(r.x());
            r.step(&g);
        }
        assert!(f(r.x()) < 1e-8, "{}", f(r.x()));
        assert!(
            Rprop::new(
                &[0.0],
                &RpropOptions {
                    increase: 0.9,
                    ..Default::default()
                }
            )
            .is_err()
        );
    }

    #[test]
    fn steps_grow_while_the_sign_holds_and_shrink_when_it_flips() {
        let mut r = Rprop::new(&[0.0], &RpropOptions::default()).unwrap();
        r.step(&[1.0]);
        r.step(&[1.0]);
        assert!((r.steps()[0] - 0.12).abs() < 1e-12);
        r.step(&[-1.0]);
        assert!((r.steps()[0] - 0.06).abs() < 1e-12);
        r.step(&[f64::NAN]);
        assert!(r.x()[0].is_finite());
    }
}
