//! The thermal half of the multirate scheme: exponential Adams steps of
//! order 2 on z' = A·z + g(t, z), z the node temperatures.
//!
//! A is the Jacobian of the model's own heat balances with respect to the
//! temperatures (forward differences of `Model::rhs`); g = f − A·z is what
//! the linear part misses: the operating point's variation within the
//! step, temperature dependent conductances, losses and capacities, the
//! drift of A itself. A step from z₀ (f₀ = f(z₀)):
//!
//! * predictor: g extrapolated with the last step's slope s,
//!   z* = z₀ + Φ₁·f₀ + h·Φ₂·s;
//! * one model evaluation f* = f(t₁, z*), g* = f* − A·z*;
//! * corrector: g interpolated linearly, z₁ = z₀ + Φ₁·f₀ + Φ₂·(g* − g₀),
//!   exact for a linear network with forcing linear in time;
//! * error estimate (z₁ − z*)/6 (Milne: the corrector's error constant is a
//!   sixth of the difference of the two), and f₁ = f* + A·(z₁ − z*) without
//!   a second evaluation.
//!
//! Φ_k = h·φ_k(hA) come from the cached matrices of a step level or, for
//! an odd step, from the vector solution of [`super::phi::solve_linear`].
//! The energy integrals follow by the trapezoidal rule on the heat rates.

use super::dense::{mul_vec, mul_vec_add, Mat};
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
    /// dg/dt from the last step (None after a restart).
    pub slope: Option<[f64; NT]>,
    /// ∂(dz/dt)/∂z, 1/s.
    pub a: Mat<NT>,
    /// ∂q/∂z, W/K.
    pub a_e: [[f64; NT]; NE],
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
    /// g* − g₀.
    pub dg: [f64; NT],
    /// Largest |corrector − predictor|/6 over the nodes, K.
    pub err_k: f64,
    /// Node of the largest error.
    pub worst: usize,
}

impl Thermal {
    /// A state at temperatures `z` and energies `e` (call [`Thermal::jacobian`] first).
    pub fn new(z: [f64; NT], e: [f64; NE]) -> Self {
        Self { z, e, fz: [0.0; NT], q: [0.0; NE], slope: None, a: [[0.0; NT]; NT], a_e: [[0.0; NT]; NE] }
    }

    /// f anew at z, and A by forward differences (N_NODES more
    /// evaluations). With `keep_history` the slope of g = f − A·z carries
    /// over to the new A (g' changes by (A_old − A_new)·z', z' ≈ f).
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
        self.slope = match (keep_history, self.slope) {
            (true, Some(mut s)) => {
                for (i, si) in s.iter_mut().enumerate() {
                    *si += (0..NT).map(|j| (a_old[i][j] - self.a[i][j]) * fz[j]).sum::<f64>();
                }
                Some(s)
            }
            _ => None,
        };
        (self.fz, self.q) = (fz, q);
    }

    /// f anew at z (the forcing changed: a breakpoint, the far side of a
    /// branch switch, a valve); `keep_history` keeps the slope of g.
    pub fn fresh(&mut self, rates: &mut impl Rates, keep_history: bool) {
        rates(&self.z, &mut self.fz, &mut self.q);
        if !keep_history {
            self.slope = None;
        }
    }

    /// z(h) of z' = A·z + c₀ + c₁·s from z₀, by the level's matrices or the
    /// vector solution.
    fn linear(&self, phi: Option<&Phi<NT>>, h: f64, c0: &[f64; NT], c1: &[f64; NT]) -> [f64; NT] {
        match phi {
            Some(p) => {
                // z₀ + Φ₁·(A·z₀ + c₀) + h·Φ₂·c₁
                let mut f0 = mul_vec(&self.a, &self.z);
                for (x, c) in f0.iter_mut().zip(c0) {
                    *x += c;
                }
                let mut z = self.z;
                mul_vec_add(&p.p1, &f0, &mut z);
                let hc1 = c1.map(|x| x * h);
                mul_vec_add(&p.p2, &hc1, &mut z);
                z
            }
            None => solve_linear(&self.a, h, &self.z, c0, c1),
        }
    }

    /// Tries a step of `h` s (`phi`: the level's matrices, None: an odd
    /// step); `rates_end` evaluates the model at the step's end.
    pub fn trial(&self, phi: Option<&Phi<NT>>, h: f64, rates_end: &mut impl Rates) -> Trial {
        let az0 = mul_vec(&self.a, &self.z);
        let g0: [f64; NT] = std::array::from_fn(|i| self.fz[i] - az0[i]);
        let zp = self.linear(phi, h, &g0, &self.slope.unwrap_or([0.0; NT]));
        let (mut fp, mut qp) = ([0.0; NT], [0.0; NE]);
        rates_end(&zp, &mut fp, &mut qp);
        let azp = mul_vec(&self.a, &zp);
        let dg: [f64; NT] = std::array::from_fn(|i| fp[i] - azp[i] - g0[i]);
        let z1 = self.linear(phi, h, &g0, &dg.map(|x| x / h));
        let dz: [f64; NT] = std::array::from_fn(|i| z1[i] - zp[i]);
        let adz = mul_vec(&self.a, &dz);
        let f1 = std::array::from_fn(|i| fp[i] + adz[i]);
        let q1 = std::array::from_fn(|i| qp[i] + self.a_e[i].iter().zip(&dz).map(|(p, q)| p * q).sum::<f64>());
        let (mut err_k, mut worst) = (0.0, 0);
        for (i, d) in dz.iter().enumerate() {
            if d.abs() / 6.0 > err_k {
                (err_k, worst) = (d.abs() / 6.0, i);
            }
        }
        Trial { h, z1, f1, q1, dg, err_k, worst }
    }

    /// Takes the tried step.
    pub fn accept(&mut self, t: &Trial) {
        for i in 0..NE {
            self.e[i] += 0.5 * t.h * (self.q[i] + t.q1[i]);
        }
        self.slope = Some(t.dg.map(|x| x / t.h));
        (self.z, self.fz, self.q) = (t.z1, t.f1, t.q1);
    }
}
