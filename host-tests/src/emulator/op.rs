//! The emulated machine's operating point at one instant: shaft speed,
//! motor current, port pressures, piston speed, leakage and throttle
//! flows (quasi-static: the hydraulics settle in milliseconds), for the
//! servo runs (position loop, spring load) and the throttle runs (speed
//! and needle drop schedules).

use super::missions::{linear_at, step_at};
use super::plant::{Op, Plant, N};
use super::props::oil_rho;
use crate::physics::candidates::Candidate;
use std::f64::consts::PI;

impl Plant<'_> {
    /// Operating point at `t` with temperatures `y` and piston position `x`.
    pub fn op(&self, t: f64, y: &[f64], x: f64) -> Op {
        let p = self.p;
        let mu_case = self.nu(y[N::CaseOil as usize]) * oil_rho(y[N::CaseOil as usize]);
        let kl = self.k_leak(mu_case);
        let air = step_at(&self.m.air, t) + self.mag(Candidate::ForcedConvection).unwrap_or(0.0);
        let d_rad = p.displacement_m3 / (2.0 * PI);
        let churn = |w: f64| self.mag(Candidate::ChurningLoss).map_or(0.0, |k| k * w.abs().powf(1.5) * w.signum());
        if self.m.scenario.is_servo() {
            let v = p.pos_gain * (linear_at(&self.m.x_ref, t) - x);
            let fc = self.mag(Candidate::CoulombFriction).map_or(0.0, |f| f * (v / 1e-3).tanh());
            // Spring, spring damping, seal friction; the 13.5 kg load's
            // inertia (< 30 N here) is left out.
            let force = 245e3 * x + 15e3 * v + p.seal_viscous * v + fc;
            let dp = force / 1526.81e-6;
            let q_leak = kl * dp.abs();
            let q = 1526.81e-6 * v + p.act_leak * dp + q_leak * dp.signum();
            let omega = q / d_rad;
            let torque = d_rad * dp + p.eta_m * d_rad * dp.abs() * omega.signum() + churn(omega);
            let drag = self.iron_drag_nm(omega);
            let (pa, pb) = (p.boost_pa + dp.max(0.0), p.boost_pa + (-dp).max(0.0));
            Op { omega, current_a: (torque.abs() + drag) / p.kt_nm_per_a, p_a: pa, p_b: pb, v, q_leak, q_path: 0.0, air }
        } else {
            let omega = step_at(&self.m.speed, t) * PI / 30.0;
            // Needle opening set for the target drop at the nominal flow
            // (first guess without leakage), then the actual drop.
            let q_nom = d_rad * omega;
            let target = step_at(&self.m.dp_bar, t).max(0.5) * 1e5;
            let rho = oil_rho(y[N::BallOil as usize]);
            let area = q_nom / (p.needle_cd * (2.0 * target / rho).sqrt());
            let mut q_path = q_nom;
            let mut dp = target;
            for _ in 0..3 {
                q_path = (q_nom - kl * dp).max(0.0);
                dp = 0.5 * rho * (q_path / (p.needle_cd * area)).powi(2) + self.hose_dp(q_path, y[N::LoopOil as usize]);
            }
            let torque = d_rad * dp * (1.0 + p.eta_m) + churn(omega);
            let drag = self.iron_drag_nm(omega);
            Op {
                omega,
                current_a: (torque + drag) / p.kt_nm_per_a,
                p_a: p.boost_pa + dp,
                p_b: p.boost_pa,
                v: 0.0,
                q_leak: kl * dp,
                q_path,
                air,
            }
        }
    }
}
