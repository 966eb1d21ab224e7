//! The product loop on a simulated board: frames in, pins and replies out.

extern crate std;
use std::vec::Vec as StdVec;

use super::*;
use crate::memory::ThermalRecord;
use crate::params_block::BLOCK_LEN;
use crate::memory::Restore;
use crate::protocol::Deframer;
use wire::{Ack, AckResult, Cmd, FromGuard, TraceReply};

use crate::Guard;
use mem_board::MemBoard;

mod block;

/// Everything the guard sent since the last call, decoded.
pub(super) fn replies(b: &mut MemBoard) -> StdVec<FromGuard> {
    let mut d = Deframer::new();
    let mut out = StdVec::new();
    for &x in b.take_tx().iter() {
        if let Some(Ok(p)) = d.push(x) {
            out.push(FromGuard::from_payload(p).expect("guard frames decode"));
        }
    }
    out
}

/// A powered-on board (boxed: it holds a 16 KiB flash).
pub(super) fn board() -> std::boxed::Box<MemBoard> {
    std::boxed::Box::new(MemBoard::new())
}

pub(super) fn sample(seq: u16, current_a: f32, p_a_bar: f32) -> Request {
    Request {
        seq,
        sample: crate::Sample { current_a, p_a_bar, p_b_bar: 3.0, speed_rpm: 500.0, position_mm: 0.0, ambient_c: 30.0 },
        reports: crate::Reports::default(),
    }
}

/// [`sample`] at rest (speed 0).
pub(super) fn at_rest(seq: u16, current_a: f32, p_a_bar: f32) -> Request {
    let mut r = sample(seq, current_a, p_a_bar);
    r.sample.speed_rpm = 0.0;
    r
}

pub(super) fn ticks(r: &[FromGuard]) -> StdVec<TickReply> {
    r.iter().filter_map(|f| if let FromGuard::Tick(t) = f { Some(*t) } else { None }).collect()
}

/// Before the first sample the valve pin is at its safe (open) level and the
/// guard waits without a fault; the watchdog is fed once per completed tick.
#[test]
fn waits_with_valve_open_until_the_first_sample() {
    let mut b = board();
    let mem = b.boot_memory();
    let mut app = App::boot(&mut *b, &GuardConfig::DEFAULT, &mem);
    assert_eq!(b.pins, Pins { valve_pin: false, ok_pin: true }, "boot: valve open (pin low), no alarm");
    assert_eq!(app.reset_cause(), ResetCause::PowerOn);
    for _ in 0..20 {
        app.tick(&mut *b, 0);
    }
    let t = ticks(&replies(&mut b));
    assert_eq!(t.len(), 20, "one tick reply per tick");
    assert!(t.iter().all(|r| !r.fresh && r.out.valve_open && r.out.faults.is_empty() && !r.pins.valve_pin));
    assert_eq!(b.feeds, 20);
}

/// The product loop ticks the guard exactly like a bare guard fed the same
/// samples (bit-identical outputs), one tick reply per tick.
#[test]
fn one_sample_per_tick_matches_the_bare_guard() {
    let mut b = board();
    let mem = b.boot_memory();
    let mut app = App::boot(&mut *b, &GuardConfig::DEFAULT, &mem);
    let mut bare = Guard::new(&GuardConfig::DEFAULT, Restore::Cold);
    for k in 0..300u16 {
        let s = sample(k, 20.0 + f32::from(k % 7), 60.0);
        b.push_rx(&s.encode());
        app.tick(&mut *b, 0);
        let want = bare.tick(&s.sample);
        let t = ticks(&replies(&mut b));
        assert_eq!(t.len(), 1);
        assert!(t[0].fresh && t[0].sample_seq == k);
        assert!(crate::protocol::GuardOutput::bit_eq(&t[0].out, &want), "tick {k}: {:?} vs {want:?}", t[0].out);
        assert_eq!(t[0].pins, Pins::for_outputs(want.valve_open, want.alarm));
    }
    assert_eq!(app.counters().accepted, 300);
}

