//! Protocol fuzzing: `Link::push_bytes` (deframer, COBS, CRC, sequence rule,
//! counters) driving a real f32 guard through `protocol::tick_guard`, and the
//! request/reply decoders on the raw input.
//!
//! Input: byte 0 is the mode. Even: the rest is the byte stream as it is
//! (garbage, truncation, overflow, stray delimiters). Odd: the rest is read as
//! a list of operations that build well-formed request frames with chosen
//! sequence numbers (next, duplicate, older, gaps, the half-range boundary),
//! sample values (near a nominal operating point or raw `f32` bits) and a
//! corruption (bit flip, truncation, lost delimiter, junk, empty frames, a
//! reply sent as request, a CRC-valid payload of the wrong length or kind).
//! Bits 1..7 of the mode give the chunk size in which the stream reaches the
//! link; the same stream is also pushed in one call, and both must give the
//! same replies.
//!
//! Checked: no panic; exactly one reply per non-empty frame; every reply's
//! wire bytes deframe to one CRC-valid payload that decodes to the same reply;
//! counters: accepted = guard ticks, accepted + rejected = replies, skipped =
//! the saturated sum of the gaps handed to the step; guard outputs finite, a
//! latched fault implies the valve open; `Request::from_payload` ok ⇒
//! `to_payload` gives the same bytes; `Reply::from_payload` ok ⇒ its
//! re-encoding decodes to the same reply; COBS encode → decode is the
//! identity and the encoding has no zero byte.

use eha_guard::faults;
use eha_guard::protection::LngBudget;
use eha_guard::protocol::{
    cobs_decode, cobs_encode, crc16, tick_guard, Deframer, Link, RejectReason, Reply, ReplyKind, Request,
    KIND_SAMPLE, REQUEST_LEN,
};
use eha_guard::{Guard, GuardConfig, Output, Restore};
use heapless::Vec as HVec;
use libfuzzer_sys::arbitrary::Unstructured;
use std::sync::OnceLock;

static TEMPLATE: OnceLock<Guard> = OnceLock::new();

/// Longest byte stream the structured mode builds.
const MAX_STREAM: usize = 8192;

fn same(a: &Reply, b: &Reply) -> bool {
    a.kind == b.kind && a.seq == b.seq && a.counters == b.counters && a.tick_cycles == b.tick_cycles && a.out.bit_eq(&b.out)
}

fn check_output(o: &Output, full_kg: f32) {
    assert!(
        o.drain_c.is_finite() && o.lng_remaining_kg.is_finite() && o.lng_seconds_left.is_finite(),
        "non-finite output {o:?}"
    );
    if o.faults.intersects(faults::LATCHED) {
        assert!(o.valve_open, "latched fault {:#x} but valve closed: {o:?}", o.faults);
    }
    assert!(o.lng_remaining_kg >= 0.0 && o.lng_remaining_kg <= full_kg, "LNG out of range: {o:?}");
}

/// The decoders on arbitrary payload bytes.
pub fn decoders(data: &[u8]) {
    if let Ok(r) = Request::from_payload(data) {
        assert_eq!(&r.to_payload()[..], data, "request re-encoding differs");
    }
    if let Ok(r) = Reply::from_payload(data) {
        let back = Reply::from_payload(&r.to_payload()).expect("a decoded reply must re-decode");
        assert!(same(&r, &back), "reply re-encoding differs: {r:?} vs {back:?}");
    }
    if let Some(&b) = data.first() {
        if let Some(r) = RejectReason::from_u8(b) {
            assert_eq!(r as u8, b);
        }
    }
    let mut out: HVec<u8, 1200> = HVec::new();
    let _ = cobs_decode(data, &mut out);
    let src = &data[..data.len().min(1024)];
    out.clear();
    cobs_encode(src, &mut out).expect("1024 bytes fit a 1200-byte COBS buffer");
    assert!(!out.contains(&0), "COBS output contains a zero");
    let mut dec: HVec<u8, 1200> = HVec::new();
    cobs_decode(&out, &mut dec).expect("own COBS encoding must decode");
    assert_eq!(&dec[..], src, "COBS round trip differs");
}

