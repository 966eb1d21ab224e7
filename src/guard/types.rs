//! Interface types of the guard (docs/contracts.md): the wire-unit [`Sample`] and
//! [`Output`], the fault word, and [`GuardConfig`].

use crate::model::ModelConsts;
use crate::protection::{AlarmConfig, LngConfig, ValveConfig};
use crate::validate::InputLimits;

/// Fault bits of [`Output::faults`]. Bits 0-6 and 14 are latched until the clear
/// rule ([`GuardOf::clear_faults`]); bits 7 and 15 are live status; bits 8-13 name
/// the latched bad input channels (`validate::CH_*` shifted by
/// [`faults::CH_SHIFT`]). The same word goes on the wire (`crate::protocol`).
pub mod faults {
    /// An input was outside its plausible range.
    pub const RANGE: u16 = 1 << 0;
    /// An input changed faster than its rate limit.
    pub const RATE: u16 = 1 << 1;
    /// An input was NaN or infinite.
    pub const NON_FINITE: u16 = 1 << 2;
    /// No new sample for `stale_steps` consecutive steps.
    pub const STALE: u16 = 1 << 3;
    /// The thermal-memory record was corrupt at boot.
    pub const MEMORY_CORRUPT: u16 = 1 << 4;
    /// The parameters could not be built into a model (model disabled, fail-safe).
    /// Not clearable at run time: needs valid parameters and a restart.
    pub const CONFIG: u16 = 1 << 5;
    /// The valve output pin reported an error (set by the board layer).
    pub const ACTUATOR: u16 = 1 << 6;
    /// LNG remaining below the low threshold (live status, not latched).
    pub const LNG_LOW: u16 = 1 << 7;
    /// The motor current and the port pressures / speed have disagreed about the
    /// shaft's loss for `crosscheck.persist_windows` windows in a row (analytic
    /// redundancy, [`crate::crosscheck`]). Latched: valve open, alarm and derate
    /// (UNTRUSTED), the model heats with the larger of the two losses.
    pub const SENSOR_DISAGREE: u16 = 1 << 14;
    /// Shift of the latched bad-channel mask inside the fault word.
    pub const CH_SHIFT: u16 = 8;
    /// The estimate is not trusted (corrupt thermal record at boot, or no sample by
    /// the start-up timeout): alarm and derate are held until a successful
    /// [`super::GuardOf::clear_faults`]. Status, not a latched fault; kept in the
    /// thermal record so a warm reset does not drop it.
    pub const UNTRUSTED: u16 = 1 << 15;
    /// Bits that latch.
    pub const LATCHED: u16 = 0x7f | SENSOR_DISAGREE;
}

/// One input sample, wire units (f32).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(any(target_os = "none", feature = "defmt"), derive(defmt::Format))]
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

/// One step's result, wire units. Always finite.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(any(target_os = "none", feature = "defmt"), derive(defmt::Format))]
pub struct Output {
    /// Predicted drain-oil temperature, degC ([`DRAIN_C_UNKNOWN`] if the model is disabled).
    pub drain_c: f32,
    /// LNG valve command (`true` = open).
    pub valve_open: bool,
    /// Over-temperature alarm (drain > 60 degC, cleared below 58 degC).
    pub alarm: bool,
    /// Derate request to the actuator controller (= alarm).
    pub derate: bool,
    /// Fault word, see [`faults`].
    pub faults: u16,
    /// LNG remaining, kg.
    pub lng_remaining_kg: f32,
    /// Seconds of LNG cooling left at the present dissipation, s.
    pub lng_seconds_left: f32,
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
    pub stale_steps: u32,
    /// Ticks after boot without any sample before the input is declared stale
    /// (1000 = 10 s). Until the first sample the guard waits: valve open (the safe
    /// state), model not started, no fault.
    pub startup_timeout_steps: u32,
    /// Consecutive fully valid samples required before `clear_faults` succeeds, steps.
    pub clear_valid_steps: u32,
    /// Consecutive valve-position reports ([`super::GuardOf::valve_feedback`]) that
    /// differ from the command before ACTUATOR latches, 10 ms ticks (50 = 0.5 s: a
    /// cryogenic solenoid valve strokes in ≤ 0.1 s; the fault campaign's rule is
    /// detection within 1 s of the mismatch).
    pub actuator_mismatch_steps: u32,
    /// Sensor cross-check (current against pressures and speed).
    pub crosscheck: crate::crosscheck::CrossCheckConfig,
}

impl GuardConfig<'static> {
    /// Defaults: [`crate::params::DEFAULT_CONSTS`] (the paper rig), Tables 2/3/6 limits, 40/38 degC valve, 60 degC alarm.
    pub const DEFAULT: GuardConfig<'static> = GuardConfig {
        model: &crate::params::DEFAULT_CONSTS,
        limits: InputLimits::DEFAULT,
        valve: ValveConfig::DEFAULT,
        alarm: AlarmConfig::DEFAULT,
        lng: LngConfig::DEFAULT,
        stale_steps: 5,
        startup_timeout_steps: 1000,
        clear_valid_steps: 100,
        actuator_mismatch_steps: 50,
        crosscheck: crate::crosscheck::CrossCheckConfig::DEFAULT,
    };
}
