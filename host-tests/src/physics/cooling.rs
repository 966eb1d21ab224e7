//! Cooling: the LNG heat exchanger by NTU–effectiveness, eqs. (20)–(22),
//! LNG sizing, eqs. (23)–(25) with Table 6, and the switching valve.
//! (Ram-air forced convection is in [`crate::heat::h_forced_plate`].)

use serde::{Deserialize, Serialize};

/// LNG properties and heat-exchanger design, Table 6 plus the exchanger
/// parameters the paper does not give (marked).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Lng {
    /// Latent heat of vaporisation c_p,LNG,latent, J/kg (Table 6: 509 kJ/kg).
    pub latent_j_per_kg: f64,
    /// Sensible specific heat c_p,LNG,sensible, J/(kg·K) (Table 6: 2.9 kJ/(kg·K)).
    pub sensible_j_per_kg_k: f64,
    /// Temperature rise of the LNG from inlet to outlet ΔT_LNG, K (Table 6: 180 °C).
    pub delta_t_k: f64,
    /// LNG density ρ_LNG, kg/m³ (Table 6: 430).
    pub density_kg_per_m3: f64,
    /// LNG inlet temperature T'₂, °C (saturated methane at 1 atm: −162 °C).
    pub inlet_c: f64,
    /// Overall conductance k_c·A_U of the exchanger, W/K (assumed; not in the paper).
    pub ua_w_per_k: f64,
    /// LNG mass flow while the valve is open, kg/s (calibrated to Fig. 15: the
    /// smallest round value that keeps the drain below 50 °C over 600 s; at
    /// 1.2 g/s it peaks at 50.1 °C).
    pub flow_kg_per_s: f64,
    /// Tank charge V_LNG, m³ (paper: 5 L with twofold redundancy).
    pub charge_m3: f64,
    /// Valve opening threshold, °C (paper: 40 °C).
    pub open_above_c: f64,
    /// Valve closing threshold, °C (not in the paper: a 4 K band, chosen so the
    /// valve cycles about once a minute instead of every few seconds).
    pub close_below_c: f64,
}

impl Default for Lng {
    fn default() -> Self {
        Self {
            latent_j_per_kg: 509e3,
            sensible_j_per_kg_k: 2.9e3,
            delta_t_k: 180.0,
            density_kg_per_m3: 430.0,
            inlet_c: -162.0,
            ua_w_per_k: 40.0,
            flow_kg_per_s: 3.0e-3,
            charge_m3: 5e-3,
            open_above_c: 40.0,
            close_below_c: 36.0,
        }
    }
}

impl Lng {
    /// Heat absorbed per kg of LNG, eq. (24) divided by M: latent + c_p·ΔT, J/kg.
    pub fn heat_per_kg(&self) -> f64 {
        self.latent_j_per_kg + self.sensible_j_per_kg_k * self.delta_t_k
    }

    /// Effective capacity rate of the LNG stream, W/K: the heat it can take
    /// per kg spread over its ΔT_LNG rise, times the mass flow.
    pub fn capacity_rate_w_per_k(&self) -> f64 {
        self.flow_kg_per_s * self.heat_per_kg() / self.delta_t_k
    }

    /// Mass of LNG needed for heat power `p_sum_w` over mission time `t_m_s`,
    /// eqs. (23)–(24): M = P·t_m / (latent + c_p·ΔT), kg.
    pub fn mass_for_kg(&self, p_sum_w: f64, t_m_s: f64) -> f64 {
        p_sum_w * t_m_s / self.heat_per_kg()
    }

    /// Volume for a mass, eq. (25): V = M/ρ, m³.
    pub fn volume_m3(&self, mass_kg: f64) -> f64 {
        mass_kg / self.density_kg_per_m3
    }

    /// Mass of the tank charge, eq. (25): M = V·ρ, kg.
    pub fn charge_kg(&self) -> f64 {
        self.charge_m3 * self.density_kg_per_m3
    }

    /// Mission time that a heat power `p_sum_w` may last on `volume_m3` of LNG,
    /// eqs. (23)–(25) solved for t_m, s.
    pub fn mission_time_s(&self, p_sum_w: f64, volume_m3: f64) -> f64 {
        volume_m3 * self.density_kg_per_m3 * self.heat_per_kg() / p_sum_w
    }