/// A CRC-valid frame of an arbitrary payload (up to 64 bytes).
fn raw_frame(payload: &[u8], out: &mut Vec<u8>) {
    let mut raw: HVec<u8, 80> = HVec::new();
    let _ = raw.extend_from_slice(&payload[..payload.len().min(64)]);
    let crc = crc16(&raw);
    let _ = raw.extend_from_slice(&crc.to_le_bytes());
    let mut enc: HVec<u8, 96> = HVec::new();
    let _ = cobs_encode(&raw, &mut enc);
    out.extend_from_slice(&enc);
    out.push(0);
}

fn byte(u: &mut Unstructured<'_>) -> u8 {
    u.arbitrary::<u8>().unwrap_or(0)
}

/// Builds a byte stream of (mostly) well-formed request frames.
pub fn structured(data: &[u8]) -> Vec<u8> {
    let mut u = Unstructured::new(data);
    let mut seq: u16 = u.arbitrary().unwrap_or(0);
    let mut out = Vec::new();
    while !u.is_empty() && out.len() < MAX_STREAM {
        let sel = byte(&mut u);
        seq = match sel % 8 {
            0..=3 => seq.wrapping_add(1),
            4 => seq,
            5 => seq.wrapping_sub(1 + u16::from(byte(&mut u))),
            6 => seq.wrapping_add(2 + u16::from(byte(&mut u))),
            _ => seq.wrapping_add(0x7ffe + u16::from(byte(&mut u) % 4)),
        };
        let raw_values = sel & 0x08 != 0;
        let v = |u: &mut Unstructured<'_>, nominal: f32, span: f32| -> f32 {
            if raw_values {
                f32::from_bits(u.arbitrary::<u32>().unwrap_or(0))
            } else {
                nominal + span * f32::from(byte(u) as i8) / 128.0
            }
        };
        let req = Request {
            seq,
            current_a: v(&mut u, 30.0, 30.0),
            p_a_bar: v(&mut u, 65.0, 60.0),
            p_b_bar: v(&mut u, 5.0, 5.0),
            speed_rpm: v(&mut u, 500.0, 500.0),
            position_mm: v(&mut u, 0.0, 10.0),
            ambient_c: v(&mut u, 16.0, 1.0),
            // The valve-position flags byte: absent, reported shut, reported open.
            valve_fb: match byte(&mut u) % 3 {
                0 => None,
                1 => Some(false),
                _ => Some(true),
            },
        };
        let wire = req.encode();
        let corrupt = if sel & 0x10 != 0 { byte(&mut u) % 10 } else { 255 };
        match corrupt {
            0 => {
                let mut w = wire.to_vec();
                let pos = usize::from(byte(&mut u)) % w.len();
                w[pos] ^= 1 << (byte(&mut u) % 8);
                out.extend_from_slice(&w);
            }
            1 => {
                let cut = usize::from(byte(&mut u)) % wire.len();
                out.extend_from_slice(&wire[..cut]);
                out.push(0);
            }
            2 => out.extend_from_slice(&wire[..wire.len() - 1]), // delimiter lost
            3 => {
                let n = usize::from(byte(&mut u) % 16);
                for _ in 0..n {
                    out.push(byte(&mut u));
                }
                out.extend_from_slice(&wire);
            }
            4 => {
                out.extend_from_slice(&[0, 0]);
                out.extend_from_slice(&wire);
            }
            5 => {
                // A reply where a request is expected (kind mismatch, CRC good).
                let rep = Reply {
                    kind: ReplyKind::Tick,
                    seq,
                    out: Output::default(),
                    counters: Default::default(),
                    tick_cycles: 0,
                };
                out.extend_from_slice(&rep.encode());
            }
            6 => {
                // CRC-valid request payload of the wrong length.
                let p = req.to_payload();
                let n = usize::from(byte(&mut u)) % 64;
                let mut q: Vec<u8> = p.iter().copied().cycle().take(n).collect();
                if let Some(k) = q.first_mut() {
                    *k = KIND_SAMPLE;
                }
                if n == REQUEST_LEN {
                    q.push(0);
                }
                raw_frame(&q, &mut out);
            }
            7 => {
                // CRC-valid payload of the right length and an unknown kind.
                let mut p = req.to_payload().to_vec();
                p[0] = byte(&mut u) | 0x02;
                raw_frame(&p, &mut out);
            }
            8 => {
                // Overflow: a long run without delimiter, then the frame.
                let n = 40 + usize::from(byte(&mut u));
                out.extend(std::iter::repeat_n(0x55, n));
                out.extend_from_slice(&wire);
            }
            9 => {
                // The same frame twice (duplicate on the wire).
                out.extend_from_slice(&wire);
                out.extend_from_slice(&wire);
            }
            _ => out.extend_from_slice(&wire),
        }
    }
    out
}

