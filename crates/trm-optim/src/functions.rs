//! Standard test functions (as in the CMA-ES and NES literature), optionally rotated by a
//! seeded random orthogonal matrix to test rotation invariance. Minimum 0.

use nalgebra::DMatrix;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};

use crate::error::{Result, invalid};

/// The function families.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// Σ xᵢ².
    Sphere,
    /// Σ 10^(6 i/(d−1)) xᵢ² (condition 10⁶).
    Ellipsoid,
    /// x₀² + 10⁶ Σ_{i>0} xᵢ².
    Cigar,
    /// 10⁶ x₀² + Σ_{i>0} xᵢ².
    Discus,
    /// Σ 100 (x_{i+1} − xᵢ²)² + (1 − xᵢ)², minimum at (1, …, 1).
    Rosenbrock,
    /// 10 d + Σ (xᵢ² − 10 cos 2π xᵢ), highly multimodal.
    Rastrigin,
}

const KINDS: [(&str, Kind); 6] = [
    ("sphere", Kind::Sphere),
    ("ellipsoid", Kind::Ellipsoid),
    ("cigar", Kind::Cigar),
    ("discus", Kind::Discus),
    ("rosenbrock", Kind::Rosenbrock),
    ("rastrigin", Kind::Rastrigin),
];

/// A test function of fixed dimension, possibly rotated: f(R x).
#[derive(Debug, Clone)]
pub struct TestFunction {
    kind: Kind,
    dim: usize,
    rotation: Option<DMatrix<f64>>,
    name: String,
}

/// Every accepted name: the plain families and `rotated-<family>`.
pub fn names() -> Vec<String> {
    KINDS
        .iter()
        .flat_map(|(n, _)| [n.to_string(), format!("rotated-{n}")])
        .collect()
}

impl TestFunction {
    /// An unrotated function.
    pub fn new(kind: Kind, dim: usize) -> Self {
        let name = KINDS
            .iter()
            .find(|(_, k)| *k == kind)
            .map_or("?", |(n, _)| n);
        TestFunction {
            kind,
            dim,
            rotation: None,
            name: name.to_string(),
        }
    }

    /// The function rotated by a random orthogonal matrix drawn from `seed`.
    pub fn rotated(kind: Kind, dim: usize, seed: u64) -> Self {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let g: DMatrix<f64> = DMatrix::from_fn(dim, dim, |_, _| StandardNormal.sample(&mut rng));
        let qr = g.qr();
        let (q, r) = (qr.q(), qr.r());
        // sign fix so the distribution is Haar
        let signs = DMatrix::from_diagonal(&r.diagonal().map(|v| v.signum()));
        let mut f = Self::new(kind, dim);
        f.rotation = Some(q * signs);
        f.name = format!("rotated-{}", f.name);
        f
    }

    /// Parses `sphere`, `rotated-ellipsoid`, …
    pub fn by_name(name: &str, dim: usize, seed: u64) -> Result<Self> {
        if dim == 0 || (dim < 2 && name.contains("rosenbrock")) {
            return Err(invalid("dim", format!("{dim} is too small for {name}")));
        }
        let (rotated, base) = match name.strip_prefix("rotated-") {
            Some(b) => (true, b),
            None => (false, name),
        };
        let kind = KINDS
            .iter()
            .find(|(n, _)| *n == base)
            .map(|(_, k)| *k)
            .ok_or_else(|| {
                invalid(
                    "function",
                    format!("`{name}`; known: {}", names().join(", ")),
                )
            })?;
        Ok(if rotated {
            Self::rotated(kind, dim, seed)
        } else {
            Self::new(kind, dim)
        })
    }

    /// The name it was built with.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// Dimension.
    pub fn dim(&self) -> usize {
        self.dim
    }

    /// The conventional start used by the tests and `cargo xtask optimise`: the origin for
    /// Rosenbrock, (1, …, 1) otherwise (rotated: the same point, since R is applied inside).
    pub fn start(&self) -> Vec<f64> {
        match self.kind {
            Kind::Rosenbrock => vec![0.0; self.dim],
            _ => vec![1.0; self.dim],
        }
    }

    /// f(x) (no allocation).
    ///
    /// # Panics
    /// If `x.len()` differs from the dimension.
    pub fn eval(&self, x: &[f64]) -> f64 {
        assert_eq!(
            x.len(),
            self.dim,
            "{} expects {} variables",
            self.name,
            self.dim
        );
        let y = |i: usize| match &self.rotation {
            None => x[i],
            Some(r) => r.row(i).iter().zip(x).map(|(a, b)| a * b).sum(),
        };
        let d = self.dim;
        match self.kind {
            Kind::Sphere => (0..d).map(|i| y(i).powi(2)).sum(),
            Kind::Ellipsoid => (0..d)
                .map(|i| {
                    let e = if d > 1 {
                        6.0 * i as f64 / (d - 1) as f64
                    } else {
                        0.0
                    };
                    10f64.powf(e) * y(i).powi(2)
                })
                .sum(),
            Kind::Cigar => y(0).powi(2) + 1e6 * (1..d).map(|i| y(i).powi(2)).sum::<f64>(),
            Kind::Discus => 1e6 * y(0).powi(2) + (1..d).map(|i| y(i).powi(2)).sum::<f64>(),
            Kind::Rosenbrock => {
                let mut prev = y(0);
                let mut total = 0.0;
                for i in 1..d {
                    let next = y(i);
                    total += 100.0 * (next - prev * prev).powi(2) + (1.0 - prev).powi(2);
                    prev = next;
                }
                total
            }
            Kind::Rastrigin => {
                10.0 * d as f64
                    + (0..d)
                        .map(|i| {
                            let v = y(i);
                            v * v - 10.0 * (2.0 * std::f64::consts::PI * v).cos()
                        })
                        .sum::<f64>()
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn minima_are_zero_and_rotations_are_orthogonal() {
        for name in names() {
            let f = TestFunction::by_name(&name, 7, 3).unwrap();
            let opt = if name.ends_with("rosenbrock") {
                // R x = 1 ⇔ x = Rᵀ 1
                match &f.rotation {
                    Some(r) => (r.transpose() * nalgebra::DVector::from_element(7, 1.0))
                        .as_slice()
                        .to_vec(),
                    None => vec![1.0; 7],
                }
            } else {
                vec![0.0; 7]
            };
            assert!(f.eval(&opt).abs() < 1e-12, "{name}");
            assert!(f.eval(&f.start()) > 0.0, "{name}");
        }
        let f = TestFunction::rotated(Kind::Sphere, 5, 1);
        let r = f.rotation.as_ref().unwrap();
        assert!(
            (r.transpose() * r - DMatrix::<f64>::identity(5, 5))
                .abs()
                .max()
                < 1e-12
        );
        assert!(TestFunction::by_name("spehre", 3, 0).is_err());
    }
}
