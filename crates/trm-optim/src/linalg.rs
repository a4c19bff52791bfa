//! Small dense helpers shared by the algorithms (allocation-free given scratch space).

use nalgebra::DMatrix;
use rand::Rng;
use rand_distr::{Distribution, StandardNormal};

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
    order.sort_by(|&a, &b| key(a).total_cmp(&key(b)).then(a.cmp(&b)));
}

/// `out = exp(a)` for a symmetric `a` of small norm (as in xNES, where ‖a‖ is a fraction):
/// a Taylor series summed until the terms vanish in double precision, after scaling by 2^-s so
/// that ‖a‖₁ ≤ 1/2, then squared s times. `t1`, `t2` are scratch of the same size.
pub(crate) fn expm_small(
    a: &DMatrix<f64>,
    out: &mut DMatrix<f64>,
    t1: &mut DMatrix<f64>,
    t2: &mut DMatrix<f64>,
) {
    let norm = (0..a.ncols())
        .map(|j| a.column(j).iter().map(|v| v.abs()).sum::<f64>())
        .fold(0.0, f64::max);
    let squarings = if norm > 0.5 {
        (norm / 0.5).log2().ceil() as i32
    } else {
        0
    };
    let scale = 0.5f64.powi(squarings);
    // term = a·scale; out = I + term
    t1.copy_from(a);
    *t1 *= scale;
    out.fill_with_identity();
    *out += &*t1;
    for k in 2..30 {
        // term ← term · a·scale / k
        t2.gemm(scale / k as f64, t1, a, 0.0);
        std::mem::swap(t1, t2);
        *out += &*t1;
        let term = t1.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        if term < 1e-17 {
            break;
        }
    }
    for _ in 0..squarings {
        t2.gemm(1.0, out, out, 0.0);
        std::mem::swap(out, t2);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn expm_matches_the_eigen_decomposition() {
        let n = 6;
        let mut a = DMatrix::from_fn(n, n, |i, j| ((i * 7 + j * 3) % 5) as f64 * 0.1 - 0.2);
        a = (&a + a.transpose()) * 0.5;
        for factor in [0.1, 1.0, 4.0] {
            let m = &a * factor;
            let eig = m.clone().symmetric_eigen();
            let expected = &eig.eigenvectors
                * DMatrix::from_diagonal(&eig.eigenvalues.map(f64::exp))
                * eig.eigenvectors.transpose();
            let (mut out, mut t1, mut t2) = (
                DMatrix::zeros(n, n),
                DMatrix::zeros(n, n),
                DMatrix::zeros(n, n),
            );
            expm_small(&m, &mut out, &mut t1, &mut t2);
            assert!((out - expected).abs().max() < 1e-12);
        }
    }
}