/// Two samples in one tick: the newer one is used, the older counted as
/// superseded; a tick with none is a missing tick; an old sequence number is
/// rejected.
#[test]
fn newest_sample_wins_missing_ticks_count_and_old_frames_are_rejected() {
    let mut b = board();
    let mem = b.boot_memory();
    let mut app = App::boot(&mut *b, &GuardConfig::DEFAULT, &mem);
    b.push_rx(&sample(1, 10.0, 50.0).encode());
    b.push_rx(&sample(2, 11.0, 50.0).encode());
    app.tick(&mut *b, 0);
    app.tick(&mut *b, 0);
    b.push_rx(&sample(2, 11.0, 50.0).encode());
    app.tick(&mut *b, 0);
    let t = ticks(&replies(&mut b));
    assert_eq!((t[0].fresh, t[0].sample_seq, t[1].fresh, t[2].fresh), (true, 2, false, false));
    let c = app.counters();
    assert_eq!((c.accepted, c.superseded, c.missing, c.rejected_sequence), (2, 1, 2, 1));
    assert_eq!(t[2].rejected, 1);
}

/// An overrun that swallowed periods: each lost period becomes a missing
/// tick (the model's clock keeps up), and the overrun is counted and traced.
#[test]
fn overrun_periods_become_missing_ticks_and_are_counted() {
    let mut b = board();
    let mem = b.boot_memory();
    let mut app = App::boot(&mut *b, &GuardConfig::DEFAULT, &mem);
    b.push_rx(&sample(1, 10.0, 50.0).encode());
    app.tick(&mut *b, 0);
    let before = app.guard().ticks();
    app.overrun(2);
    b.push_rx(&sample(2, 10.0, 50.0).encode());
    app.tick(&mut *b, 2);
    assert_eq!(app.guard().ticks() - before, 3, "two catch-up ticks and the tick's own");
    assert_eq!(app.counters().overruns, 2);
    assert!(app.guard().trace().iter().any(|e| matches!(e, Trace::Overrun { lost_ticks: 2, .. })));
    let t = ticks(&replies(&mut b));
    assert_eq!(t.last().map(|r| r.overruns), Some(2));
}

/// A valve pin that reads back wrong latches ACTUATOR and opens the valve
/// in the same tick.
#[test]
fn pin_read_back_mismatch_latches_actuator_and_opens_the_valve() {
    let mut b = board();
    let mem = b.boot_memory();
    let mut app = App::boot(&mut *b, &GuardConfig::DEFAULT, &mem);
    b.push_rx(&sample(1, 10.0, 50.0).encode());
    app.tick(&mut *b, 0);
    assert!(!ticks(&replies(&mut b))[0].out.valve_open, "cold oil: valve closed");
    b.stuck_valve_pin = Some(false);
    b.push_rx(&sample(2, 10.0, 50.0).encode());
    app.tick(&mut *b, 0);
    let t = ticks(&replies(&mut b));
    assert!(t[0].out.valve_open && t[0].out.faults.intersects(crate::faults::ACTUATOR), "{:?}", t[0]);
}

/// Sends `arm` with `token`, ticks once with sample `seq`, reads the
/// nonce from its ack and sends `confirm` with the key `command_key` makes of
/// it (rig id all zero: the compiled-in default), ticks once more with
/// sample `seq + 1`; the confirmation's ack.
pub(super) fn arm_confirm(app: &mut App, b: &mut MemBoard, token: u16, arm: Cmd, confirm: Cmd, seq: u16, s: &Request) -> Ack {
    b.push_rx(&Command { token, cmd: arm, arg: 0 }.encode());
    b.push_rx(&Request { seq, ..*s }.encode());
    app.tick(&mut *b, 0);
    let nonce = replies(b)
        .iter()
        .find_map(|f| match f {
            FromGuard::Ack(a) if a.token == token && a.result == AckResult::Done => Some(a.value),
            _ => None,
        })
        .expect("the arm's ack");
    let key = wire::command_key(&[0; 16], nonce, confirm);
    let t2 = token.wrapping_add(1);
    b.push_rx(&Command { token: t2, cmd: confirm, arg: key }.encode());
    b.push_rx(&Request { seq: seq.wrapping_add(1), ..*s }.encode());
    app.tick(&mut *b, 0);
    replies(b)
        .iter()
        .find_map(|f| match f {
            FromGuard::Ack(a) if a.token == t2 => Some(*a),
            _ => None,
        })
        .expect("the confirmation's ack")
}

