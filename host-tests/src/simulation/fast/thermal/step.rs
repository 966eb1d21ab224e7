//! One thermal step: the predictor ([`Thermal::predict`]) and the
//! corrector ([`Thermal::correct`]) with its implicit drift solve, the
//! derivatives of the g polynomial they extrapolate, and the small
//! Gaussian elimination of the drift's system.

use super::{Prediction, Thermal, Trial, NE, NT};
use crate::fast::dense::{mul_vec_add_cols, mul_vec_cols};
use crate::fast::phi::{solve_linear, Phi};

/// h·max_j ‖(Â − A)_j‖₁ below which the drift stays in the explicit g
/// (the explicit treatment is stable and accurate there, and the implicit
/// solve costs two products a drifting column; Case 2's steps).
const DRIFT_GATE: f64 = 0.05;
/// Fixed-point iterations of the drift on an odd step solved by vectors
/// (no level matrices for the exact solve), at most.
const DRIFT_ITERS: u32 = 4;

impl Thermal {
    /// z(h) of z' = A·z + g₀ + g'·s + g''·s²/2 from z₀ (A·z₀ + g₀ = f₀),
    /// by the level's matrices or the vector solution. `base`: z₀ + Φ₁·f₀
    /// of the level's matrices when already taken (the predictor's, shared
    /// with the corrector: the same sums, so the same bits).
    fn linear(&self, phi: Option<&Phi<NT>>, h: f64, g0: &[f64; NT], d: &([f64; NT], [f64; NT]), base: Option<&[f64; NT]>) -> [f64; NT] {
        if self.a_zero {
            // A = 0: Φ_k = h/k!·I, f₀ = g₀.
            let (c1, c2) = (h * h / 2.0, h * h * h / 6.0);
            return std::array::from_fn(|i| self.z[i] + h * self.fz[i] + c1 * d.0[i] + c2 * d.1[i]);
        }
        match phi {
            Some(p) => {
                // z₀ + Φ₁·f₀ + h·Φ₂·g' + h²·Φ₃·g''
                let mut z = match base {
                    Some(b) => *b,
                    None => self.base(p),
                };
                mul_vec_add_cols(&p.cols[1], &d.0.map(|x| x * h), &mut z);
                mul_vec_add_cols(&p.cols[2], &d.1.map(|x| x * h * h), &mut z);
                z
            }
            None => solve_linear(&self.a, h, &self.z, [g0, &d.0, &d.1]),
        }
    }

    /// z₀ + Φ₁·f₀ of a level's matrices.
    fn base(&self, p: &Phi<NT>) -> [f64; NT] {
        let mut z = self.z;
        mul_vec_add_cols(&p.cols[0], &self.fz, &mut z);
        z
    }

    /// The predictor of a step of `h` s (`phi`: the level's matrices, None:
    /// an odd step): z*, g₀ and z₀ + Φ₁·f₀ for the corrector.
    pub fn predict(&self, phi: Option<&Phi<NT>>, h: f64) -> Prediction {
        let az0 = mul_vec_cols(&self.a_cols, &self.z);
        let g0: [f64; NT] = std::array::from_fn(|i| self.fz[i] - az0[i]);
        // The polynomial through the stored g and g₀.
        let mut pts: [(f64, &[f64; NT]); 3] = [(0.0, &g0); 3];
        let n = self.hist.len().min(2);
        for (k, (t, g, _)) in self.hist[self.hist.len() - n..].iter().enumerate() {
            pts[k] = (t - self.t, g);
        }
        pts[n] = (0.0, &g0);
        let base = phi.filter(|_| !self.a_zero).map(|p| self.base(p));
        let zp = self.linear(phi, h, &g0, &derivatives(&pts[..=n]), base.as_ref());
        Prediction { zp, g0, base }
    }

