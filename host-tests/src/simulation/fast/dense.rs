//! Small dense matrices whose size is known at compile time (the thermal
//! network's N_NODES, the hydraulics' ix::N): products, the 1-norm and an LU
//! factorisation with partial pivoting. Row-major `[[f64; N]; N]` on the
//! stack: no allocation, and loops the compiler unrolls and vectorises (a
//! 12×12 product is ~0.3 µs here, against ~2 µs through nalgebra's
//! dynamic matrices, measured in `docs/reference-speed.md`).

/// An N×N matrix, row-major.
pub type Mat<const N: usize> = [[f64; N]; N];

/// The zero matrix.
pub fn zeros<const N: usize>() -> Mat<N> {
    [[0.0; N]; N]
}

/// The identity.
pub fn identity<const N: usize>() -> Mat<N> {
    let mut m = zeros();
    for (i, row) in m.iter_mut().enumerate() {
        row[i] = 1.0;
    }
    m
}

/// The product a·b. On x86-64 CPUs with AVX2 (detected at run time) the
/// same loops compiled for AVX2, 4 lanes against SSE2's 2: the
/// φ-functions' products, the bulk of a Jacobian refresh, measured
/// 3.5 k → 1.2 k instructions per 12×12 product. Same floating-point
/// operations in the same order (no fused multiply-add): the same bits.
pub fn mul<const N: usize>(a: &Mat<N>, b: &Mat<N>) -> Mat<N> {
    #[cfg(target_arch = "x86_64")]
    {
        if std::arch::is_x86_feature_detected!("avx2") {
            // SAFETY: the CPU supports AVX2, checked just above.
            return unsafe { mul_avx2(a, b) };
        }
    }
    mul_portable(a, b)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn mul_avx2<const N: usize>(a: &Mat<N>, b: &Mat<N>) -> Mat<N> {
    mul_portable(a, b)
}

#[inline(always)]
fn mul_portable<const N: usize>(a: &Mat<N>, b: &Mat<N>) -> Mat<N> {
    let mut c = zeros();
    for (ci, ai) in c.iter_mut().zip(a) {
        for (aik, bk) in ai.iter().zip(b) {
            for (cij, bkj) in ci.iter_mut().zip(bk) {
                *cij += aik * bkj;
            }
        }
    }
    c
}

/// The rows of a·b, each handed to `row(i, r)` as it is finished: the
/// same sums in the same order as [`mul`] (the same bits), without a
/// zeroed result matrix nor its copy on return (the φ doublings write
/// their level's box row by row). AVX2 where the CPU has it, as [`mul`].
pub fn mul_rows<const N: usize, F: FnMut(usize, [f64; N])>(a: &Mat<N>, b: &Mat<N>, row: F) {
    #[cfg(target_arch = "x86_64")]
    {
        if std::arch::is_x86_feature_detected!("avx2") {
            // SAFETY: the CPU supports AVX2, checked just above.
            return unsafe { mul_rows_avx2(a, b, row) };
        }
    }
    mul_rows_portable(a, b, row)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn mul_rows_avx2<const N: usize, F: FnMut(usize, [f64; N])>(a: &Mat<N>, b: &Mat<N>, row: F) {
    mul_rows_portable(a, b, row)
}

#[inline(always)]
fn mul_rows_portable<const N: usize, F: FnMut(usize, [f64; N])>(a: &Mat<N>, b: &Mat<N>, mut row: F) {
    for (i, ai) in a.iter().enumerate() {
        let mut ci = [0.0; N];
        for (aik, bk) in ai.iter().zip(b) {
            for (cij, bkj) in ci.iter_mut().zip(bk) {
                *cij += aik * bkj;
            }
        }
        row(i, ci);
    }
}

/// The product a·x.
pub fn mul_vec<const N: usize>(a: &Mat<N>, x: &[f64; N]) -> [f64; N] {
    let mut y = [0.0; N];
    mul_vec_add(a, x, &mut y);
    y
}

/// y += a·x, as a sum of columns: y += x_j·a\[·\]\[j\] runs along y, so the
/// compiler vectorises it (a row-by-row dot product is one dependent chain
/// of additions, measured 3× slower on the 12-node network); with AVX2
/// where the CPU has it, as [`mul`].
pub fn mul_vec_add<const N: usize>(a: &Mat<N>, x: &[f64; N], y: &mut [f64; N]) {
    #[cfg(target_arch = "x86_64")]
    {
        if std::arch::is_x86_feature_detected!("avx2") {
            // SAFETY: the CPU supports AVX2, checked just above.
            return unsafe { mul_vec_add_avx2(a, x, y) };
        }
    }
    mul_vec_add_portable(a, x, y)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn mul_vec_add_avx2<const N: usize>(a: &Mat<N>, x: &[f64; N], y: &mut [f64; N]) {
    mul_vec_add_portable(a, x, y)
}

#[inline(always)]
fn mul_vec_add_portable<const N: usize>(a: &Mat<N>, x: &[f64; N], y: &mut [f64; N]) {
    let mut acc = [0.0; N];
    for (j, xj) in x.iter().enumerate() {
        for (acc_i, ai) in acc.iter_mut().zip(a) {
            *acc_i += ai[j] * xj;
        }
    }
    for (yi, s) in y.iter_mut().zip(acc) {
        *yi += s;
    }
}

/// The transpose: the columns of `a` as rows.
pub fn transpose<const N: usize>(a: &Mat<N>) -> Mat<N> {
    std::array::from_fn(|j| std::array::from_fn(|i| a[i][j]))
}

/// y += a·x with `cols` = aᵀ (a's columns as rows): the same sums in the
/// same order as [`mul_vec_add`], but each column is contiguous, so the
/// column updates y += x_j·a\[·\]\[j\] are vector operations (measured on the
/// 13-node network with AVX2: ~330 → ~130 instructions per product, the
/// thermal step's nine products per try).
pub fn mul_vec_add_cols<const N: usize>(cols: &Mat<N>, x: &[f64; N], y: &mut [f64; N]) {
    #[cfg(target_arch = "x86_64")]
    {
        if std::arch::is_x86_feature_detected!("avx2") {
            // SAFETY: the CPU supports AVX2, checked just above.
            return unsafe { mul_vec_add_cols_avx2(cols, x, y) };
        }
    }
    mul_vec_add_cols_portable(cols, x, y)
}

/// a·x with `cols` = aᵀ ([`mul_vec_add_cols`]).
pub fn mul_vec_cols<const N: usize>(cols: &Mat<N>, x: &[f64; N]) -> [f64; N] {
    let mut y = [0.0; N];
    mul_vec_add_cols(cols, x, &mut y);
    y
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn mul_vec_add_cols_avx2<const N: usize>(cols: &Mat<N>, x: &[f64; N], y: &mut [f64; N]) {
    mul_vec_add_cols_portable(cols, x, y)
}

#[inline(always)]
fn mul_vec_add_cols_portable<const N: usize>(cols: &Mat<N>, x: &[f64; N], y: &mut [f64; N]) {
    let mut acc = [0.0; N];
    for (xj, cj) in x.iter().zip(cols) {
        for (acc_i, cij) in acc.iter_mut().zip(cj) {
            *acc_i += cij * xj;
        }
    }
    for (yi, s) in y.iter_mut().zip(acc) {
        *yi += s;
    }
}

/// The 1-norm (largest column sum of absolute values).
pub fn norm1<const N: usize>(a: &Mat<N>) -> f64 {
    (0..N).map(|j| a.iter().map(|r| r[j].abs()).sum::<f64>()).fold(0.0, f64::max)
}

/// a·s + b·t, element-wise.
pub fn lin2<const N: usize>(a: &Mat<N>, s: f64, b: &Mat<N>, t: f64) -> Mat<N> {
    let mut c = *a;
    for (ci, bi) in c.iter_mut().zip(b) {
        for (x, y) in ci.iter_mut().zip(bi) {
            *x = *x * s + y * t;
        }
    }
    c
}

/// LU factorisation with partial pivoting, P·A = L·U.
#[derive(Debug, Clone, Copy)]
pub struct Lu<const N: usize> {
    lu: Mat<N>,
    piv: [usize; N],
}

impl<const N: usize> Lu<N> {
    /// Factorises `a`; `None` when a pivot is zero or not finite.
    pub fn new(mut a: Mat<N>) -> Option<Self> {
        let mut piv = [0usize; N];
        for k in 0..N {
            // The last of the largest pivots (as `Iterator::max_by` chose it).
            let mut p = k;
            for i in k + 1..N {
                if a[i][k].abs().total_cmp(&a[p][k].abs()).is_ge() {
                    p = i;
                }
            }
            piv[k] = p;
            if p != k {
                a.swap(k, p);
            }
            let d = a[k][k];
            if d == 0.0 || !d.is_finite() {
                return None;
            }
            let inv = 1.0 / d;
            let rk = a[k];
            for ri in a.iter_mut().skip(k + 1) {
                let f = ri[k] * inv;
                ri[k] = f;
                for j in k + 1..N {
                    ri[j] -= f * rk[j];
                }
            }
        }
        Some(Self { lu: a, piv })
    }

    /// Solves A·x = b in place.
    pub fn solve(&self, b: &mut [f64; N]) {
        for k in 0..N {
            b.swap(k, self.piv[k]);
        }
        for i in 0..N {
            let s: f64 = (0..i).map(|j| self.lu[i][j] * b[j]).sum();
            b[i] -= s;
        }
        for i in (0..N).rev() {
            let s: f64 = (i + 1..N).map(|j| self.lu[i][j] * b[j]).sum();
            b[i] = (b[i] - s) / self.lu[i][i];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// LU solve of a 3×3 system that needs pivoting (zero leading entry),
    /// against the hand solution x = (1, 2, 3), to round-off (1e-12).
    #[test]
    fn lu_solves_a_pivoted_system() {
        let a: Mat<3> = [[0.0, 2.0, 1.0], [1.0, 1.0, 1.0], [4.0, -1.0, 2.0]];
        let x = [1.0, 2.0, 3.0];
        let mut b = mul_vec(&a, &x);
        Lu::new(a).expect("regular").solve(&mut b);
        for (p, q) in b.iter().zip(&x) {
            assert!((p - q).abs() < 1e-12, "{b:?}");
        }
        assert!(Lu::new([[1.0, 2.0], [2.0, 4.0]]).is_none(), "singular matrix factorised");
    }

    /// The product against hand values, and the 1-norm.
    #[test]
    fn product_and_norm() {
        let a: Mat<2> = [[1.0, 2.0], [3.0, 4.0]];
        let b: Mat<2> = [[0.0, 1.0], [1.0, 0.0]];
        assert_eq!(mul(&a, &b), [[2.0, 1.0], [4.0, 3.0]]);
        assert_eq!(norm1(&a), 6.0);
        assert_eq!(mul(&identity(), &a), a);
        let mut c = zeros();
        mul_rows(&a, &b, |i, r| c[i] = r);
        assert_eq!(c, mul(&a, &b));
    }
}
