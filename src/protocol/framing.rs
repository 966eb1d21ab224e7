//! Framing of the wire protocol: CRC-16/CCITT-FALSE, COBS, delimiters, and
//! the deframer that splits a byte stream back into checked payloads (see
//! the [module docs](super) for the format).

use super::{DecodeError, WireFrame, MAX_PAYLOAD, MAX_RAW, MAX_WIRE};
use heapless::Vec;

// ---------------------------------------------------------------- CRC-16

/// CRC-16/CCITT-FALSE lookup table, built at compile time (const
/// evaluation: an out-of-range index would be a compile error, never a
/// runtime panic). `CRC_TABLE[i]` is the register after one byte `i` from
/// zero (`i << 16 mod P`). (A second table for two bytes per step saved
/// about 2.5 instructions per byte for 512 B of flash: not kept, for the
/// product image's flash limit.)
#[allow(clippy::indexing_slicing)]
static CRC_TABLE: [u16; 256] = {
    let mut t = [0u16; 256];
    let mut i = 0;
    while i < 256 {
        let mut crc = (i as u16) << 8;
        let mut bit = 0;
        while bit < 8 {
            crc = if crc & 0x8000 != 0 { (crc << 1) ^ 0x1021 } else { crc << 1 };
            bit += 1;
        }
        t[i] = crc;
        i += 1;
    }
    t
};

/// One byte of CRC-16/CCITT-FALSE.
#[inline(always)]
pub(crate) fn crc16_byte(crc: u16, b: u8) -> u16 {
    let idx = usize::from(((crc >> 8) as u8) ^ b);
    (crc << 8) ^ CRC_TABLE.get(idx).copied().unwrap_or(0)
}

/// CRC-16/CCITT-FALSE of `data`, a word at a time: two bytes of input
/// XORed into the register at once (the register is 16 bits wide), then two
/// table steps with no input; the register is kept in 32 bits whose upper
/// half collects shifted-out bits no step reads (masked at the end). With
/// the one table: 4.5 instructions per byte on the Cortex-M4, against 7 for
/// the byte at a time.
#[inline(never)]
pub fn crc16(data: &[u8]) -> u16 {
    #[inline(always)]
    fn step(crc: u32) -> u32 {
        (crc << 8) ^ u32::from(CRC_TABLE.get(((crc >> 8) & 0xFF) as usize).copied().unwrap_or(0))
    }
    let (words, rest) = data.as_chunks::<4>();
    let mut crc: u32 = 0xFFFF;
    for w in words {
        let w = u32::from_be_bytes(*w);
        crc = step(step(crc ^ (w >> 16)));
        crc = step(step(crc ^ w));
    }
    rest.iter().fold(crc as u16, |crc, b| crc16_byte(crc, *b))
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

/// Where a frame's payload starts in a [`WireFrame`] buffer: after the
/// leading delimiter and the first COBS code byte.
pub(crate) const PAYLOAD_AT: usize = 2;

impl WireFrame {
    /// An empty frame buffer (zeroed: the delimiters are already there).
    #[inline(always)]
    pub(crate) fn zeroed() -> Self {
        WireFrame { buf: [0u8; MAX_WIRE], start: 0, len: 0 }
    }

    /// Frames the `n` payload bytes written at [`PAYLOAD_AT`]: appends the
    /// CRC, COBS-encodes in place and ends with the delimiter; `lead` keeps
    /// the leading `0x00` (replies, see the module docs).
    ///
    /// The encoding runs backwards over the bytes: each zero becomes the
    /// distance to the next zero (or to the trailing delimiter), and the
    /// code byte before the payload the distance to the first. That is
    /// COBS for any frame shorter than 254 bytes (every frame here: at most
    /// [`MAX_RAW`]), with no copy and no per-byte block bookkeeping.
    #[inline(never)]
    pub(crate) fn seal(&mut self, n: usize, lead: bool) {
        let n = n.min(MAX_PAYLOAD);
        let crc = crc16(self.buf.get(PAYLOAD_AT..PAYLOAD_AT + n).unwrap_or(&[]));
        if let Some(c) = self.buf.get_mut(PAYLOAD_AT + n..PAYLOAD_AT + n + 2) {
            c.copy_from_slice(&crc.to_le_bytes());
        }
        let end = PAYLOAD_AT + n + 2; // the trailing delimiter
        let mut next = end;
        if let Some(data) = self.buf.get_mut(PAYLOAD_AT..end) {
            for (k, x) in data.iter_mut().enumerate().rev() {
                if *x == 0 {
                    let at = PAYLOAD_AT + k;
                    *x = (next - at) as u8;
                    next = at;
                }
            }
        }
        if let Some(code) = self.buf.get_mut(PAYLOAD_AT - 1) {
            *code = (next - (PAYLOAD_AT - 1)) as u8;
        }
        if let Some(d) = self.buf.get_mut(end) {
            *d = 0;
        }
        self.start = if lead { 0 } else { 1 };
        self.len = end + 1 - self.start;
    }

    /// The payload area: a writer at [`PAYLOAD_AT`].
    #[inline(always)]
    pub(crate) fn payload(&mut self) -> super::PutAt<'_> {
        super::PutAt::new(self.buf.get_mut(PAYLOAD_AT..).unwrap_or(&mut []))
    }
}

