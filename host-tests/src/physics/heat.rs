//! Heat-transfer correlations, eqs. (12)–(19) of the paper with the Table 1
//! dimensionless groups, in their correct textbook forms.
//!
//! Where the paper's printed form differs from the textbook, the function's
//! doc says so. All areas m², lengths m, temperatures °C, results W/(m²·K),
//! W/K or W.

use crate::air::air_at;
use crate::fluid::{G_M_PER_S2, KELVIN_OFFSET};

/// Stefan–Boltzmann constant, W/(m²·K⁴) (eq. 19).
pub const SIGMA_W_PER_M2_K4: f64 = 5.670_374e-8;

/// Reynolds number of a duct flow (Table 1): Re = v·d/ν.
pub fn reynolds(q_m3_per_s: f64, d_m: f64, nu: f64) -> f64 {
    let v = q_m3_per_s.abs() / (std::f64::consts::PI * 0.25 * d_m * d_m);
    v * d_m / nu
}

/// Laminar mean Nusselt number in a tube, eq. (13) (Gnielinski/VDI form,
/// thermally and hydrodynamically developing flow, constant wall temperature):
/// Nu = [3.66³ + 0.7³ + (1.615·(Re·Pr·d/L)^(1/3) − 0.7)³]^(1/3).
///
/// The paper prints a square root of Re·Pr·d/L; the VDI Heat Atlas form (and
/// the dimensional consistency with the Lévêque limit) is the cube root used here.
/// The (Pr/Pr_w)^0.11 viscosity correction is taken as 1 (wall and bulk
/// temperatures differ by tens of K at most; the correction is below 5 %).
pub fn nu_laminar(re: f64, pr: f64, d_over_l: f64) -> f64 {
    nu_laminar_x(re * pr * d_over_l)
}

/// [`nu_laminar`] as a function of its one argument X = Re·Pr·d/L.
pub fn nu_laminar_x(x: f64) -> f64 {
    let g = 1.615 * x.max(0.0).cbrt() - 0.7;
    (3.66f64.powi(3) + 0.7f64.powi(3) + g.max(0.0).powi(3)).cbrt()
}

/// Turbulent mean Nusselt number in a tube, eq. (14), Gnielinski (1976) with
/// Filonenko's friction factor ξ = (1.82·log10 Re − 1.64)⁻², as the paper
/// prints it: Nu = (ξ/8)(Re − 1000)Pr / (1 + 12.7·√(ξ/8)·(Pr^(2/3) − 1)) ·
/// [1 + (d/L)^(2/3)].
///
/// The paper's only departure from the published form is Pr^(1/3) in the
/// denominator (a misprint: Gnielinski's is Pr^(2/3)); its ξ/8 is the same
/// as here. The (Pr/Pr_w)^0.11 factor is taken as 1, as in eq. (13).
pub fn nu_turbulent(re: f64, pr: f64, d_over_l: f64) -> f64 {
    let xi = (1.82 * re.log10() - 1.64).powi(-2);
    let num = xi / 8.0 * (re - 1000.0) * pr;
    let den = 1.0 + 12.7 * (xi / 8.0).sqrt() * (pr.powf(2.0 / 3.0) - 1.0);
    num / den * (1.0 + d_over_l.powf(2.0 / 3.0))
}

/// Mean Nusselt number of a tube flow over all regimes: eq. (13) below
/// Re = 2300, eq. (14) above 10⁴, and Gnielinski's (1995) linear blend in
/// between, so the coefficient is continuous (important for the stiff solver).
pub fn nu_tube(re: f64, pr: f64, d_over_l: f64) -> f64 {
    nu_tube_with(re, pr, d_over_l, nu_laminar_x)
}

/// [`nu_tube`] with the laminar Nusselt number of X = Re·Pr·d/L given
/// (exact: [`nu_laminar_x`]; the fast plant's interpolation of it).
pub fn nu_tube_with(re: f64, pr: f64, d_over_l: f64, laminar: impl Fn(f64) -> f64) -> f64 {
    nu_tube_turb(re, pr, d_over_l, laminar, 1.0)
}

