//! Product frames on the controller UART, beside the sample request of
//! [`crate::protocol`] (same framing: COBS, CRC-16, `0x00` delimiters).
//!
//! Controller → guard: sample requests ([`crate::protocol::Request`], kind
//! `0x02`) at the 10 ms tick rate, and [`Command`] frames (kind `0x10`).
//! Guard → controller: one [`TickReply`] per tick, an [`Ack`] per command,
//! a [`Status`] on request, and a trace dump as one [`TraceReply`] per event.
//! Frame layouts are in `docs/firmware.md` ("What the controller must send,
//! and what it gets back"; the commands under "Commands: arm, then confirm");
//! all fields little-endian, floats as IEEE-754 binary32 bit patterns.

use crate::protocol::{DecodeError, PutAt, Rd, WireFrame};
use crate::trace::{RestoreKind, Trace};
use crate::interface::Output;

mod codec;
mod command;
mod reply;

pub use command::{command_key, Ack, AckResult, Cmd, Command, Refusal, ARM_WINDOW_TICKS, COMMAND_INTERVAL_TICKS};
pub use reply::ReplyEncoder;

/// Kind byte of a command frame (controller → guard).
pub const KIND_COMMAND: u8 = 0x10;
/// Kind byte of a tick reply.
pub const KIND_TICK: u8 = 0x90;
/// Kind byte of a command acknowledgement.
pub const KIND_ACK: u8 = 0x91;
/// Kind byte of a status reply.
pub const KIND_STATUS: u8 = 0x92;
/// Kind byte of a trace-event reply.
pub const KIND_TRACE: u8 = 0x93;

/// Payload length of a command, bytes.
pub const COMMAND_LEN: usize = 8;
/// Payload length of a tick reply, bytes.
pub const TICK_LEN: usize = 33;
/// Bytes of the tick reply's per-tick tail (tick, sample sequence, fresh).
pub const TICK_TAIL_LEN: usize = 7;
/// Payload length of an acknowledgement, bytes.
pub const ACK_LEN: usize = 9;
/// Payload length of a status reply, bytes.
pub const STATUS_LEN: usize = 50;
/// Payload length of a trace-event reply, bytes.
pub const TRACE_LEN: usize = 18;

/// Output pin levels read back from the port's output register.
///
/// Electrical design (README, "Wiring"): both pins are active high for the
/// *healthy* state, so a pin at its reset level (low) is the safe state.
/// `valve_pin` high energises a normally-open valve to close it; `ok_pin`
/// high means "no alarm, no derate".
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Pins {
    /// Valve pin level: `true` = energised = valve closed.
    pub valve_pin: bool,
    /// OK pin level: `true` = no alarm; `false` = alarm/derate.
    pub ok_pin: bool,
}

impl Pins {
    /// The levels that command `valve_open` and `alarm`.
    pub fn for_outputs(valve_open: bool, alarm: bool) -> Pins {
        Pins { valve_pin: !valve_open, ok_pin: !alarm }
    }
}

/// Why the MCU last reset (kept in no-init RAM across the reset, see
/// [`super::reset`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ResetCause {
    /// Power-on (no-init RAM held no cause record).
    PowerOn = 0,
    /// The watchdog expired (the tick loop stopped).
    Watchdog = 1,
    /// A panic (should not happen: the core has no panicking path).
    Panic = 2,
    /// A HardFault or other fault exception.
    HardFault = 3,
    /// An unexpected interrupt.
    Exception = 4,
    /// A reset without a recorded cause (pin reset, debugger, software).
    Other = 5,
}

impl ResetCause {
    /// From the wire/record code (unknown codes are [`ResetCause::Other`]).
    pub fn from_code(c: u8) -> ResetCause {
        match c {
            0 => ResetCause::PowerOn,
            1 => ResetCause::Watchdog,
            2 => ResetCause::Panic,
            3 => ResetCause::HardFault,
            4 => ResetCause::Exception,
            _ => ResetCause::Other,
        }
    }
}

/// Wire code of a restore kind (tick reply and status).
pub(crate) fn restore_code(k: RestoreKind) -> u8 {
    match k {
        RestoreKind::Cold => 0,
        RestoreKind::Warm => 1,
        RestoreKind::Corrupt => 2,
        RestoreKind::PowerLoss => 3,
    }
}

/// Restore kind from its wire code.
pub fn restore_from_code(c: u8) -> Option<RestoreKind> {
    match c {
        0 => Some(RestoreKind::Cold),
        1 => Some(RestoreKind::Warm),
        2 => Some(RestoreKind::Corrupt),
        3 => Some(RestoreKind::PowerLoss),
        _ => None,
    }
}

/// Sent once per tick: the outputs of that tick.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TickReply {
    /// Tick counter since boot (10 ms ticks).
    pub tick: u32,
    /// Sequence number of the newest accepted sample.
    pub sample_seq: u16,
    /// `true` when a new sample arrived for this tick; `false` = missing.
    pub fresh: bool,
    /// NOT_COMMISSIONED: the model runs the compiled-in paper-rig constants
    /// (no parameter block in flash), not this machine's
    /// ([`crate::params_block`]). Bit 1 of the `fresh` byte.
    pub not_commissioned: bool,
    /// The guard's output of this tick.
    pub out: Output,
    /// Pin levels read back after writing them.
    pub pins: Pins,
    /// Ticks that overran their period since boot (saturating).
    pub overruns: u16,
    /// Frames rejected since boot (all reasons, saturating).
    pub rejected: u16,
    /// How this boot's thermal state was initialised.
    pub restore: RestoreKind,
    /// Why the MCU last reset.
    pub reset_cause: ResetCause,
}

