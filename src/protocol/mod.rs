//! Wire protocol between the host (or the actuator controller) and the
//! thermal guard: one request frame per 10 ms tick, one reply frame back.
//!
//! The same bytes travel over semihosting stdin/stderr in QEMU and over a UART
//! on a real board; nothing here knows the transport. The firmware feeds
//! received bytes to [`Link::push_bytes`] and writes whatever it is handed
//! back. Host tools use the same encoders and decoders (the `eha-sim` crate
//! depends on this crate), so there is exactly one definition of the format.
//!
//! # Framing
//! `payload ++ crc16_le(payload)` is COBS-encoded and terminated by `0x00`.
//! Replies are also *preceded* by `0x00`, so any junk the transport mixes in
//! before a reply (e.g. an emulator warning on the same stream) is isolated
//! as a separate, rejected frame instead of corrupting the reply. Empty frames
//! (two delimiters in a row) are ignored on both sides; they are the resync
//! idiom.
//!
//! CRC: CRC-16/CCITT-FALSE (poly 0x1021, init 0xFFFF, no reflection, no final
//! xor; check value of `"123456789"` = 0x29B1). It detects every single-bit,
//! every double-bit and every burst error up to 16 bits in frames of this size.
//!
//! CRC and COBS are written here (≈80 lines) instead of taken from the `crc`
//! and `cobs` crates, for the product image's budgets (measured, session 18,
//! docs/firmware-numbers.md): with both crates it is 33 368 B, past its
//! 32 KiB; with `crc` for the CRC-16 alone it fits (+100 B) but the product
//! loop costs 91 instructions more per tick (the CRC runs on every frame in
//! and out). The unit tests check the published CRC check value and the
//! COBS round trip against a reference encoder.
//!
//! # Request (host → guard), payload 28 bytes
//! | off | type | field |
//! |---|---|---|
//! | 0 | u8 | kind = [`KIND_SAMPLE`] |
//! | 1 | u16 | sequence number |
//! | 3 | f32 | `current_a` (A rms) |
//! | 7 | f32 | `p_a_bar` |
//! | 11 | f32 | `p_b_bar` |
//! | 15 | f32 | `speed_rpm` |
//! | 19 | f32 | `position_mm` |
//! | 23 | f32 | `ambient_c` |
//! | 27 | u8 | flags: bit0 valve position reported, bit1 valve reported open (only with bit0); bits 2-7 reserved, 0 |
//!
//! A frame with a reserved flag bit set, or bit1 without bit0, is rejected
//! ([`RejectReason::Kind`]). The valve position is the read-back of the LNG valve
//! ([`crate::GuardOf::valve_feedback`]); without it (bit0 clear) the guard takes
//! the command as the position.
//!
//! # Reply (guard → host), payload 37 bytes
//! | off | type | field |
//! |---|---|---|
//! | 0 | u8 | kind: [`KIND_TICK`], [`KIND_REJECT`] or [`KIND_DONE`] |
//! | 1 | u16 | sequence number (see [`ReplyKind`]) |
//! | 3 | u8 | reject reason ([`RejectReason`] as u8, 0 for tick/done) |
//! | 4 | f32 | predicted drain temperature, °C |
//! | 8 | u8 | flags: bit0 valve open, bit1 alarm, bit2 derate |
//! | 9 | u16 | fault word ([`crate::faults`]): bits 0-6 latched RANGE, RATE, NON_FINITE, STALE, MEMORY_CORRUPT, CONFIG, ACTUATOR; bit 7 LNG_LOW (status); bits 8-13 latched bad channels (current, p_A, p_B, speed, position, ambient); bit 14 latched SENSOR_DISAGREE; bit 15 UNTRUSTED (status) |
//! | 11 | f32 | LNG remaining, kg |
//! | 15 | f32 | LNG seconds left at present dissipation, s |
//! | 19 | u16 | rejected: CRC |
//! | 21 | u16 | rejected: framing (COBS, length, overflow, unknown kind) |
//! | 23 | u16 | rejected: sequence (duplicate or older than the last accepted) |
//! | 25 | u16 | frames skipped (sum of sequence gaps of accepted frames) |
//! | 27 | u32 | accepted frames |
//! | 31 | u32 | cost of the tick in core-clock cycles (0 when not measured) |
//! | 35 | u16 | reserved, 0 |
//!
//! All multi-byte fields are little-endian; floats are IEEE-754 binary32 bit
//! patterns, so values cross the wire bit-exactly.
//!
//! # Sequence rule
//! The first frame sets the sequence. A later frame is accepted when its
//! sequence number is newer than the last accepted one (wrapping, within half
//! the u16 range); a duplicate or an older frame is rejected and counted.
//! A frame that skips ahead is accepted (one lost frame must not lock the link
//! up forever) and the skipped count is reported, so the controller can see
//! it.
//!
//! # Rejections
//! Every non-empty frame gets exactly one reply: a [`KIND_TICK`] reply when it
//! was accepted and the guard ticked, otherwise a [`KIND_REJECT`] reply that
//! carries the reason, the counters and the *last* output unchanged. The
//! guard never ticks on a rejected frame. This keeps a lockstep host from
//! waiting forever on a frame that was damaged on the way.