/// [`nu_tube_with`] with the turbulent law (eq. 14) times `turb_scale`,
/// above 10⁴ and in the blend's turbulent end (`Rig`'s
/// `blocks.duct_turbulent_scale`, calibrated by `duct_turbulent`): the
/// blend stays linear in Re between its values at 2300 and 10⁴, as the
/// firmware's anchors read it. 1: [`nu_tube_with`] exactly.
#[inline]
pub fn nu_tube_turb(re: f64, pr: f64, d_over_l: f64, laminar: impl Fn(f64) -> f64, turb_scale: f64) -> f64 {
    if re <= 2300.0 {
        laminar(re * pr * d_over_l)
    } else if re >= 1e4 {
        turb_scale * nu_turbulent(re, pr, d_over_l)
    } else {
        let gamma = (re - 2300.0) / (1e4 - 2300.0);
        (1.0 - gamma) * laminar(2300.0 * pr * d_over_l) + gamma * turb_scale * nu_turbulent(1e4, pr, d_over_l)
    }
}

/// Mean Nusselt number Nu = h·2e/k of the oil film between a rotating inner
/// cylinder and a fixed outer one (Taylor–Couette flow, no axial flow), by
/// Becker & Kaye (1962) as compiled by Fénot et al. (Int. J. Thermal Sci. 50,
/// 2011): Nu = 2 below the Taylor instability (Ta < 1700, conduction across
/// the gap), 0.128·Ta^0.367 up to 10⁴, 0.409·Ta^0.241 above (continuous at
/// both joins). `ta` is the Taylor number ω²·R_m·e³/ν² (geometric factor 1:
/// gap small against the radius).
pub fn nu_taylor_couette(ta: f64) -> f64 {
    if ta < 1700.0 {
        2.0
    } else if ta < 1e4 {
        (0.128 * ta.powf(0.367)).max(2.0)
    } else {
        0.409 * ta.powf(0.241)
    }
}

/// Mean Nusselt number Nu = h·L/k of a laminar boundary layer over a plate
/// of length L moving through a fluid at rest (Pohlhausen):
/// Nu = 0.664·Re^½·Pr^⅓ (Pr ≥ 0.6, Re below transition); 0 at rest.
pub fn nu_flat_plate_laminar(re: f64, pr: f64) -> f64 {
    0.664 * re.max(0.0).sqrt() * pr.cbrt()
}

/// Rayleigh number Gr·Pr of free convection (Table 1 Grashof number times Pr)
/// for a surface at `t_wall_c` in air at `t_air_c` and static pressure
/// `p_pa`, length `l_m`; properties at the film temperature ½(T_w + T_air)
/// (Gr ∝ 1/ν² ∝ p²: thinner air at altitude convects less).
pub fn rayleigh(t_wall_c: f64, t_air_c: f64, p_pa: f64, l_m: f64) -> (f64, f64, f64) {
    let film = 0.5 * (t_wall_c + t_air_c);
    let a = air_at(film, p_pa);
    let gr = G_M_PER_S2 * a.beta * (t_wall_c - t_air_c).abs() * l_m.powi(3) / (a.nu * a.nu);
    (gr * a.pr, a.pr, a.k)
}

/// Free-convection coefficient of a horizontal cylinder of outer diameter
/// `d_o`, eq. (15), Churchill–Chu (1975):
/// Nu = {0.6 + 0.387·Ra^(1/6) / [1 + (0.559/Pr)^(9/16)]^(8/27)}².
///
/// The paper prints `0.387·Gr·Pr^(1/6)`; the published correlation raises the
/// Rayleigh number Gr·Pr as a whole to the 1/6.
/// Air at static pressure `p_pa`.
pub fn h_free_cylinder(t_wall_c: f64, t_air_c: f64, p_pa: f64, d_o: f64) -> f64 {
    let (ra, pr, k) = rayleigh(t_wall_c, t_air_c, p_pa, d_o);
    let nu = (0.6 + 0.387 * ra.powf(1.0 / 6.0) / (1.0 + (0.559 / pr).powf(9.0 / 16.0)).powf(8.0 / 27.0)).powi(2);
    nu * k / d_o
}

