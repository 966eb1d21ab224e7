//! Interface types of the guard (docs/contracts.md): the wire-unit [`Sample`] and
//! [`Output`], the fault word, and [`GuardConfig`].

use crate::model::ModelConsts;
use crate::protection::{AlarmConfig, LngConfig, ValveConfig};
use crate::validate::InputLimits;

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
    /// Derate request to the actuator controller (= alarm).
    pub derate: bool,
    /// The faults ([`crate::faults`]; on the wire as their 16-bit word).
    pub faults: crate::faults::Faults,
    /// LNG remaining, kg.
    pub lng_remaining_kg: f32,
    /// Seconds of LNG cooling left at the present dissipation, s.
    pub lng_seconds_left: f32,
}

/// What the controller reports beside the sample, once per tick, each
/// optional: the valve position read back ([`super::GuardOf::valve_feedback`]),
/// the LNG supply pressure ([`super::GuardOf::lng_supply`]) and the motor's
/// electrical frequency ([`super::GuardOf::check_speed`]).
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

/// Everything configurable, SI/wire units.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GuardConfig<'a> {
    /// Reduced-model constants in model units, `f32` words: the compiled-in
    /// [`crate::params::DEFAULT_CONSTS`] or a parameter block
    /// ([`crate::params_block`]); from SI parameters on the host with
    /// `model::consts::derive(&p)?.to_f32()`.
    pub model: &'a ModelConsts<f32>,
    /// Input ranges and rates.
    pub limits: InputLimits,
    /// LNG valve thresholds and dwell.
    pub valve: ValveConfig,
    /// Over-temperature alarm.
    pub alarm: AlarmConfig,
    /// LNG heat sink.
    pub lng: LngConfig,
    /// Consecutive missing samples, once samples have started, that make the input
    /// stale, 10 ms ticks (5 = 50 ms).
    pub stale_ticks: u32,
    /// Ticks after boot without any sample before the input is declared stale
    /// (1000 = 10 s). Until the first sample the guard waits: valve open (the safe
    /// state), model not started, no fault.
    pub startup_timeout_ticks: u32,
    /// Consecutive fully valid samples required before `clear_faults` succeeds, 10 ms ticks.
    pub clear_valid_ticks: u32,
    /// Consecutive valve-position reports ([`super::GuardOf::valve_feedback`]) that
    /// differ from the command before ACTUATOR latches, 10 ms ticks (50 = 0.5 s: a
    /// cryogenic solenoid valve strokes in ≤ 0.1 s; the fault campaign's rule is
    /// detection within 1 s of the mismatch).
    pub actuator_mismatch_ticks: u32,
    /// Sensor cross-check (current against pressures and speed).
    pub crosscheck: crate::crosscheck::CrossCheckConfig,
    /// Speed plausibility (electrical frequency, piston flow, stall).
    pub speed: crate::speedcheck::SpeedCheckConfig,
}

impl GuardConfig<'static> {
    /// Defaults: [`crate::params::DEFAULT_CONSTS`] (the paper rig), Tables 2/3/6 limits, 40/38 degC valve, 60 degC alarm.
    pub const DEFAULT: GuardConfig<'static> = GuardConfig {
        model: &crate::params::DEFAULT_CONSTS,
        limits: InputLimits::DEFAULT,
        valve: ValveConfig::DEFAULT,
        alarm: AlarmConfig::DEFAULT,
        lng: LngConfig::DEFAULT,
        stale_ticks: 5,
        startup_timeout_ticks: 1000,
        clear_valid_ticks: 100,
        actuator_mismatch_ticks: 50,
        crosscheck: crate::crosscheck::CrossCheckConfig::DEFAULT,
        speed: crate::speedcheck::SpeedCheckConfig::DEFAULT,
    };
}