use heapless::Vec;

/// Request flag: the valve position is reported in this frame.
pub const FLAG_VALVE_FB: u8 = 1 << 0;
/// Request flag: the reported valve position is open (only with [`FLAG_VALVE_FB`]).
pub const FLAG_VALVE_FB_OPEN: u8 = 1 << 1;

/// Request kind: one sensor sample, one guard tick.
pub const KIND_SAMPLE: u8 = 0x01;
/// Reply kind: the frame was accepted and the guard ticked.
pub const KIND_TICK: u8 = 0x81;
/// Reply kind: the frame was rejected (reason in byte 3); outputs are the last ones.
pub const KIND_REJECT: u8 = 0x82;
/// Reply kind: completion marker, end of input reached; outputs are the last ones.
pub const KIND_DONE: u8 = 0x83;

/// Length of a request payload (without CRC).
pub const REQUEST_LEN: usize = 28;
/// Length of a reply payload (without CRC).
pub const REPLY_LEN: usize = 37;
/// Largest payload of any frame, these and the product frames of
/// [`crate::product::wire`] (the status reply is the longest).
pub const MAX_PAYLOAD: usize = 48;
/// Largest payload + CRC of any frame.
pub const MAX_RAW: usize = MAX_PAYLOAD + 2;
/// Largest COBS-encoded frame without delimiters.
pub const MAX_ENCODED: usize = MAX_RAW + MAX_RAW / 254 + 1;
/// Buffer size of an encoded frame with leading and trailing delimiter.
pub const MAX_WIRE: usize = MAX_ENCODED + 2;

/// Bytes of one encoded frame on the wire (delimiters included).
pub type WireFrame = Vec<u8, MAX_WIRE>;

mod codec;
mod framing;
mod link;

pub(crate) use codec::Rd;
pub(crate) use framing::frame;
pub use framing::{cobs_decode, cobs_encode, crc16, Deframer, Payload};
pub use link::Link;

// ------------------------------------------------------------- messages

/// Why a frame was rejected.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[repr(u8)]
pub enum RejectReason {
    /// CRC mismatch (corruption).
    Crc = 1,
    /// Not valid COBS, or too short to hold a CRC (truncation, garbage).
    Cobs = 2,
    /// Valid CRC but wrong payload length for its kind (truncated sender).
    Length = 3,
    /// Frame longer than any valid frame (missing delimiter, garbage).
    Overflow = 4,
    /// Unknown frame kind.
    Kind = 5,
    /// Sequence number duplicate or older than the last accepted one.
    Sequence = 6,
}

impl RejectReason {
    /// Decode the wire byte.
    pub fn from_u8(b: u8) -> Option<Self> {
        Some(match b {
            1 => Self::Crc,
            2 => Self::Cobs,
            3 => Self::Length,
            4 => Self::Overflow,
            5 => Self::Kind,
            6 => Self::Sequence,
            _ => return None,
        })
    }
}

/// One sensor sample for one guard tick (the wire form of the guard's `Sample`).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Request {
    /// Sequence number (wrapping).
    pub seq: u16,
    /// Motor phase current, A rms.
    pub current_a: f32,
    /// Pump port A pressure, bar (gauge).
    pub p_a_bar: f32,
    /// Pump port B pressure, bar (gauge).
    pub p_b_bar: f32,
    /// Motor/pump speed, rpm (signed).
    pub speed_rpm: f32,
    /// Piston position, mm.
    pub position_mm: f32,
    /// Ambient air temperature, degC.
    pub ambient_c: f32,
    /// LNG valve position read back (`Some(true)` open), `None` when not reported.
    pub valve_fb: Option<bool>,
}

/// What the guard reports after a tick: the guard's own [`crate::Output`].
pub type GuardOutput = crate::Output;

impl Request {
    /// The guard's sample carried by this frame.
    pub fn sample(&self) -> crate::Sample {
        crate::Sample {
            current_a: self.current_a,
            p_a_bar: self.p_a_bar,
            p_b_bar: self.p_b_bar,
            speed_rpm: self.speed_rpm,
            position_mm: self.position_mm,
            ambient_c: self.ambient_c,
        }
    }
}