/// Free-convection coefficient of a cube-shaped block of side `a`, eq. (16)
/// (VDI Heat Atlas F2, bodies of arbitrary shape, characteristic length
/// l = A/P-type: here the side `a`):
/// Nu = 5.748 + 0.752·[Ra / f(Pr)]^0.252, f(Pr) = [1 + (0.492/Pr)^(9/16)]^(16/9).
///
/// The paper prints the Prandtl function with a minus sign (which makes it
/// negative for air) and a characteristic length A_o/(4a³) that is not a
/// length; the published plus sign and l_c = a are used.
/// Air at static pressure `p_pa`.
pub fn h_free_cube(t_wall_c: f64, t_air_c: f64, p_pa: f64, a: f64) -> f64 {
    let (ra, pr, k) = rayleigh(t_wall_c, t_air_c, p_pa, a);
    let f = (1.0 + (0.492 / pr).powf(9.0 / 16.0)).powf(16.0 / 9.0);
    let nu = 5.748 + 0.752 * (ra / f).powf(0.252);
    nu * k / a
}

/// Forced-convection (ram-air) coefficient of a housing in an air stream of
/// `v_mps`, turbulent flat plate of run length `l_m`:
/// Nu = 0.037·Re^0.8·Pr^(1/3), air properties at `t_air_c` and static
/// pressure `p_pa` (Re ∝ ρ: at altitude the same speed cools less, h ∝ p^0.8).
///
/// The paper's Table 5 coefficients grow exactly as v^0.8 (66.13 → 115.13 →
/// 173.25 W/(m²·K) for 15 → 30 → 50 m/s), the signature of this correlation;
/// the run length is calibrated to its 15 m/s entry (see `rig::Housing`).
pub fn h_forced_plate(v_mps: f64, l_m: f64, t_air_c: f64, p_pa: f64) -> f64 {
    if v_mps <= 0.0 {
        return 0.0;
    }
    let a = air_at(t_air_c, p_pa);
    let re = v_mps * l_m / a.nu;
    0.037 * re.powf(0.8) * a.pr.cbrt() * a.k / l_m
}

/// Mixed convection: Churchill's combination (h_free³ + h_forced³)^(1/3) of
/// the free and forced coefficients on the same surface (assisting flow).
pub fn h_mixed(h_free: f64, h_forced: f64) -> f64 {
    (h_free.powi(3) + h_forced.powi(3)).cbrt()
}

/// Radiative heat flow from a surface to its surroundings, eq. (19):
/// φ₃ = σ·ε·A·(T_w⁴ − T_air⁴), W.
pub fn radiation_w(emissivity: f64, area_m2: f64, t_wall_c: f64, t_air_c: f64) -> f64 {
    let tw = t_wall_c + KELVIN_OFFSET;
    let ta = t_air_c + KELVIN_OFFSET;
    SIGMA_W_PER_M2_K4 * emissivity * area_m2 * (tw.powi(4) - ta.powi(4))
}

/// Conductance of a cylindrical wall, eq. (17): G = 2π·k·L / ln(d_o/d_i), W/K.
pub fn g_cylinder_wall(k_w_per_m_k: f64, length_m: f64, d_o: f64, d_i: f64) -> f64 {
    2.0 * std::f64::consts::PI * k_w_per_m_k * length_m / (d_o / d_i).ln()
}

/// Conductance of a plane wall of face a² and thickness L_w, eq. (18):
/// G = k·a²/L_w, W/K.
pub fn g_plane_wall(k_w_per_m_k: f64, a_m: f64, thickness_m: f64) -> f64 {
    k_w_per_m_k * a_m * a_m / thickness_m
}

/// Two conductances in series, W/K (eq. 12 film in series with eq. 17/18 wall).
pub fn series(g1: f64, g2: f64) -> f64 {
    if g1 <= 0.0 || g2 <= 0.0 {
        0.0
    } else {
        g1 * g2 / (g1 + g2)
    }
}