/// Pushes `stream` into a fresh link in chunks of `chunk` bytes, stepping a
/// fresh guard; returns the replies after checking every invariant.
fn drive(stream: &[u8], chunk: usize) -> Vec<Reply> {
    let template = TEMPLATE.get_or_init(|| Guard::new(&GuardConfig::DEFAULT, Restore::Cold));
    let full_kg = LngBudget::new(&GuardConfig::DEFAULT.lng).remaining_kg();
    let mut g = template.clone();
    let mut link = Link::new();
    let mut replies = Vec::new();
    let mut ticks = 0u32;
    let mut gaps = 0u64;
    for part in stream.chunks(chunk.max(1)) {
        link.push_bytes(
            part,
            |req, skipped| {
                ticks += 1;
                gaps += u64::from(skipped);
                let o = tick_guard(&mut g, req, skipped);
                check_output(&o, full_kg);
                (o, ticks)
            },
            |rep, wire| {
                assert_eq!(wire.first(), Some(&0), "reply must start with a delimiter");
                assert_eq!(wire.last(), Some(&0), "reply must end with a delimiter");
                let mut d = Deframer::new();
                let got: Vec<_> = wire.iter().filter_map(|&b| d.push(b)).collect();
                assert_eq!(got.len(), 1, "one reply frame must deframe to one payload");
                assert!(!d.pending());
                let p = got[0].as_ref().expect("own reply frame must pass COBS and CRC");
                let back = Reply::from_payload(p).expect("own reply payload must decode");
                assert!(same(rep, &back), "reply changed on the wire: {rep:?} vs {back:?}");
                replies.push(*rep);
            },
        );
    }
    // One reply per non-empty frame; a partial frame stays pending.
    let mut frames = 0usize;
    let mut len = 0usize;
    for &b in stream {
        if b == 0 {
            frames += usize::from(len > 0);
            len = 0;
        } else {
            len += 1;
        }
    }
    assert_eq!(replies.len(), frames, "replies vs non-empty frames");
    assert_eq!(link.pending(), len > 0);
    let c = link.counters();
    assert_eq!(c.accepted, ticks, "accepted vs guard ticks");
    assert_eq!(replies.iter().filter(|r| r.kind == ReplyKind::Tick).count(), ticks as usize);
    if replies.len() < usize::from(u16::MAX) {
        assert_eq!(c.accepted as usize + c.rejected() as usize, replies.len(), "counters: {c:?}");
    }
    assert_eq!(u64::from(c.skipped), gaps.min(u64::from(u16::MAX)), "skipped vs gaps");
    if let Some(last) = replies.last() {
        assert_eq!(last.counters, c);
    }
    let done = link.done();
    assert_eq!(done.kind, ReplyKind::Done);
    assert_eq!(done.seq, link.last_seq().unwrap_or(0));
    replies
}

/// Runs one input.
pub fn run(data: &[u8]) {
    let Some((&mode, rest)) = data.split_first() else { return };
    decoders(rest);
    let built;
    let stream: &[u8] = if mode & 1 == 0 {
        rest
    } else {
        built = structured(rest);
        &built
    };
    let chunk = usize::from(mode >> 1) + 1;
    let a = drive(stream, chunk);
    if chunk >= stream.len() {
        return;
    }
    let b = drive(stream, stream.len());
    assert_eq!(a.len(), b.len());
    for (x, y) in a.iter().zip(&b) {
        assert!(same(x, y), "chunking changed a reply: {x:?} vs {y:?}");
    }
}
