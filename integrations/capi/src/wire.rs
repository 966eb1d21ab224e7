//! The product's UART frames for a C loop (`eha_guard::protocol`,
//! `eha_guard::product::wire`; layouts in docs/firmware.md): sample requests
//! and commands in (a deframer fed what the UART received, COBS + CRC-16), tick replies
//! out; and the two frames of the QEMU lockstep transport
//! (`eha_guard::protocol::lockstep`: end of tick, completion marker) that
//! the processor-in-the-loop harness reads.

use core::ffi::c_void;
use core::mem::{align_of, size_of};

use eha_guard::product::wire::{restore_from_code, Counters, Pins, ResetCause, Status, TickReply};
use eha_guard::protocol::lockstep::{tick_end, DONE_TOKEN};
use eha_guard::protocol::{Deframer, DecodeError, Request, WireFrame, MAX_WIRE, PROTOCOL_VERSION};
use eha_guard::Faults;

use crate::types::*;

/// Bytes of storage a deframer needs (at least).
pub const EHA_WIRE_DEFRAMER_SIZE: usize = 88;
/// Alignment of the deframer's storage, bytes.
pub const EHA_WIRE_DEFRAMER_ALIGN: usize = 8;
/// The longest encoded frame, bytes (delimiters included).
pub const EHA_WIRE_FRAME_MAX: usize = 61;

const _: () = assert!(size_of::<WireShim>() <= EHA_WIRE_DEFRAMER_SIZE);
const _: () = assert!(align_of::<WireShim>() <= EHA_WIRE_DEFRAMER_ALIGN);
const _: () = assert!(EHA_WIRE_FRAME_MAX == MAX_WIRE);

/// Storage word of an initialised deframer.
const READY: u32 = 0x4548_4446; // "EHDF"

#[repr(C)]
struct WireShim {
    magic: u32,
    d: Deframer,
}

/// What [`eha_wire_feed`] found.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum EhaWireEvent {
    /// No frame ended with this byte.
    EhaWireNone = 0,
    /// A sample request: `msg.seq` and `msg.sample`.
    EhaWireSample = 1,
    /// A command: `msg.token`, `msg.command` (wire code), `msg.arg`.
    EhaWireCommand = 2,
    /// A frame failed its CRC.
    EhaWireRejectedCrc = -1,
    /// A frame was malformed (COBS, length, kind, overflow).
    EhaWireRejectedFraming = -2,
    /// The deframer storage is NULL, misaligned or not initialised.
    EhaWireErrState = -3,
}

/// A frame decoded by [`eha_wire_feed`].
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct EhaWireMessage {
    /// Sample: its sequence number (wrapping).
    pub seq: u16,
    /// Command: the token the reply echoes.
    pub token: u16,
    /// Command: its wire code (1 clear arm, 2 refill arm, 3 status,
    /// 4 trace, 5 clear confirm, 6 refill confirm).
    pub command: u8,
    /// 0.
    pub reserved: [u8; 3],
    /// Command: its argument (a confirmation's key).
    pub arg: u32,
    /// Sample: the sample and the controller's reports.
    pub sample: EhaSample,
}

/// Initialises a deframer in `storage` (`size` bytes, aligned to
/// [`EHA_WIRE_DEFRAMER_ALIGN`]).
///
/// # Safety
/// `storage` NULL or valid for writes of `size` bytes.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn eha_wire_deframer_init(storage: *mut c_void, size: usize) -> EhaStatus {
    if storage.is_null() {
        return EhaStatus::EhaErrNull;
    }
    if size < size_of::<WireShim>() {
        return EhaStatus::EhaErrStorageSize;
    }
    let p = storage.cast::<WireShim>();
    if !p.is_aligned() {
        return EhaStatus::EhaErrStorageAlign;
    }
    // SAFETY: aligned and valid for writes of a `WireShim` (checked, caller).
    unsafe { p.write(WireShim { magic: READY, d: Deframer::new() }) };
    EhaStatus::EhaOk
}

