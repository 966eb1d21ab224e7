//! Framing of the wire protocol: CRC-16/CCITT-FALSE, COBS, delimiters, and
//! the deframer that splits a byte stream back into checked payloads (see
//! the [module docs](super) for the format).

use super::{DecodeError, WireFrame, MAX_PAYLOAD, MAX_RAW, MAX_WIRE};
use heapless::Vec;

// ---------------------------------------------------------------- CRC-16

/// CRC-16/CCITT-FALSE lookup tables, built at compile time (const
/// evaluation: an out-of-range index would be a compile error, never a
/// runtime panic). `CRC_TABLE[i]` is the register after one byte `i` from
/// zero (`i << 16 mod P`); `CRC_TABLE2[i]` the same shifted by one byte more
/// (`i << 24 mod P`), so two bytes cost two lookups
/// ([`crc16`]; 512 B of flash for about 2.5 instructions per byte fewer on
/// the ~60 bytes framed per tick, measured with the bench).
#[allow(clippy::indexing_slicing)]
const CRC_TABLES: ([u16; 256], [u16; 256]) = {
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
    let mut t2 = [0u16; 256];
    let mut i = 0;
    while i < 256 {
        t2[i] = (t[i] << 8) ^ t[(t[i] >> 8) as usize];
        i += 1;
    }
    (t, t2)
};
static CRC_TABLE: [u16; 256] = CRC_TABLES.0;
static CRC_TABLE2: [u16; 256] = CRC_TABLES.1;

/// One byte of CRC-16/CCITT-FALSE.
#[inline(always)]
pub(crate) fn crc16_byte(crc: u16, b: u8) -> u16 {
    let idx = usize::from(((crc >> 8) as u8) ^ b);
    (crc << 8) ^ CRC_TABLE.get(idx).copied().unwrap_or(0)
}

