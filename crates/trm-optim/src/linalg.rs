//! Small dense helpers shared by the algorithms (allocation-free given scratch space).

use nalgebra::DMatrix;
use rand::Rng;
use rand_distr::{Distribution, StandardNormal};

/// Whether every value is finite (no early exit: the loop vectorises).
pub(crate) fn all_finite(values: &[f64]) -> bool {
    values.iter().fold(true, |ok, v| ok & v.is_finite())
}

/// Fills `out` with standard normal samples.
#[inline]
pub(crate) fn fill_normal(rng: &mut dyn Rng, out: &mut [f64]) {
    for v in out {
        *v = StandardNormal.sample(rng);
    }
}

/// Indices of `fitness` sorted best (smallest) first; NaN ranks last.
pub(crate) fn rank(fitness: &[f64], order: &mut Vec<usize>) {
    order.clear();
    order.extend(0..fitness.len());
    let key = |i: usize| {
        let f = fitness[i];
        if f.is_nan() { f64::INFINITY } else { f }
    };
    order.sort_unstable_by(|&a, &b| key(a).total_cmp(&key(b)).then(a.cmp(&b)));
}

/// Scratch space for [`expm`], sized once for n × n matrices.
#[derive(Debug, Clone)]
pub(crate) struct ExpmScratch {
    a: DMatrix<f64>,
    a2: DMatrix<f64>,
    a3: DMatrix<f64>,
    a4: DMatrix<f64>,
    t: DMatrix<f64>,
}

impl ExpmScratch {
    pub(crate) fn new(n: usize) -> Self {
        let z = || DMatrix::zeros(n, n);
        ExpmScratch {
            a: z(),
            a2: z(),
            a3: z(),
            a4: z(),
            t: z(),
        }
    }
}

/// `out = exp(a)`, for the small updates of xNES: a is scaled by 2^-s so that ‖a‖₁ ≤ 1/4, the
/// degree-12 Taylor polynomial (truncation error below 10⁻¹⁷ relative there) is evaluated with
/// the Paterson–Stockmeyer scheme in 5 matrix products, and the result squared s times. No
/// allocation, no linear solve.
pub(crate) fn expm(a: &DMatrix<f64>, out: &mut DMatrix<f64>, s: &mut ExpmScratch) {
    // c_k = 1/k!
    let mut c = [1.0f64; 13];
    for k in 1..13 {
        c[k] = c[k - 1] / k as f64;
    }
    let squarings = scaled(a, s);
    taylor(&c, out, s);
    for _ in 0..squarings {
        s.t.gemm(1.0, out, out, 0.0);
        std::mem::swap(out, &mut s.t);
    }
}

/// `out = φ(a) = (exp(a) − I) a⁻¹ = Σ aᵏ/(k+1)!` (defined for singular a too), as [`expm`]:
/// scaled so that ‖a‖₁ ≤ 1/4, a degree-12 Taylor polynomial, then doubled back with
/// φ(2x) = φ(x) (x φ(x) + 2) / 2. It gives exp of a low-rank update cheaply:
/// exp(Z W Zᵀ) = I + Z φ(W ZᵀZ) W Zᵀ.
pub(crate) fn phim(a: &DMatrix<f64>, out: &mut DMatrix<f64>, s: &mut ExpmScratch) {
    // c_k = 1/(k+1)!
    let mut c = [1.0f64; 13];
    for k in 1..13 {
        c[k] = c[k - 1] / (k + 1) as f64;
    }
    let doublings = scaled(a, s);
    taylor(&c, out, s);
    for _ in 0..doublings {
        // s.a holds the current argument x; out = φ(x) → φ(2x), x → 2x
        s.t.gemm(1.0, &s.a, out, 0.0);
        for i in 0..s.t.nrows() {
            s.t[(i, i)] += 2.0;
        }
        s.a2.gemm(0.5, out, &s.t, 0.0);
        std::mem::swap(out, &mut s.a2);
        s.a *= 2.0;
    }
}

