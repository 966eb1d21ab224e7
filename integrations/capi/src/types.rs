//! The plain-C types of the API and their conversions to the guard's own.
//! Inputs that C could fill with any bit pattern (flags, enumerations) are
//! integers checked on entry, never Rust `bool`s or enums.

use eha_guard::faults::{self, Faults};
use eha_guard::guard::DRAIN_C_UNKNOWN;
use eha_guard::memory::ThermalRecord;
use eha_guard::{Output, Reports, Sample};

/// What a call returns: 0 success, > 0 success with a notice, < 0 an error
/// (the call did nothing, or did the fail-safe thing it says).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum EhaStatus {
    /// Done.
    EhaOk = 0,
    /// `eha_guard_init`: the parameter block region is erased (no block):
    /// the guard runs the compiled-in paper-rig constants, as the product
    /// does with an empty PARAMS region (NOT_COMMISSIONED). Not this machine.
    EhaNotCommissioned = 1,
    /// A required pointer is NULL. From `eha_guard_init` with a NULL
    /// parameter block: the guard is initialised in its CONFIG fail-safe.
    EhaErrNull = -1,
    /// The storage is smaller than [`crate::guard::EHA_GUARD_STORAGE_SIZE`].
    EhaErrStorageSize = -2,
    /// The storage is not aligned to [`crate::guard::EHA_GUARD_STORAGE_ALIGN`].
    EhaErrStorageAlign = -3,
    /// `eha_guard_init`: the parameter block was refused (length, magic,
    /// version, word count, CRC, alignment, or values the model rejects):
    /// the guard is initialised in its CONFIG fail-safe (valve open, alarm,
    /// derate, no estimate), as the product does.
    EhaErrParams = -4,
    /// The storage does not hold an initialised guard (never initialised,
    /// overwritten, or poisoned by a caught panic). Outputs written by the
    /// call are the fail-safe ones.
    EhaErrState = -5,
    /// An argument is out of its range (a flag not 0/1, an unknown
    /// enumeration value). `eha_guard_tick`: the sample was not used and the
    /// tick ran as a missing sample.
    EhaErrArg = -6,
    /// A Rust panic was caught at the boundary (host builds only): the
    /// storage is poisoned, the outputs written are the fail-safe ones.
    EhaErrPanic = -7,
    /// An output buffer is too small.
    EhaErrBuffer = -8,
    /// Command refused: no matching arm within its window.
    EhaRefusedNotArmed = -10,
    /// Command refused: wrong key.
    EhaRefusedKey = -11,
    /// Command refused: within the interval since the last confirmed one.
    EhaRefusedTooSoon = -12,
    /// Command refused by the guard's rule: a clear with faults still
    /// present in the last second, a refill with the valve open or in alarm.
    EhaRefusedRule = -13,
}

/// [`EhaSample::valve_feedback`]: no position switch is wired.
pub const EHA_FEEDBACK_NONE: i8 = -1;
/// [`EhaSample::valve_feedback`]: the valve reports shut.
pub const EHA_FEEDBACK_SHUT: i8 = 0;
/// [`EhaSample::valve_feedback`]: the valve reports open.
pub const EHA_FEEDBACK_OPEN: i8 = 1;

/// One 10 ms sample and the controller's reports (wire units).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct EhaSample {
    /// Motor phase current, A rms (eq. 1-3 copper loss).
    pub current_a: f32,
    /// Pump port A pressure, bar gauge.
    pub p_a_bar: f32,
    /// Pump port B pressure, bar gauge.
    pub p_b_bar: f32,
    /// Motor = pump shaft speed, rpm, signed by direction.
    pub speed_rpm: f32,
    /// Piston position, mm.
    pub position_mm: f32,
    /// Ambient air temperature near the actuator, degC.
    pub ambient_c: f32,
    /// LNG supply pressure at the valve, bar gauge (used when
    /// `has_lng_supply` is 1; below the minimum, or NaN, the tank is empty).
    pub lng_supply_bar: f32,
    /// The motor drive's electrical frequency, Hz, signed like the speed
    /// (used when `has_elec_hz` is 1: the speed plausibility check).
    pub elec_hz: f32,
    /// LNG valve position switch: [`EHA_FEEDBACK_NONE`], [`EHA_FEEDBACK_SHUT`]
    /// or [`EHA_FEEDBACK_OPEN`]. Without it no cooling is credited.
    pub valve_feedback: i8,
    /// 1: `lng_supply_bar` is measured; 0: not reported.
    pub has_lng_supply: u8,
    /// 1: `elec_hz` is measured; 0: not reported.
    pub has_elec_hz: u8,
    /// 0.
    pub reserved: u8,
}