/// CRC-16/CCITT-FALSE of `data`.
#[inline(never)]
pub fn crc16(data: &[u8]) -> u16 {
    let mut crc: u16 = 0xFFFF;
    let mut pairs = data.chunks_exact(2);
    for p in &mut pairs {
        if let [b0, b1] = *p {
            let x = crc ^ u16::from_be_bytes([b0, b1]);
            // the indices are < 256 by construction; `get` keeps the tick
            // path free of panicking indexing
            crc = CRC_TABLE2.get(usize::from(x >> 8)).copied().unwrap_or(0) ^ CRC_TABLE.get(usize::from(x & 0xFF)).copied().unwrap_or(0);
        }
    }
    for &b in pairs.remainder() {
        crc = crc16_byte(crc, b);
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

/// Splits a byte stream at `0x00` delimiters, COBS-decodes the bytes as they
/// arrive and CRC-checks each frame at its delimiter. Fixed memory (one
/// decoded frame, [`MAX_RAW`] bytes); garbage of any length is consumed
/// without panicking.
#[derive(Clone, Debug)]
pub struct Deframer {
    buf: [u8; MAX_RAW],
    len: usize,
    /// Data bytes left in the open COBS block (0: the next byte is a code).
    left: usize,
    /// The open block ends in a zero (its code was below 0xFF), owed when
    /// another block follows.
    zero: bool,
    /// Inside a frame (a byte other than a delimiter has arrived).
    active: bool,
    /// The frame is longer than any frame: refused at its delimiter.
    overflow: bool,
}

impl Default for Deframer {
    fn default() -> Self {
        Self::new()
    }
}

impl Deframer {
    /// An idle deframer.
    pub const fn new() -> Self {
        Self { buf: [0; MAX_RAW], len: 0, left: 0, zero: false, active: false, overflow: false }
    }

    /// Feed one byte. Returns `Some` at the end of a non-empty frame: the
    /// CRC-checked payload (valid until the next call) or why it was refused.
    pub fn push(&mut self, b: u8) -> Option<Result<&[u8], DecodeError>> {
        self.feed(&[b]).1
    }

    /// Feeds bytes up to and including the first delimiter that ends a
    /// non-empty frame. Returns how many bytes were taken and, if a frame
    /// ended, its payload (valid until the next call) or why it was refused.
    /// The decoder's state stays in locals over the run, and a data byte
    /// costs one compare more than a copy (the product loop decodes a sample
    /// frame every tick: this is on its hot path).
    #[inline(never)]
    pub fn feed(&mut self, bytes: &[u8]) -> (usize, Option<Result<&[u8], DecodeError>>) {
        if !self.active {
            // A whole frame in `bytes` (the usual case: one sample frame per
            // tick, read at once), decoded straight from them in one pass
            // that stops at the delimiter. A frame not complete in `bytes`
            // goes the byte-wise way.
            if let Some((taken, res)) = decode_whole(bytes, &mut self.buf) {
                return (taken, res.map(|r| r.and_then(|n| Self::check(self.buf.get(..n).unwrap_or(&[])))));
            }
        }
        self.feed_bytes(bytes)
    }

    /// [`Deframer::feed`] byte by byte (a frame split across calls).
    fn feed_bytes(&mut self, bytes: &[u8]) -> (usize, Option<Result<&[u8], DecodeError>>) {
        let (mut len, mut left, mut zero, mut active, mut overflow) = (self.len, self.left, self.zero, self.active, self.overflow);
        let buf = &mut self.buf;
        let n = bytes.len();
        let mut i = 0;
        let mut ended = false;
        while i < n {
            if left != 0 && !overflow {
                // up to `left` data bytes in one run, up to a zero (a
                // delimiter inside a block: the frame is refused at it)
                let src = bytes.get(i..).unwrap_or(&[]);
                let dst = buf.get_mut(len..).unwrap_or(&mut []);
                let run = left.min(src.len());
                if dst.len() < run {
                    overflow = true;
                    continue;
                }
                let mut k = 0;
                for (d, &x) in dst.iter_mut().zip(src).take(run) {
                    if x == 0 {
                        break;
                    }
                    *d = x;
                    k += 1;
                }
                len += k;
                left -= k;
                i += k;
                if i >= n {
                    break;
                }
            }
            let b = bytes.get(i).copied().unwrap_or(0);
            i += 1;
            if b == 0 {
                if active {
                    ended = true;
                    break;
                }
                continue; // empty frame: resync idiom, ignored
            }
            active = true;
            if overflow {
                continue;
            }
            // a code byte: the previous block's zero (if owed), then `b - 1`
            // data bytes
            if zero {
                match buf.get_mut(len) {
                    Some(d) => {
                        *d = 0;
                        len += 1;
                    }
                    None => overflow = true,
                }
            }
            zero = b != 0xFF;
            left = usize::from(b) - 1;
        }
        (self.len, self.left, self.zero, self.active, self.overflow) = (len, left, zero, active, overflow);
        (i, if ended { self.end() } else { None })
    }

    fn end(&mut self) -> Option<Result<&[u8], DecodeError>> {
        let (len, left, overflow) = (self.len, self.left, self.overflow);
        self.len = 0;
        self.left = 0;
        self.zero = false;
        self.active = false;
        self.overflow = false;
        if overflow {
            return Some(Err(DecodeError::Overflow));
        }
        // a block running past the delimiter, or no room for a CRC
        if left != 0 || len < 3 {
            return Some(Err(DecodeError::Cobs));
        }
        Some(Self::check(self.buf.get(..len).unwrap_or(&[])))
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
        self.active
    }
}

/// Decodes the first frame of `src` into `out` when `src` holds all of it:
/// leading delimiters are skipped; `Some((taken, Some(Ok(n))))` for `n`
/// decoded bytes up to and including the delimiter, `Some((taken,
/// Some(Err)))` for a damaged frame (a zero inside a block, or one longer
/// than any frame, `taken` up to its delimiter), `Some((taken, None))` when
/// `src` is only delimiters, `None` when the frame is not complete in `src`.
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
    // `i` is at a code byte: the zero the previous block owes (not after a
    // 0xFF block), then `code - 1` data bytes copied in one run. Plain
    // indices and one bounds check per block: float payloads have many
    // short blocks.
    let mut j = 0usize;
    let mut owed = false;
    loop {
        let code = usize::from(*src.get(i)?);
        if code == 0 {
            // the delimiter right after a whole block
            return Some((i + 1, Some(Ok(j))));
        }
        if owed {
            let Some(d) = out.get_mut(j) else { return skip_to_delimiter(src, i, DecodeError::Overflow) };
            *d = 0;
            j += 1;
        }
        owed = code != 0xFF;
        let (from, to) = (i + 1, i + code);
        let block = src.get(from..to)?;
        let Some(dst) = out.get_mut(j..j + (code - 1)) else { return skip_to_delimiter(src, from, DecodeError::Overflow) };
        let mut k = 0;
        while let (Some(&x), Some(d)) = (block.get(k), dst.get_mut(k)) {
            if x == 0 {
                // a delimiter inside a block: the frame ends short
                return Some((from + k + 1, Some(Err(DecodeError::Cobs))));
            }
            *d = x;
            k += 1;
        }
        j += code - 1;
        i = to;
    }
}

/// The rest of a refused frame up to its delimiter, if `src` holds it.
fn skip_to_delimiter(src: &[u8], from: usize, e: DecodeError) -> Option<(usize, Option<Result<usize, DecodeError>>)> {
    let z = src.get(from..)?.iter().position(|b| *b == 0)?;
    Some((from + z + 1, Some(Err(e))))
}