    /// The corrector's exact drift solve (see `correct`) with at most `K`
    /// drifting columns: z₁ += M·δ over them.
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    fn drift_exact<const K: usize>(&self, phi: Option<&Phi<NT>>, h: f64, c1: f64, c2: f64, da: &[[f64; NT]; NT], zp: &[f64; NT], z1: &mut [f64; NT]) {
        let n = self.da_n;
        let mut w = [[0.0; NT]; K];
        for k in 0..n {
            let v = &da[self.da_idx[k]];
            match phi {
                Some(p) if !self.a_zero => {
                    mul_vec_add_cols(&p.cols[1], &v.map(|x| x * h * c1), &mut w[k]);
                    mul_vec_add_cols(&p.cols[2], &v.map(|x| x * h * h * c2), &mut w[k]);
                }
                _ => {
                    let s = h * h * c1 / 2.0 + h * h * h * c2 / 6.0;
                    w[k] = v.map(|x| x * s);
                }
            }
        }
        let mut mat = [[0.0; K]; K];
        let mut x = [0.0; K];
        for r in 0..n {
            for c in 0..n {
                mat[r][c] = f64::from(u8::from(r == c)) - w[c][self.da_idx[r]];
            }
            x[r] = z1[self.da_idx[r]] - zp[self.da_idx[r]];
        }
        solve_small(&mut mat, &mut x, n);
        for k in 0..n {
            for i in 0..NT {
                z1[i] += w[k][i] * x[k];
            }
        }
    }

    /// The corrector of the step predicted by [`Thermal::predict`] (`pred`,
    /// with the same `phi` and `h`), given the model's rates `fp`, `qp` at
    /// the predicted end.
    pub fn correct(&self, phi: Option<&Phi<NT>>, h: f64, pred: &Prediction, fp: &[f64; NT], qp: &[f64; NE]) -> Trial {
        let (zp, g0) = (&pred.zp, &pred.g0);
        let azp = mul_vec_cols(&self.a_cols, zp);
        let gp: [f64; NT] = std::array::from_fn(|i| fp[i] - azp[i]);
        // The polynomial through the latest stored g, g₀ and g*.
        let mut pts: [(f64, &[f64; NT]); 3] = [(0.0, g0); 3];
        let m = self.hist.len().min(1);
        if let Some((t, g, _)) = self.hist.last() {
            pts[0] = (t - self.t, g);
        }
        pts[m] = (0.0, g0);
        pts[m + 1] = (h, &gp);
        let mut z1 = self.linear(phi, h, g0, &derivatives(&pts[..m + 2]), pred.base.as_ref());
        if let Some(da) = self.da_cols.as_ref().filter(|_| h * self.da_norm >= DRIFT_GATE) {
            // The corrector with g at its end linear in the drift:
            // g(z₁) = g* + (Â − A)·(z₁ − z*). z₁ is affine in g*: a change δ
            // of it moves z₁ by M·δ, M = c₁·h·Φ₂ + c₂·h²·Φ₃ (c₁, c₂ the
            // weights of the end point in g', g''); with δ = Σ_k (Â − A)_k·dz_k
            // over the drifting columns k, a k×k system.
            let n = self.da_n;
            let (c1, c2) = end_weights(&pts[..m + 2]);
            let exact = self.a_zero || phi.is_some();
            if exact {
                // (The system's arrays as small as the drifting columns
                // allow: zeroed whole, NT×NT, they were two `memset`s a try.)
                if n <= DRIFT_SMALL {
                    self.drift_exact::<DRIFT_SMALL>(phi, h, c1, c2, da, zp, &mut z1);
                } else {
                    self.drift_exact::<NT>(phi, h, c1, c2, da, zp, &mut z1);
                }
            } else {
                for _ in 0..DRIFT_ITERS {
                    let dz: [f64; NT] = std::array::from_fn(|i| z1[i] - zp[i]);
                    let c = mul_vec_cols(da, &dz);
                    let ge: [f64; NT] = std::array::from_fn(|i| gp[i] + c[i]);
                    let mut pe = pts;
                    pe[m + 1] = (h, &ge);
                    let zn = self.linear(phi, h, g0, &derivatives(&pe[..m + 2]), pred.base.as_ref());
                    let moved = zn.iter().zip(&z1).fold(0.0f64, |a, (x, y)| a.max((x - y).abs()));
                    z1 = zn;
                    if moved < 1e-9 {
                        break;
                    }
                }
            }
        }
        let dz: [f64; NT] = std::array::from_fn(|i| z1[i] - zp[i]);
        let mut adz = mul_vec_cols(&self.a_cols, &dz);
        if let Some(da) = &self.da_cols {
            mul_vec_add_cols(da, &dz, &mut adz);
        }
        let f1 = std::array::from_fn(|i| fp[i] + adz[i]);
        let q1 = std::array::from_fn(|i| qp[i] + self.a_e[i].iter().zip(&dz).map(|(p, q)| p * q).sum::<f64>());
        let milne = if m == 1 { 10.0 } else { 6.0 };
        let (mut err_k, mut worst) = (0.0, 0);
        for (i, d) in dz.iter().enumerate() {
            if d.abs() / milne > err_k {
                (err_k, worst) = (d.abs() / milne, i);
            }
        }
        Trial { h, z1, f1, q1, g0: *g0, err_k, worst }
    }
}

