//! The thermal half of the multirate scheme: exponential Adams steps of
//! order 3 on z' = A·z + g(t, z), z the node temperatures.
//!
//! A is the Jacobian of the model's own heat balances with respect to the
//! temperatures (forward differences of `Model::rhs`); g = f − A·z is what
//! the linear part misses: the operating point's variation within the
//! step, temperature dependent conductances, losses and capacities, the
//! drift of A itself. A step from z₀ (f₀ = f(z₀)) with the g of the two
//! previous steps in store:
//!
//! * predictor: g extrapolated by the parabola through g₋₂, g₋₁, g₀;
//!   z* = z₀ + Φ₁·f₀ + h·Φ₂·g' + h²·Φ₃·g'' (the exact solution for that
//!   forcing);
//! * one model evaluation f* = f(t₁, z*), g* = f* − A·z*;
//! * corrector: the parabola through g₋₁, g₀, g*; error estimate
//!   (z₁ − z*)/10 (Milne: the corrector's error constant, 1/24, is a tenth
//!   of the difference of the two, 3/8 + 1/24), and f₁ = f* + A·(z₁ − z*)
//!   without a second evaluation.
//!
//! The drift of A: A is taken once after a start (its φ-functions cost
//! ~0.26 M instructions anew), and the network's self-derivatives move with
//! the temperatures (Case 1's case oil: its diagonal 4.3× from the start to
//! 600 s). Left in g, that difference is explicit, and the steps were held
//! by its instability, an error growing from step to step at a fixed step.
//! [`Thermal::drift`] takes a few columns of the Jacobian anew (Â) and keeps
//! Â − A beside A; the corrector then solves g(z₁) = g* + (Â − A)·(z₁ − z*)
//! for z₁ (a small system in the drifting columns: z₁ is affine in g*), so
//! that part is implicit as in an Adams–Moulton corrector, and f₁ takes Â.
//!
//! Order 3 rather than 2: a forcing that is quadratic in time (a copper loss
//! ∝ I² under a steady piston speed) is integrated exactly; the order-2
//! corrector's error on it has one sign in every step and added up to
//! 1e-2 K on the winding of a servo mission. With one g in store the step
//! is of order 2, with none of order 1 (after a restart).
//!
//! Φ_k = h·φ_k(hA) come from the cached matrices of a step level or, for
//! an odd step, from the vector solution of [`super::phi::solve_linear`].
//! The energy integrals follow by the trapezoidal rule on the heat rates.

use super::dense::{mul_vec_add_cols, mul_vec_cols, transpose, Mat};
use super::phi::{solve_linear, Phi};
use crate::model::{N_STATE, T0};
use crate::network::N_NODES;

/// Node temperatures.
pub const NT: usize = N_NODES;
/// Energy integrals after the temperatures.
pub const NE: usize = N_STATE - T0 - N_NODES;

/// The model's heat balances at the current time and operating point:
/// node temperatures in, (dz/dt K/s, energy rates W) out.
pub trait Rates: FnMut(&[f64; NT], &mut [f64; NT], &mut [f64; NE]) {}
impl<F: FnMut(&[f64; NT], &mut [f64; NT], &mut [f64; NE])> Rates for F {}

/// h·max_j ‖(Â − A)_j‖₁ below which the drift stays in the explicit g
/// (the explicit treatment is stable and accurate there, and the implicit
/// solve costs two products a drifting column; Case 2's steps).
const DRIFT_GATE: f64 = 0.05;
/// Fixed-point iterations of the drift on an odd step solved by vectors
/// (no level matrices for the exact solve), at most.
const DRIFT_ITERS: u32 = 4;

/// The scheme's state between steps.
#[derive(Debug, Clone)]
pub struct Thermal {
    /// Node temperatures, °C.
    pub z: [f64; NT],
    /// Energy integrals, J.
    pub e: [f64; NE],
    /// dz/dt at z, K/s.
    pub fz: [f64; NT],
    /// Energy rates at z, W.
    pub q: [f64; NE],
    /// Time of z, s.
    pub t: f64,
    /// (t, g, z) of the previous steps, latest last (the current A's g).
    hist: Vec<(f64, [f64; NT], [f64; NT])>,
    /// ∂(dz/dt)/∂z, 1/s.
    pub a: Mat<NT>,
    /// Aᵀ, for products A·v ([`mul_vec_cols`]).
    a_cols: Mat<NT>,
    /// ∂q/∂z, W/K.
    pub a_e: [[f64; NT]; NE],
    /// Whether A is zero (no Jacobian taken yet).
    a_zero: bool,
    /// Â − A by columns (Â a later Jacobian of some columns, the φ-functions
    /// still of A): the drift the corrector treats implicitly.
    da_cols: Option<Mat<NT>>,
    /// The drifting columns (`da_n` of them).
    da_idx: [usize; NT],
    da_n: usize,
    /// Largest ‖(Â − A)_j‖₁ of the kept drift, 1/s.
    da_norm: f64,
}

/// A step predicted from the current state ([`Thermal::predict`]).
#[derive(Debug, Clone, Copy)]
pub struct Prediction {
    /// Predicted temperatures z*, °C.
    pub zp: [f64; NT],
    /// g at the step's start (current A), K/s.
    pub g0: [f64; NT],
    /// z₀ + Φ₁·f₀ of the level's matrices (None: an odd step by vectors, or A = 0).
    base: Option<[f64; NT]>,
}

