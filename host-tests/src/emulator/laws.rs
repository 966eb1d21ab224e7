//! The emulated machine's own laws, apart from its network: the oil's
//! viscosity, the pump's leakage gaps, the iron loss and its drag, the case
//! film, the hoses' pressure drop and the outer surfaces' heat loss (its
//! correlations, not the reference's: docs/commissioning.md lists where
//! they differ).

use super::params::RefLaw;
use super::plant::Plant;
use super::props::{self, oil_cp, oil_nu, oil_rho};
use std::f64::consts::PI;

impl Plant<'_> {
    /// Kinematic viscosity at `t_c`: the emulator oil's own Walther line,
    /// at every node's temperature (leakage, hoses, films).
    pub(super) fn nu(&self, t_c: f64) -> f64 {
        oil_nu(t_c)
    }

    /// Leakage conductance of eqs. (5)–(7) with the emulator's own pump
    /// geometry (9 pistons of 9.5 mm, seal 22 mm, eccentricity 0.4;
    /// slipper r2/r1 = 1.6; port plate φ = π, r = 21 mm, L = 5.5 mm),
    /// common gap `gap_m`, m³/(s·Pa).
    pub(super) fn k_leak(&self, mu: f64) -> f64 {
        let d3 = self.p.gap_m.powi(3);
        let piston = 9.0 * PI * 0.0095 * d3 * (1.0 + 1.5 * 0.16) / (12.0 * mu * 0.022);
        let slipper = 9.0 * PI * d3 / (6.0 * mu * 1.6f64.ln());
        let port = PI * 0.021 * d3 / (12.0 * mu * 0.0055);
        piston + slipper + port
    }

    /// Iron loss, eq. (2), W.
    pub(super) fn iron_w(&self, omega: f64) -> f64 {
        let f = self.p.pole_pairs * omega.abs() / (2.0 * PI);
        let b = self.p.b_peak_t;
        let [kh, kc, ke] = self.p.iron_k;
        kh * f * b * b + kc * f * f * b * b + ke * f.powf(1.5) * b.powf(1.5)
    }

    /// Iron-loss drag on the shaft, N·m: eq. (2)'s loss over the speed (at
    /// least 1 rad/s); none with [`RefLaw::NoIronDrag`].
    pub(super) fn iron_drag_nm(&self, omega: f64) -> f64 {
        if self.p.like_reference.has(RefLaw::NoIronDrag) {
            return 0.0;
        }
        self.iron_w(omega) / omega.abs().max(1.0)
    }

    /// Case-oil film on a wetted area `a` (m²) at shaft speed `omega`
    /// (rad/s), oil at `t_c` °C with kinematic viscosity `nu`, W/K: the
    /// rotating cylinder ([`props::case_film`]); with the experiment switch
    /// [`RefLaw::CaseGapFilm`] the reference's law instead,
    /// conduction across a 3 mm gap (Nu = 2 on the gap's hydraulic
    /// diameter 2e) rising with the Taylor number ω²·r·e³/ν² above 1700
    /// (0.128·Ta^0.367 to 1e4, then 0.409·Ta^0.241).
    pub(super) fn case_film(&self, omega: f64, a: f64, nu: f64, t_c: f64) -> f64 {
        if self.p.like_reference.has(RefLaw::CaseFilmOmegaNu) {
            let d = 2.0 * self.p.r_rotor;
            let re = omega.abs() * d * d / nu;
            let pr40 = oil_nu(40.0) * oil_rho(40.0) * oil_cp(40.0) / props::oil_k(40.0);
            return (2.0 + 0.133 * re.powf(2.0 / 3.0) * pr40.powf(1.0 / 3.0)) * props::oil_k(t_c) / d * a;
        }
        if !self.p.like_reference.has(RefLaw::CaseGapFilm) {
            return props::case_film(omega, self.p.r_rotor, a, nu, t_c);
        }
        // the paper rig's 3 mm gap, the reference's Nusselt law itself
        let e = 0.003;
        let ta = omega * omega * (self.p.r_rotor + 0.5 * e) * e.powi(3) / (nu * nu);
        crate::physics::heat::nu_taylor_couette(ta) * props::oil_k(t_c) / (2.0 * e) * a
    }

    /// Pressure drop of the throttle hoses, eq. (10): Darcy friction
    /// (64/Re laminar, Blasius turbulent) plus local losses, Pa.
    pub(super) fn hose_dp(&self, q: f64, t_c: f64) -> f64 {
        let [l, d, xi] = self.p.hose;
        let vel = q / (PI * d * d / 4.0);
        let re = (vel * d / self.nu(t_c)).max(1.0);
        let lambda = if re < 2300.0 { 64.0 / re } else { 0.3164 * re.powf(-0.25) };
        (lambda * l / d + xi) * 0.5 * oil_rho(t_c) * vel * vel
    }

    /// Heat lost by a surface `s` = (area, height, diameter) at `t_w` to
    /// ambient `t_a` with air speed `air`: sides (80 %, Churchill–Chu
    /// vertical), top and bottom faces (10 % each, McAdams), each mixed
    /// with Churchill–Bernstein cross flow, plus radiation, W.
    pub(super) fn outer_w(&self, s: [f64; 3], t_w: f64, t_a: f64, air: f64) -> f64 {
        let [a, hgt, d] = s;
        let forced = if air > 0.0 { props::h_cross_flow(air, d, 0.5 * (t_w + t_a)) } else { 0.0 };
        let side = props::h_mixed(props::h_free_vertical(t_w, t_a, hgt), forced);
        let top = props::h_mixed(props::h_free_horizontal(t_w, t_a, d, true), forced);
        let bot = props::h_mixed(props::h_free_horizontal(t_w, t_a, d, false), forced);
        (0.8 * side + 0.1 * top + 0.1 * bot) * a * (t_w - t_a) + props::radiation_w(self.p.emissivity, a, t_w, t_a)
    }
}
