//! The fault word's bits as C constants, each asserted at compile time
//! equal to the guard's own (`eha_guard::faults`): a C caller tests
//! `EhaOutput::faults` against them.

use eha_guard::faults;

/// Fault bit: an input outside its plausible range.
pub const EHA_FAULT_RANGE: u32 = 1 << 0;
/// Fault bit: an input changed faster than its rate limit.
pub const EHA_FAULT_RATE: u32 = 1 << 1;
/// Fault bit: an input was NaN or infinite.
pub const EHA_FAULT_NON_FINITE: u32 = 1 << 2;
/// Fault bit: no sample for `stale_ticks` ticks (every input at its worst case).
pub const EHA_FAULT_STALE: u32 = 1 << 3;
/// Fault bit: the thermal record was damaged at boot.
pub const EHA_FAULT_MEMORY_CORRUPT: u32 = 1 << 4;
/// Fault bit: no usable parameters: model disabled, fail-safe, never cleared.
pub const EHA_FAULT_CONFIG: u32 = 1 << 5;
/// Fault bit: the valve pin or its position switch disagreed with the command.
pub const EHA_FAULT_ACTUATOR: u32 = 1 << 6;
/// Status bit: LNG remaining below its low threshold, or no supply pressure.
pub const EHA_FAULT_LNG_LOW: u32 = 1 << 7;
/// Shift of the latched bad-channel mask in the fault word.
pub const EHA_FAULT_CHANNEL_SHIFT: u32 = 8;
/// Fault bit: current and pressures/speed disagree (analytic redundancy).
pub const EHA_FAULT_SENSOR_DISAGREE: u32 = 1 << 14;
/// Status bit: the estimate is not trusted (alarm and derate held).
pub const EHA_FAULT_UNTRUSTED: u32 = 1 << 15;
/// Status bit: a non-volatile save failed (derate).
pub const EHA_FAULT_NV_FAILED: u32 = 1 << 16;
/// Status bit: cooling credited on the LNG budget alone (no supply pressure).
pub const EHA_FAULT_LNG_UNCONFIRMED: u32 = 1 << 17;
/// Status bit: no valve position reported, no cooling credited.
pub const EHA_FAULT_NO_VALVE_FEEDBACK: u32 = 1 << 18;
/// Status bit: the estimate is still forgetting an unknown start.
pub const EHA_FAULT_RECOVERING: u32 = 1 << 19;

const _: () = {
    assert!(EHA_FAULT_RANGE == faults::RANGE.bits());
    assert!(EHA_FAULT_RATE == faults::RATE.bits());
    assert!(EHA_FAULT_NON_FINITE == faults::NON_FINITE.bits());
    assert!(EHA_FAULT_STALE == faults::STALE.bits());
    assert!(EHA_FAULT_MEMORY_CORRUPT == faults::MEMORY_CORRUPT.bits());
    assert!(EHA_FAULT_CONFIG == faults::CONFIG.bits());
    assert!(EHA_FAULT_ACTUATOR == faults::ACTUATOR.bits());
    assert!(EHA_FAULT_LNG_LOW == faults::LNG_LOW.bits());
    assert!(EHA_FAULT_CHANNEL_SHIFT == faults::CH_SHIFT);
    assert!(EHA_FAULT_SENSOR_DISAGREE == faults::SENSOR_DISAGREE.bits());
    assert!(EHA_FAULT_UNTRUSTED == faults::UNTRUSTED.bits());
    assert!(EHA_FAULT_NV_FAILED == faults::NV_FAILED.bits());
    assert!(EHA_FAULT_LNG_UNCONFIRMED == faults::LNG_UNCONFIRMED.bits());
    assert!(EHA_FAULT_NO_VALVE_FEEDBACK == faults::NO_VALVE_FEEDBACK.bits());
    assert!(EHA_FAULT_RECOVERING == faults::RECOVERING.bits());
};