/// Copies `a` into `s.a`, scaled by 2^-k so that its 1-norm is at most 1/4; returns k.
fn scaled(a: &DMatrix<f64>, s: &mut ExpmScratch) -> i32 {
    let norm = a
        .as_slice()
        .chunks_exact(a.nrows().max(1))
        .map(|column| column.iter().map(|v| v.abs()).sum::<f64>())
        .fold(0.0, f64::max);
    let k = if norm > 0.25 {
        (norm / 0.25).log2().ceil() as i32
    } else {
        0
    };
    s.a.copy_from(a);
    s.a *= 0.5f64.powi(k);
    k
}

/// `out = Σ_{k ≤ 12} c_k Aᵏ` for A = `s.a`, by Paterson–Stockmeyer in 5 matrix products.
fn taylor(c: &[f64; 13], out: &mut DMatrix<f64>, s: &mut ExpmScratch) {
    s.a2.gemm(1.0, &s.a, &s.a, 0.0);
    s.a3.gemm(1.0, &s.a2, &s.a, 0.0);
    s.a4.gemm(1.0, &s.a2, &s.a2, 0.0);
    // B_j = c_{4j} I + c_{4j+1} A + c_{4j+2} A² + c_{4j+3} A³
    let block =
        |m: &mut DMatrix<f64>, j: usize, a: &DMatrix<f64>, a2: &DMatrix<f64>, a3: &DMatrix<f64>| {
            let [c0, c1, c2, c3] = [c[4 * j], c[4 * j + 1], c[4 * j + 2], c[4 * j + 3]];
            let n = m.nrows();
            for (((v, x1), x2), x3) in m
                .as_mut_slice()
                .iter_mut()
                .zip(a.as_slice())
                .zip(a2.as_slice())
                .zip(a3.as_slice())
            {
                *v += c1 * x1 + c2 * x2 + c3 * x3;
            }
            for v in m.as_mut_slice().iter_mut().step_by(n + 1) {
                *v += c0;
            }
        };
    // p = B0 + A⁴ (B1 + A⁴ (B2 + c12 A⁴))
    s.t.copy_from(&s.a4);
    s.t *= c[12];
    block(&mut s.t, 2, &s.a, &s.a2, &s.a3);
    out.gemm(1.0, &s.a4, &s.t, 0.0);
    block(out, 1, &s.a, &s.a2, &s.a3);
    s.t.gemm(1.0, &s.a4, out, 0.0);
    block(&mut s.t, 0, &s.a, &s.a2, &s.a3);
    std::mem::swap(out, &mut s.t);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn phim_times_a_is_expm_minus_identity() {
        let n = 7;
        let a = DMatrix::from_fn(n, n, |i, j| ((i * 5 + j * 3) % 7) as f64 * 0.1 - 0.3);
        for factor in [0.0, 0.01, 0.2, 1.0, 6.0] {
            let m = &a * factor;
            let mut s = ExpmScratch::new(n);
            let (mut e, mut p) = (DMatrix::zeros(n, n), DMatrix::zeros(n, n));
            expm(&m, &mut e, &mut s);
            phim(&m, &mut p, &mut s);
            let want = e - DMatrix::identity(n, n);
            let scale = want.abs().max().max(1e-300);
            let got = &m * &p;
            assert!(
                (got - &want).abs().max() <= 1e-13 * scale.max(1.0),
                "factor {factor}"
            );
            if factor == 0.0 {
                assert_eq!(p, DMatrix::identity(n, n));
            }
        }
    }

    #[test]
    fn expm_matches_the_eigen_decomposition() {
        let n = 6;
        let mut a = DMatrix::from_fn(n, n, |i, j| ((i * 7 + j * 3) % 5) as f64 * 0.1 - 0.2);
        a = (&a + a.transpose()) * 0.5;
        for factor in [0.01, 0.1, 1.0, 3.0, 20.0] {
            let m = &a * factor;
            let eig = m.clone().symmetric_eigen();
            let expected = &eig.eigenvectors
                * DMatrix::from_diagonal(&eig.eigenvalues.map(f64::exp))
                * eig.eigenvectors.transpose();
            let mut out = DMatrix::zeros(n, n);
            expm(&m, &mut out, &mut ExpmScratch::new(n));
            let scale = expected.abs().max();
            assert!(
                (out - expected).abs().max() < 1e-13 * scale,
                "factor {factor}"
            );
        }
    }
}
