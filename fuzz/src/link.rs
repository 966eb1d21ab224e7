//! Frame fuzzing: the product application's receive path (deframer, COBS,
//! CRC, frame kinds, the sequence rule, the command queue, counters) on the
//! shared in-memory board, driving the real f32 guard, one tick per chunk of
//! bytes; and the request / product-frame decoders on the raw input.
//!
//! Input: byte 0 is the mode. Even: the rest is the byte stream as it is
//! (garbage, truncation, overflow, stray delimiters). Odd: the rest is read as
//! a list of operations that build well-formed sample frames with chosen
//! sequence numbers (next, duplicate, older, gaps, the half-range boundary),
//! sample values (near a nominal operating point or raw `f32` bits) and a
//! corruption (bit flip, truncation, lost delimiter, junk, empty frames, a
//! tick reply sent as a request, a CRC-valid payload of the wrong length or
//! kind). Bits 1..7 of the mode give the chunk size, the bytes received per
//! tick; the same stream is also fed in one tick, and the frame counters
//! must agree.
//!
//! Checked: no panic; exactly one tick reply per tick, CRC-valid and
//! decodable; frames counted once: accepted + rejected + commands = the
//! non-empty frames; outputs finite, a latched fault implies the valve open;
//! `Request::from_payload` ok ⇒ `to_payload` gives the same bytes; a decoded
//! product frame re-encodes to the same frame; COBS encode → decode is the
//! identity and the encoding has no zero byte.

use eha_guard::faults;
use eha_guard::product::mem_board::MemBoard;
use eha_guard::product::wire::{FromGuard, Pins, ResetCause, TickReply};
use eha_guard::product::App;
use eha_guard::protection::LngBudget;
use eha_guard::protocol::{cobs_decode, cobs_encode, crc16, Deframer, Request, KIND_SAMPLE, REQUEST_LEN};
use eha_guard::trace::RestoreKind;
use eha_guard::{GuardConfig, Output};
use heapless::Vec as HVec;
use libfuzzer_sys::arbitrary::Unstructured;
use std::sync::OnceLock;

/// Longest byte stream the structured mode builds.
const MAX_STREAM: usize = 8192;

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
    if let Ok(f) = FromGuard::from_payload(data) {
        // decode ∘ encode is the identity on what decodes (codes outside
        // an enum decode to its catch-all, so compare re-encodings)
        let enc = |f: &FromGuard| match f {
            FromGuard::Tick(t) => t.encode(),
            FromGuard::Ack(a) => a.encode(),
            FromGuard::Status(s) => s.encode(),
            FromGuard::Trace(t) => t.encode(),
        };
        let wire = enc(&f);
        let mut d = Deframer::new();
        let back: Vec<Vec<u8>> = wire.iter().filter_map(|&b| d.push(b).map(|r| r.expect("own frame").to_vec())).collect();
        assert_eq!(back.len(), 1);
        let again = FromGuard::from_payload(&back[0]).expect("own frame decodes");
        assert_eq!(&enc(&again)[..], &wire[..], "product frame re-encoding differs");
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
        // (fields in the order the input bytes are read)
        let sample = eha_guard::Sample {
            current_a: v(&mut u, 30.0, 30.0),
            p_a_bar: v(&mut u, 65.0, 60.0),
            p_b_bar: v(&mut u, 5.0, 5.0),
            speed_rpm: v(&mut u, 500.0, 500.0),
            position_mm: v(&mut u, 0.0, 10.0),
            ambient_c: v(&mut u, 16.0, 1.0),
        };
        let reports = eha_guard::Reports {
            // The valve-position flags byte: absent, reported shut, reported open.
            valve_fb: match byte(&mut u) % 3 {
                0 => None,
                1 => Some(false),
                _ => Some(true),
            },
            // the optional inputs: absent, near nominal, or raw bits
            elec_hz: (sel & 0x20 != 0).then(|| v(&mut u, 83.0, 80.0)),
            lng_supply_bar: (sel & 0x40 != 0).then(|| v(&mut u, 3.0, 3.0)),
        };
        let req = Request { seq, sample, reports };
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
                // A tick reply where a request is expected (kind mismatch, CRC good).
                let rep = TickReply {
                    tick: u32::from(seq),
                    sample_seq: seq,
                    fresh: true,
                    not_commissioned: false,
                    out: Output::default(),
                    pins: Pins::default(),
                    overruns: 0,
                    rejected: 0,
                    restore: RestoreKind::Cold,
                    reset_cause: ResetCause::PowerOn,
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
                if (REQUEST_LEN..=eha_guard::protocol::REQUEST_MAX_LEN).contains(&n) {
                    q.push(0xFF);
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

/// Feeds `stream` to a freshly booted application, `chunk` bytes per tick;
/// returns (accepted, rejected, commands) after checking every invariant.
fn drive(stream: &[u8], chunk: usize) -> (u32, u32, u16) {
    static TEMPLATE: OnceLock<App> = OnceLock::new();
    let full_kg = LngBudget::new(&GuardConfig::DEFAULT.lng).remaining_kg();
    let mut board = Box::new(MemBoard::new());
    let template = TEMPLATE.get_or_init(|| {
        let mut b = Box::new(MemBoard::new());
        let mem = b.boot_memory();
        App::boot(&mut *b, &GuardConfig::DEFAULT, &mem)
    });
    let mut app = template.clone();
    for part in stream.chunks(chunk.max(1)) {
        board.push_rx(part);
        app.tick(&mut *board, 0);
        let mut d = Deframer::new();
        let mut ticks = 0;
        for &b in board.take_tx().iter() {
            if let Some(r) = d.push(b) {
                let p = r.expect("own frames must pass COBS and CRC");
                match FromGuard::from_payload(p).expect("own frames must decode") {
                    FromGuard::Tick(t) => {
                        ticks += 1;
                        check_output(&t.out, full_kg);
                    }
                    _ => {}
                }
            }
        }
        assert!(!d.pending());
        assert_eq!(ticks, 1, "one tick reply per tick");
    }
    // The rest of the stream's last frame, if unterminated, stays pending;
    // count the frames the application saw.
    let mut frames = 0u32;
    let mut len = 0usize;
    for &b in stream {
        if b == 0 {
            frames += u32::from(len > 0);
            len = 0;
        } else {
            len += 1;
        }
    }
    let c = app.counters();
    let rejected = u32::from(c.rejected_crc) + u32::from(c.rejected_framing) + u32::from(c.rejected_sequence);
    if frames < u32::from(u16::MAX) {
        assert_eq!(c.accepted + rejected + u32::from(c.commands), frames, "frames counted once: {c:?}");
    }
    (c.accepted, rejected, c.commands)
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
    if chunk >= stream.len() || stream.len() > eha_guard::product::mem_board::MEM_RX {
        return;
    }
    let b = drive(stream, stream.len());
    assert_eq!(a, b, "the bytes per tick changed the frame counters");
}
