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

// ---------------------------------------------------------------- CRC-16

/// CRC-16/CCITT-FALSE lookup table, built at compile time (const evaluation:
/// an out-of-range index would be a compile error, never a runtime panic).
#[allow(clippy::indexing_slicing)]
const CRC_TABLE: [u16; 256] = {
    let mut table = [0u16; 256];
    let mut i = 0;
    while i < 256 {
        let mut crc = (i as u16) << 8;
        let mut bit = 0;
        while bit < 8 {
            crc = if crc & 0x8000 != 0 { (crc << 1) ^ 0x1021 } else { crc << 1 };
            bit += 1;
        }
        table[i] = crc;
        i += 1;
    }
    table
};

/// CRC-16/CCITT-FALSE of `data`.
pub fn crc16(data: &[u8]) -> u16 {
    let mut crc: u16 = 0xFFFF;
    for &b in data {
        let idx = usize::from(((crc >> 8) as u8) ^ b);
        // `idx` < 256 by construction; `get` keeps the tick path free of
        // panicking indexing.
        crc = (crc << 8) ^ CRC_TABLE.get(idx).copied().unwrap_or(0);
    }
    crc
}

// ------------------------------------------------------------------ COBS

/// COBS-encode `src` into `out` (no delimiter). Returns `None` if `out` is full.
pub fn cobs_encode<const N: usize>(src: &[u8], out: &mut Vec<u8, N>) -> Option<()> {
    let mut code_pos = out.len();
    out.push(0).ok()?; // placeholder for the first code byte
    let mut code: u8 = 1;
    for &b in src {
        if b == 0 {
            *out.get_mut(code_pos)? = code;
            code_pos = out.len();
            out.push(0).ok()?;
            code = 1;
        } else {
            out.push(b).ok()?;
            code += 1;
            if code == 0xFF {
                *out.get_mut(code_pos)? = code;
                code_pos = out.len();
                out.push(0).ok()?;
                code = 1;
            }
        }
    }
    *out.get_mut(code_pos)? = code;
    Some(())
}

/// COBS-decode `src` (no delimiter) into `out`. `None` on malformed input
/// (a zero byte, a code running past the end) or when `out` is full.
pub fn cobs_decode<const N: usize>(src: &[u8], out: &mut Vec<u8, N>) -> Option<()> {
    out.clear();
    let mut i = 0;
    while i < src.len() {
        let code = *src.get(i)?;
        if code == 0 {
            return None;
        }
        let end = i + usize::from(code);
        if end > src.len() {
            return None;
        }
        let block = src.get(i + 1..end)?;
        if block.contains(&0) {
            return None;
        }
        out.extend_from_slice(block).ok()?;
        i = end;
        if code != 0xFF && i < src.len() {
            out.push(0).ok()?;
        }
    }
    Some(())
}

/// Frame `payload`: append the CRC, COBS-encode, surround with delimiters.
/// `lead` adds the leading `0x00` (used for replies, see the module docs).
pub(crate) fn frame(payload: &[u8], lead: bool) -> WireFrame {
    let mut raw: Vec<u8, MAX_RAW> = Vec::new();
    let mut out = WireFrame::new();
    // Payloads here are fixed-size and fit; the `ok()`s cannot fail, and if
    // they ever did the result would be a short frame the peer rejects, not a
    // panic.
    let _ = raw.extend_from_slice(payload);
    let _ = raw.extend_from_slice(&crc16(payload).to_le_bytes());
    if lead {
        let _ = out.push(0);
    }
    let _ = cobs_encode(&raw, &mut out);
    let _ = out.push(0);
    out
}

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

