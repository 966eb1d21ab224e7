//! Property tests of the wire protocol (`eha_guard::protocol`, the product
//! frames) and of the application's frame acceptance (sequence rule,
//! counters), host side, on the product application itself (the shared
//! in-memory board).

use eha_guard::product::mem_board::MemBoard;
use eha_guard::product::wire::{Pins, ResetCause, TickReply};
use eha_guard::protocol::{crc16, Deframer, GuardOutput, Request};
use eha_guard::trace::RestoreKind;
use eha_guard::GuardConfig;
use eha_sim::pil::sil::AppTarget;
use eha_sim::pil::Target;
use proptest::prelude::*;

fn any_f32() -> impl Strategy<Value = f32> {
    // Every bit pattern, NaNs and infinities included: the wire carries bits.
    any::<u32>().prop_map(f32::from_bits)
}

prop_compose! {
    fn any_request()(seq in any::<u16>(), v in proptest::array::uniform6(any_f32()), fb in proptest::option::of(any::<bool>()),
                     hz in proptest::option::of(any_f32()), lng in proptest::option::of(any_f32())) -> Request {
        let sample = eha_guard::Sample { current_a: v[0], p_a_bar: v[1], p_b_bar: v[2], speed_rpm: v[3], position_mm: v[4], ambient_c: v[5] };
        Request { seq, sample, reports: eha_guard::Reports { valve_fb: fb, elec_hz: hz, lng_supply_bar: lng } }
    }
}

prop_compose! {
    fn any_reply()(
        tick in any::<u32>(), seq in any::<u16>(), fresh in any::<bool>(), nc in any::<bool>(), drain in any_f32(), flags in 0u8..8,
        faults in any::<u32>(), kg in any_f32(), secs in any_f32(), pins in 0u8..4, c in proptest::array::uniform2(any::<u16>()),
        restore in 0u8..4, cause in 0u8..6,
    ) -> TickReply {
        TickReply {
            tick,
            sample_seq: seq,
            fresh,
            not_commissioned: nc,
            out: GuardOutput { drain_c: drain, valve_open: flags & 1 != 0, alarm: flags & 2 != 0, derate: flags & 4 != 0, faults: eha_guard::Faults::from_bits(faults), lng_remaining_kg: kg, lng_seconds_left: secs },
            pins: Pins { valve_pin: pins & 1 != 0, ok_pin: pins & 2 != 0 },
            overruns: c[0],
            rejected: c[1],
            restore: eha_guard::product::wire::restore_from_code(restore).unwrap_or(RestoreKind::Cold),
            reset_cause: ResetCause::from_code(cause),
        }
    }
}

fn bits(r: &Request) -> [u32; 6] {
    let s = &r.sample;
    [s.current_a, s.p_a_bar, s.p_b_bar, s.speed_rpm, s.position_mm, s.ambient_c].map(f32::to_bits)
}

fn decode_all(bytes: &[u8]) -> Vec<Result<Vec<u8>, eha_guard::protocol::DecodeError>> {
    let mut d = Deframer::new();
    bytes.iter().filter_map(|&b| d.push(b).map(|r| r.map(<[u8]>::to_vec))).collect()
}

fn app() -> AppTarget<f32> {
    AppTarget::boot(&GuardConfig::DEFAULT, Box::new(MemBoard::new()))
}

