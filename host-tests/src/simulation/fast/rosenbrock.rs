//! An adaptive Rosenbrock integrator for small stiff systems (the
//! hydraulic states: line pressures, piston, shaft speed; eigenvalues to
//! −5000 1/s when a check valve opens), in the formulation of Hairer &
//! Wanner, "Solving ODEs II" (1996), §IV.7, as the KPP/FATODE codes write it:
//!
//!   G = 1/(γh) − J,  Y_i = y₀ + Σ_{j<i} a_ij·K_j,
//!   G·K_i = f(t₀ + α_i·h, Y_i) + Σ_{j<i} c_ij/h·K_j + γ_i·h·∂f/∂t,
//!   y₁ = y₀ + Σ m_j·K_j,  error = Σ e_j·K_j.
//!
//! RODAS4 (6 stages, order 4, embedded 3, L-stable, stiffly accurate) with
//! a forward-difference Jacobian and ∂f/∂t. Written here rather than taken
//! from diffsol because the system is 5 states: a step is ~1 µs on
//! fixed-size arrays against diffsol's ~6 µs per BDF step on this model
//! (`docs/reference-speed.md`).

use super::dense::{Lu, Mat};

/// A Rosenbrock tableau (strictly lower triangular a and c by rows).
#[derive(Debug, Clone, Copy)]
pub struct Tableau<const S: usize> {
    /// Stage abscissae α_i.
    pub alpha: [f64; S],
    /// γ_i = Σ_j γ_ij (γ₁ = γ, the diagonal).
    pub gamma: [f64; S],
    /// a_ij, i > j.
    pub a: [[f64; S]; S],
    /// c_ij, i > j.
    pub c: [[f64; S]; S],
    /// Solution weights.
    pub m: [f64; S],
    /// Error weights.
    pub e: [f64; S],
    /// Whether stage i evaluates f anew (else it reuses the previous stage's).
    pub new_f: [bool; S],
    /// Order of the error estimate plus one (the step-size exponent).
    pub elo: f64,
}

/// RODAS4 (Hairer & Wanner 1996): 6 stages, order 4(3), L-stable.
pub const RODAS4: Tableau<6> = {
    let a7 = 1.221224509226641;
    let a8 = 6.019134481288629;
    let a9 = 12.53708332932087;
    let a10 = -0.687886036105895;
    Tableau {
        alpha: [0.0, 0.386, 0.21, 0.63, 1.0, 1.0],
        gamma: [0.25, -0.1043, 0.1035, -0.03620000000000023, 0.0, 0.0],
        a: [
            [0.0; 6],
            [1.544, 0.0, 0.0, 0.0, 0.0, 0.0],
            [0.9466785280815826, 0.2557011698983284, 0.0, 0.0, 0.0, 0.0],
            [3.314825187068521, 2.896124015972201, 0.9986419139977817, 0.0, 0.0, 0.0],
            [a7, a8, a9, a10, 0.0, 0.0],
            [a7, a8, a9, a10, 1.0, 0.0],
        ],
        c: [
            [0.0; 6],
            [-5.6688, 0.0, 0.0, 0.0, 0.0, 0.0],
            [-2.430093356833875, -0.2063599157091915, 0.0, 0.0, 0.0, 0.0],
            [-0.1073529058151375, -9.594562251023355, -20.47028614809616, 0.0, 0.0, 0.0],
            [7.496443313967647, -10.24680431464352, -33.99990352819905, 11.7089089320616, 0.0, 0.0],
            [8.083246795921522, -7.981132988064893, -31.52159432874371, 16.31930543123136, -6.058818238834054, 0.0],
        ],
        m: [a7, a8, a9, a10, 1.0, 1.0],
        e: [0.0, 0.0, 0.0, 0.0, 0.0, 1.0],
        new_f: [true; 6],
        elo: 4.0,
    }
};

/// Counters of a Rosenbrock integrator.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct RosStats {
    /// Accepted steps.
    pub steps: u64,
    /// Rejected steps.
    pub rejected: u64,
    /// Right-hand-side evaluations (stages, Jacobian columns, ∂f/∂t).
    pub evals: u64,
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
}

