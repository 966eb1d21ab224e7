//! The model's inputs: one 10 ms tick of validated samples in model units
//! (hA, hbar, hrad/s, mm, degC), and the wire → model unit scales.

use crate::num::Num;

/// Wire → model unit: A → hA.
pub const HA_PER_A: f64 = 0.01;
/// Wire → model unit: bar → hbar (10 MPa).
pub const HBAR_PER_BAR: f64 = 0.01;
/// Wire → model unit: rpm → hrad/s (100 rad/s).
pub const HRADS_PER_RPM: f64 = 2.0 * core::f64::consts::PI / 60.0 / 100.0;

/// One tick of validated inputs in model units (hA, hbar, hrad/s, mm, degC).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ModelInputN<N> {
    /// Motor phase current, hA (100 A) rms.
    pub current_ha: N,
    /// Port A pressure, hbar gauge.
    pub p_a_hbar: N,
    /// Port B pressure, hbar gauge.
    pub p_b_hbar: N,
    /// Shaft speed, hrad/s (signed; positive delivers into port A).
    pub speed_hrads: N,
    /// Piston position change over this tick, mm (signed).
    pub dpos_mm: N,
    /// Ambient air temperature, degC.
    pub ambient_c: N,
}

impl<N: Num> ModelInputN<N> {
    /// One tick's inputs from wire units (A, bar, rpm, mm of piston travel in
    /// this tick, degC) given as `f64`: host tools and tests. The firmware
    /// scales its `f32` samples in its own number type ([`InputScales`]).
    pub fn from_wire_f64(current_a: f64, p_a_bar: f64, p_b_bar: f64, speed_rpm: f64, dpos_mm: f64, ambient_c: f64) -> Self {
        let f = N::from_f64;
        ModelInputN {
            current_ha: f(current_a * HA_PER_A),
            p_a_hbar: f(p_a_bar * HBAR_PER_BAR),
            p_b_hbar: f(p_b_bar * HBAR_PER_BAR),
            speed_hrads: f(speed_rpm * HRADS_PER_RPM),
            dpos_mm: f(dpos_mm),
            ambient_c: f(ambient_c),
        }
    }
}

/// Wire → model unit scales in the number type (built once).
#[derive(Clone, Copy, Debug)]
pub struct InputScales<N: Num> {
    /// A → hA.
    pub ha_per_a: N::Scale,
    /// bar → hbar.
    pub hbar_per_bar: N::Scale,
    /// rpm → hrad/s.
    pub hrads_per_rpm: N::Scale,
    /// Unity (mm, degC).
    pub one: N::Scale,
}

impl<N: Num> InputScales<N> {
    /// The scale of each sample channel, in channel order `[current, p_A, p_B,
    /// speed, position, ambient]` (`validate::CH_*`).
    #[inline(always)]
    pub fn per_channel(&self) -> [N::Scale; 6] {
        [self.ha_per_a, self.hbar_per_bar, self.hbar_per_bar, self.hrads_per_rpm, self.one, self.one]
    }

    /// Builds the scales; `None` only if the number type cannot hold them.
    pub fn new() -> Option<Self> {
        Some(InputScales {
            ha_per_a: N::scale_from_f64(HA_PER_A)?,
            hbar_per_bar: N::scale_from_f64(HBAR_PER_BAR)?,
            hrads_per_rpm: N::scale_from_f64(HRADS_PER_RPM)?,
            one: N::scale_from_f64(1.0)?,
        })
    }
}