/// Little-endian field reader that never panics (also used by
/// [`crate::product::wire`]).
pub(crate) struct Rd<'a>(pub(crate) &'a [u8]);
impl Rd<'_> {
    fn arr<const K: usize>(&mut self) -> Result<[u8; K], DecodeError> {
        let (head, tail) = self.0.split_at_checked(K).ok_or(DecodeError::Length)?;
        self.0 = tail;
        head.try_into().map_err(|_| DecodeError::Length)
    }
    pub(crate) fn u8(&mut self) -> Result<u8, DecodeError> {
        Ok(u8::from_le_bytes(self.arr()?))
    }
    pub(crate) fn u16(&mut self) -> Result<u16, DecodeError> {
        Ok(u16::from_le_bytes(self.arr()?))
    }
    pub(crate) fn u32(&mut self) -> Result<u32, DecodeError> {
        Ok(u32::from_le_bytes(self.arr()?))
    }
    pub(crate) fn f32(&mut self) -> Result<f32, DecodeError> {
        Ok(f32::from_le_bytes(self.arr()?))
    }
}

impl Request {
    /// Payload bytes (without CRC).
    pub fn to_payload(&self) -> Vec<u8, REQUEST_LEN> {
        let mut p = Vec::new();
        let _ = p.push(KIND_SAMPLE);
        let _ = p.extend_from_slice(&self.seq.to_le_bytes());
        for v in [self.current_a, self.p_a_bar, self.p_b_bar, self.speed_rpm, self.position_mm, self.ambient_c] {
            let _ = p.extend_from_slice(&v.to_le_bytes());
        }
        let flags = match self.valve_fb {
            None => 0,
            Some(false) => FLAG_VALVE_FB,
            Some(true) => FLAG_VALVE_FB | FLAG_VALVE_FB_OPEN,
        };
        let _ = p.push(flags);
        p
    }

    /// Parse a payload (CRC already checked and stripped).
    pub fn from_payload(p: &[u8]) -> Result<Self, DecodeError> {
        let mut r = Rd(p);
        if r.u8()? != KIND_SAMPLE {
            return Err(DecodeError::Kind);
        }
        if p.len() != REQUEST_LEN {
            return Err(DecodeError::Length);
        }
        let mut q = Request {
            seq: r.u16()?,
            current_a: r.f32()?,
            p_a_bar: r.f32()?,
            p_b_bar: r.f32()?,
            speed_rpm: r.f32()?,
            position_mm: r.f32()?,
            ambient_c: r.f32()?,
            valve_fb: None,
        };
        q.valve_fb = match r.u8()? {
            0 => None,
            FLAG_VALVE_FB => Some(false),
            f if f == FLAG_VALVE_FB | FLAG_VALVE_FB_OPEN => Some(true),
            _ => return Err(DecodeError::Kind),
        };
        Ok(q)
    }

    /// Wire bytes: COBS frame terminated by `0x00` (no leading delimiter).
    pub fn encode(&self) -> WireFrame {
        frame(&self.to_payload(), false)
    }
}

impl Reply {
    /// Payload bytes (without CRC).
    pub fn to_payload(&self) -> Vec<u8, REPLY_LEN> {
        let (kind, reason) = match self.kind {
            ReplyKind::Tick => (KIND_TICK, 0u8),
            ReplyKind::Reject(r) => (KIND_REJECT, r as u8),
            ReplyKind::Done => (KIND_DONE, 0u8),
        };
        let c = &self.counters;
        let mut p = Vec::new();
        let _ = p.push(kind);
        let _ = p.extend_from_slice(&self.seq.to_le_bytes());
        let _ = p.push(reason);
        let _ = p.extend_from_slice(&self.out.drain_c.to_le_bytes());
        let _ = p.push(self.out.flags());
        let _ = p.extend_from_slice(&self.out.faults.bits().to_le_bytes());
        let _ = p.extend_from_slice(&self.out.lng_remaining_kg.to_le_bytes());
        let _ = p.extend_from_slice(&self.out.lng_seconds_left.to_le_bytes());
        let _ = p.extend_from_slice(&c.rejected_crc.to_le_bytes());
        let _ = p.extend_from_slice(&c.rejected_framing.to_le_bytes());
        let _ = p.extend_from_slice(&c.rejected_sequence.to_le_bytes());
        let _ = p.extend_from_slice(&c.skipped.to_le_bytes());
        let _ = p.extend_from_slice(&c.accepted.to_le_bytes());
        let _ = p.extend_from_slice(&self.tick_cycles.to_le_bytes());
        let _ = p.extend_from_slice(&0u16.to_le_bytes());
        p
    }