/// Commands: status at once; an armed, keyed refill is done; a clear is
/// refused until the clear rule holds; a trace dump arrives over several
/// ticks; the test-only injections are refused in a build without
/// `fault-inject`.
#[test]
fn commands_status_refill_clear_trace() {
    let mut b = board();
    let mem = b.boot_memory();
    let mut app = App::boot(&mut *b, &GuardConfig::DEFAULT, &mem);
    // A non-finite sample latches NON_FINITE (the valve opens: no refill).
    b.push_rx(&sample(1, f32::NAN, 50.0).encode());
    app.tick(&mut *b, 0);
    let cmd = |token, cmd| Command { token, cmd, arg: 0 }.encode();
    // the pump at rest, consistent sensors
    let rest = |k| at_rest(k, 0.0, 5.0);
    b.push_rx(&cmd(9, Cmd::Status));
    app.tick(&mut *b, 0);
    let r = replies(&mut b);
    let st = r.iter().find_map(|f| if let FromGuard::Status(s) = f { Some(*s) } else { None }).expect("status");
    assert_eq!((st.token, st.tick, st.counters.missing, st.faults.intersects(crate::faults::NON_FINITE)), (9, 2, 1, true));
    let a = arm_confirm(&mut app, &mut b, 7, Cmd::ClearArm, Cmd::ClearConfirm, 2, &rest(2));
    assert_eq!((a.cmd, a.result, a.value), (Cmd::ClearConfirm, AckResult::Refused, wire::Refusal::Rule as u32), "clear rule not met");
    // 100 valid ticks, then the clear succeeds (the interval counts
    // confirmed commands: the refused one counted).
    for k in 4..1100u16 {
        b.push_rx(&rest(k).encode());
        app.tick(&mut *b, 0);
    }
    replies(&mut b);
    let a = arm_confirm(&mut app, &mut b, 10, Cmd::ClearArm, Cmd::ClearConfirm, 1100, &rest(0));
    assert_eq!((a.result, a.value), (AckResult::Done, 0), "cleared, trusted");
    assert!(!app.guard().faults().intersects(crate::faults::LATCHED));
    // the valve closes after its dwell (cold oil), no alarm: the refill is done
    for k in 1102..1400u16 {
        b.push_rx(&rest(k).encode());
        app.tick(&mut *b, 0);
    }
    replies(&mut b);
    assert!(!app.guard().output().valve_open, "{:?}", app.guard().output());
    let a = arm_confirm(&mut app, &mut b, 20, Cmd::RefillArm, Cmd::RefillConfirm, 1400, &rest(0));
    assert_eq!(a.result, AckResult::Done, "{a:?}");
    b.push_rx(&cmd(12, Cmd::InjectHang));
    b.push_rx(&cmd(11, Cmd::Trace));
    for k in 1402..1430u16 {
        b.push_rx(&rest(k).encode());
        app.tick(&mut *b, 0);
    }
    let r = replies(&mut b);
    #[cfg(not(feature = "fault-inject"))]
    assert!(r.contains(&FromGuard::Ack(Ack { token: 12, cmd: Cmd::InjectHang, result: AckResult::Refused, value: wire::Refusal::Unavailable as u32 })));
    let dump: StdVec<TraceReply> = r.iter().filter_map(|f| if let FromGuard::Trace(t) = f { Some(*t) } else { None }).collect();
    assert!(!dump.is_empty());
    assert_eq!(dump.len(), usize::from(dump[0].count), "the whole ring arrives");
    assert!(dump.iter().enumerate().all(|(i, t)| usize::from(t.index) == i && t.token == 11));
    assert!(dump.iter().any(|t| t.event.tag == 7), "the faults-cleared event is in the dump");
    // every armed command is in the trace: code (aux bits 0-7), result (8-15)
    let cmds: StdVec<u32> = dump.iter().filter(|t| t.event.tag == 11).map(|t| t.event.aux).collect();
    let rule = wire::Refusal::Rule as u32;
    assert_eq!(cmds, [1, 5 | rule << 8, 1, 5, 2, 6, 0xE0 | (wire::Refusal::Unavailable as u32) << 8], "{cmds:?}");
}

