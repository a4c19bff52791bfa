//! The Nelder–Mead simplex method (Nelder and Mead, "A simplex method for function
//! minimization", Computer Journal 1965), as an ask/tell state machine: reflection, expansion,
//! outside/inside contraction and shrink, with the standard coefficients (1, 2, ½, ½) or the
//! dimension-adaptive ones of Gao and Han (2012).

use rand::Rng;
use serde::{Deserialize, Serialize};

use crate::core::{Optimizer, Population, Start, State};
use crate::error::Result;

/// Nelder–Mead settings.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SimplexOptions {
    /// Use Gao and Han's coefficients (better in high dimension) instead of (1, 2, ½, ½).
    pub adaptive: bool,
}

#[derive(Debug, Clone, Copy, PartialEq)]
enum Phase {
    Init,
    Reflect,
    Expand,
    ContractOutside,
    ContractInside,
    Shrink,
}

/// The Nelder–Mead optimiser. The first simplex is the start mean and the mean plus the step
/// along each axis. Deterministic: `ask` ignores the generator.
#[derive(Debug, Clone)]
pub struct NelderMead {
    state: State,
    alpha: f64,
    gamma: f64,
    rho: f64,
    shrink: f64,
    vertices: Vec<Vec<f64>>,
    values: Vec<f64>,
    order: Vec<usize>,
    centroid: Vec<f64>,
    reflected: Vec<f64>,
    reflected_f: f64,
    batch: Population,
    phase: Phase,
}

impl NelderMead {
    /// A new simplex at the start.
    pub fn new(start: &Start, options: &SimplexOptions) -> Result<Self> {
        let steps = start.check()?;
        let d = steps.len();
        let n = d as f64;
        let (alpha, gamma, rho, shrink) = if options.adaptive {
            (1.0, 1.0 + 2.0 / n, 0.75 - 1.0 / (2.0 * n), 1.0 - 1.0 / n)
        } else {
            (1.0, 2.0, 0.5, 0.5)
        };
        let mut vertices = vec![start.mean.clone(); d + 1];
        for (i, v) in vertices.iter_mut().skip(1).enumerate() {
            v[i] += steps[i];
        }
        let mut s = NelderMead {
            state: State::new(start, 1),
            alpha,
            gamma,
            rho,
            shrink,
            values: vec![f64::INFINITY; d + 1],
            order: (0..=d).collect(),
            centroid: vec![0.0; d],
            reflected: vec![0.0; d],
            reflected_f: f64::INFINITY,
            batch: Population::default(),
            vertices,
            phase: Phase::Init,
        };
        s.batch.fill_from(&s.vertices);
        for v in &mut s.batch.iter_mut() {
            s.state.clamp(v);
        }
        Ok(s)
    }

    fn sort(&mut self) {
        let values = &self.values;
        let key = |i: usize| {
            if values[i].is_nan() {
                f64::INFINITY
            } else {
                values[i]
            }
        };
        self.order
            .sort_unstable_by(|&a, &b| key(a).total_cmp(&key(b)).then(a.cmp(&b)));
    }

    fn worst(&self) -> usize {
        self.order[self.order.len() - 1]
    }

    /// Sets batch[0] = centroid + t (from − centroid).
    fn point(&mut self, from: usize, t: f64) {
        let from = if from == usize::MAX {
            &self.reflected
        } else {
            &self.vertices[from]
        };
        self.batch.resize(self.centroid.len(), 1);
        for i in 0..self.centroid.len() {
            self.batch[0][i] = self.centroid[i] + t * (from[i] - self.centroid[i]);
        }
        self.state.clamp(&mut self.batch[0]);
    }

    /// Every coordinate's distance from the best vertex, vertex by vertex.
    fn deviations(&self) -> impl Iterator<Item = f64> + '_ {
        let best = &self.vertices[self.order[0]];
        self.vertices
            .iter()
            .flat_map(move |v| v.iter().zip(best).map(|(a, b)| (a - b).abs()))
    }

    fn start_reflection(&mut self) {
        self.sort();
        let d = self.centroid.len();
        self.centroid.fill(0.0);
        for &k in &self.order[..d] {
            add_divided(&mut self.centroid, &self.vertices[k], d as f64);
        }
        self.point(self.worst(), -self.alpha);
        self.phase = Phase::Reflect;
    }

    fn replace_worst(&mut self, from_batch: bool, f: f64) {
        let w = self.worst();
        if from_batch {
            self.vertices[w].copy_from_slice(&self.batch[0]);
        } else {
            self.vertices[w].copy_from_slice(&self.reflected);
        }
        self.values[w] = f;
        self.start_reflection();
    }

    fn start_shrink(&mut self) {
        let best = self.order[0];
        self.batch
            .resize(self.centroid.len(), self.vertices.len() - 1);
        let mut j = 0;
        for k in 0..self.vertices.len() {
            if k == best {
                continue;
            }
            for i in 0..self.centroid.len() {
                let b = self.vertices[best][i];
                self.batch[j][i] = b + self.shrink * (self.vertices[k][i] - b);
            }
            self.state.clamp(&mut self.batch[j]);
            j += 1;
        }
        self.phase = Phase::Shrink;
    }
}

