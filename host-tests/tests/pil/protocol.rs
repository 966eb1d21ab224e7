//! Property tests of the wire protocol (`eha_guard::protocol`), host side.

use eha_guard::protocol::{
    crc16, Counters, Deframer, GuardOutput, Link, RejectReason, Reply, ReplyKind, Request,
};
use proptest::prelude::*;

fn any_f32() -> impl Strategy<Value = f32> {
    // Every bit pattern, NaNs and infinities included: the wire carries bits.
    any::<u32>().prop_map(f32::from_bits)
}

prop_compose! {
    fn any_request()(seq in any::<u16>(), v in proptest::array::uniform6(any_f32()), fb in proptest::option::of(any::<bool>())) -> Request {
        Request { seq, current_a: v[0], p_a_bar: v[1], p_b_bar: v[2], speed_rpm: v[3], position_mm: v[4], ambient_c: v[5], valve_fb: fb }
    }
}

prop_compose! {
    fn any_reply()(
        kind in 0u8..8, seq in any::<u16>(), drain in any_f32(), flags in 0u8..8, faults in any::<u16>(),
        kg in any_f32(), secs in any_f32(), c in proptest::array::uniform4(any::<u16>()), acc in any::<u32>(), ticks in any::<u32>(),
    ) -> Reply {
        let kind = match kind {
            0 => ReplyKind::Tick,
            1 => ReplyKind::Done,
            r => ReplyKind::Reject(RejectReason::from_u8(r - 1).unwrap_or(RejectReason::Crc)),
        };
        Reply {
            kind,
            seq,
            out: GuardOutput { drain_c: drain, valve_open: flags & 1 != 0, alarm: flags & 2 != 0, derate: flags & 4 != 0, faults: eha_guard::Faults::from_bits(faults), lng_remaining_kg: kg, lng_seconds_left: secs },
            counters: Counters { rejected_crc: c[0], rejected_framing: c[1], rejected_sequence: c[2], skipped: c[3], accepted: acc },
            tick_cycles: ticks,
        }
    }
}

fn bits(r: &Request) -> [u32; 6] {
    [r.current_a, r.p_a_bar, r.p_b_bar, r.speed_rpm, r.position_mm, r.ambient_c].map(f32::to_bits)
}

fn decode_all(bytes: &[u8]) -> Vec<Result<eha_guard::protocol::Payload, eha_guard::protocol::DecodeError>> {
    let mut d = Deframer::new();
    bytes.iter().filter_map(|&b| d.push(b)).collect()
}

/// Feed bytes to a fresh guard-side link whose "guard" echoes the sequence number.
fn link_replies(link: &mut Link, bytes: &[u8]) -> Vec<Reply> {
    let mut out = Vec::new();
    link.push_bytes(bytes, |r, _| (GuardOutput { drain_c: f32::from(r.seq), ..Default::default() }, 0), |rep, _| out.push(*rep));
    out
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 512, ..ProptestConfig::default() })]

    #[test]
    fn request_round_trip_is_bit_exact(r in any_request()) {
        let wire = r.encode();
        prop_assert_eq!(wire.iter().filter(|&&b| b == 0).count(), 1, "only the delimiter is zero");
        let got = decode_all(&wire);
        prop_assert_eq!(got.len(), 1);
        let back = Request::from_payload(got[0].as_ref().unwrap()).unwrap();
        prop_assert_eq!(back.seq, r.seq);
        prop_assert_eq!(bits(&back), bits(&r));
        prop_assert_eq!(back.valve_fb, r.valve_fb);
    }

    #[test]
    fn reply_round_trip_is_bit_exact(r in any_reply()) {
        let wire = r.encode();
        let got = decode_all(&wire);
        prop_assert_eq!(got.len(), 1);
        let back = Reply::from_payload(got[0].as_ref().unwrap()).unwrap();
        prop_assert_eq!(back.kind, r.kind);
        prop_assert!(back.out.bit_eq(&r.out));
        prop_assert_eq!(back.counters, r.counters);
        prop_assert_eq!((back.seq, back.tick_cycles), (r.seq, r.tick_cycles));
    }

    /// Every single-bit corruption of a request is rejected: never accepted,
    /// never steps the guard, each resulting frame counted exactly once.
    #[test]
    fn every_single_bit_corruption_is_rejected(r in any_request()) {
        let wire = r.encode();
        for bit in 0..wire.len() * 8 {
            let mut bad = wire.to_vec();
            bad[bit / 8] ^= 1 << (bit % 8);
            bad.push(0); // resync in case the flip hit the delimiter
            let mut link = Link::new();
            let replies = link_replies(&mut link, &bad);
            prop_assert!(!replies.is_empty(), "bit {}: no reply", bit);
            for rep in &replies {
                prop_assert!(matches!(rep.kind, ReplyKind::Reject(_)), "bit {}: accepted {:?}", bit, rep);
            }
            prop_assert_eq!(link.counters().accepted, 0);
            prop_assert_eq!(link.counters().rejected() as usize, replies.len());
        }
    }

    #[test]
    fn truncated_frames_are_rejected(r in any_request(), cut in 1usize..30) {
        let wire = r.encode();
        let cut = cut.min(wire.len() - 2);
        let mut bad = wire[..cut].to_vec();
        bad.push(0);
        let mut link = Link::new();
        let replies = link_replies(&mut link, &bad);
        prop_assert_eq!(replies.len(), 1);
        prop_assert!(matches!(replies[0].kind, ReplyKind::Reject(_)));
    }

    /// Sequence rule: a frame is accepted iff it is newer than the last accepted one.
    #[test]
    fn out_of_order_frames_are_rejected(seqs in proptest::collection::vec(any::<u16>(), 1..50)) {
        let mut link = Link::new();
        let mut last: Option<u16> = None;
        for (i, s) in seqs.iter().enumerate() {
            let r = Request { seq: *s, ..Request::default() };
            let rep = link_replies(&mut link, &r.encode());
            let newer = last.is_none_or(|l| { let d = s.wrapping_sub(l); d != 0 && d <= 0x8000 });
            if newer {
                prop_assert_eq!(rep[0].kind, ReplyKind::Tick, "frame {}", i);
                last = Some(*s);
            } else {
                prop_assert_eq!(rep[0].kind, ReplyKind::Reject(RejectReason::Sequence), "frame {}", i);
            }
        }
    }

    /// Arbitrary bytes never panic, every non-empty frame gets exactly one
    /// reply, and a good frame afterwards is still accepted.
    #[test]
    fn garbage_never_panics_and_link_recovers(garbage in proptest::collection::vec(any::<u8>(), 0..600)) {
        let mut link = Link::new();
        let replies = link_replies(&mut link, &garbage);
        let c = link.counters();
        prop_assert_eq!(c.rejected() + c.accepted, replies.len() as u32);
        let next = link.last_seq().map_or(0, |s| s.wrapping_add(1));
        let mut tail = vec![0u8];
        tail.extend_from_slice(&Request { seq: next, ..Request::default() }.encode());
        let rep = link_replies(&mut link, &tail);
        prop_assert_eq!(rep.last().map(|r| r.kind), Some(ReplyKind::Tick));
    }

    #[test]
    fn crc_detects_any_single_bit_error(data in proptest::collection::vec(any::<u8>(), 1..64), bit in any::<usize>()) {
        let bit = bit % (data.len() * 8);
        let mut bad = data.clone();
        bad[bit / 8] ^= 1 << (bit % 8);
        prop_assert_ne!(crc16(&data), crc16(&bad));
    }
}