/// Frame `payload` (at most [`MAX_PAYLOAD`] bytes): append the CRC,
/// COBS-encode, surround with delimiters. `lead` adds the leading `0x00`
/// (used for replies, see the module docs).
pub fn frame(payload: &[u8], lead: bool) -> WireFrame {
    let mut f = WireFrame::zeroed();
    let mut p = f.payload();
    p.bytes(payload);
    let n = p.len();
    f.seal(n, lead);
    f
}

// ------------------------------------------------------------ deframing

/// Splits a byte stream at `0x00` delimiters, COBS-decodes each frame and
/// CRC-checks it at its delimiter. Fixed memory (one frame, [`MAX_RAW`]
/// bytes and its code byte and delimiter); garbage of any length is consumed
/// without panicking.
#[derive(Clone, Debug)]
pub struct Deframer {
    /// The decoded frame; while a frame arrives in pieces, its encoded
    /// bytes up to and including its delimiter (decoded there in place).
    buf: [u8; RAW_CAP],
    /// Encoded bytes in `buf`; non-zero: inside a frame.
    len: usize,
    /// The frame is longer than any frame: refused at its delimiter.
    overflow: bool,
}

/// A frame's encoded bytes and delimiter: the code byte, [`MAX_RAW`] bytes
/// (no frame here reaches a 0xFF block) and the delimiter.
const RAW_CAP: usize = MAX_RAW + 2;

impl Default for Deframer {
    fn default() -> Self {
        Self::new()
    }
}

impl Deframer {
    /// An idle deframer.
    pub const fn new() -> Self {
        Self { buf: [0; RAW_CAP], len: 0, overflow: false }
    }

    /// Feed one byte. Returns `Some` at the end of a non-empty frame: the
    /// CRC-checked payload (valid until the next call) or why it was refused.
    pub fn push(&mut self, b: u8) -> Option<Result<&[u8], DecodeError>> {
        self.feed(&[b]).1
    }

    /// Feeds bytes up to and including the first delimiter that ends a
    /// non-empty frame. Returns how many bytes were taken and, if a frame
    /// ended, its payload (valid until the next call) or why it was refused.
    /// A whole frame in `bytes` (the usual case: the product loop reads one
    /// sample frame per tick at once) is decoded straight from them; a
    /// frame in pieces is gathered up to its delimiter and decoded in place.
    #[inline(never)]
    pub fn feed(&mut self, bytes: &[u8]) -> (usize, Option<Result<&[u8], DecodeError>>) {
        if self.len == 0 {
            if let Some(out) = self.buf.first_chunk_mut::<MAX_RAW>() {
                if let Some((taken, res)) = decode_whole(bytes, out) {
                    return (taken, res.map(|r| r.and_then(|n| Self::check(self.buf.get(..n).unwrap_or(&[])))));
                }
            }
        }
        let (i, ended) = self.gather(bytes);
        if !ended {
            return (i, None);
        }
        let n = core::mem::replace(&mut self.len, 0);
        if core::mem::replace(&mut self.overflow, false) {
            return (i, Some(Err(DecodeError::Overflow)));
        }
        let res = decode_in_place(&mut self.buf, n);
        (i, Some(res.and_then(|n| Self::check(self.buf.get(..n).unwrap_or(&[])))))
    }

    /// Appends the bytes of `bytes` up to and including the first delimiter
    /// that ends a frame to `buf` (delimiters before a frame are skipped;
    /// bytes past `buf`'s end set `overflow`). Returns how many were taken
    /// and whether the delimiter was among them.
    fn gather(&mut self, bytes: &[u8]) -> (usize, bool) {
        let mut i = 0;
        while let Some(&b) = bytes.get(i) {
            i += 1;
            if b == 0 && self.len == 0 {
                continue; // empty frame: resync idiom, ignored
            }
            match self.buf.get_mut(self.len) {
                Some(d) => {
                    *d = b;
                    self.len += 1;
                }
                None => self.overflow = true,
            }
            if b == 0 {
                return (i, true);
            }
        }
        (i, false)
    }