/// Garbage, bursts and truncated frames: counted as rejected, the tick
/// still completes with its one reply and the watchdog is still fed.
#[test]
fn garbage_is_counted_and_every_tick_completes() {
    let mut b = board();
    let mem = b.boot_memory();
    let mut app = App::boot(&mut *b, &GuardConfig::DEFAULT, &mem);
    let mut x: u32 = 12345;
    for k in 0..200u16 {
        for _ in 0..(k % 97) {
            x = x.wrapping_mul(1_103_515_245).wrapping_add(12345);
            b.push_rx(&[(x >> 16) as u8]);
        }
        if k % 3 == 0 {
            let f = sample(1000 + k, 10.0, 50.0).encode();
            b.push_rx(&[0]);
            b.push_rx(&f);
        }
        app.tick(&mut *b, 0);
    }
    let t = ticks(&replies(&mut b));
    assert_eq!(t.len(), 200);
    assert_eq!(b.feeds, 200);
    let c = app.counters();
    assert!(c.rejected_crc + c.rejected_framing > 50, "{c:?}");
    assert!(c.accepted >= 40, "most clean frames after a delimiter get through: {c:?}");
}

/// A warm reboot restores the thermal state from the A/B records and reads
/// the recorded reset cause.
#[test]
fn warm_reboot_restores_the_estimate_and_the_cause() {
    let mut b = board();
    let mem = b.boot_memory();
    let mut app = App::boot(&mut *b, &GuardConfig::DEFAULT, &mem);
    for k in 0..500u16 {
        b.push_rx(&sample(k, 40.0, 150.0).encode());
        app.tick(&mut *b, 0);
    }
    let before = app.guard().output().drain_c;
    b.cause = b.cause.with_cause(ResetCause::Watchdog);
    let mem = b.boot_memory();
    let app2 = App::boot(&mut *b, &GuardConfig::DEFAULT, &mem);
    assert_eq!(app2.reset_cause(), ResetCause::Watchdog);
    let after = app2.guard().snapshot().temps_c;
    let was = app.guard().snapshot().temps_c;
    assert_eq!(after, was, "every node restored");
    assert!(before > 30.0);
}


/// A failing non-volatile store is tried once per [`NV_RETRY_TICKS`], not on
/// every tick (an erase attempt can stall the MCU for seconds); a working
/// one is written by the policy (first record at once, then on a 2 K rise).
#[test]
fn failing_nv_store_is_retried_once_a_minute_not_every_tick() {
    let mut b = std::boxed::Box::new(MemBoard::new().with_nv());
    b.set_flash_faults(false, true);
    let mem = b.boot_memory();
    let mut app = App::boot(&mut *b, &GuardConfig::DEFAULT, &mem);
    for k in 0..12_000u32 {
        b.push_rx(&sample((k & 0xFFFF) as u16, 30.0, 150.0).encode());
        app.tick(&mut *b, 0);
    }
    replies(&mut b);
    assert_eq!(b.nv_calls, 2, "ticks 1 and 6001 of 12 000");
    assert_eq!(app.counters().nv_failures, 2);
    let mut ok = std::boxed::Box::new(MemBoard::new().with_nv());
    let mem = ok.boot_memory();
    let mut app = App::boot(&mut *ok, &GuardConfig::DEFAULT, &mem);
    for k in 0..50u32 {
        ok.push_rx(&sample(k as u16, 30.0, 150.0).encode());
        app.tick(&mut *ok, 0);
    }
    // The estimate rises ~0.7 K in these 0.5 s, no fault: nothing due after the first.
    assert_eq!(ok.nv_calls, 1, "one record at the start; the next on a 2 K rise");
}


