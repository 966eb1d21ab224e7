//! Adaptive Rosenbrock integrators for small stiff systems (the hydraulic
//! states: line pressures, piston, shaft speed; eigenvalues to −5000 1/s
//! when a check valve opens), in the formulation of Hairer & Wanner,
//! "Solving ODEs II" (1996), §IV.7, as the KPP/FATODE codes write it:
//!
//!   G = 1/(γh) − W,  Y_i = y₀ + Σ_{j<i} a_ij·K_j,
//!   G·K_i = f(t₀ + α_i·h, Y_i) + Σ_{j<i} c_ij/h·K_j + γ_i·h·∂f/∂t,
//!   y₁ = y₀ + Σ m_j·K_j,  error = Σ e_j·K_j,
//!
//! W the Jacobian (forward differences) or, for a W-method, an older one.
//!
//! * RODAS4 (6 stages, order 4(3), L-stable, stiffly accurate): needs the
//!   Jacobian of every step, 12 evaluations per step on 5 states.
//! * ROS34PW2 (Rang & Angermann 2005; 4 stages, order 3(2), L-stable,
//!   stiffly accurate, a W-method: order 3 with any W): keeps its Jacobian
//!   for up to `jac_max_age` steps, 5 evaluations per step.
//!
//! Written here rather than taken from diffsol because the system is 5
//! states: a step is a few hundred nanoseconds on fixed-size arrays against
//! diffsol's ~6 µs per BDF step on this model (`docs/reference-speed.md`).

use super::dense::{Lu, Mat};

mod tableau;
#[cfg(test)]
mod tests;

pub use tableau::{Tableau, RODAS4};

/// Steps to `t_max` up to which they are made equal (see `Rosenbrock::step`):
/// then they reuse one factorisation. Measured (`FastPlant::run`): Case 2
/// 211.9 → 205.8 M instructions, Case 1 unchanged; made equal at any
/// distance, Case 2 206.5 M but Case 1 3.69 → 3.86 M (13 more thermal steps).
const EQUAL_STEPS_MAX: u32 = 4;

/// Most stages of a tableau here.
pub(crate) const S_MAX: usize = 6;

/// Counters of a Rosenbrock integrator.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct RosStats {
    /// Accepted steps.
    pub steps: u64,
    /// Rejected steps.
    pub rejected: u64,
    /// Right-hand-side evaluations (stages, Jacobian columns, ∂f/∂t).
    pub evals: u64,
    /// Jacobians taken (N evaluations each).
    pub jacobians: u64,
}

/// Why a Rosenbrock integration stopped.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum RosError {
    /// The step fell below the minimum at this time, s.
    StepUnderflow(f64),
    /// G = 1/(γh) − J was singular or not finite at this time, s.
    Singular(f64),
}

/// An adaptive Rosenbrock integrator of an N-state system.
#[derive(Debug, Clone)]
pub struct Rosenbrock<const N: usize> {
    /// Relative tolerance.
    pub rtol: f64,
    /// Absolute tolerances, in the states' units.
    pub atol: [f64; N],
    /// Typical magnitudes of the states (scale of the Jacobian's differences).
    pub scale: [f64; N],
    /// Step the next integration starts with, s.
    pub h: f64,
    /// Counters.
    pub stats: RosStats,
    tab: Tableau,
    /// Steps a Jacobian is kept (0: every step, as RODAS4 needs).
    jac_max_age: u32,
    /// The kept Jacobian, the steps it has served and the step it was taken at.
    jac: Option<(Mat<N>, u32, f64)>,
    /// The factorised iteration matrix 1/(γh) − W of the kept Jacobian
    /// and the step h it was built for: a step of the same length (to
    /// 1e-12: equal steps to `t_max` differ in their last bits; W then
    /// differs by δ·I, δ ≈ 1e-12/(γh)) reuses it. Steps of equal length are
    /// frequent here (steps cut at thermal step ends on a power-of-two
    /// ladder, halved remnants): measured, Case 2 221.6 → 213.1 M
    /// instructions, outputs bit-identical. Reused for steps within 1.2×,
    /// 1.5× or 2× of h (a W-method keeps its order with W = J + δ·I),
    /// the rejections rose 1.7–2.8-fold and Case 2 took 223–273 M.
    lu: Option<(Lu<N>, f64)>,
}

