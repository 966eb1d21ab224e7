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
        Self { z, e, fz: [0.0; NT], q: [0.0; NE], t, hist: Vec::with_capacity(3), a: [[0.0; NT]; NT], a_cols: [[0.0; NT]; NT], a_e: [[0.0; NT]; NE], a_zero: true }
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
        let (mut fp, mut qp) = ([0.0; NT], [0.0; NE]);
        for j in 0..NT {
            let mut zp = self.z;
            let d = 1e-5 * (1.0 + self.z[j].abs());
            zp[j] += d;
            rates(&zp, &mut fp, &mut qp);
            for i in 0..NT {
                self.a[i][j] = (fp[i] - fz[i]) / d;
            }
            for i in 0..NE {
                self.a_e[i][j] = (qp[i] - q[i]) / d;
            }
        }
        self.a_cols = transpose(&self.a);
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
    /// by the level's matrices or the vector solution.
    fn linear(&self, phi: Option<&Phi<NT>>, h: f64, g0: &[f64; NT], d: &([f64; NT], [f64; NT])) -> [f64; NT] {
        if self.a_zero {
            // A = 0: Φ_k = h/k!·I, f₀ = g₀.
            let (c1, c2) = (h * h / 2.0, h * h * h / 6.0);
            return std::array::from_fn(|i| self.z[i] + h * self.fz[i] + c1 * d.0[i] + c2 * d.1[i]);
        }
        match phi {
            Some(p) => {
                // z₀ + Φ₁·f₀ + h·Φ₂·g' + h²·Φ₃·g''
                let mut z = self.z;
                mul_vec_add_cols(&p.cols[0], &self.fz, &mut z);
                mul_vec_add_cols(&p.cols[1], &d.0.map(|x| x * h), &mut z);
                mul_vec_add_cols(&p.cols[2], &d.1.map(|x| x * h * h), &mut z);
                z
            }
            None => solve_linear(&self.a, h, &self.z, [g0, &d.0, &d.1]),
        }
    }

    /// The predictor of a step of `h` s (`phi`: the level's matrices, None:
    /// an odd step): z* and g₀.
    pub fn predict(&self, phi: Option<&Phi<NT>>, h: f64) -> ([f64; NT], [f64; NT]) {
        let az0 = mul_vec_cols(&self.a_cols, &self.z);
        let g0: [f64; NT] = std::array::from_fn(|i| self.fz[i] - az0[i]);
        // The polynomial through the stored g and g₀.
        let mut pts: [(f64, &[f64; NT]); 3] = [(0.0, &g0); 3];
        let n = self.hist.len().min(2);
        for (k, (t, g, _)) in self.hist[self.hist.len() - n..].iter().enumerate() {
            pts[k] = (t - self.t, g);
        }
        pts[n] = (0.0, &g0);
        (self.linear(phi, h, &g0, &derivatives(&pts[..=n])), g0)
    }

    /// The corrector of the step predicted by [`Thermal::predict`] (`zp`,
    /// `g0`), given the model's rates `fp`, `qp` at the predicted end.
    pub fn correct(&self, phi: Option<&Phi<NT>>, h: f64, zp: &[f64; NT], g0: &[f64; NT], fp: &[f64; NT], qp: &[f64; NE]) -> Trial {
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
        let z1 = self.linear(phi, h, g0, &derivatives(&pts[..m + 2]));
        let dz: [f64; NT] = std::array::from_fn(|i| z1[i] - zp[i]);
        let adz = mul_vec_cols(&self.a_cols, &dz);
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