/// Frame and tick counters of the product loop (saturating).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Counters {
    /// Frames with a CRC mismatch.
    pub rejected_crc: u16,
    /// Frames with bad COBS, length, kind, or a full command queue.
    pub rejected_framing: u16,
    /// Samples that were duplicates or older than the last accepted one.
    pub rejected_sequence: u16,
    /// Samples replaced by a newer one within the same tick.
    pub superseded: u16,
    /// Samples accepted.
    pub accepted: u32,
    /// Ticks without a new sample.
    pub missing: u32,
    /// Timer periods lost to ticks that overran.
    pub overruns: u32,
    /// Commands executed.
    pub commands: u16,
    /// Non-volatile saves that failed (each followed by [`super::NV_RETRY_TICKS`]
    /// without an attempt).
    pub nv_failures: u16,
}

impl Counters {
    /// Frames rejected for any reason (saturating).
    pub(crate) fn rejected(&self) -> u16 {
        self.rejected_crc.saturating_add(self.rejected_framing).saturating_add(self.rejected_sequence)
    }
}

/// Counters and health, on request.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Status {
    /// The command's token.
    pub token: u16,
    /// Tick counter since boot.
    pub tick: u32,
    /// The product loop's frame and tick counters.
    pub counters: Counters,
    /// Longest tick, core-clock cycles (0 when the board cannot measure it).
    pub worst_tick_cycles: u32,
    /// Stack high-water mark of the tick loop, bytes (0 when not measured).
    pub stack_high_water_b: u16,
    /// Stack used by boot, bytes (0 when not measured).
    pub boot_stack_b: u16,
    /// Why the MCU last reset ([`ResetCause`] code).
    pub reset_cause: u8,
    /// Restore kind code (0 cold, 1 warm, 2 corrupt record).
    pub restore: u8,
    /// Boots since power-on (from no-init RAM).
    pub boots: u16,
    /// Received bytes lost to a full receive buffer.
    pub rx_overflow: u16,
    /// Faults now.
    pub faults: crate::faults::Faults,
    /// Protocol version of this firmware ([`crate::protocol::PROTOCOL_VERSION`]).
    pub protocol: u8,
}

/// One trace event in a dump.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TraceReply {
    /// The command's token.
    pub token: u16,
    /// Index of this event in the dump (0 = oldest).
    pub index: u8,
    /// Events in the dump.
    pub count: u8,
    /// The event (see [`encode_trace`]).
    pub event: TraceWire,
}

/// A trace event flattened for the wire: tag, tick, a value and an aux word.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TraceWire {
    /// Event tag: 1 restore, 2 valve open, 3 valve close, 4 alarm, 5 alarm
    /// clear, 6 fault, 7 faults cleared, 8 LNG low, 9 overrun, 10 reset, 11 command.
    pub tag: u8,
    /// Guard tick of the event.
    pub tick: u32,
    /// Drain °C (valve/alarm events), LNG kg (LNG low), else 0.
    pub value: f32,
    /// Fault bits, restore/reset cause code, forced flag, lost ticks, or a
    /// command's code and (bits 8-15) its result (0 done, else the [`Refusal`]).
    pub aux: u32,
}

/// Flattens a trace event for the wire.
pub fn encode_trace(t: &Trace) -> TraceWire {
    let w = |tag, tick, value, aux| TraceWire { tag, tick, value, aux };
    match *t {
        Trace::Restore { tick, kind } => w(1, tick, 0.0, u32::from(restore_code(kind))),
        Trace::ValveOpen { tick, drain_c, forced } => w(2, tick, drain_c, u32::from(forced)),
        Trace::ValveClose { tick, drain_c } => w(3, tick, drain_c, 0),
        Trace::Alarm { tick, drain_c } => w(4, tick, drain_c, 0),
        Trace::AlarmClear { tick, drain_c } => w(5, tick, drain_c, 0),
        Trace::Fault { tick, new_bits } => w(6, tick, 0.0, new_bits.bits()),
        Trace::FaultsCleared { tick, bits } => w(7, tick, 0.0, bits.bits()),
        Trace::LngLow { tick, remaining_kg } => w(8, tick, remaining_kg, 0),
        Trace::Overrun { tick, lost_ticks } => w(9, tick, 0.0, u32::from(lost_ticks)),
        Trace::Reset { tick, cause } => w(10, tick, 0.0, u32::from(cause)),
        Trace::Command { tick, code, result } => w(11, tick, 0.0, u32::from(code) | (u32::from(result) << 8)),
        Trace::Params { tick, source } => w(12, tick, 0.0, u32::from(source)),
    }
}

/// Any frame the guard sends, decoded (host side).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum FromGuard {
    /// A tick's outputs.
    Tick(TickReply),
    /// A command acknowledgement.
    Ack(Ack),
    /// A status reply.
    Status(Status),
    /// One trace event.
    Trace(TraceReply),
}

impl FromGuard {
    /// Decodes a guard → controller payload by its kind byte.
    pub fn from_payload(p: &[u8]) -> Result<FromGuard, DecodeError> {
        match p.first() {
            Some(&KIND_TICK) => TickReply::from_payload(p).map(FromGuard::Tick),
            Some(&KIND_ACK) => Ack::from_payload(p).map(FromGuard::Ack),
            Some(&KIND_STATUS) => Status::from_payload(p).map(FromGuard::Status),
            Some(&KIND_TRACE) => TraceReply::from_payload(p).map(FromGuard::Trace),
            _ => Err(DecodeError::Kind),
        }
    }
}
