//! Wire protocol between the host (or the actuator controller) and the
//! thermal guard: one request frame per 10 ms tick, one reply frame back.
//!
//! The same bytes travel over a UART on a board and over semihosting in the
//! QEMU PIL image; nothing here knows the transport. The product loop
//! ([`crate::product::App`]) feeds received bytes to a [`Deframer`]. Host
//! tools use the same encoders and decoders (the `eha-sim` crate depends on
//! this crate), so there is exactly one definition of the format.
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
//! and `cobs` crates, for the product image's budgets (measured,
//! docs/firmware-numbers.md): with both crates it is 33 368 B, past its
//! 32 KiB; with `crc` for the CRC-16 alone it fits (+100 B) but the product
//! loop costs 91 instructions more per tick (the CRC runs on every frame in
//! and out). The unit tests check the published CRC check value and the
//! COBS round trip against a reference encoder.
//!
//! # Request (host → guard), payload 28, 32 or 36 bytes
//! | off | type | field |
//! |---|---|---|
//! | 0 | u8 | kind = [`KIND_SAMPLE`] (`0x02`: protocol version 2) |
//! | 1 | u16 | sequence number |
//! | 3 | f32 | `current_a` (A rms) |
//! | 7 | f32 | `p_a_bar` |
//! | 11 | f32 | `p_b_bar` |
//! | 15 | f32 | `speed_rpm` |
//! | 19 | f32 | `position_mm` |
//! | 23 | f32 | `ambient_c` |
//! | 27 | u8 | flags: bit0 valve position reported, bit1 valve reported open (only with bit0), bit2 motor electrical frequency follows, bit3 LNG supply pressure follows; bits 4-7 reserved, 0 |
//! | 28 | f32 | `elec_hz`: the motor drive's electrical (commutation) frequency, Hz, signed like the speed (only with bit2) |
//! | 28 or 32 | f32 | `lng_supply_bar`: LNG supply pressure at the valve, bar gauge (only with bit3) |
//!
//! A frame with a reserved flag bit set, bit1 without bit0, or a length that
//! does not match its flags is rejected ([`DecodeError::Kind`],
//! [`DecodeError::Length`]). The valve position is the read-back of the LNG
//! valve ([`crate::GuardOf::valve_feedback`]); without it (bit0 clear) the
//! guard takes no cooling credit. The electrical frequency is the second,
//! independent speed source ([`crate::speedcheck`]); the supply pressure
//! confirms that the tank has LNG ([`crate::GuardOf::lng_supply`]).
//! Version 1 frames (kind `0x01`, 28 bytes) are refused: a controller of
//! the old protocol gets no sample accepted and the guard goes STALE,
//! fail-safe.
//!
//! The guard's frames back (tick reply, acknowledgements, status, trace)
//! are the product frames of [`crate::product::wire`]; the sequence rule
//! and the counters live in the one application loop, [`crate::product`].

use crate::interface::{Reports, Sample};
use heapless::Vec;

/// Version of the controller protocol (the sample request and the product
/// frames), reported in the status reply. 2: one application loop (the
/// tick reply's per-tick tail last, 33 bytes), the fault word 32 bits (tick
/// reply, status, trace), the sample's optional speed-reference and LNG
/// supply-pressure fields, the keyed clear and refill (arm, then confirm
/// with a key; 8-byte command, 9-byte ack). 1: the first product protocol.
pub const PROTOCOL_VERSION: u8 = 2;

/// Request flag: the valve position is reported in this frame.
pub const FLAG_VALVE_FB: u8 = 1 << 0;
/// Request flag: the reported valve position is open (only with [`FLAG_VALVE_FB`]).
pub const FLAG_VALVE_FB_OPEN: u8 = 1 << 1;
/// Request flag: the motor's electrical frequency follows.
pub const FLAG_ELEC_HZ: u8 = 1 << 2;
/// Request flag: the LNG supply pressure follows.
pub const FLAG_LNG_SUPPLY: u8 = 1 << 3;

/// Request kind: one sensor sample (protocol version 2).
pub const KIND_SAMPLE: u8 = 0x02;