impl<const N: usize> Rosenbrock<N> {
    /// An integrator with tolerances `rtol`, `atol`, state magnitudes
    /// `scale` and first step `h0`.
    pub fn new(rtol: f64, atol: [f64; N], scale: [f64; N], h0: f64) -> Self {
        Self::with_method(RODAS4, 0, rtol, atol, scale, h0)
    }

    /// An integrator with the method `tab`, keeping a Jacobian for up to
    /// `jac_max_age` steps (only a W-method keeps its order so).
    pub fn with_method(tab: Tableau, jac_max_age: u32, rtol: f64, atol: [f64; N], scale: [f64; N], h0: f64) -> Self {
        Self { rtol, atol, scale, h: h0, stats: RosStats::default(), tab, jac_max_age, jac: None, lu: None }
    }

    /// Forgets the kept Jacobian (the right-hand side changed: a breakpoint).
    pub fn forget_jacobian(&mut self) {
        self.jac = None;
        self.lu = None;
    }

    /// Integrates y' = f(t, y) from `t0` to `t1` with RODAS4, calling
    /// `on_point(t, y, f(t, y))` at `t0` and after every accepted step
    /// (the points of a cubic Hermite dense output). `f(t, y, dy)` fills dy.
    pub fn integrate<F, P>(&mut self, mut f: F, t0: f64, y: &mut [f64; N], t1: f64, mut on_point: P) -> Result<(), RosError>
    where
        F: FnMut(f64, &[f64; N], &mut [f64; N]),
        P: FnMut(f64, &[f64; N], &[f64; N]),
    {
        let mut t = t0;
        let mut f0 = [0.0; N];
        f(t, y, &mut f0);
        self.stats.evals += 1;
        on_point(t, y, &f0);
        while t1 - t > 1e-14 * t1.abs().max(1.0) {
            t = self.step(&mut f, t, y, &mut f0, t1, false)?;
            on_point(t, y, &f0);
        }
        Ok(())
    }

    /// One accepted step from (`t`, `y`) with `f0` = f(t, y), ending at or
    /// before `t_max` (exactly at `t_max` when the step reaches it or would
    /// leave less than 5 % of itself). Updates `y` and `f0` to the new point
    /// and returns its time; the next step size is kept in `self.h`.
    ///
    /// With `lazy_end`, a step that ends at `t_max` leaves f there to the
    /// caller (`f0` all NaN, no evaluation): [`super::hydraulic::HydTrack`]
    /// takes it only where it is read (the thermal step's end usually
    /// takes it anew with the new temperatures).
    pub fn step<F>(&mut self, f: &mut F, t: f64, y: &mut [f64; N], f0: &mut [f64; N], t_max: f64, lazy_end: bool) -> Result<f64, RosError>
    where
        F: FnMut(f64, &[f64; N], &mut [f64; N]),
    {
        // The stage count as a constant for the two tableaus here (the
        // stage loops unrolled: the same operations in the same order,
        // fewer instructions), the tableau's own count otherwise.
        match self.tab.s {
            4 => self.step_s::<F, 4>(f, t, y, f0, t_max, lazy_end),
            6 => self.step_s::<F, 6>(f, t, y, f0, t_max, lazy_end),
            _ => self.step_s::<F, 0>(f, t, y, f0, t_max, lazy_end),
        }
    }

