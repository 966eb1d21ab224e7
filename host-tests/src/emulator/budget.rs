//! The case (drain) oil's heat balance by source, read-only
//! ([`Plant::case_budget`]): the same laws as the right-hand side, for
//! heat-source audits against the reference.

use super::plant::{CaseBudget, Plant, N, NS};
use super::props::{self, oil_cp, oil_rho};
use std::f64::consts::PI;

impl Plant<'_> {
    /// The case (drain) oil's heat balance at `t` with state `y`, read-only
    /// (the same laws as [`Plant::rhs`], for heat-source audits against the
    /// reference): what enters the case oil by source and what its films
    /// take to the housing.
    pub fn case_budget(&self, t: f64, y: &[f64]) -> CaseBudget {
        let p = self.p;
        let o = self.op(t, y, y[NS - 1]);
        let tn = |n: N| y[n as usize];
        let dp = o.p_a - o.p_b;
        let d_rad = p.displacement_m3 / (2.0 * PI);
        let mech = p.eta_m * d_rad * dp.abs() * o.omega.abs();
        let at = if self.m.scenario.is_servo() { 0.0 } else { props::oil_alpha(tn(N::PortOil)) * (tn(N::PortOil) + 273.15) };
        let nu_case = self.nu(tn(N::CaseOil));
        let film: f64 = p.a_case.iter().map(|&a| self.case_film(o.omega, a, nu_case, tn(N::CaseOil))).sum();
        let wall = p.a_case[0] * tn(N::Barrel) + p.a_case[1] * tn(N::EndCap);
        let wall = wall / (p.a_case[0] + p.a_case[1]);
        let rho_cp = oil_rho(tn(N::PortOil)) * oil_cp(tn(N::PortOil));
        CaseBudget {
            mech_w: p.mech_split[1] * mech,
            mech_total_w: mech,
            leak_w: (1.0 - at) * o.q_leak * (o.p_a.max(o.p_b) - p.boost_pa),
            inflow_w: o.q_leak * rho_cp * (tn(N::PortOil) - tn(N::CaseOil)),
            film_w_per_k: film,
            wall_c: wall,
            case_c: tn(N::CaseOil),
            q_leak: o.q_leak,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::missions::{draw, EmuScenario};
    use super::super::params::EmuParams;
    use super::super::plant::Hidden;
    use super::*;
    use crate::physics::candidates::Candidate;
    use rand::SeedableRng;

    /// The case budget is the case-oil node's own balance: capacity × dT/dt
    /// of [`Plant::rhs`] equals what enters (mechanical share, leakage
    /// throttled, the leakage's enthalpy from the port oil) minus the films
    /// to the wall, at a hot state 600 s into a throttle mix (to 1e-9
    /// relative: the same laws, summed in another order).
    #[test]
    fn case_budget_is_the_case_oil_balance() {
        let p = EmuParams::default();
        let m = draw(EmuScenario::ThrottleMix, 900.0, &mut rand_chacha::ChaCha8Rng::seed_from_u64(7));
        let plant = Plant { p: &p, m: &m, h: Hidden { effect: Candidate::None, magnitude: 0.0 } };
        let trace = plant.run(300.0);
        let (t, y, _) = &trace[2];
        let mut dy = vec![0.0; NS];
        plant.rhs(*t, y, &mut dy);
        let c = plant.capacities(y)[N::CaseOil as usize];
        let b = plant.case_budget(*t, y);
        let net = b.mech_w + b.leak_w + b.inflow_w - b.film_w_per_k * (b.case_c - b.wall_c);
        let lhs = c * dy[N::CaseOil as usize];
        assert!(b.mech_w > 0.0 && b.leak_w > 0.0 && b.case_c > b.wall_c, "{b:?}");
        assert!((lhs - net).abs() <= 1e-9 * (b.mech_w + b.leak_w + b.inflow_w.abs()), "C dT/dt {lhs} W, budget {net} W ({b:?})");
    }
}