impl<const N: usize> Rosenbrock<N> {
    /// An integrator with tolerances `rtol`, `atol`, state magnitudes
    /// `scale` and first step `h0`.
    pub fn new(rtol: f64, atol: [f64; N], scale: [f64; N], h0: f64) -> Self {
        Self { rtol, atol, scale, h: h0, stats: RosStats::default() }
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
            t = self.step(&mut f, t, y, &mut f0, t1)?;
            on_point(t, y, &f0);
        }
        Ok(())
    }

    /// One accepted step from (`t`, `y`) with `f0` = f(t, y), ending at or
    /// before `t_max` (exactly at `t_max` when the step reaches it or would
    /// leave less than 5 % of itself). Updates `y` and `f0` to the new point
    /// and returns its time; the next step size is kept in `self.h`.
    pub fn step<F>(&mut self, f: &mut F, t: f64, y: &mut [f64; N], f0: &mut [f64; N], t_max: f64) -> Result<f64, RosError>
    where
        F: FnMut(f64, &[f64; N], &mut [f64; N]),
    {
        let tab = &RODAS4;
        const S: usize = 6;
        let h_min = 1e-14 * t_max.abs().max(1.0);
        let h_try = self.h;
        let mut h = h_try.min(t_max - t);
        if t + 1.05 * h >= t_max {
            h = t_max - t;
        }
        // Jacobian by forward differences, ∂f/∂t likewise (backwards at the
        // interval's end: a schedule may step there).
        let mut jac: Mat<N> = [[0.0; N]; N];
        let mut yp = *y;
        let mut fp = [0.0; N];
        for j in 0..N {
            let d = 1e-7 * (y[j].abs() + self.scale[j]);
            yp[j] = y[j] + d;
            f(t, &yp, &mut fp);
            for i in 0..N {
                jac[i][j] = (fp[i] - f0[i]) / d;
            }
            yp[j] = y[j];
        }
        let dt = 1e-7 * t.abs().max(1.0);
        let dt = if t + dt > t_max { -dt } else { dt };
        f(t + dt, y, &mut fp);
        self.stats.evals += N as u64 + 1;
        let mut dfdt = [0.0; N];
        for i in 0..N {
            dfdt[i] = (fp[i] - f0[i]) / dt;
        }
        let mut rejected = false;
        loop {
            let mut g = jac;
            for (i, row) in g.iter_mut().enumerate() {
                for x in row.iter_mut() {
                    *x = -*x;
                }
                row[i] += 1.0 / (tab.gamma[0] * h);
            }
            let lu = Lu::new(g).ok_or(RosError::Singular(t))?;
            let mut k = [[0.0; N]; S];
            let mut fs = *f0;
            for s in 0..S {
                if s > 0 && tab.new_f[s] {
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
                for s in 0..S {
                    y1[i] += tab.m[s] * k[s][i];
                    e += tab.e[s] * k[s][i];
                }
                let sc = self.atol[i] + self.rtol * y[i].abs().max(y1[i].abs());
                err += (e / sc).powi(2);
            }
            let err = (err / N as f64).sqrt();
            let fac = (0.9 / err.powf(1.0 / tab.elo)).clamp(0.2, 6.0);
            if err <= 1.0 && err.is_finite() {
                let t1 = if h == t_max - t { t_max } else { t + h };
                *y = y1;
                f(t1, y, f0);
                self.stats.evals += 1;
                self.stats.steps += 1;
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
            h *= if err.is_finite() { fac.min(0.5) } else { 0.1 };
            if h < h_min {
                return Err(RosError::StepUnderflow(t));
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Convergence order on y' = −y + sin t (exact solution known): halving
    /// a fixed step must cut the error at t = 2 by ~2⁴ (order 4; 12–20
    /// accepted around 16). A wrong tableau coefficient breaks the order.
    #[test]
    fn rodas4_is_fourth_order_on_a_nonstiff_problem() {
        // y' = -y + sin(t) exact: y = Ce^{-t} + (sin t - cos t)/2.
        let run = |h: f64| {
            let mut r = Rosenbrock::<1>::new(1.0, [1.0], [1.0], h);
            let mut y = [1.0];
            // tolerances so loose that no step is rejected or enlarged:
            // fixed steps h by integrating interval by interval.
            let n = (2.0 / h).round() as usize;
            for k in 0..n {
                r.h = h;
                r.integrate(|t, y, d| d[0] = -y[0] + t.sin(), k as f64 * h, &mut y, (k + 1) as f64 * h, |_, _, _| {}).expect("ok");
            }
            let t: f64 = 2.0;
            let c = 1.0 + 0.5;
            (y[0] - (c * (-t).exp() + (t.sin() - t.cos()) / 2.0)).abs()
        };
        let (e1, e2) = (run(0.1), run(0.05));
        let ratio = e1 / e2;
        assert!((12.0..20.0).contains(&ratio), "errors {e1:e} {e2:e}, ratio {ratio}");
    }

    /// Adaptive integration of a stiff forced system (λ = −5000 1/s, the
    /// check-valve time scale): y' = −5000·(y − sin t) + cos t has the
    /// solution y = sin t from y(0) = 0. At tolerances 1e-6 the error at
    /// t = 10 s stays below 1e-6, and the steps are set by the forcing,
    /// not by the stiff eigenvalue (an explicit method would need
    /// 10 s / 0.4 ms = 25 000 steps; measured here: 93).
    #[test]
    fn rodas4_adaptive_on_a_stiff_forced_problem() {
        let mut r = Rosenbrock::<1>::new(1e-6, [1e-6], [1.0], 1e-4);
        let mut y = [0.0];
        r.integrate(|t, y, d| d[0] = -5000.0 * (y[0] - t.sin()) + t.cos(), 0.0, &mut y, 10.0, |_, _, _| {}).expect("ok");
        println!("{:?}, error {:.2e}", r.stats, (y[0] - 10f64.sin()).abs());
        assert!((y[0] - 10f64.sin()).abs() < 1e-6, "y = {} vs {}", y[0], 10f64.sin());
        assert!(r.stats.steps < 1000, "{:?}", r.stats);
    }
}
