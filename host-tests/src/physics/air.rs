//! The outside air: its properties at a film temperature and pressure and
//! the standard atmosphere's pressure at altitude, for the free- and
//! forced-convection correlations (eqs. 15, 16, the ram air).

use super::fluid::KELVIN_OFFSET;
use std::cell::Cell;

/// Dry air: the outside medium of the free- and forced-convection
/// correlations (eqs. 15, 16 and the ram-air model).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AirProps {
    /// Kinematic viscosity, m²/s.
    pub nu: f64,
    /// Thermal conductivity, W/(m·K).
    pub k: f64,
    /// Prandtl number.
    pub pr: f64,
    /// Volumetric expansion coefficient 1/T of an ideal gas, 1/K.
    pub beta: f64,
}

/// Sea-level standard pressure, Pa.
pub const P_SEA_LEVEL_PA: f64 = 101_325.0;

/// Static pressure of the ICAO standard atmosphere at `altitude_m`
/// (troposphere, 0–11 km: p = p₀(1 − 2.25577e-5·h)^5.25588), Pa; held at the
/// tropopause value above 11 km (the ram-air cases of the paper fly lower).
///
/// The last altitude's value is kept per thread (keyed by its bits: the
/// answer is the value computed): every outer surface of every heat
/// balance asks for it, a `pow` each time.
pub fn isa_pressure_pa(altitude_m: f64) -> f64 {
    thread_local! {
        static LAST: Cell<(u64, f64)> = const { Cell::new((u64::MAX, f64::NAN)) };
    }
    let key = altitude_m.to_bits();
    LAST.with(|c| {
        let (k, p) = c.get();
        if k == key {
            return p;
        }
        let h = altitude_m.clamp(-500.0, 11_000.0);
        let p = P_SEA_LEVEL_PA * (1.0 - 2.25577e-5 * h).powf(5.25588);
        c.set((key, p));
        p
    })
}

/// Air properties at film temperature `t_c` °C and 101325 Pa (sea level).
pub fn air(t_c: f64) -> AirProps {
    air_at(t_c, P_SEA_LEVEL_PA)
}

/// Air properties at film temperature `t_c` °C and static pressure `p_pa`
/// (Sutherland's law for μ, ideal-gas density ρ = p/(R·T), linear fits for k
/// and cp that match the standard tables to < 1 % between −20 and 150 °C; μ,
/// k, cp and Pr do not depend on pressure at these densities, ν = μ/ρ does).
pub fn air_at(t_c: f64, p_pa: f64) -> AirProps {
    let t_k = t_c + KELVIN_OFFSET;
    let mu = 1.716e-5 * (t_k / 273.15).powf(1.5) * (273.15 + 110.4) / (t_k + 110.4);
    let rho = p_pa / (287.05 * t_k);
    let k = 0.02414 + 7.4e-5 * t_c;
    let cp = 1005.0 + 0.02 * t_c;
    AirProps { nu: mu / rho, k, pr: mu * cp / k, beta: 1.0 / t_k }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Air at 20 °C: ν = 1.516e-5 m²/s, k = 0.0257 W/(m·K), Pr = 0.71 in the
    /// standard tables (Incropera A.4, interpolated); 2 % covers the fits.
    #[test]
    fn air_properties_match_tables() {
        let a = air(20.0);
        assert!((a.nu - 1.516e-5).abs() / 1.516e-5 < 0.02, "nu {}", a.nu);
        assert!((a.k - 0.0257).abs() / 0.0257 < 0.02, "k {}", a.k);
        assert!((a.pr - 0.71).abs() / 0.71 < 0.02, "pr {}", a.pr);
    }

    /// Air at altitude: the ISA pressure at 5 km is 54.0 kPa (ICAO table:
    /// 54.05 kPa, 0.2 %), and ν scales with 1/p at fixed temperature.
    #[test]
    fn air_over_pressure() {
        let p5 = isa_pressure_pa(5000.0);
        assert!((p5 - 54_048.0).abs() / 54_048.0 < 2e-3, "{p5}");
        let (a0, a5) = (air_at(0.0, P_SEA_LEVEL_PA), air_at(0.0, p5));
        assert!((a5.nu / a0.nu - P_SEA_LEVEL_PA / p5).abs() < 1e-12);
        assert_eq!(a5.pr, a0.pr);
    }
}