/// Feeds received bytes up to the end of the first frame among them:
/// `used` receives how many bytes were taken (call again with the rest);
/// at the end of a frame returns what it was and fills `msg` (may be NULL).
/// A whole chunk is decoded in one pass (the product loop's transport).
///
/// # Safety
/// `deframer` as initialised by [`eha_wire_deframer_init`]; `bytes` valid
/// for reads of `len` bytes; `used` valid for a write; `msg` NULL or valid
/// for a write.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn eha_wire_feed(deframer: *mut c_void, bytes: *const u8, len: usize, used: *mut usize, msg: *mut EhaWireMessage) -> EhaWireEvent {
    let p = deframer.cast::<WireShim>();
    if bytes.is_null() || used.is_null() {
        return EhaWireEvent::EhaWireErrState;
    }
    // SAFETY: NULL-checked, aligned, valid for reads (caller); the word is
    // read before the rest is taken as initialised.
    if p.is_null() || !p.is_aligned() || unsafe { core::ptr::addr_of!((*p).magic).read() } != READY {
        return EhaWireEvent::EhaWireErrState;
    }
    // SAFETY: initialised (READY).
    let w = unsafe { &mut *p };
    // SAFETY: valid for reads of `len` bytes (caller).
    let input = unsafe { core::slice::from_raw_parts(bytes, len) };
    let (k, res) = w.d.feed(input);
    // SAFETY: valid for writes (caller).
    unsafe { used.write(k) };
    let mut m = EhaWireMessage::default();
    let ev = match res {
        None => return EhaWireEvent::EhaWireNone,
        Some(Err(DecodeError::Crc)) => EhaWireEvent::EhaWireRejectedCrc,
        Some(Err(_)) => EhaWireEvent::EhaWireRejectedFraming,
        Some(Ok(payload)) => match payload.first() {
            Some(&eha_guard::product::wire::KIND_COMMAND) => match eha_guard::product::wire::Command::from_payload(payload) {
                Ok(c) => {
                    m.token = c.token;
                    m.command = c.cmd.code();
                    m.arg = c.arg;
                    EhaWireEvent::EhaWireCommand
                }
                Err(_) => EhaWireEvent::EhaWireRejectedFraming,
            },
            _ => match Request::from_payload(payload) {
                Ok(r) => {
                    m.seq = r.seq;
                    m.sample = sample_of(&r);
                    EhaWireEvent::EhaWireSample
                }
                Err(DecodeError::Crc) => EhaWireEvent::EhaWireRejectedCrc,
                Err(_) => EhaWireEvent::EhaWireRejectedFraming,
            },
        },
    };
    if !msg.is_null() {
        // SAFETY: non-null and valid for writes (caller).
        unsafe { msg.write(m) };
    }
    ev
}

/// The C sample of a request frame.
fn sample_of(req: &Request) -> EhaSample {
    let (s, r) = (&req.sample, &req.reports);
    EhaSample {
        current_a: s.current_a,
        p_a_bar: s.p_a_bar,
        p_b_bar: s.p_b_bar,
        speed_rpm: s.speed_rpm,
        position_mm: s.position_mm,
        ambient_c: s.ambient_c,
        lng_supply_bar: r.lng_supply_bar.unwrap_or(0.0),
        elec_hz: r.elec_hz.unwrap_or(0.0),
        valve_feedback: match r.valve_fb {
            None => EHA_FEEDBACK_NONE,
            Some(false) => EHA_FEEDBACK_SHUT,
            Some(true) => EHA_FEEDBACK_OPEN,
        },
        has_lng_supply: u8::from(r.lng_supply_bar.is_some()),
        has_elec_hz: u8::from(r.elec_hz.is_some()),
        reserved: 0,
    }
}

/// The levels to drive for `out` (README, "Wiring"; both active high for
/// the healthy state, so a pin at its reset level is the safe state):
/// `valve_pin` 1 energises the normally-open valve shut, `ok_pin` 1 means no
/// alarm and no derate.
///
/// # Safety
/// `out` valid; `valve_pin`, `ok_pin` valid for writes.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn eha_pins_for(out: *const EhaOutput, valve_pin: *mut u8, ok_pin: *mut u8) -> EhaStatus {
    if out.is_null() || valve_pin.is_null() || ok_pin.is_null() {
        return EhaStatus::EhaErrNull;
    }
    // SAFETY: valid (caller).
    let o = unsafe { (*out).to_guard() };
    let p = Pins::for_outputs(o.valve_open, o.alarm || o.derate);
    // SAFETY: valid for writes (caller).
    unsafe {
        valve_pin.write(u8::from(p.valve_pin));
        ok_pin.write(u8::from(p.ok_pin));
    }
    EhaStatus::EhaOk
}

/// One tick's reply frame, as the product image sends it.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct EhaTickReply {
    /// Tick counter since boot (10 ms ticks).
    pub tick: u32,
    /// Sequence number of the newest accepted sample.
    pub sample_seq: u16,
    /// 1: a new sample arrived for this tick; 0: missing.
    pub fresh: u8,
    /// 1: the paper-rig constants run (no parameter block).
    pub not_commissioned: u8,
    /// The guard's output of this tick.
    pub out: EhaOutput,
    /// Valve pin level read back (1 = energised = shut).
    pub valve_pin: u8,
    /// OK pin level read back (1 = no alarm, no derate).
    pub ok_pin: u8,
    /// `EHA_RESTORE_*` of this boot.
    pub restore: u8,
    /// Why the MCU last reset: 0 power-on, 1 watchdog, 2 panic, 3 HardFault,
    /// 4 unexpected exception, 5 other.
    pub reset_cause: u8,
    /// Ticks that overran their period since boot (saturating).
    pub overruns: u16,
    /// Frames rejected since boot (saturating).
    pub rejected: u16,
}