impl Optimizer for NelderMead {
    fn name(&self) -> &'static str {
        "simplex"
    }

    fn dim(&self) -> usize {
        self.centroid.len()
    }

    fn ask(&mut self, _rng: &mut dyn Rng) -> &Population {
        self.state.asked(self.batch.len());
        &self.batch
    }

    fn tell(&mut self, fitness: &[f64]) -> Result<()> {
        self.state.told(&self.batch, fitness)?;
        let f = |v: f64| if v.is_nan() { f64::INFINITY } else { v };
        match self.phase {
            Phase::Init => {
                for (k, v) in fitness.iter().enumerate() {
                    self.vertices[k].copy_from_slice(&self.batch[k]);
                    self.values[k] = f(*v);
                }
                self.start_reflection();
            }
            Phase::Reflect => {
                let fr = f(fitness[0]);
                let best = self.values[self.order[0]];
                let second_worst = self.values[self.order[self.order.len() - 2]];
                let worst = self.values[self.worst()];
                self.reflected.copy_from_slice(&self.batch[0]);
                self.reflected_f = fr;
                if fr < best {
                    self.point(usize::MAX, self.gamma);
                    self.phase = Phase::Expand;
                } else if fr < second_worst {
                    self.replace_worst(false, fr);
                } else if fr < worst {
                    self.point(usize::MAX, self.rho);
                    self.phase = Phase::ContractOutside;
                } else {
                    self.point(self.worst(), self.rho);
                    self.phase = Phase::ContractInside;
                }
            }
            Phase::Expand => {
                let fe = f(fitness[0]);
                if fe < self.reflected_f {
                    self.replace_worst(true, fe);
                } else {
                    self.replace_worst(false, self.reflected_f);
                }
            }
            Phase::ContractOutside => {
                let fc = f(fitness[0]);
                if fc <= self.reflected_f {
                    self.replace_worst(true, fc);
                } else {
                    self.start_shrink();
                }
            }
            Phase::ContractInside => {
                let fc = f(fitness[0]);
                if fc < self.values[self.worst()] {
                    self.replace_worst(true, fc);
                } else {
                    self.start_shrink();
                }
            }
            Phase::Shrink => {
                let best = self.order[0];
                let mut j = 0;
                for k in 0..self.vertices.len() {
                    if k == best {
                        continue;
                    }
                    self.vertices[k].copy_from_slice(&self.batch[j]);
                    self.values[k] = f(fitness[j]);
                    j += 1;
                }
                self.start_reflection();
            }
        }
        Ok(())
    }

    fn mean(&self) -> &[f64] {
        &self.vertices[self.order[0]]
    }

    fn spread(&self) -> f64 {
        self.deviations().fold(0.0, f64::max)
    }

    fn spread_below(&self, t: f64) -> bool {
        let mut spread = 0.0f64;
        for d in self.deviations() {
            if d >= t {
                return false;
            }
            spread = spread.max(d);
        }
        spread < t
    }

    fn state(&self) -> &State {
        &self.state
    }

    fn state_mut(&mut self) -> &mut State {
        &mut self.state
    }
}

/// `c += v / n`, element by element (the centroid's sum, in the order and with the roundings of
/// the plain loop), compiled for several instruction sets with the best chosen at run time: the
/// d² divisions of a simplex step go 4 at a time with AVX.
#[allow(unsafe_code)] // multiversion's run-time CPU-feature dispatch
#[multiversion::multiversion(targets("x86_64+avx2+fma", "x86_64+avx", "aarch64+neon"))]
fn add_divided(c: &mut [f64], v: &[f64], n: f64) {
    for (c, v) in c.iter_mut().zip(v) {
        *c += v / n;
    }
}
