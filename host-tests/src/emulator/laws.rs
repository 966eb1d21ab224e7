//! The emulated machine's own laws, apart from its network: the oil's
//! viscosity, the pump's leakage gaps, the iron loss and its drag, the case
//! film, the hoses' pressure drop and the outer surfaces' heat loss (its
//! correlations, not the reference's: docs/commissioning-foreign.md lists where
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

    /// Film conductance of oil flowing at `q` m³/s through a duct
    /// `dct` = (diameter, length, wetted area), the oil at node temperature
    /// `t_c`, W/K: the machine's Hausen/Gnielinski law
    /// ([`props::duct_film`]); with [`RefLaw::DuctLaw`] the reference's
    /// Nusselt law on the same area (with [`RefLaw::DuctLawBlocks`] on a
    /// `block` film only).
    pub(super) fn duct(&self, dct: [f64; 3], q: f64, t_c: f64, block: bool) -> f64 {
        let nu = self.nu(t_c);
        let lr = self.p.like_reference;
        if !(lr.has(RefLaw::DuctLaw) || block && lr.has(RefLaw::DuctLawBlocks)) {
            return props::duct_film(q, dct[0], dct[1], dct[2], nu, t_c);
        }
        let [d, l, area] = dct;
        let re = crate::physics::heat::reynolds(q, d, nu);
        let pr = nu * oil_rho(t_c) * oil_cp(t_c) / props::oil_k(t_c);
        crate::physics::heat::nu_tube_with(re, pr, d / l, crate::physics::heat::nu_laminar_x) * props::oil_k(t_c) / d * area
    }

    /// A block film `g` (W/K) behind which the block of outer area `a_out`
    /// (m²) sits: `g` itself, or with [`RefLaw::BlockWall`] in series with
    /// the reference's wall (eq. 18: 45 W/(m·K) steel, 30 mm, on a face of
    /// side √(a_out/6)), W/K.
    pub(super) fn block_film(&self, g: f64, a_out: f64) -> f64 {
        if !self.p.like_reference.has(RefLaw::BlockWall) {
            return g;
        }
        crate::physics::heat::series(g, crate::physics::heat::g_plane_wall(45.0, (a_out / 6.0).sqrt(), 0.03))
    }

    /// Heat lost by a surface `s` = (area, height, diameter) at `t_w` to
    /// ambient `t_a` with air speed `air`: sides (80 %, Churchill–Chu
    /// vertical), top and bottom faces (10 % each, McAdams), each mixed
    /// with Churchill–Bernstein cross flow, plus radiation, W. With
    /// [`RefLaw::OuterLaw`] the reference's correlations instead
    /// (`cube`: a block, eq. 16 on the side √(area/6); otherwise a
    /// horizontal cylinder of the diameter, eq. 15; the flat plate's forced
    /// convection over 0.352 m mixed in).
    pub(super) fn outer_w(&self, s: [f64; 3], cube: bool, t_w: f64, t_a: f64, air: f64) -> f64 {
        let [a, hgt, d] = s;
        if self.p.like_reference.has(RefLaw::OuterLaw) {
            use crate::physics::heat as h;
            let p_air = 101_325.0;
            let free = if cube { h::h_free_cube(t_w, t_a, p_air, (a / 6.0).sqrt()) } else { h::h_free_cylinder(t_w, t_a, p_air, d) };
            let conv = if air > 0.0 { h::h_mixed(free, h::h_forced_plate(air, 0.352, t_a, p_air)) } else { free };
            return conv * a * (t_w - t_a) + props::radiation_w(self.p.emissivity, a, t_w, t_a);
        }
        let forced = if air > 0.0 { props::h_cross_flow(air, d, 0.5 * (t_w + t_a)) } else { 0.0 };
        let side = props::h_mixed(props::h_free_vertical(t_w, t_a, hgt), forced);
        let top = props::h_mixed(props::h_free_horizontal(t_w, t_a, d, true), forced);
        let bot = props::h_mixed(props::h_free_horizontal(t_w, t_a, d, false), forced);
        (0.8 * side + 0.1 * top + 0.1 * bot) * a * (t_w - t_a) + props::radiation_w(self.p.emissivity, a, t_w, t_a)
    }
}