    /// [`Rosenbrock::step`] with `S` stages (0: `self.tab.s`).
    #[inline(always)]
    fn step_s<F, const S: usize>(&mut self, f: &mut F, t: f64, y: &mut [f64; N], f0: &mut [f64; N], t_max: f64, lazy_end: bool) -> Result<f64, RosError>
    where
        F: FnMut(f64, &[f64; N], &mut [f64; N]),
    {
        let tab = &self.tab;
        let ns = if S == 0 { tab.s } else { S };
        let h_min = 1e-14 * t_max.abs().max(1.0);
        let h_try = self.h;
        // Near `t_max`, equal steps to it rather than full ones and a
        // remnant: a remnant far below the kept Jacobian's step takes a new
        // Jacobian, and so does the full step after it (measured on Case 2:
        // 9.2 k Jacobians for 28.6 k steps, 6.9 k of them for the step
        // ratio); equal steps also reuse their factorisation (`lu`).
        // (For a W-method only: with a Jacobian every step, as RODAS4
        // takes it, there is no factorisation to share, and the equal steps
        // took a stiff test problem from within 1e-6 to 1.32e-6.)
        let d = t_max - t;
        let mut h = if 1.05 * h_try >= d {
            d
        } else if t + 2.0 * h_try > t_max {
            0.5 * d
        } else if self.jac_max_age > 0 && d <= EQUAL_STEPS_MAX as f64 * h_try {
            d / (d / h_try).ceil()
        } else {
            h_try
        };
        // ∂f/∂t anew every step (forward difference, backwards at the
        // interval's end: a schedule may step there). Kept with the
        // Jacobian instead, as a W-method allows, it cost Case 2 27 % more
        // hydraulic steps and twice the rejections.
        let mut fp = [0.0; N];
        let dt = 1e-7 * t.abs().max(1.0);
        let dt = if t + dt > t_max { -dt } else { dt };
        f(t + dt, y, &mut fp);
        self.stats.evals += 1;
        let dfdt: [f64; N] = std::array::from_fn(|i| (fp[i] - f0[i]) / dt);
        let mut rejected = false;
        loop {
            // A kept Jacobian serves while the step stays within 4× of the
            // step it was taken at: a W-method keeps its order with any W,
            // but a stiff steady state (a check valve holding a line at
            // the accumulator pressure) drifts under much longer steps
            // with an old one (measured: 0.01 bar in Case 1).
            // (Borrowed where kept, not copied: a step reads them only.)
            let kept = matches!(self.jac, Some((_, age, hj)) if age < self.jac_max_age && h <= 4.0 * hj && hj <= 4.0 * h);
            if !kept {
                let j = jacobian(f, t, y, f0, &self.scale, &mut self.stats);
                self.jac = Some((j, 0, h));
                self.lu = None;
            }
            let lu_kept = matches!(self.lu, Some((_, hl)) if (h - hl).abs() <= 1e-12 * hl);
            if !lu_kept {
                let Some((jac, _, _)) = &self.jac else { unreachable!("a Jacobian was just taken") };
                let mut g = *jac;
                for (i, row) in g.iter_mut().enumerate() {
                    for x in row.iter_mut() {
                        *x = -*x;
                    }
                    row[i] += 1.0 / (tab.gamma[0] * h);
                }
                let lu = Lu::new(g).ok_or(RosError::Singular(t))?;
                self.lu = Some((lu, h));
            }
            let Some((lu, _)) = &self.lu else { unreachable!("an LU was just built") };
            let mut k = [[0.0; N]; S_MAX];
            let mut fs = *f0;
            for s in 0..ns {
                if s > 0 {
                    let mut ys = *y;
                    for (j, kj) in k.iter().enumerate().take(s) {
                        let a = tab.a[s][j];
                        if a != 0.0 {
                            for i in 0..N {
                                ys[i] += a * kj[i];
                            }
                        }
                    }
                    f(t + tab.alpha[s] * h, &ys, &mut fs);
                    self.stats.evals += 1;
                }
                let mut rhs = fs;
                for (j, kj) in k.iter().enumerate().take(s) {
                    let c = tab.c[s][j] / h;
                    for i in 0..N {
                        rhs[i] += c * kj[i];
                    }
                }
                let gh = tab.gamma[s] * h;
                for i in 0..N {
                    rhs[i] += gh * dfdt[i];
                }
                lu.solve(&mut rhs);
                k[s] = rhs;
            }
            let mut y1 = *y;
            let mut err = 0.0;
            for i in 0..N {
                let mut e = 0.0;
                for ((m, es), ks) in tab.m.iter().zip(&tab.e).zip(&k).take(ns) {
                    y1[i] += m * ks[i];
                    e += es * ks[i];
                }
                let sc = self.atol[i] + self.rtol * y[i].abs().max(y1[i].abs());
                err += (e / sc).powi(2);
            }
            let err = (err / N as f64).sqrt();
            // err^(1/elo), without a `pow` for the two tableaus here.
            let root = match tab.elo {
                3.0 => cbrt_factor(err),
                4.0 => err.sqrt().sqrt(),
                e => err.powf(1.0 / e),
            };
            let fac = (0.9 / root).clamp(0.2, 6.0);
            if err <= 1.0 && err.is_finite() {
                let t1 = if h == t_max - t { t_max } else { t + h };
                *y = y1;
                if lazy_end && t1 == t_max {
                    *f0 = [f64::NAN; N];
                } else {
                    f(t1, y, f0);
                    self.stats.evals += 1;
                }
                self.stats.steps += 1;
                if let Some((_, age, _)) = &mut self.jac {
                    *age += 1;
                }
                // A step cut short by t_max keeps the step it was cut from.
                self.h = if rejected {
                    h * fac.min(1.0)
                } else if h < h_try {
                    (h * fac).max(h_try)
                } else {
                    h * fac
                };
                return Ok(t1);
            }
            self.stats.rejected += 1;
            rejected = true;
            // A kept Jacobian may be what failed: take a fresh one.
            if self.jac.is_some_and(|(_, age, _)| age > 0) {
                self.jac = None;
                self.lu = None;
            }
            h *= if err.is_finite() { fac.min(0.5) } else { 0.1 };
            if h < h_min {
                return Err(RosError::StepUnderflow(t));
            }
        }
    }

}