/// Flash storage of a parameter block for a test (4-byte aligned, leaked: it
/// lives as long as the flash it stands for).
pub(super) fn flash_block(bytes: [u8; BLOCK_LEN]) -> &'static [u8; BLOCK_LEN] {
    #[repr(C, align(4))]
    struct Aligned([u8; BLOCK_LEN]);
    &std::boxed::Box::leak(std::boxed::Box::new(Aligned(bytes))).0
}

/// Another EHA's constants: the pump's mechanical loss 1.5× the paper rig's
/// (eq. 8), with its own Phi (the exact ZOH of its own nominal Jacobian, as
/// the reduction computes it: the friction heat depends on the oil's
/// temperature through the pump's shares, so the paper rig's Phi fails the
/// stability check's 1e-7 s and the block would be refused). Checked to build.
pub(super) fn other_rig() -> crate::model::ModelConsts<f32> {
    use crate::model::{etd_matrix, Model};
    let mut c = crate::model::ModelConsts { k_mech: crate::model::DEFAULT_CONSTS.k_mech * 1.5, ..crate::model::DEFAULT_CONSTS };
    let j = Model::<f32>::for_linearisation(&c).map(|m| m.nominal_jacobian_f32().map(|r| r.map(f64::from)));
    c.phi = etd_matrix(&j.unwrap_or_default(), crate::params::S_PER_STEP).map(|r| r.map(|x| x as f32));
    assert_eq!(Model::<f32>::from_consts(&c).err(), None, "the other rig's constants must build a model");
    c
}

/// Power loss on a board with a real-time clock: the
/// non-volatile record carries the clock reading; after 24 h off the restore
/// is cooled by the model's rest bound (never below the air), on a board
/// without a clock it stays at the saved temperatures plus the write
/// policy's 2 K; a first sample with a warmer ambient than the saved one
/// raises every node by the difference.
#[test]
fn power_loss_restore_is_cooled_over_the_clocks_off_time() {
    // the save carries the clock
    let mut b = std::boxed::Box::new(MemBoard::new().with_nv());
    b.rtc = Some(5_000);
    let mem = b.boot_memory();
    let mut app = App::boot(&mut *b, &GuardConfig::DEFAULT, &mem);
    b.push_rx(&sample(1, 10.0, 40.0).encode());
    app.tick(&mut *b, 0);
    assert_eq!(b.nv_saved.map(|r| r.rtc_s), Some(5_000), "the first save is stamped");

    let hot = ThermalRecord::new([55.0, 60.0, 50.0, 45.0, 40.0, 30.0], 20.0, 0, 0, 100).with_rtc(Some(5_000));
    let boot_after = |rtc: Option<u32>, ambient_c: f32| {
        let mut b = board();
        b.rtc = rtc;
        // the clock's last-alive stamp: the machine stopped at the save
        let mem = BootMemory { nv: crate::memory::nv::NvLoad::Valid(hot), alive_s: rtc.map(|_| 5_000), nv_failing: false, ..b.boot_memory() };
        let mut app = App::boot(&mut *b, &GuardConfig::DEFAULT, &mem);
        let mut s = sample(1, 0.0, 3.0);
        s.sample.speed_rpm = 0.0;
        s.sample.ambient_c = ambient_c;
        b.push_rx(&s.encode());
        app.tick(&mut *b, 0);
        let t = ticks(&replies(&mut b));
        let last = *t.last().expect("a tick reply");
        (last.restore, last.out.drain_c)
    };
    let (kind, uncooled) = boot_after(None, 20.0);
    assert_eq!(kind, RestoreKind::PowerLoss);
    assert!((uncooled - 62.0).abs() < 0.05, "no clock: saved + 2 K, got {uncooled}");
    let (_, day) = boot_after(Some(5_000 + 86_400), 20.0);
    // pump group bound: 11.5 h; 24 h counted (from the last-alive stamp)
    assert!(day > 20.0 && day < 35.0, "24 h off: {day}");
    let (_, warmer) = boot_after(Some(5_000 + 86_400), 25.0);
    assert!((warmer - day - 5.0).abs() < 0.05, "a 5 K warmer first ambient raises the drain by 5 K: {day} -> {warmer}");
}
