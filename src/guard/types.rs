//! The guard's configuration, [`GuardConfig`] (its wire-unit interface types
//! are in [`crate::interface`]; docs/contracts.md).

use crate::model::ModelConsts;
use crate::protection::{AlarmConfig, LngConfig, ValveConfig};
use crate::validate::InputLimits;

/// Everything configurable, SI/wire units.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GuardConfig<'a> {
    /// Reduced-model constants in model units, `f32` words: the compiled-in
    /// [`crate::model::DEFAULT_CONSTS`] or a parameter block
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
    /// Defaults: [`crate::model::DEFAULT_CONSTS`] (the paper rig), Tables 2/3/6 limits, 40/38 degC valve, 60 degC alarm.
    pub const DEFAULT: GuardConfig<'static> = GuardConfig {
        model: &crate::model::DEFAULT_CONSTS,
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