    /// The payload of a decoded frame after its CRC check.
    fn check(raw: &[u8]) -> Result<&[u8], DecodeError> {
        let Some((body, [c0, c1])) = raw.len().checked_sub(2).and_then(|m| raw.split_at_checked(m)).and_then(|(b, c)| Some((b, <[u8; 2]>::try_from(c).ok()?))) else {
            return Err(DecodeError::Cobs);
        };
        if body.is_empty() {
            return Err(DecodeError::Cobs);
        }
        if u16::from_le_bytes([c0, c1]) != crc16(body) {
            return Err(DecodeError::Crc);
        }
        Ok(body)
    }

    /// True while a partial frame is buffered (bytes received, no delimiter yet).
    pub fn pending(&self) -> bool {
        self.len != 0
    }
}

/// Decodes the first frame of `src` into `out` when `src` holds all of it:
/// leading delimiters are skipped; `Some((taken, Some(Ok(n))))` for `n`
/// decoded bytes up to and including the delimiter, `Some((taken,
/// Some(Err)))` for a damaged frame (a block running past the delimiter, or
/// one longer than any frame, `taken` up to its delimiter), `Some((taken,
/// None))` when `src` is only delimiters, `None` when the frame is not
/// complete in `src`.
///
/// Between delimiters no byte is zero (that is what COBS is for), so the
/// bytes after the first code are copied up to the delimiter a word at a
/// time (the first word that holds a zero byte holds the delimiter), and
/// then the chain of codes is walked in `out`: each code stands where its
/// block's owed zero goes. A code of 0xFF (a block of 254 bytes, owing no
/// zero) runs past the delimiter of any frame here ([`MAX_RAW`] < 254), so
/// it is refused as such.
#[inline(always)]
fn decode_whole(src: &[u8], out: &mut [u8; MAX_RAW]) -> Option<(usize, Option<Result<usize, DecodeError>>)> {
    let n = src.len();
    let mut i = 0;
    while src.get(i) == Some(&0) {
        i += 1;
    }
    if i == n {
        return Some((i, None));
    }
    let first = usize::from(*src.get(i)?);
    let body = src.get(i + 1..)?;
    // copy up to the delimiter: whole words while none of their bytes is zero
    let mut k = 0usize;
    while let (Some(s), Some(d)) = (body.get(k..k + 4), out.get_mut(k..k + 4)) {
        let w = u32::from_le_bytes(<[u8; 4]>::try_from(s).ok()?);
        if w.wrapping_sub(0x0101_0101) & !w & 0x8080_8080 != 0 {
            break;
        }
        d.copy_from_slice(s);
        k += 4;
    }
    loop {
        match *body.get(k)? {
            0 => break,
            x => {
                let Some(d) = out.get_mut(k) else { return skip_to_delimiter(src, i + 1 + k, DecodeError::Overflow) };
                *d = x;
                k += 1;
            }
        }
    }
    let taken = i + 1 + k + 1;
    // the chain of codes: each one's position gets its owed zero
    let mut at = first - 1;
    while at < k {
        let Some(c) = out.get_mut(at) else { break };
        let code = usize::from(*c);
        *c = 0;
        at += code;
    }
    if at != k {
        return Some((taken, Some(Err(DecodeError::Cobs))));
    }
    Some((taken, Some(Ok(k))))
}

/// Decodes the `n` encoded bytes at the start of `buf` (a frame and its
/// delimiter, `n` ≤ [`RAW_CAP`]) in place, as [`decode_whole`] does: the
/// bytes after the first code move down by one, each code of the chain
/// becomes its block's owed zero. Returns the decoded length.
fn decode_in_place(buf: &mut [u8; RAW_CAP], n: usize) -> Result<usize, DecodeError> {
    let first = usize::from(buf.first().copied().unwrap_or(0));
    // the decoded bytes: all but the code byte and the delimiter
    let m = n.saturating_sub(2);
    for k in 0..m {
        let x = buf.get(k + 1).copied().unwrap_or(0);
        if let Some(d) = buf.get_mut(k) {
            *d = x;
        }
    }
    let mut at = first.wrapping_sub(1);
    while at < m {
        let Some(c) = buf.get_mut(at) else { break };
        let code = usize::from(*c);
        *c = 0;
        at += code;
    }
    if at != m || first == 0 {
        return Err(DecodeError::Cobs);
    }
    Ok(m)
}

/// The rest of a refused frame up to its delimiter, if `src` holds it.
fn skip_to_delimiter(src: &[u8], from: usize, e: DecodeError) -> Option<(usize, Option<Result<usize, DecodeError>>)> {
    let z = src.get(from..)?.iter().position(|b| *b == 0)?;
    Some((from + z + 1, Some(Err(e))))
}