impl EhaSample {
    /// The guard's sample and reports; `None` when a flag is out of range.
    pub fn to_guard(&self) -> Option<(Sample, Reports)> {
        let flag = |f: u8, v: f32| match f {
            0 => Some(None),
            1 => Some(Some(v)),
            _ => None,
        };
        let valve_fb = match self.valve_feedback {
            EHA_FEEDBACK_NONE => None,
            EHA_FEEDBACK_SHUT => Some(false),
            EHA_FEEDBACK_OPEN => Some(true),
            _ => return None,
        };
        let s = Sample {
            current_a: self.current_a,
            p_a_bar: self.p_a_bar,
            p_b_bar: self.p_b_bar,
            speed_rpm: self.speed_rpm,
            position_mm: self.position_mm,
            ambient_c: self.ambient_c,
        };
        let r = Reports { valve_fb, lng_supply_bar: flag(self.has_lng_supply, self.lng_supply_bar)?, elec_hz: flag(self.has_elec_hz, self.elec_hz)? };
        Some((s, r))
    }
}

/// One tick's result. Always finite except `lng_seconds_left` (infinite
/// with no dissipation).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct EhaOutput {
    /// Predicted pump drain-port oil temperature, degC, with the parameter
    /// block's commissioning margin added (the value the valve and alarm act
    /// on; [`EHA_DRAIN_C_UNKNOWN`] without a model: CONFIG).
    pub drain_c: f32,
    /// LNG remaining, kg.
    pub lng_remaining_kg: f32,
    /// Seconds of LNG cooling left at the present dissipation, s.
    pub lng_seconds_left: f32,
    /// The fault word (`EHA_FAULT_*` bits; bits 8-13 the bad input channels).
    pub faults: u32,
    /// LNG cooling valve command: 1 open.
    pub valve_open: u8,
    /// Over-temperature alarm (drain above 60 degC, cleared below 58 degC),
    /// or an untrusted estimate: 1 raised.
    pub alarm: u8,
    /// Derate request to the actuator controller: 1 raised.
    pub derate: u8,
    /// 0.
    pub reserved: u8,
}

/// [`EhaOutput::drain_c`] when the model is disabled (CONFIG), degC.
pub const EHA_DRAIN_C_UNKNOWN: f32 = 1.0e6;
const _: () = assert!(EHA_DRAIN_C_UNKNOWN == DRAIN_C_UNKNOWN);

impl EhaOutput {
    /// The C form of the guard's output.
    pub fn of(o: &Output) -> Self {
        EhaOutput {
            drain_c: o.drain_c,
            lng_remaining_kg: o.lng_remaining_kg,
            lng_seconds_left: o.lng_seconds_left,
            faults: o.faults.bits(),
            valve_open: u8::from(o.valve_open),
            alarm: u8::from(o.alarm),
            derate: u8::from(o.derate),
            reserved: 0,
        }
    }

    /// The guard's output of this C form (flags other than 0 read as set).
    pub fn to_guard(&self) -> Output {
        Output {
            drain_c: self.drain_c,
            valve_open: self.valve_open != 0,
            alarm: self.alarm != 0,
            derate: self.derate != 0,
            faults: Faults::from_bits(self.faults),
            lng_remaining_kg: self.lng_remaining_kg,
            lng_seconds_left: self.lng_seconds_left,
        }
    }

    /// What an error path writes: the fail-safe state (valve open, alarm,
    /// derate, no estimate, CONFIG), so a caller that ignores the status
    /// still drives the safe side.
    pub const FAIL_SAFE: EhaOutput = EhaOutput {
        drain_c: EHA_DRAIN_C_UNKNOWN,
        lng_remaining_kg: 0.0,
        lng_seconds_left: 0.0,
        faults: faults::CONFIG.bits(),
        valve_open: 1,
        alarm: 1,
        derate: 1,
        reserved: 0,
    };
}

/// The thermal record (what survives a reset or a power loss), field for
/// field the product's record: store it in no-init RAM (two slots, A and B)
/// and in non-volatile memory as `eha_guard_record` says; its byte form
/// ([`EHA_RECORD_BYTES`](crate::EHA_RECORD_BYTES), `eha_record_to_bytes`) is
/// little-endian in field order.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct EhaRecord {
    /// LNG heat-sink energy used, cJ (0.01 J).
    pub lng_used_cj: u32,
    /// Guard tick counter (10 ms) at save time.
    pub tick: u32,
    /// Record magic (`"EHAT"`).
    pub magic: u32,
    /// Record format version ([`EHA_RECORD_FORMAT_VERSION`](crate::EHA_RECORD_FORMAT_VERSION)).
    pub version: u16,
    /// 0.
    pub reserved: u16,
    /// Recorded fault bits.
    pub faults: u32,
    /// Node temperatures of the reduced model, degC: pump housing, case oil,
    /// loop oil, main block, ball-valve block, actuator.
    pub temps_c: [f32; 6],
    /// Ambient the temperatures were referred to, degC.
    pub ambient_c: f32,
    /// Write sequence number (bits 0-30) and the valve state (bit 31).
    pub seq_flags: u32,
    /// Battery-backed clock at the write, s ([`EHA_RTC_NONE`]: no clock).
    pub rtc_s: u32,
    /// CRC-32 (IEEE) of the preceding fields' little-endian bytes.
    pub crc: u32,
}

const _: () = assert!(core::mem::size_of::<EhaRecord>() == eha_guard::memory::RECORD_BYTES);
const _: () = assert!(core::mem::size_of::<ThermalRecord>() == eha_guard::memory::RECORD_BYTES);

