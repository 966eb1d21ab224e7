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
//!
//! Split by topic: this file holds the scheme's state and results
//! ([`Thermal`], [`Prediction`], [`Trial`]) and taking a step; `jacobian`
//! the linear part (A, its drift Â − A, f anew at a restart); `step` the
//! predictor and the corrector with their interpolation and drift solve.

mod jacobian;
mod step;

use super::dense::Mat;
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
    /// Aᵀ, for products A·v ([`mul_vec_cols`](super::dense::mul_vec_cols)).
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
