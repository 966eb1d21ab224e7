//! Small dense `f64` linear algebra used once at init (never in the step):
//! matrix product and the matrix exponential for the exact ZOH discretisation.

/// `a · b` for `N × N` matrices.
pub fn matmul<const N: usize>(a: &[[f64; N]; N], b: &[[f64; N]; N]) -> [[f64; N]; N] {
    let mut c = [[0.0; N]; N];
    for (ci, ai) in c.iter_mut().zip(a.iter()) {
        for (aik, bk) in ai.iter().zip(b.iter()) {
            for (cij, bkj) in ci.iter_mut().zip(bk.iter()) {
                *cij += aik * bkj;
            }
        }
    }
    c
}

/// Infinity norm (max absolute row sum).
pub fn norm_inf<const N: usize>(a: &[[f64; N]; N]) -> f64 {
    a.iter()
        .map(|r| r.iter().map(|x| libm::fabs(*x)).sum::<f64>())
        .fold(0.0, f64::max)
}

/// Identity matrix.
pub fn identity<const N: usize>() -> [[f64; N]; N] {
    let mut m = [[0.0; N]; N];
    for (i, r) in m.iter_mut().enumerate() {
        if let Some(x) = r.get_mut(i) {
            *x = 1.0;
        }
    }
    m
}

/// `exp(a) - I` by scaling and squaring with a degree-16 Taylor series.
///
/// Returning `exp(a) - I` (not `exp(a)`) keeps entries far below 1 at full
/// relative precision: [`crate::model::etd_matrix`] takes `Phi` from the upper-right
/// block of the augmented matrix, and the squarings that form it multiply the
/// small diagonal block `exp(A h 2^-s) - I`, never `I + tiny`. The argument is scaled
/// by `2^-s` so that `‖a‖∞ 2^-s ≤ 2^-4`; the truncation error is then below
/// `(1/16)^17 / 17! ≈ 2e-35` relative, far under `f64` rounding. Squaring uses
/// `E(2x) = 2E(x) + E(x)^2` with `E = exp - I`, which never forms `I + tiny`.
pub fn expm1m<const N: usize>(a: &[[f64; N]; N]) -> [[f64; N]; N] {
    let norm = norm_inf(a);
    let mut s = 0u32;
    let mut scale = 1.0;
    while norm * scale > 0.0625 && s < 64 {
        scale *= 0.5;
        s += 1;
    }
    let mut x = *a;
    for r in x.iter_mut() {
        for v in r.iter_mut() {
            *v *= scale;
        }
    }
    // Horner: E = x (I + x/2 (I + x/3 (... (I + x/16))))
    let mut e = identity::<N>();
    for k in (2..=16).rev() {
        let mut t = matmul(&x, &e);
        for r in t.iter_mut() {
            for v in r.iter_mut() {
                *v /= k as f64;
            }
        }
        for (i, r) in t.iter_mut().enumerate() {
            if let Some(d) = r.get_mut(i) {
                *d += 1.0;
            }
        }
        e = t;
    }
    let mut em = matmul(&x, &e);
    for _ in 0..s {
        let sq = matmul(&em, &em);
        for (r, q) in em.iter_mut().zip(sq.iter()) {
            for (v, w) in r.iter_mut().zip(q.iter()) {
                *v = 2.0 * *v + w;
            }
        }
    }
    em
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn expm_of_diagonal_and_rotation() {
        // diag(-1, 2): exp - 1 = e^-1 - 1, e^2 - 1 (libm reference, 1e-13 relative).
        let a = [[-1.0, 0.0], [0.0, 2.0]];
        let e = expm1m(&a);
        assert!((e[0][0] - (libm::exp(-1.0) - 1.0)).abs() < 1e-14);
        assert!((e[1][1] - (libm::exp(2.0) - 1.0)).abs() < 1e-12);
        assert!(e[0][1].abs() < 1e-300 && e[1][0].abs() < 1e-300);
        // Rotation generator [[0, -t], [t, 0]] → [[cos t - 1, -sin t], [sin t, cos t - 1]].
        let t = 3.0;
        let r = expm1m(&[[0.0, -t], [t, 0.0]]);
        assert!((r[0][0] - (libm::cos(t) - 1.0)).abs() < 1e-12);
        assert!((r[1][0] - libm::sin(t)).abs() < 1e-12);
    }

    #[test]
    fn expm_keeps_tiny_entries_precise() {
        // a = -1e-7: exp(a) - 1 = -9.9999995e-8 to 1e-15 relative (expm1 reference).
        let e = expm1m(&[[-1e-7]]);
        assert!((e[0][0] - libm::expm1(-1e-7)).abs() < 1e-22);
    }
}