/// A step tried from the current state.
#[derive(Debug, Clone, Copy)]
pub struct Trial {
    /// Step, s.
    pub h: f64,
    /// Corrected temperatures.
    pub z1: [f64; NT],
    /// dz/dt there (linear correction of the evaluation at the predictor).
    pub f1: [f64; NT],
    /// Energy rates there.
    pub q1: [f64; NE],
    /// g at the step's start (current A).
    pub g0: [f64; NT],
    /// Largest |corrector − predictor|/6 over the nodes, K.
    pub err_k: f64,
    /// Node of the largest error.
    pub worst: usize,
}

impl Thermal {
    /// A state at time `t`, temperatures `z` and energies `e` (call
    /// [`Thermal::jacobian`] first).
    pub fn new(t: f64, z: [f64; NT], e: [f64; NE]) -> Self {
        Self { z, e, fz: [0.0; NT], q: [0.0; NE], t, hist: Vec::with_capacity(3), a: [[0.0; NT]; NT], a_cols: [[0.0; NT]; NT], a_e: [[0.0; NT]; NE], a_zero: true, da_cols: None, da_idx: [0; NT], da_n: 0, da_norm: 0.0 }
    }

    /// Whether A is zero (no Jacobian taken yet).
    pub fn is_zero(&self) -> bool {
        self.a_zero
    }

    /// f anew at z, and A by forward differences (N_NODES more
    /// evaluations). With `keep_history` the stored g are rewritten for the
    /// new A (g = f − A·z changes by (A_old − A_new)·z).
    pub fn jacobian(&mut self, rates: &mut impl Rates, keep_history: bool) {
        let a_old = self.a;
        let (mut fz, mut q) = ([0.0; NT], [0.0; NE]);
        rates(&self.z, &mut fz, &mut q);
        for j in 0..NT {
            let col = self.column(rates, j, &fz, &q);
            for (i, x) in col.iter().enumerate() {
                self.a[i][j] = *x;
            }
        }
        self.a_cols = transpose(&self.a);
        self.da_cols = None;
        self.da_n = 0;
        self.a_zero = self.a.iter().all(|r| r.iter().all(|&x| x == 0.0));
        if keep_history {
            for (_, g, z) in self.hist.iter_mut() {
                for (i, gi) in g.iter_mut().enumerate() {
                    *gi += (0..NT).map(|j| (a_old[i][j] - self.a[i][j]) * z[j]).sum::<f64>();
                }
            }
        } else {
            self.hist.clear();
        }
        (self.fz, self.q) = (fz, q);
    }

    /// Column `j` of the temperatures' Jacobian by a forward difference from
    /// `fz`, `q` (the rates at z): returned; the energies' column is written
    /// into `a_e` (one evaluation).
    fn column(&mut self, rates: &mut impl Rates, j: usize, fz: &[f64; NT], q: &[f64; NE]) -> [f64; NT] {
        let (mut fp, mut qp) = ([0.0; NT], [0.0; NE]);
        let mut zp = self.z;
        let d = 1e-5 * (1.0 + self.z[j].abs());
        zp[j] += d;
        rates(&zp, &mut fp, &mut qp);
        for i in 0..NE {
            self.a_e[i][j] = (qp[i] - q[i]) / d;
        }
        std::array::from_fn(|i| (fp[i] - fz[i]) / d)
    }

    /// The columns `cols` of the Jacobian anew by forward differences
    /// (1 + cols.len() evaluations), kept as Â − A beside A: the φ-functions
    /// stay those of A, the corrector treats the difference implicitly.
    pub fn drift(&mut self, rates: &mut impl Rates, cols: &[usize]) {
        let (mut fz, mut q) = ([0.0; NT], [0.0; NE]);
        rates(&self.z, &mut fz, &mut q);
        let mut da = self.da_cols.unwrap_or([[0.0; NT]; NT]);
        for &j in cols {
            let col = self.column(rates, j, &fz, &q);
            for (i, x) in col.iter().enumerate() {
                da[j][i] = x - self.a[i][j];
            }
            if !self.da_idx[..self.da_n].contains(&j) {
                self.da_idx[self.da_n] = j;
                self.da_n += 1;
            }
        }
        self.da_norm = da.iter().map(|c| c.iter().map(|x| x.abs()).sum::<f64>()).fold(0.0, f64::max);
        self.da_cols = Some(da);
    }

    /// f anew at z (the forcing changed: a breakpoint, the far side of a
    /// branch switch, a valve). With `keep_history` the stored g are
    /// shifted by the jump of g here (a step in the forcing, its
    /// derivatives unchanged); without, they are forgotten.
    pub fn fresh(&mut self, rates: &mut impl Rates, keep_history: bool) {
        let old = self.fz;
        rates(&self.z, &mut self.fz, &mut self.q);
        if keep_history {
            for (_, g, _) in self.hist.iter_mut() {
                for i in 0..NT {
                    g[i] += self.fz[i] - old[i];
                }
            }
        } else {
            self.hist.clear();
        }
    }

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

    /// Takes the tried step.
    pub fn accept(&mut self, t: &Trial) {
        for i in 0..NE {
            self.e[i] += 0.5 * t.h * (self.q[i] + t.q1[i]);
        }
        if self.hist.len() == 2 {
            self.hist.remove(0);
        }
        self.hist.push((self.t, t.g0, self.z));
        (self.z, self.fz, self.q) = (t.z1, t.f1, t.q1);
        self.t += t.h;
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
