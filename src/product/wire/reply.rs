//! The tick reply as the product loop sends it every tick: the head (the
//! outputs, pins and counters) is CRC'd and COBS-encoded only when it
//! changes, and each tick only the 7-byte tail (tick, sample sequence,
//! fresh) and the CRC are encoded after it. Measured with the bench: the
//! reply costs about 520 instructions framed whole, on 9 ticks of 10 it
//! changes only in its tail.

use super::{TickReply, TICK_LEN, TICK_TAIL_LEN};
use crate::protocol::{crc16_byte, PutAt, MAX_WIRE};

/// A forward COBS encoder into a fixed buffer: `code_at` is the index of
/// the open block's code byte, `at` the next free index, `code` the open
/// block's code so far.
#[derive(Clone, Copy, Debug)]
struct Cobs {
    at: usize,
    code_at: usize,
    code: u8,
    crc: u16,
}

const _: () = assert!(MAX_WIRE < 0xFF);

impl Cobs {
    #[inline(always)]
    fn push(&mut self, buf: &mut [u8], b: u8) {
        self.crc = crc16_byte(self.crc, b);
        self.put(buf, b);
    }

    #[inline(always)]
    fn put(&mut self, buf: &mut [u8], b: u8) {
        if b == 0 {
            self.close(buf);
            return;
        }
        if let Some(x) = buf.get_mut(self.at) {
            *x = b;
        }
        self.at += 1;
        // (no block fills to a 0xFF code: a reply is shorter than 254 bytes)
        self.code = self.code.wrapping_add(1);
    }

    #[inline(always)]
    fn close(&mut self, buf: &mut [u8]) {
        if let Some(x) = buf.get_mut(self.code_at) {
            *x = self.code;
        }
        self.code_at = self.at;
        self.at += 1;
        self.code = 1;
    }
}

/// Words of the framed head: the leading delimiter, the first code byte
/// and the head's bytes (a zero among them becomes a code in its place).
const HEAD_WORDS: usize = (2 + TICK_LEN - TICK_TAIL_LEN).div_ceil(4);
const _: () = assert!(HEAD_WORDS == 7 && HEAD_WORDS * 4 <= MAX_WIRE);

/// The product loop's tick-reply encoder (see the module docs). Its head is
/// keyed by whatever the caller says changes it (the guard's output epoch,
/// the pins and the counters). It writes into a buffer the caller gives
/// (the board's own transmit buffer where it has one): the framed head is
/// copied whole, a fixed-size copy, and the tail encoded after it.
#[derive(Clone, Debug)]
pub struct ReplyEncoder {
    /// The framed head, as words: copied a word at a time whatever the
    /// alignment of the buffer it goes to (a library `memcpy` of its
    /// unknown alignment costs about 80 instructions).
    head_buf: [[u8; 4]; HEAD_WORDS],
    /// The encoder's state after the head.
    head: Cobs,
    key: Option<(u32, u8, u16, u16)>,
}

impl Default for ReplyEncoder {
    fn default() -> Self {
        Self::new()
    }
}

impl ReplyEncoder {
    /// An encoder with no head yet.
    pub const fn new() -> Self {
        ReplyEncoder { head_buf: [[0; 4]; HEAD_WORDS], head: Cobs { at: 0, code_at: 0, code: 1, crc: 0xFFFF }, key: None }
    }

    /// The wire bytes of `r` (leading and trailing delimiter) written at
    /// the start of `out`; returns their count. `epoch` changes whenever
    /// the outputs in `r` change.
    #[inline(never)]
    pub fn frame_into(&mut self, r: &TickReply, epoch: u32, out: &mut [u8; MAX_WIRE]) -> usize {
        let pins = u8::from(r.pins.valve_pin) | (u8::from(r.pins.ok_pin) << 1);
        let key = Some((epoch, pins, r.overruns, r.rejected));
        if self.key != key {
            self.key = key;
            let mut head = [0u8; TICK_LEN - TICK_TAIL_LEN];
            r.head(&mut PutAt::new(&mut head));
            let framed = self.head_buf.as_flattened_mut();
            if let Some(x) = framed.first_mut() {
                *x = 0; // the leading delimiter
            }
            let mut c = Cobs { at: 2, code_at: 1, code: 1, crc: 0xFFFF };
            for b in head {
                c.push(framed, b);
            }
            self.head = c;
        }
        if let Some([w0, w1, w2, w3, w4, w5, w6]) = out.as_chunks_mut::<4>().0.first_chunk_mut::<HEAD_WORDS>() {
            // word by word, not in a loop (which LLVM turns back into a
            // library `memcpy` call)
            let [h0, h1, h2, h3, h4, h5, h6] = self.head_buf;
            (*w0, *w1, *w2, *w3, *w4, *w5, *w6) = (h0, h1, h2, h3, h4, h5, h6);
        }
        let mut c = self.head;
        for b in r.tail() {
            c.push(out, b);
        }
        for b in c.crc.to_le_bytes() {
            c.put(out, b);
        }
        if let Some(x) = out.get_mut(c.code_at) {
            *x = c.code;
        }
        if let Some(x) = out.get_mut(c.at) {
            *x = 0; // the trailing delimiter
        }
        (c.at + 1).min(MAX_WIRE)
    }

    /// [`ReplyEncoder::frame_into`] a buffer of its own (tests, hosts).
    pub fn frame(&mut self, r: &TickReply, epoch: u32) -> heapless::Vec<u8, MAX_WIRE> {
        let mut out = [0u8; MAX_WIRE];
        let n = self.frame_into(r, epoch, &mut out);
        heapless::Vec::from_slice(out.get(..n).unwrap_or(&[])).unwrap_or_default()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    extern crate std;
    use crate::product::wire::{Pins, ResetCause};
    use crate::trace::RestoreKind;

    fn reply(k: u32) -> TickReply {
        TickReply {
            tick: k,
            sample_seq: (k * 7) as u16,
            fresh: !k.is_multiple_of(3),
            not_commissioned: k.is_multiple_of(5),
            out: crate::Output { drain_c: [0.0, 40.5, 1e6][(k / 4 % 3) as usize], valve_open: k.is_multiple_of(2), ..Default::default() },
            pins: Pins { valve_pin: k % 4 == 1, ok_pin: true },
            overruns: (k / 8) as u16,
            rejected: (k / 16) as u16,
            restore: RestoreKind::Warm,
            reset_cause: ResetCause::Watchdog,
        }
    }

    /// The cached encoder gives the bytes of the whole-frame encoder at
    /// every tick, whether its head was reused or rebuilt.
    #[test]
    fn cached_head_gives_the_same_bytes() {
        let mut e = ReplyEncoder::new();
        for k in 0..300u32 {
            let r = reply(k);
            // the epoch changes with the outputs (every 4 ticks here)
            assert_eq!(&e.frame(&r, k / 4 * 2 + k % 2)[..], &r.encode()[..], "tick {k}");
        }
    }
}