/// Most missed ticks replayed into the guard for one sequence gap. After
/// `stale_ticks` (5) misses the STALE fault has latched and the guard runs on
/// worst-case inputs; a longer gap would only spend time, so it is capped.
pub const MAX_MISSED_TICKS: u16 = 100;

/// The firmware's core tick for one accepted frame, shared by the firmware
/// binary and the host SIL twin so both run exactly the same code: frames
/// the sequence numbers say were lost count as missed samples
/// ([`crate::GuardOf::tick_missing`], at most [`MAX_MISSED_TICKS`]), then
/// the frame's valve position, if reported, goes to
/// [`crate::GuardOf::valve_feedback`] and the guard ticks on the frame's sample.
pub fn tick_guard<N: crate::num::Num>(guard: &mut crate::GuardOf<N>, req: &Request, skipped: u16) -> GuardOutput {
    for _ in 0..skipped.min(MAX_MISSED_TICKS) {
        let _ = guard.tick_missing();
    }
    if let Some(open) = req.valve_fb {
        guard.valve_feedback(open);
    }
    guard.tick(&req.sample())
}

impl GuardOutput {
    /// Flags byte: bit0 valve, bit1 alarm, bit2 derate.
    pub fn flags(&self) -> u8 {
        u8::from(self.valve_open) | (u8::from(self.alarm) << 1) | (u8::from(self.derate) << 2)
    }

    /// Bitwise equality (floats compared by bit pattern, so NaN == NaN).
    pub fn bit_eq(&self, other: &Self) -> bool {
        self.drain_c.to_bits() == other.drain_c.to_bits()
            && self.flags() == other.flags()
            && self.faults == other.faults
            && self.lng_remaining_kg.to_bits() == other.lng_remaining_kg.to_bits()
            && self.lng_seconds_left.to_bits() == other.lng_seconds_left.to_bits()
    }
}

/// Rejection and acceptance counters (saturating).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Counters {
    /// Frames rejected for a CRC mismatch.
    pub rejected_crc: u16,
    /// Frames rejected for framing: COBS, length, overflow, unknown kind.
    pub rejected_framing: u16,
    /// Frames rejected as duplicate or older than the last accepted one.
    pub rejected_sequence: u16,
    /// Sequence numbers skipped by accepted frames (lost frames).
    pub skipped: u16,
    /// Accepted frames (guard ticks).
    pub accepted: u32,
}

impl Counters {
    /// Total rejected frames.
    pub fn rejected(&self) -> u32 {
        u32::from(self.rejected_crc) + u32::from(self.rejected_framing) + u32::from(self.rejected_sequence)
    }
}

/// Kind of reply.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ReplyKind {
    /// Accepted; `seq` is the request's sequence number; the guard ticked.
    Tick,
    /// Rejected; `seq` is the offending frame's number when it could be read,
    /// else the last accepted one.
    Reject(RejectReason),
    /// End of input; `seq` is the last accepted sequence number.
    Done,
}

/// A reply frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Reply {
    /// Tick, reject or done.
    pub kind: ReplyKind,
    /// Sequence number (see [`ReplyKind`]).
    pub seq: u16,
    /// Guard output (the last one for reject/done).
    pub out: GuardOutput,
    /// Counters after this frame.
    pub counters: Counters,
    /// Core-clock cycles spent in the guard tick (0 when not measured).
    pub tick_cycles: u32,
}

/// Errors of the host-side decoders.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DecodeError {
    /// Malformed COBS or too short.
    Cobs,
    /// Longer than any valid frame.
    Overflow,
    /// CRC mismatch.
    Crc,
    /// Wrong payload length.
    Length,
    /// Unknown kind byte.
    Kind,
}

impl DecodeError {
    fn reason(self) -> RejectReason {
        match self {
            DecodeError::Cobs => RejectReason::Cobs,
            DecodeError::Overflow => RejectReason::Overflow,
            DecodeError::Crc => RejectReason::Crc,
            DecodeError::Length => RejectReason::Length,
            DecodeError::Kind => RejectReason::Kind,
        }
    }
}

impl core::fmt::Display for DecodeError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(match self {
            DecodeError::Cobs => "malformed COBS or frame too short",
            DecodeError::Overflow => "frame longer than any valid frame",
            DecodeError::Crc => "CRC mismatch",
            DecodeError::Length => "wrong payload length",
            DecodeError::Kind => "unknown frame kind",
        })
    }
}

#[cfg(test)]
mod tests;
