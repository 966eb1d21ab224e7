//! Unit tests of the wire protocol: CRC check value, COBS round trip against
//! a reference encoder, frame encode/decode, the sequence rule and the link.

extern crate std;
use super::*;

fn req(seq: u16) -> Request {
    Request {
        seq,
        current_a: 12.5,
        p_a_bar: 80.0,
        p_b_bar: 3.25,
        speed_rpm: -1500.0,
        position_mm: 42.0,
        ambient_c: 21.0,
        valve_fb: None,
    }
}

#[test]
fn crc_check_value() {
    assert_eq!(crc16(b"123456789"), 0x29B1);
    assert_eq!(crc16(b""), 0xFFFF);
}

#[test]
fn cobs_known_vectors() {
    // Vectors from the COBS paper / Wikipedia.
    let cases: &[(&[u8], &[u8])] = &[
        (&[0x00], &[0x01, 0x01]),
        (&[0x00, 0x00], &[0x01, 0x01, 0x01]),
        (&[0x11, 0x22, 0x00, 0x33], &[0x03, 0x11, 0x22, 0x02, 0x33]),
        (&[0x11, 0x22, 0x33, 0x44], &[0x05, 0x11, 0x22, 0x33, 0x44]),
        (&[0x11, 0x00, 0x00, 0x00], &[0x02, 0x11, 0x01, 0x01, 0x01]),
    ];
    for (raw, enc) in cases {
        let mut out: Vec<u8, 16> = Vec::new();
        cobs_encode(raw, &mut out).unwrap();
        assert_eq!(&out[..], *enc);
        let mut dec: Vec<u8, 16> = Vec::new();
        cobs_decode(enc, &mut dec).unwrap();
        assert_eq!(&dec[..], *raw);
    }
}

#[test]
fn cobs_long_run() {
    // 254 non-zero bytes need the 0xFF code block.
    let raw: [u8; 300] = core::array::from_fn(|i| (i % 255) as u8 + 1);
    let mut out: Vec<u8, 310> = Vec::new();
    cobs_encode(&raw, &mut out).unwrap();
    assert!(!out.contains(&0));
    let mut dec: Vec<u8, 310> = Vec::new();
    cobs_decode(&out, &mut dec).unwrap();
    assert_eq!(&dec[..], &raw[..]);
}

#[test]
fn request_round_trip_and_size() {
    let r = req(7);
    let wire = r.encode();
    assert_eq!(wire.last(), Some(&0));
    assert_eq!(wire.iter().filter(|&&b| b == 0).count(), 1);
    let mut d = Deframer::new();
    let mut got = None;
    for &b in &wire {
        if let Some(p) = d.push(b) {
            got = Some(Request::from_payload(&p.unwrap()).unwrap());
        }
    }
    assert_eq!(got, Some(r));
}

#[test]
fn request_valve_feedback_flags() {
    // None / shut / open round-trip through the flags byte (offset 27).
    for fb in [None, Some(false), Some(true)] {
        let r = Request { valve_fb: fb, ..req(3) };
        let p = r.to_payload();
        assert_eq!(p.len(), REQUEST_LEN);
        assert_eq!(p[27], match fb { None => 0, Some(false) => 1, Some(true) => 3 });
        assert_eq!(Request::from_payload(&p), Ok(r));
    }
    // Reserved bits, or "open" without "reported", are rejected.
    for flags in [2u8, 4, 0x80, 0xff, 7] {
        let mut p = req(3).to_payload();
        p[27] = flags;
        assert_eq!(Request::from_payload(&p), Err(DecodeError::Kind), "flags {flags:#x}");
    }
}

#[test]
fn tick_guard_passes_the_valve_feedback() {
    // A cold guard commands the valve shut at 21 degC; 50 frames reporting it
    // open latch ACTUATOR (GuardConfig::DEFAULT.actuator_mismatch_ticks = 50).
    let mut g = crate::GuardOf::<f32>::new(&crate::GuardConfig::DEFAULT, crate::Restore::Cold);
    let s = Request { current_a: 0.0, p_a_bar: 5.0, p_b_bar: 5.0, speed_rpm: 500.0, ..req(0) };
    let o = tick_guard(&mut g, &s, 0);
    assert!(!o.valve_open && o.faults.is_empty(), "{o:?}");
    let mut o = o;
    for k in 1..=50u16 {
        o = tick_guard(&mut g, &Request { seq: k, valve_fb: Some(true), ..s }, 0);
    }
    assert!(o.valve_open && o.faults.contains(crate::faults::ACTUATOR), "{o:?}");
}

