//! Framing of the wire protocol: CRC-16/CCITT-FALSE, COBS, delimiters, and
//! the deframer that splits a byte stream back into checked payloads (see
//! the [module docs](super) for the format).

use super::{DecodeError, WireFrame, MAX_ENCODED, MAX_RAW};
use heapless::Vec;

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
