//! Power losses, eqs. (1)–(11) of the paper, plus the throttling, relief and
//! check-valve losses of the rig's valve blocks. Every function returns W
//! (or m³/s for the leakage flows that carry the leakage heat).

use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// Motor copper loss, eq. (1): P_cu = m·I²·R, W, with the phase resistance
/// optionally corrected to the winding temperature (extension
/// `winding-resistance-temperature`: R = R25·(1 + α·(T_w − 25))).
pub fn copper_w(phases: f64, i_rms_a: f64, r25_ohm: f64, alpha_per_k: Option<f64>, t_winding_c: f64) -> f64 {
    let r = match alpha_per_k {
        Some(alpha) => r25_ohm * (1.0 + alpha * (t_winding_c - 25.0)),
        None => r25_ohm,
    };
    phases * i_rms_a * i_rms_a * r
}

/// Bertotti stator iron-loss coefficients of eq. (2).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct IronLoss {
    /// Hysteresis coefficient k_h, W/(Hz·T²).
    pub k_h: f64,
    /// Eddy-current coefficient k_c, W/(Hz²·T²).
    pub k_c: f64,
    /// Excess-loss coefficient k_e, W/(Hz·T)^1.5.
    pub k_e: f64,
    /// Peak flux density B_m of the stator, T.
    pub b_peak_t: f64,
    /// Pole pairs (electrical frequency f = pole pairs · n/60).
    pub pole_pairs: f64,
}

impl IronLoss {
    /// Stator iron loss, eq. (2): P_Fe = k_h·f·B² + k_c·f²·B² + k_e·f^1.5·B^1.5, W,
    /// at shaft speed `omega` rad/s (either sign).
    pub fn power_w(&self, omega: f64) -> f64 {
        let f = self.pole_pairs * omega.abs() / (2.0 * PI);
        let b = self.b_peak_t;
        self.k_h * f * b * b + self.k_c * f * f * b * b + self.k_e * (f * b).powf(1.5)
    }
}

/// Motor bearing friction loss, eq. (3): P_mc = k_m·M_m·ω, W, where the
/// product k_m·M_m is given as a friction torque in N·m.
pub fn bearing_w(friction_torque_nm: f64, omega: f64) -> f64 {
    friction_torque_nm * omega.abs()
}

/// Leakage-gap geometry of the axial piston pump, eqs. (5)–(7).
/// The paper gives the equations but not the dimensions; the defaults are
/// those of a 19 cm³/rev nine-piston pump and are marked in `rig/`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PumpGaps {
    /// Number of pistons N.
    pub pistons: f64,
    /// Piston diameter d_z, m.
    pub piston_d_m: f64,
    /// Piston sealing length L_z, m.
    pub piston_seal_m: f64,
    /// Piston–bore film thickness δ_z, m.
    pub piston_gap_m: f64,
    /// Eccentricity ratio e of the piston in its bore.
    pub eccentricity: f64,
    /// Slipper–swash-plate film thickness δ_h, m.
    pub slipper_gap_m: f64,
    /// Slipper sealing land outer/inner radius ratio r₂/r₁.
    pub slipper_r2_over_r1: f64,
    /// Valve-plate leak angle φ_p, rad.
    pub port_angle_rad: f64,
    /// Valve-plate radius r_p, m.
    pub port_radius_m: f64,
    /// Valve-plate film thickness δ_p, m.
    pub port_gap_m: f64,
    /// Valve-plate sealing length L_p, m.
    pub port_seal_m: f64,
}

impl PumpGaps {
    /// Total leakage conductance of the three gap pairs at dynamic viscosity
    /// `mu` (Pa·s), m³/(s·Pa): the leakage flow is this times Δp, and the
    /// heat released is Δp times the flow, so that
    /// P = Δp²·(this) is exactly the sum of eqs. (5), (6) and (7).
    ///
    /// Only the pistons on the high-pressure kidney (N/2) see the port
    /// pressure difference; eqs. (5)–(6) are written for the N pistons of a
    /// pump with both kidneys pressurised, so the factor ½ is applied here.
    pub fn conductance(&self, mu: f64) -> f64 {
        let n_hp = 0.5 * self.pistons;
        let piston = n_hp * PI * self.piston_d_m * self.piston_gap_m.powi(3) * (1.0 + 1.5 * self.eccentricity.powi(2))
            / (12.0 * mu * self.piston_seal_m);
        let slipper = n_hp * PI * self.slipper_gap_m.powi(3) / (6.0 * mu * self.slipper_r2_over_r1.ln());
        let port = self.port_angle_rad * self.port_radius_m * self.port_gap_m.powi(3) / (12.0 * mu * self.port_seal_m);
        piston + slipper + port
    }
}