#[test]
fn reply_round_trip() {
    let rep = Reply {
        kind: ReplyKind::Reject(RejectReason::Sequence),
        seq: 65535,
        out: GuardOutput {
            drain_c: 40.125,
            valve_open: true,
            alarm: false,
            derate: true,
            faults: crate::faults::Faults::from_bits(0xA5A5),
            lng_remaining_kg: 2.0,
            lng_seconds_left: f32::INFINITY,
        },
        counters: Counters { rejected_crc: 1, rejected_framing: 2, rejected_sequence: 3, skipped: 4, accepted: 5 },
        tick_cycles: 1234,
    };
    let wire = rep.encode();
    assert_eq!(wire.first(), Some(&0));
    let mut d = Deframer::new();
    let got: std::vec::Vec<_> = wire.iter().filter_map(|&b| d.push(b)).collect();
    assert_eq!(got.len(), 1);
    assert_eq!(Reply::from_payload(got[0].as_ref().unwrap()).unwrap(), rep);
}

fn run(link: &mut Link, bytes: &[u8]) -> std::vec::Vec<Reply> {
    let mut replies = std::vec::Vec::new();
    link.push_bytes(
        bytes,
        |r, _| (GuardOutput { drain_c: r.seq as f32, ..Default::default() }, 0),
        |rep, _| replies.push(*rep),
    );
    replies
}

#[test]
fn sequence_rules() {
    let mut l = Link::new();
    assert_eq!(run(&mut l, &req(10).encode())[0].kind, ReplyKind::Tick);
    // duplicate
    assert_eq!(run(&mut l, &req(10).encode())[0].kind, ReplyKind::Reject(RejectReason::Sequence));
    // older
    assert_eq!(run(&mut l, &req(9).encode())[0].kind, ReplyKind::Reject(RejectReason::Sequence));
    // next
    let r = run(&mut l, &req(11).encode());
    assert_eq!((r[0].kind, r[0].seq, r[0].out.drain_c), (ReplyKind::Tick, 11, 11.0));
    // gap of 2 is accepted and counted
    let r = run(&mut l, &req(14).encode());
    assert_eq!(r[0].kind, ReplyKind::Tick);
    assert_eq!(r[0].counters.skipped, 2);
    assert_eq!(r[0].counters.rejected_sequence, 2);
    assert_eq!(r[0].counters.accepted, 3);
    // wrap-around
    let mut l = Link::new();
    run(&mut l, &req(65535).encode());
    assert_eq!(run(&mut l, &req(0).encode())[0].kind, ReplyKind::Tick);
}

#[test]
fn rejected_frame_does_not_tick_and_keeps_last_output() {
    let mut l = Link::new();
    run(&mut l, &req(1).encode());
    let mut bad = req(2).encode();
    bad[3] ^= 0x40;
    let mut stepped = false;
    let mut replies = std::vec::Vec::new();
    l.push_bytes(&bad, |_, _| { stepped = true; (GuardOutput::default(), 0) }, |r, _| replies.push(*r));
    assert!(!stepped);
    assert!(matches!(replies[0].kind, ReplyKind::Reject(RejectReason::Crc | RejectReason::Cobs)));
    assert_eq!(replies[0].out.drain_c, 1.0);
    assert_eq!(replies[0].seq, 1);
    // the link recovers on the next good frame
    assert_eq!(run(&mut l, &req(2).encode())[0].kind, ReplyKind::Tick);
}

#[test]
fn truncated_frame_rejected() {
    let wire = req(1).encode();
    let n = wire.len();
    for cut in 1..n - 1 {
        let mut l = Link::new();
        let mut bytes: std::vec::Vec<u8> = wire[..cut].to_vec();
        bytes.push(0);
        let r = run(&mut l, &bytes);
        assert_eq!(r.len(), 1, "cut {cut}");
        assert!(matches!(r[0].kind, ReplyKind::Reject(_)), "cut {cut}");
        assert_eq!(l.counters().accepted, 0);
        assert_eq!(l.counters().rejected(), 1);
    }
}

#[test]
fn overflow_rejected_once_and_recovers() {
    let mut l = Link::new();
    let garbage = [0x55u8; 500];
    let mut bytes = garbage.to_vec();
    bytes.push(0);
    bytes.extend_from_slice(&req(3).encode());
    let r = run(&mut l, &bytes);
    assert_eq!(r.len(), 2);
    assert_eq!(r[0].kind, ReplyKind::Reject(RejectReason::Overflow));
    assert_eq!(r[1].kind, ReplyKind::Tick);
}

#[test]
fn empty_frames_ignored() {
    let mut l = Link::new();
    assert!(run(&mut l, &[0, 0, 0]).is_empty());
    assert_eq!(l.counters(), Counters::default());
}