    /// Parse a payload (CRC already checked and stripped).
    pub fn from_payload(p: &[u8]) -> Result<Self, DecodeError> {
        if p.len() != REPLY_LEN {
            return Err(DecodeError::Length);
        }
        let mut r = Rd(p);
        let kind_b = r.u8()?;
        let seq = r.u16()?;
        let reason = r.u8()?;
        let kind = match kind_b {
            KIND_TICK => ReplyKind::Tick,
            KIND_DONE => ReplyKind::Done,
            KIND_REJECT => ReplyKind::Reject(RejectReason::from_u8(reason).ok_or(DecodeError::Kind)?),
            _ => return Err(DecodeError::Kind),
        };
        let drain_c = r.f32()?;
        let flags = r.u8()?;
        let faults = crate::faults::Faults::from_bits(r.u16()?);
        let lng_remaining_kg = r.f32()?;
        let lng_seconds_left = r.f32()?;
        let counters = Counters {
            rejected_crc: r.u16()?,
            rejected_framing: r.u16()?,
            rejected_sequence: r.u16()?,
            skipped: r.u16()?,
            accepted: r.u32()?,
        };
        let tick_cycles = r.u32()?;
        Ok(Reply {
            kind,
            seq,
            out: GuardOutput {
                drain_c,
                valve_open: flags & 1 != 0,
                alarm: flags & 2 != 0,
                derate: flags & 4 != 0,
                faults,
                lng_remaining_kg,
                lng_seconds_left,
            },
            counters,
            tick_cycles,
        })
    }

    /// Wire bytes: `0x00`, COBS frame, `0x00`.
    pub fn encode(&self) -> WireFrame {
        frame(&self.to_payload(), true)
    }
}

// ------------------------------------------------------------ deframing

/// Splits a byte stream at `0x00` delimiters, COBS-decodes and CRC-checks each
/// frame. Fixed memory; garbage of any length is consumed without panicking.
#[derive(Debug, Default)]
pub struct Deframer {
    buf: Vec<u8, MAX_ENCODED>,
    overflow: bool,
}

/// A decoded, CRC-checked payload.
pub type Payload = Vec<u8, MAX_RAW>;

impl Deframer {
    /// An idle deframer.
    pub const fn new() -> Self {
        Self { buf: Vec::new(), overflow: false }
    }

    /// Feed one byte. Returns `Some` at the end of a non-empty frame.
    pub fn push(&mut self, b: u8) -> Option<Result<Payload, DecodeError>> {
        if b != 0 {
            if !self.overflow && self.buf.push(b).is_err() {
                self.overflow = true;
            }
            return None;
        }
        let overflow = core::mem::replace(&mut self.overflow, false);
        if overflow {
            self.buf.clear();
            return Some(Err(DecodeError::Overflow));
        }
        if self.buf.is_empty() {
            return None; // empty frame: resync idiom, ignored
        }
        let mut raw = Payload::new();
        let decoded = cobs_decode(&self.buf, &mut raw);
        self.buf.clear();
        if decoded.is_none() || raw.len() < 3 {
            return Some(Err(DecodeError::Cobs));
        }
        let n = raw.len() - 2;
        let (body, crc) = raw.split_at(n);
        let got = u16::from_le_bytes([crc.first().copied().unwrap_or(0), crc.get(1).copied().unwrap_or(0)]);
        if got != crc16(body) {
            return Some(Err(DecodeError::Crc));
        }
        raw.truncate(n);
        Some(Ok(raw))
    }

    /// True while a partial frame is buffered (bytes received, no delimiter yet).
    pub fn pending(&self) -> bool {
        !self.buf.is_empty() || self.overflow
    }
}