/// The Jacobian at (t, y) by forward differences, `f0` = f(t, y), with
/// increments relative to the states' magnitudes `scale`.
fn jacobian<const N: usize, F>(f: &mut F, t: f64, y: &[f64; N], f0: &[f64; N], scale: &[f64; N], stats: &mut RosStats) -> Mat<N>
where
    F: FnMut(f64, &[f64; N], &mut [f64; N]),
{
    let mut jac: Mat<N> = [[0.0; N]; N];
    let mut yp = *y;
    let mut fp = [0.0; N];
    for j in 0..N {
        let d = 1e-7 * (y[j].abs() + scale[j]);
        yp[j] = y[j] + d;
        f(t, &yp, &mut fp);
        for i in 0..N {
            jac[i][j] = (fp[i] - f0[i]) / d;
        }
        yp[j] = y[j];
    }
    stats.evals += N as u64;
    stats.jacobians += 1;
    jac
}

/// ∛x for the step-size factor, relative error below 1e-13 (test below):
/// a first guess from the exponent's bits divided by three, then two
/// Halley steps (cubic convergence: ~3 % → ~3e-5 → ~1e-14). ~25
/// instructions against ~130 of the software `cbrt` (the step sizes only
/// need a few digits; ~125 roots a Case 1 run). Beyond 1e±300, zero, ∞ and
/// NaN: `f64::cbrt`.
#[inline]
fn cbrt_factor(x: f64) -> f64 {
    if !(1e-300..1e300).contains(&x) {
        return x.cbrt();
    }
    let mut y = f64::from_bits(x.to_bits() / 3 + 0x2A9F_7893_782D_A1CE);
    for _ in 0..2 {
        let y3 = y * y * y;
        y *= (y3 + 2.0 * x) / (2.0 * y3 + x);
    }
    y
}