/// One tick with `bytes` received: (used the sample with this sequence
/// number, frames rejected so far).
fn tick(a: &mut AppTarget<f32>, bytes: &[u8]) -> (Option<u16>, u16) {
    let r = a.tick(bytes, 0).expect("a tick reply").reply;
    (r.fresh.then_some(r.sample_seq), r.rejected)
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 256, ..ProptestConfig::default() })]

    #[test]
    fn request_round_trip_is_bit_exact(r in any_request()) {
        let wire = r.encode();
        prop_assert_eq!(wire.iter().filter(|&&b| b == 0).count(), 1, "only the delimiter is zero");
        let got = decode_all(&wire);
        prop_assert_eq!(got.len(), 1);
        let back = Request::from_payload(got[0].as_ref().unwrap()).unwrap();
        prop_assert_eq!(back.seq, r.seq);
        prop_assert_eq!(bits(&back), bits(&r));
        prop_assert_eq!(back.reports.valve_fb, r.reports.valve_fb);
        prop_assert_eq!(back.reports.elec_hz.map(f32::to_bits), r.reports.elec_hz.map(f32::to_bits));
        prop_assert_eq!(back.reports.lng_supply_bar.map(f32::to_bits), r.reports.lng_supply_bar.map(f32::to_bits));
    }

    #[test]
    fn tick_reply_round_trip_is_bit_exact(r in any_reply()) {
        let wire = r.encode();
        let got = decode_all(&wire);
        prop_assert_eq!(got.len(), 1);
        let back = TickReply::from_payload(got[0].as_ref().unwrap()).unwrap();
        prop_assert!(eha_sim::pil::report::same_reply(&back, &r), "{:?} vs {:?}", back, r);
    }

    /// Every single-bit corruption of a sample frame is rejected: never used
    /// by a tick, each resulting frame counted exactly once.
    #[test]
    fn every_single_bit_corruption_is_rejected(r in any_request()) {
        let wire = r.encode();
        let mut a = app();
        let mut rejected = 0u16;
        for bit in 0..wire.len() * 8 {
            let mut bad = wire.to_vec();
            bad[bit / 8] ^= 1 << (bit % 8);
            bad.push(0); // resync in case the flip hit the delimiter
            let frames = decode_all(&bad).len() as u16;
            let (used, rej) = tick(&mut a, &bad);
            prop_assert_eq!(used, None, "bit {}: a corrupted frame was used", bit);
            rejected += frames;
            prop_assert_eq!(rej, rejected, "bit {}: every frame counted once", bit);
        }
        prop_assert_eq!(a.app().counters().accepted, 0);
    }

    #[test]
    fn truncated_frames_are_rejected(r in any_request(), cut in 1usize..30) {
        let wire = r.encode();
        let cut = cut.min(wire.len() - 2);
        let mut bad = wire[..cut].to_vec();
        bad.push(0);
        let mut a = app();
        prop_assert_eq!(tick(&mut a, &bad), (None, 1));
    }

    /// Sequence rule: a sample is used iff it is newer than the last accepted one.
    #[test]
    fn out_of_order_frames_are_rejected(seqs in proptest::collection::vec(any::<u16>(), 1..50)) {
        let mut a = app();
        let mut last: Option<u16> = None;
        for (i, s) in seqs.iter().enumerate() {
            let r = Request { seq: *s, ..Request::default() };
            let (used, _) = tick(&mut a, &r.encode());
            let newer = last.is_none_or(|l| { let d = s.wrapping_sub(l); d != 0 && d <= 0x8000 });
            if newer {
                prop_assert_eq!(used, Some(*s), "frame {}", i);
                last = Some(*s);
            } else {
                prop_assert_eq!(used, None, "frame {}", i);
            }
        }
    }

    /// Arbitrary bytes never panic, every tick still replies, and a good
    /// frame afterwards is still used.
    #[test]
    fn garbage_never_panics_and_the_loop_recovers(garbage in proptest::collection::vec(any::<u8>(), 0..600)) {
        let mut a = app();
        let _ = tick(&mut a, &garbage);
        let c = a.app().counters();
        let next = c.accepted.checked_sub(1).map_or(0u16, |_| 0x8000);
        let mut tail = vec![0u8];
        tail.extend_from_slice(&Request { seq: next, ..Request::default() }.encode());
        let (used, _) = tick(&mut a, &tail);
        prop_assert!(used.is_some() || c.accepted > 0, "a good frame after garbage must be used: {c:?}");
    }

    #[test]
    fn crc_detects_any_single_bit_error(data in proptest::collection::vec(any::<u8>(), 1..64), bit in any::<usize>()) {
        let bit = bit % (data.len() * 8);
        let mut bad = data.clone();
        bad[bit / 8] ^= 1 << (bit % 8);
        prop_assert_ne!(crc16(&data), crc16(&bad));
    }
}