/// Length of a request payload without its optional fields (without CRC).
pub const REQUEST_LEN: usize = 28;
/// Longest request payload (both optional fields).
pub const REQUEST_MAX_LEN: usize = REQUEST_LEN + 8;
/// Largest payload of any frame, the request and the product frames of
/// [`crate::product::wire`] (the status reply is the longest).
pub const MAX_PAYLOAD: usize = 56;
/// Largest payload + CRC of any frame.
pub const MAX_RAW: usize = MAX_PAYLOAD + 2;
/// Largest COBS-encoded frame without delimiters.
pub const MAX_ENCODED: usize = MAX_RAW + MAX_RAW / 254 + 1;
/// Buffer size of an encoded frame with leading and trailing delimiter.
pub const MAX_WIRE: usize = MAX_ENCODED + 2;

/// Bytes of one encoded frame on the wire (delimiters included): a fixed
/// buffer, read as a byte slice.
#[derive(Clone, Copy)]
pub struct WireFrame {
    buf: [u8; MAX_WIRE],
    start: usize,
    len: usize,
}

impl WireFrame {
    /// The frame's bytes.
    pub fn as_slice(&self) -> &[u8] {
        self.buf.get(self.start..self.start + self.len).unwrap_or(&[])
    }
}

impl core::ops::Deref for WireFrame {
    type Target = [u8];
    fn deref(&self) -> &[u8] {
        self.as_slice()
    }
}

impl core::fmt::Debug for WireFrame {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        self.as_slice().fmt(f)
    }
}

/// Writes a payload's little-endian fields into a byte buffer in order
/// (after inlining: plain stores at constant offsets).
pub(crate) struct PutAt<'a> {
    buf: &'a mut [u8],
    at: usize,
}

impl<'a> PutAt<'a> {
    /// A writer at the start of `buf`.
    #[inline(always)]
    pub(crate) fn new(buf: &'a mut [u8]) -> Self {
        PutAt { buf, at: 0 }
    }
    /// Bytes written so far (those past the buffer's end are dropped: the
    /// frame is then short and its peer refuses it; every payload here is
    /// sized to fit [`MAX_PAYLOAD`]).
    #[inline(always)]
    pub(crate) fn len(&self) -> usize {
        self.at.min(MAX_PAYLOAD)
    }
    /// Appends bytes.
    #[inline(always)]
    pub(crate) fn bytes(&mut self, b: &[u8]) {
        if let Some(d) = self.buf.get_mut(self.at..self.at + b.len()) {
            d.copy_from_slice(b);
        }
        self.at += b.len();
    }
    /// Appends a byte.
    #[inline(always)]
    pub(crate) fn u8(&mut self, v: u8) {
        self.bytes(&[v]);
    }
    /// Appends a little-endian u16.
    #[inline(always)]
    pub(crate) fn u16(&mut self, v: u16) {
        self.bytes(&v.to_le_bytes());
    }
    /// Appends a little-endian u32.
    #[inline(always)]
    pub(crate) fn u32(&mut self, v: u32) {
        self.bytes(&v.to_le_bytes());
    }
    /// Appends an f32's bit pattern, little-endian.
    #[inline(always)]
    pub(crate) fn f32(&mut self, v: f32) {
        self.bytes(&v.to_le_bytes());
    }
}

mod codec;
mod framing;
pub mod lockstep;

pub(crate) use codec::Rd;
pub use framing::frame;
pub(crate) use framing::crc16_byte;
pub use framing::{cobs_decode, cobs_encode, crc16, Deframer};

// ------------------------------------------------------------- messages

/// One request frame: the guard's sample for one tick and the controller's
/// reports beside it, as the guard takes them
/// ([`crate::GuardOf::tick_reported`]).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Request {
    /// Sequence number (wrapping).
    pub seq: u16,
    /// The sensor sample, wire units.
    pub sample: Sample,
    /// The valve position read back, the motor's electrical frequency and
    /// the LNG supply pressure, each when reported.
    pub reports: Reports,
}

/// What the guard reports after a tick: the guard's own [`crate::interface::Output`].
pub type GuardOutput = crate::interface::Output;

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

/// Why a frame was refused.
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