/// Pump leakage heat, eqs. (5)–(7) summed: P = K·Δp², W, with
/// K = [`PumpGaps::conductance`] in m³/(s·Pa) and Δp in Pa.
pub fn leakage_w(conductance: f64, dp_pa: f64) -> f64 {
    conductance * dp_pa * dp_pa
}

/// Pump mechanical (friction) loss, eq. (8): P_m = η_m·M_p·ω, W, with the
/// load torque M_p = D·|Δp| (D in m³/rad): the pressure term of
/// [`PumpFriction`].
pub fn pump_mechanical_w(eta_m: f64, displacement_m3_per_rad: f64, dp_pa: f64, omega: f64) -> f64 {
    eta_m * displacement_m3_per_rad * dp_pa.abs() * omega.abs()
}

/// The pump's friction heat by term of eq. (8) extended with the no-load and
/// viscous torques (Wilson's loss-torque model):
/// T = T₀ + C_v·μ·D·|ω| + η_m·D·|Δp|, heat T·|ω|, W.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct PumpFriction {
    /// No-load term T₀·|ω|, W.
    pub no_load_w: f64,
    /// Viscous term C_v·μ·D·ω², W.
    pub viscous_w: f64,
    /// Pressure term η_m·D·|Δp|·|ω| (eq. 8), W.
    pub pressure_w: f64,
}

impl PumpFriction {
    /// The three terms at speed `omega` (rad/s), pressure difference `dp_pa`
    /// and film viscosity `mu` (Pa·s), for no-load torque `t0_nm`, viscous
    /// coefficient `cv`, pressure coefficient `eta_m` and displacement `d`
    /// (m³/rad).
    pub fn new(t0_nm: f64, cv: f64, eta_m: f64, d: f64, mu: f64, dp_pa: f64, omega: f64) -> Self {
        let w = omega.abs();
        Self { no_load_w: t0_nm * w, viscous_w: cv * mu * d * w * w, pressure_w: pump_mechanical_w(eta_m, d, dp_pa, omega) }
    }

    /// Total friction heat, W.
    pub fn total_w(&self) -> f64 {
        self.no_load_w + self.viscous_w + self.pressure_w
    }
}

/// Churning loss of the rotating group (extension `churning-loss`):
/// P = k·|ω|^2.5, W. The paper neglects it at its low test speed (eq. 9);
/// the ω^2.5 law is that of a disc spinning in oil in the turbulent regime.
pub fn churning_w(k_w_per_rad_s_2_5: f64, omega: f64) -> f64 {
    k_w_per_rad_s_2_5 * omega.abs().powf(2.5)
}

/// Darcy friction factor of a pipe by flow regime: 64/Re (laminar,
/// Re ≤ 2300), Blasius 0.3164·Re^-0.25 (turbulent, Re ≥ 4000), linear blend
/// between. Used by eq. (10).
pub fn darcy_friction(re: f64) -> f64 {
    let re = re.max(1e-9);
    if re <= 2300.0 {
        64.0 / re
    } else if re >= 4000.0 {
        0.3164 * re.powf(-0.25)
    } else {
        let g = (re - 2300.0) / 1700.0;
        (1.0 - g) * 64.0 / 2300.0 + g * 0.3164 * 4000f64.powf(-0.25)
    }
}

/// A hydraulic line of the valve blocks and hoses for eq. (10).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Line {
    /// Total length l_pipe, m.
    pub length_m: f64,
    /// Bore d_pipe, m.
    pub diameter_m: f64,
    /// Sum of the local loss coefficients Σξ (bends, tees, ports).
    pub local_loss_coeff: f64,
}

impl Line {
    /// Flow area, m².
    pub fn area_m2(&self) -> f64 {
        PI * 0.25 * self.diameter_m * self.diameter_m
    }