    /// Heat taken from the oil by the exchanger, eqs. (20)–(22), W, for an oil
    /// capacity rate `c_oil` (W/K) entering at `t_oil_c`.
    pub fn exchanger_w(&self, c_oil_w_per_k: f64, t_oil_c: f64) -> f64 {
        let c_lng = self.capacity_rate_w_per_k();
        let (c_min, c_max) = if c_lng < c_oil_w_per_k { (c_lng, c_oil_w_per_k) } else { (c_oil_w_per_k, c_lng) };
        if c_min <= 0.0 {
            return 0.0;
        }
        let ntu = self.ua_w_per_k / c_min;
        effectiveness(ntu, c_min / c_max) * c_min * (t_oil_c - self.inlet_c)
    }
}

/// Cross-flow exchanger effectiveness, eq. (21) (both fluids unmixed):
/// η = 1 − exp{(NTU^0.22/C*)·[exp(−C*·NTU^0.78) − 1]}, with the C* → 0 limit
/// η = 1 − exp(−NTU) (a boiling stream) taken smoothly below C* = 1e-9.
pub fn effectiveness(ntu: f64, c_star: f64) -> f64 {
    if ntu <= 0.0 {
        return 0.0;
    }
    if c_star < 1e-9 {
        return 1.0 - (-ntu).exp();
    }
    1.0 - ((ntu.powf(0.22) / c_star) * ((-c_star * ntu.powf(0.78)).exp() - 1.0)).exp()
}

/// Result of an LNG sizing, eqs. (23)–(25).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Sizing {
    /// Heat sink needed Q_LNG, J (eq. 23).
    pub heat_j: f64,
    /// LNG mass M_LNG, kg (eq. 24).
    pub mass_kg: f64,
    /// LNG volume V_LNG, m³ (eq. 25).
    pub volume_m3: f64,
    /// Volume with the redundancy factor, m³.
    pub volume_with_redundancy_m3: f64,
    /// Mass with the redundancy factor, kg.
    pub mass_with_redundancy_kg: f64,
}

/// Size the LNG charge for heat power `p_sum_w` over `t_m_s` with a
/// redundancy factor (the paper uses 2, rounding 4.6 L up to 5 L).
pub fn size(lng: &Lng, p_sum_w: f64, t_m_s: f64, redundancy: f64) -> Sizing {
    let mass_kg = lng.mass_for_kg(p_sum_w, t_m_s);
    let volume_m3 = lng.volume_m3(mass_kg);
    Sizing {
        heat_j: p_sum_w * t_m_s,
        mass_kg,
        volume_m3,
        volume_with_redundancy_m3: volume_m3 * redundancy,
        mass_with_redundancy_kg: mass_kg * redundancy,
    }
}

/// Thermostatic switching valve with a hysteresis band: opens above
/// `open_above_c`, closes below `close_below_c` (paper: "opened ... when the
/// temperature is greater than 40 °C").
pub fn valve_next(open: bool, t_c: f64, lng: &Lng) -> bool {
    if open {
        t_c >= lng.close_below_c
    } else {
        t_c > lng.open_above_c
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// C* → 0 limit of eq. (21) is 1 − e^(−NTU); the general form approaches it.
    #[test]
    fn effectiveness_limit() {
        let a = effectiveness(2.0, 1e-6);
        let b = 1.0 - (-2.0f64).exp();
        assert!((a - b).abs() < 1e-4, "{a} {b}");
        assert!((effectiveness(2.0, 1e-12) - b).abs() < 1e-15);
    }

    /// Balanced unmixed cross-flow exchanger, NTU = 1, C* = 1: eq. (21) gives
    /// 1 − exp(e⁻¹ − 1) = 0.4685; the exact series solution is 0.476
    /// (Incropera Fig. 11.18). Eq. (21) is the approximate closed form, good to
    /// about 2 % there.
    #[test]
    fn effectiveness_balanced_crossflow() {
        let e = effectiveness(1.0, 1.0);
        assert!((e - (1.0 - ((-1.0f64).exp() - 1.0).exp())).abs() < 1e-12);
        assert!((e - 0.476).abs() / 0.476 < 0.02, "{e}");
    }
}
