//! The guard's interface in wire units (docs/contracts.md): one input
//! [`Sample`], the controller's [`Reports`] beside it, one tick's [`Output`].
//! Below the guard, the validation and the protocol, which all use them.

/// One input sample, wire units (f32).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Sample {
    /// Motor phase current, A rms.
    pub current_a: f32,
    /// Pump port A pressure, bar.
    pub p_a_bar: f32,
    /// Pump port B pressure, bar.
    pub p_b_bar: f32,
    /// Motor speed, rpm (signed).
    pub speed_rpm: f32,
    /// Piston position, mm.
    pub position_mm: f32,
    /// Ambient temperature, degC.
    pub ambient_c: f32,
}

/// One tick's result, wire units. Always finite.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Output {
    /// Predicted drain-oil temperature, degC: the model's case oil plus the
    /// parameter block's commissioning margin (`drain_margin_k`, 0 for the
    /// paper rig), the value the valve and alarm act on ([`DRAIN_C_UNKNOWN`]
    /// if the model is disabled).
    pub drain_c: f32,
    /// LNG valve command (`true` = open).
    pub valve_open: bool,
    /// Over-temperature alarm (drain > 60 degC, cleared below 58 degC).
    pub alarm: bool,
    /// Derate request to the actuator controller: the alarm, or a protection
    /// weaker than the estimate says (ACTUATOR: the valve does not follow
    /// its command; NV_FAILED: the thermal record could not be saved). Equal
    /// to [`Output::alarm`] while neither fault stands.
    pub derate: bool,
    /// The faults ([`crate::faults`]; on the wire as their 32-bit word).
    pub faults: crate::faults::Faults,
    /// LNG remaining, kg.
    pub lng_remaining_kg: f32,
    /// Seconds of LNG cooling left at the present dissipation, s.
    pub lng_seconds_left: f32,
}

/// What the controller reports beside the sample, once per tick, each
/// optional: the valve position read back ([`crate::GuardOf::valve_feedback`]),
/// the LNG supply pressure ([`crate::GuardOf::lng_supply`]) and the motor's
/// electrical frequency ([`crate::GuardOf::check_speed`]).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Reports {
    /// LNG valve position read back (`Some(true)` open), `None` when not reported.
    pub valve_fb: Option<bool>,
    /// LNG supply pressure at the valve, bar gauge; `None` when not reported.
    pub lng_supply_bar: Option<f32>,
    /// The motor drive's electrical frequency, Hz (signed like the speed);
    /// `None` when not reported.
    pub elec_hz: Option<f32>,
}

/// Drain temperature reported when no model is available (CONFIG fault), degC.
pub const DRAIN_C_UNKNOWN: f32 = 1.0e6;