    /// Pressure drop of flow `q` (m³/s) at kinematic viscosity `nu` and
    /// density `rho`, eq. (10) without the flow factor:
    /// Δp = (λ·l/d + Σξ)·ρ·v²/2, signed with the flow, Pa.
    pub fn dp_pa(&self, q: f64, nu: f64, rho: f64) -> f64 {
        let v = q / self.area_m2();
        let re = v.abs() * self.diameter_m / nu;
        let lambda = darcy_friction(re);
        (lambda * self.length_m / self.diameter_m + self.local_loss_coeff) * 0.5 * rho * v * v.abs()
    }

    /// Heat generated in the line, eq. (10): P_pipe = Δp·q, W (≥ 0).
    pub fn power_w(&self, q: f64, nu: f64, rho: f64) -> f64 {
        self.dp_pa(q, nu, rho) * q
    }
}

/// Actuator internal leakage loss, eq. (11): P_ac = Δp_ac·q_cl, W, with the
/// laminar cross-piston leakage q_cl = k_cl·Δp_ac.
pub fn actuator_leak_w(k_cl_m3_per_s_pa: f64, dp_pa: f64) -> f64 {
    k_cl_m3_per_s_pa * dp_pa * dp_pa
}

/// Throttling loss of a valve passing flow `q` (m³/s) with a pressure drop
/// `dp` (Pa): the whole hydraulic power Δp·q becomes heat in the oil, W.
pub fn throttle_w(dp_pa: f64, q: f64) -> f64 {
    (dp_pa * q).abs()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Eq. (1): 3 phases, 10 A, 0.074 Ω → 22.2 W exactly; with α = 0.00393 at
    /// 75 °C the resistance rises by 19.65 %.
    #[test]
    fn copper_loss() {
        assert!((copper_w(3.0, 10.0, 0.074, None, 75.0) - 22.2).abs() < 1e-12);
        let hot = copper_w(3.0, 10.0, 0.074, Some(0.00393), 75.0);
        assert!((hot / 22.2 - 1.1965).abs() < 1e-12);
    }

    /// The leakage heat is quadratic in Δp and inverse in μ (eqs. 5–7).
    #[test]
    fn leakage_scales_with_dp_squared_over_mu() {
        let g = PumpGaps {
            pistons: 9.0,
            piston_d_m: 0.01,
            piston_seal_m: 0.02,
            piston_gap_m: 10e-6,
            eccentricity: 0.5,
            slipper_gap_m: 10e-6,
            slipper_r2_over_r1: 1.5,
            port_angle_rad: PI,
            port_radius_m: 0.02,
            port_gap_m: 10e-6,
            port_seal_m: 0.005,
        };
        let p1 = leakage_w(g.conductance(0.04), 6e6);
        let p2 = leakage_w(g.conductance(0.02), 12e6);
        assert!((p2 / p1 - 8.0).abs() < 1e-12);
    }

    /// Darcy factor: 64/Re laminar, Blasius turbulent, continuous blend.
    #[test]
    fn darcy_regimes() {
        assert!((darcy_friction(1000.0) - 0.064).abs() < 1e-12);
        assert!((darcy_friction(1e5) - 0.3164 * 1e5f64.powf(-0.25)).abs() < 1e-12);
        let a = darcy_friction(2300.0 - 1e-6);
        let b = darcy_friction(2300.0 + 1e-6);
        assert!((a - b).abs() < 1e-6);
    }

    /// Laminar line: Δp = 128·μ·l·q/(π·d⁴) (Hagen–Poiseuille) when Σξ = 0.
    #[test]
    fn line_is_hagen_poiseuille_when_laminar() {
        let line = Line { length_m: 1.0, diameter_m: 0.01, local_loss_coeff: 0.0 };
        let (nu, rho, q) = (46e-6, 870.0, 1e-5);
        let hp = 128.0 * nu * rho * 1.0 * q / (PI * 1e-8);
        assert!((line.dp_pa(q, nu, rho) - hp).abs() / hp < 1e-9);
    }

    /// Iron loss at 500 rpm with 4 pole pairs (f = 33.3 Hz) by hand.
    #[test]
    fn iron_loss_by_hand() {
        let il = IronLoss { k_h: 0.3, k_c: 0.002, k_e: 0.01, b_peak_t: 1.4, pole_pairs: 4.0 };
        let omega = 500.0 * 2.0 * PI / 60.0;
        let f: f64 = 4.0 * 500.0 / 60.0;
        let expect = 0.3 * f * 1.96 + 0.002 * f * f * 1.96 + 0.01 * (f * 1.4).powf(1.5);
        assert!((il.power_w(omega) - expect).abs() < 1e-9);
    }
}