/// No battery-backed clock (for [`EhaRecord::rtc_s`] and [`EhaBoot`]).
pub const EHA_RTC_NONE: u32 = u32::MAX;
const _: () = assert!(EHA_RTC_NONE == eha_guard::memory::RTC_NONE);

impl EhaRecord {
    /// The C form of a record.
    pub fn of(r: &ThermalRecord) -> Self {
        EhaRecord {
            lng_used_cj: r.lng_used_cj,
            tick: r.tick,
            magic: r.magic,
            version: r.version,
            reserved: r.reserved,
            faults: r.faults,
            temps_c: r.temps_c,
            ambient_c: r.ambient_c,
            seq_flags: r.seq_flags,
            rtc_s: r.rtc_s,
            crc: r.crc,
        }
    }

    /// The guard's record of this C form (not checked: see `classify`).
    pub fn to_guard(&self) -> ThermalRecord {
        ThermalRecord {
            lng_used_cj: self.lng_used_cj,
            tick: self.tick,
            magic: self.magic,
            version: self.version,
            reserved: self.reserved,
            faults: self.faults,
            temps_c: self.temps_c,
            ambient_c: self.ambient_c,
            seq_flags: self.seq_flags,
            rtc_s: self.rtc_s,
            crc: self.crc,
        }
    }
}

/// [`EhaBoot::nv_status`]: the non-volatile store holds no record (erased).
pub const EHA_NV_NONE: i32 = 0;
/// [`EhaBoot::nv_status`]: a record was read (it is checked again here: one
/// that fails its check counts as damaged).
pub const EHA_NV_VALID: i32 = 1;
/// [`EhaBoot::nv_status`]: a record is there but could not be read or failed
/// its check: the machine may be hot (conservative start).
pub const EHA_NV_DAMAGED: i32 = 2;

/// What the firmware found in its memories at boot (all optional: a NULL
/// `EhaBoot*` is a board without thermal memory: a cold start).
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct EhaBoot {
    /// No-init RAM record slot A as found (whatever bits are there), or NULL.
    pub ram_a: *const EhaRecord,
    /// No-init RAM record slot B, or NULL.
    pub ram_b: *const EhaRecord,
    /// The non-volatile record when `nv_status` is [`EHA_NV_VALID`], else NULL.
    pub nv_record: *const EhaRecord,
    /// [`EHA_NV_NONE`], [`EHA_NV_VALID`] or [`EHA_NV_DAMAGED`].
    pub nv_status: i32,
    /// The battery-backed clock now, s ([`EHA_RTC_NONE`]: none).
    pub rtc_now_s: u32,
    /// The clock's last-alive stamp before the power loss, s
    /// ([`EHA_RTC_NONE`]: none). With both, a power loss cools the restored
    /// state over the off-time; without, it restores it as saved.
    pub alive_s: u32,
    /// 1: the last-alive word says the non-volatile saves were failing
    /// before the power loss (conservative start); 0 otherwise.
    pub nv_failing: u8,
    /// Boots counted by the firmware (seeds the command nonces; 0: unknown).
    pub boot_count: u16,
}

/// [`EhaBootInfo::restore`]: cold start (every node at the first ambient).
pub const EHA_RESTORE_COLD: i32 = 0;
/// Warm reset: a valid RAM record was restored.
pub const EHA_RESTORE_WARM: i32 = 1;
/// A damaged record: conservative start (every node at the alarm
/// temperature, valve open, alarm and derate until a clear after recovery).
pub const EHA_RESTORE_CORRUPT: i32 = 2;
/// Power loss: the non-volatile record, raised by the write policy's margin.
pub const EHA_RESTORE_POWER_LOSS: i32 = 3;

/// [`EhaBootInfo::params`]: no block (erased region): the paper rig.
pub const EHA_PARAMS_DEFAULT: i32 = 0;
/// A valid parameter block.
pub const EHA_PARAMS_BLOCK: i32 = 1;
/// The block was refused (its header, CRC or alignment, or values the
/// model rejects): CONFIG, fail-safe.
pub const EHA_PARAMS_INVALID: i32 = 2;

/// What `eha_guard_init` did.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct EhaBootInfo {
    /// `EHA_RESTORE_*`: how the thermal state started.
    pub restore: i32,
    /// `EHA_PARAMS_*`: where the model constants come from.
    pub params: i32,
}

/// What `eha_guard_record` asks the firmware to store.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct EhaRecordWrite {
    /// 1: the state changed: store `record` in RAM slot `slot`; 0: nothing
    /// to store this tick (the rest is left as it was).
    pub changed: u8,
    /// RAM slot, 0 = A, 1 = B (they alternate: a reset during a write
    /// leaves the other one).
    pub slot: u8,
    /// 1: also save `record` to non-volatile memory now (the write policy),
    /// then report the outcome with `eha_guard_nv_saved`.
    pub nv_due: u8,
    /// 0.
    pub reserved: u8,
    /// The sealed record.
    pub record: EhaRecord,
}