#[cfg(test)]
mod tests {
    /// Becker & Kaye's three pieces join: 2 at Ta = 1700 (0.128·1700^0.367 =
    /// 1.96, held at 2) and 3.77 at 10⁴ from both sides (to 0.5 %: the
    /// published coefficients are rounded to three figures).
    #[test]
    fn taylor_couette_pieces_join() {
        assert_eq!(super::nu_taylor_couette(1000.0), 2.0);
        let (a, b) = (super::nu_taylor_couette(1e4 - 1e-6), super::nu_taylor_couette(1e4));
        assert!((a - b).abs() / b < 5e-3 && (b - 3.77).abs() < 0.01, "{a} {b}");
    }

    use super::*;

    /// Fully developed laminar limit: long tube, Nu → 3.66 (Graetz), to 1 %.
    #[test]
    fn laminar_tends_to_graetz_limit() {
        let nu = nu_laminar(100.0, 0.7, 1e-6);
        assert!((nu - 3.66).abs() / 3.66 < 0.01, "{nu}");
    }

    /// Gnielinski at Re = 1e5, Pr = 0.7, long tube equals the published
    /// formula with Filonenko's friction factor evaluated by hand (to
    /// round-off) and lies within the ±25 % uncertainty band of Dittus–Boelter
    /// (199.4).
    #[test]
    fn gnielinski_matches_textbook() {
        let nu = nu_turbulent(1e5, 0.7, 0.0);
        let xi = (1.82f64 * 5.0 - 1.64).powi(-2);
        let expect = xi / 8.0 * 99_000.0 * 0.7 / (1.0 + 12.7 * (xi / 8.0).sqrt() * (0.7f64.powf(2.0 / 3.0) - 1.0));
        assert!((nu - expect).abs() < 1e-9);
        let db = 0.023 * 1e5f64.powf(0.8) * 0.7f64.powf(0.4);
        assert!((nu - db).abs() / db < 0.25, "gnielinski {nu} vs dittus-boelter {db}");
    }

    /// The regime blend is continuous at both ends (jumps would stall the
    /// stiff solver's Newton iterations).
    #[test]
    fn tube_nusselt_is_continuous() {
        for re in [2300.0, 1e4] {
            let lo = nu_tube(re * (1.0 - 1e-9), 500.0, 0.1);
            let hi = nu_tube(re * (1.0 + 1e-9), 500.0, 0.1);
            assert!((lo - hi).abs() / lo < 1e-6, "jump at {re}: {lo} {hi}");
        }
    }

    /// Churchill–Chu cylinder: d = 0.1 m, wall 50 °C in 20 °C air. Hand
    /// calculation with table air at the 35 °C film (ν = 1.65e-5 m²/s,
    /// k = 0.0267 W/(m·K), Pr = 0.71): Ra = 2.49e6, Nu = 18.9, h = 5.03
    /// W/(m²·K); 3 % covers the property fits.
    #[test]
    fn churchill_chu_cylinder_magnitude() {
        let h = h_free_cylinder(50.0, 20.0, crate::air::P_SEA_LEVEL_PA, 0.1);
        assert!((h - 5.03).abs() / 5.03 < 0.03, "{h}");
    }

    /// Radiation: 1 m², ε = 1, 100 °C to 0 °C:
    /// 5.670374e-8 × (1.938803e10 − 5.566789e9) = 783.71 W by hand.
    #[test]
    fn radiation_black_body() {
        let q = radiation_w(1.0, 1.0, 100.0, 0.0);
        assert!((q - 783.71).abs() < 0.05, "{q}");
    }

    /// Wall conductances against hand calculation to round-off.
    #[test]
    fn wall_conductances() {
        let g = g_cylinder_wall(50.0, 1.0, 0.2, 0.1);
        assert!((g - 2.0 * std::f64::consts::PI * 50.0 / 2f64.ln()).abs() < 1e-9);
        assert!((g_plane_wall(50.0, 0.2, 0.01) - 200.0).abs() < 1e-9);
    }
}