// ------------------------------------------------------------------ link

/// The guard's end of the link: deframes requests, enforces the sequence
/// rule, counts rejections, ticks the guard on accepted frames and produces
/// exactly one reply per non-empty frame. Transport independent.
#[derive(Debug, Default)]
pub struct Link {
    rx: Deframer,
    last_seq: Option<u16>,
    counters: Counters,
    last_out: GuardOutput,
}

fn sat_inc(c: &mut u16) {
    *c = c.saturating_add(1);
}

impl Link {
    /// A fresh link: no sequence yet, counters zero.
    pub const fn new() -> Self {
        Self {
            rx: Deframer::new(),
            last_seq: None,
            counters: Counters {
                rejected_crc: 0,
                rejected_framing: 0,
                rejected_sequence: 0,
                skipped: 0,
                accepted: 0,
            },
            last_out: GuardOutput {
                drain_c: 0.0,
                valve_open: false,
                alarm: false,
                derate: false,
                faults: crate::faults::Faults::NONE,
                lng_remaining_kg: 0.0,
                lng_seconds_left: 0.0,
            },
        }
    }

    /// Counters so far.
    pub fn counters(&self) -> Counters {
        self.counters
    }

    /// Last accepted sequence number.
    pub fn last_seq(&self) -> Option<u16> {
        self.last_seq
    }

    /// True while a partial frame is buffered.
    pub fn pending(&self) -> bool {
        self.rx.pending()
    }

    /// Feed received bytes. For each complete frame, `tick` is called when it
    /// is accepted (it returns the guard output and the tick's cost in core-clock cycles)
    /// and `send` gets the encoded reply. Never panics, never blocks.
    pub fn push_bytes<S, W>(&mut self, bytes: &[u8], mut tick: S, mut send: W)
    where
        S: FnMut(&Request, u16) -> (GuardOutput, u32),
        W: FnMut(&Reply, &[u8]),
    {
        for &b in bytes {
            let Some(res) = self.rx.push(b) else { continue };
            let reply = self.handle(res, &mut tick);
            send(&reply, &reply.encode());
        }
    }

    fn handle<S>(&mut self, res: Result<Payload, DecodeError>, tick: &mut S) -> Reply
    where
        S: FnMut(&Request, u16) -> (GuardOutput, u32),
    {
        let reject_seq = self.last_seq.unwrap_or(0);
        let req = match res.and_then(|p| Request::from_payload(&p)) {
            Ok(r) => r,
            Err(e) => {
                match e {
                    DecodeError::Crc => sat_inc(&mut self.counters.rejected_crc),
                    _ => sat_inc(&mut self.counters.rejected_framing),
                }
                return self.reply(ReplyKind::Reject(e.reason()), reject_seq, 0);
            }
        };
        let mut gap = 0;
        if let Some(last) = self.last_seq {
            let ahead = req.seq.wrapping_sub(last);
            if ahead == 0 || ahead > 0x8000 {
                sat_inc(&mut self.counters.rejected_sequence);
                return self.reply(ReplyKind::Reject(RejectReason::Sequence), req.seq, 0);
            }
            gap = ahead - 1;
            self.counters.skipped = self.counters.skipped.saturating_add(gap);
        }
        self.last_seq = Some(req.seq);
        self.counters.accepted = self.counters.accepted.saturating_add(1);
        let (out, cycles) = tick(&req, gap);
        self.last_out = out;
        self.reply(ReplyKind::Tick, req.seq, cycles)
    }

    fn reply(&self, kind: ReplyKind, seq: u16, tick_cycles: u32) -> Reply {
        Reply { kind, seq, out: self.last_out, counters: self.counters, tick_cycles }
    }

    /// The completion marker: sent once at end of input.
    pub fn done(&self) -> Reply {
        self.reply(ReplyKind::Done, self.last_seq.unwrap_or(0), 0)
    }
}

#[cfg(test)]
mod tests;