/// g' and g'' at s = 0 of the polynomial through `pts` (s, g) (one point:
/// constant; two: line; three: parabola), by divided differences.
fn derivatives(pts: &[(f64, &[f64; NT])]) -> ([f64; NT], [f64; NT]) {
    let (mut d1, mut d2) = ([0.0; NT], [0.0; NT]);
    match pts {
        [(x0, y0), (x1, y1)] => {
            for i in 0..NT {
                d1[i] = (y1[i] - y0[i]) / (x1 - x0);
            }
        }
        [(x0, y0), (x1, y1), (x2, y2)] => {
            for i in 0..NT {
                let d01 = (y1[i] - y0[i]) / (x1 - x0);
                let d12 = (y2[i] - y1[i]) / (x2 - x1);
                let d012 = (d12 - d01) / (x2 - x0);
                d1[i] = d01 - d012 * (x0 + x1);
                d2[i] = 2.0 * d012;
            }
        }
        _ => {}
    }
    (d1, d2)
}

/// The weights of the last point's value in g' and g'' at s = 0 of
/// [`derivatives`].
fn end_weights(pts: &[(f64, &[f64; NT])]) -> (f64, f64) {
    match pts {
        [(x0, _), (x1, _)] => (1.0 / (x1 - x0), 0.0),
        [(x0, _), (x1, _), (x2, _)] => {
            let d = 1.0 / ((x2 - x1) * (x2 - x0));
            (-(x0 + x1) * d, 2.0 * d)
        }
        _ => (0.0, 0.0),
    }
}

/// Drifting columns up to which the corrector's drift solve takes
/// K×K arrays (beyond it, NT×NT).
const DRIFT_SMALL: usize = 4;

/// Solves the leading n×n system m·x = b in place (Gaussian elimination
/// with partial pivoting; b becomes x). Not `dense::Lu`: that factorises
/// the whole NT×NT matrix, ~13³/3 operations a corrector for a system of
/// the one or two drifting columns.
#[inline(always)]
fn solve_small<const K: usize>(m: &mut [[f64; K]; K], b: &mut [f64; K], n: usize) {
    for c in 0..n {
        let p = (c..n).max_by(|&i, &j| m[i][c].abs().total_cmp(&m[j][c].abs())).unwrap_or(c);
        m.swap(c, p);
        b.swap(c, p);
        let pivot = m[c];
        for r in c + 1..n {
            let f = m[r][c] / pivot[c];
            for (x, p) in m[r][c..n].iter_mut().zip(&pivot[c..n]) {
                *x -= f * p;
            }
            b[r] -= f * b[c];
        }
    }
    for c in (0..n).rev() {
        let s: f64 = (c + 1..n).map(|k| m[c][k] * b[k]).sum();
        b[c] = (b[c] - s) / m[c][c];
    }
}