/// Copies a frame into `buf`.
///
/// # Safety
/// `buf` NULL or valid for writes of `cap` bytes; `len` NULL or valid.
unsafe fn emit(f: &WireFrame, buf: *mut u8, cap: usize, len: *mut usize) -> EhaStatus {
    if buf.is_null() || len.is_null() {
        return EhaStatus::EhaErrNull;
    }
    let b = f.as_slice();
    if b.len() > cap {
        return EhaStatus::EhaErrBuffer;
    }
    // SAFETY: `buf` valid for `cap` ≥ `b.len()` bytes, `len` valid (caller);
    // the frame is a separate buffer.
    unsafe {
        core::ptr::copy_nonoverlapping(b.as_ptr(), buf, b.len());
        len.write(b.len());
    }
    EhaStatus::EhaOk
}

/// Encodes a tick reply into `buf` (`cap` ≥ [`EHA_WIRE_FRAME_MAX`]); `len`
/// receives its length.
///
/// # Safety
/// `reply` valid; `buf` valid for writes of `cap` bytes; `len` valid.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn eha_wire_tick_reply(reply: *const EhaTickReply, buf: *mut u8, cap: usize, len: *mut usize) -> EhaStatus {
    // SAFETY: NULL or valid (caller).
    let Some(r) = (unsafe { reply.as_ref() }) else { return EhaStatus::EhaErrNull };
    let Some(restore) = restore_from_code(r.restore) else { return EhaStatus::EhaErrArg };
    let t = TickReply {
        tick: r.tick,
        sample_seq: r.sample_seq,
        fresh: r.fresh != 0,
        not_commissioned: r.not_commissioned != 0,
        out: r.out.to_guard(),
        pins: Pins { valve_pin: r.valve_pin != 0, ok_pin: r.ok_pin != 0 },
        overruns: r.overruns,
        rejected: r.rejected,
        restore,
        reset_cause: ResetCause::from_code(r.reset_cause),
    };
    // SAFETY: forwarded (caller).
    unsafe { emit(&t.encode(), buf, cap, len) }
}

/// QEMU lockstep transport: the end-of-tick frame (the tick's cost in
/// core-clock cycles; 0 when not measured).
///
/// # Safety
/// `buf` valid for writes of `cap` bytes; `len` valid.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn eha_wire_lockstep_tick_end(cycles: u32, buf: *mut u8, cap: usize, len: *mut usize) -> EhaStatus {
    // SAFETY: forwarded (caller).
    unsafe { emit(&tick_end(cycles), buf, cap, len) }
}

/// The counters of a lockstep run's completion marker.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct EhaLockstepDone {
    /// Tick counter at the end.
    pub tick: u32,
    /// Samples accepted.
    pub accepted: u32,
    /// Ticks without a new sample.
    pub missing: u32,
    /// Frames rejected for their CRC.
    pub rejected_crc: u16,
    /// Frames rejected for framing.
    pub rejected_framing: u16,
    /// Samples rejected as duplicate or older.
    pub rejected_sequence: u16,
    /// Boots since power-on.
    pub boots: u16,
    /// The fault word at the end.
    pub faults: u32,
}

/// QEMU lockstep transport: the completion marker at end of input (a status
/// frame with the harness's token and the final counters).
///
/// # Safety
/// `done` valid; `buf` valid for writes of `cap` bytes; `len` valid.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn eha_wire_lockstep_done(done: *const EhaLockstepDone, buf: *mut u8, cap: usize, len: *mut usize) -> EhaStatus {
    // SAFETY: NULL or valid (caller).
    let Some(d) = (unsafe { done.as_ref() }) else { return EhaStatus::EhaErrNull };
    let s = Status {
        token: DONE_TOKEN,
        tick: d.tick,
        boots: d.boots,
        counters: Counters {
            rejected_crc: d.rejected_crc,
            rejected_framing: d.rejected_framing,
            rejected_sequence: d.rejected_sequence,
            accepted: d.accepted,
            missing: d.missing,
            ..Counters::default()
        },
        faults: Faults::from_bits(d.faults),
        protocol: PROTOCOL_VERSION,
        ..Status::default()
    };
    // SAFETY: forwarded (caller).
    unsafe { emit(&s.encode(), buf, cap, len) }
}
