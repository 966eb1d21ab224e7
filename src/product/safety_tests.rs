//! The safety case on the product loop: every path that could leave the
//! valve closed while the oil may be hot, or let a fault clear itself, has a
//! test here (thermal memory, commands, configuration, erase stalls).

extern crate std;

use super::tests::{board, replies, sample, ticks};
use super::*;
use crate::faults;
use mem_board::MemBoard;
use std::boxed::Box;

/// A board with a non-volatile store and a clock at `rtc_s`.
fn nv_board(rtc_s: u32) -> Box<MemBoard> {
    let mut b = Box::new(MemBoard::new().with_nv());
    b.rtc = Some(rtc_s);
    b.rtc_backup = Some(0);
    b
}

/// Boots on `b` from what its memories hold.
fn boot(b: &mut MemBoard) -> App {
    let mem = b.boot_memory();
    App::boot(b, &GuardConfig::DEFAULT, &mem)
}

/// A hot record (55-60 °C) stamped at `rtc_s`.
fn hot_record(rtc_s: u32) -> ThermalRecord {
    ThermalRecord::new([55.0, 60.0, 50.0, 45.0, 40.0, 30.0], 20.0, 5_000_000, 0, 100).with_seq(7, true).with_rtc(Some(rtc_s))
}

/// One tick with the nominal sample `k`; the tick reply.
fn tick(app: &mut App, b: &mut MemBoard, k: u32) -> TickReply {
    b.push_rx(&sample((k & 0xFFFF) as u16, 20.0, 40.0).encode());
    app.tick(b, 0);
    *ticks(&replies(b)).last().expect("a tick reply")
}

/// A flash that cannot be read at boot is not "no record": the machine may
/// be hot, so the start is conservative (every node at the alarm
/// temperature, MEMORY_CORRUPT, valve open, alarm until trusted).
#[test]
fn an_unreadable_flash_record_is_a_conservative_start_not_a_cold_one() {
    let mut b = nv_board(1_000);
    b.nv.as_mut().map(|s| s.save(&hot_record(1_000)));
    b.power_loss();
    b.set_flash_faults(true, false);
    let mut app = boot(&mut b);
    let r = tick(&mut app, &mut b, 1);
    assert_eq!(r.restore, RestoreKind::Corrupt, "restore {:?}, faults {:?}", r.restore, r.out.faults);
    assert!(r.out.faults.contains(faults::MEMORY_CORRUPT | faults::UNTRUSTED) && r.out.valve_open && r.out.alarm, "{:?}", r.out);
}

/// A record in flash that fails its check (bad CRC, or the NaN estimate the
/// write policy let through) is damaged, not absent: conservative start.
#[test]
fn a_damaged_flash_record_is_a_conservative_start_not_a_cold_one() {
    let mut bad_crc = hot_record(1_000);
    bad_crc.crc ^= 1;
    let mut nan = hot_record(1_000);
    nan.temps_c[1] = f32::NAN;
    let nan = nan.with_rtc(Some(1_000)); // resealed: only its value is wrong
    for (name, rec) in [("bad CRC", bad_crc), ("NaN estimate", nan)] {
        let mut b = nv_board(1_000);
        b.nv.as_mut().map(|s| s.save(&rec));
        b.power_loss();
        let mut app = boot(&mut b);
        let r = tick(&mut app, &mut b, 1);
        assert_eq!(r.restore, RestoreKind::Corrupt, "{name}: restore {:?}", r.restore);
        assert!(r.out.valve_open && r.out.alarm, "{name}: {:?}", r.out);
    }
}

/// A failed non-volatile save is reported: NV_FAILED, derate, the OK pin
/// low (the valve is not forced: the estimate itself is good).
#[test]
fn a_failed_save_latches_nv_failed_with_derate() {
    let mut b = nv_board(1_000);
    b.set_flash_faults(false, true);
    let mut app = boot(&mut b);
    let r = tick(&mut app, &mut b, 1);
    assert_eq!(b.nv_calls, 1, "the first record is due at once");
    assert!(r.out.faults.contains(faults::NV_FAILED) && r.out.derate && !r.pins.ok_pin, "{:?}", r);
}

/// The retry timer of a failing store survives the 497-day wrap of the
/// tick counter (a saturating deadline stopped every save until the
/// counter came round again).
#[test]
fn failed_saves_are_retried_across_the_tick_counter_wrap() {
    let mut b = nv_board(1_000);
    b.set_flash_faults(false, true);
    let mut app = boot(&mut b);
    tick(&mut app, &mut b, 0);
    // jump the application's tick counter to 7 000 ticks before the wrap
    let before = u32::MAX - 7_000 - app.tick;
    b.push_rx(&sample(1, 20.0, 40.0).encode());
    app.tick(&mut *b, before);
    let calls = b.nv_calls;
    for k in 2..20_000u32 {
        tick(&mut app, &mut b, k);
    }
    assert!(b.nv_calls >= calls + 2, "saves retried once a minute across the wrap: {} -> {}", calls, b.nv_calls);
}

/// After a power loss the LNG used is never under-counted: the restore adds
/// the most the write policy can have left unwritten (110 kJ).
#[test]
fn lng_used_is_never_under_counted_after_a_power_loss() {
    let mut b = nv_board(1_000);
    let rec = hot_record(1_000);
    b.nv.as_mut().map(|s| s.save(&rec));
    b.rtc_backup = Some(1_000);
    b.power_loss();
    let app = boot(&mut b);
    let used = app.guard().snapshot().lng_used_cj;
    let unwritten = NvPolicy::DEFAULT.lng_rise_cj;
    assert!(used >= rec.lng_used_cj + unwritten, "restored {used} cJ, saved {} cJ + up to {unwritten} cJ unwritten", rec.lng_used_cj);
}

/// Power-off cooling counts only from a time the board knows the machine
/// stopped: the last-alive stamp in the clock's backup register. A record
/// far older than that (its saves failed while the machine ran on) is
/// stale: a conservative start, not a record cooled over hours the machine
/// was running.
#[test]
fn no_cooling_over_hours_the_machine_ran_after_its_last_save() {
    let mut b = nv_board(5_000);
    let mut app = boot(&mut b);
    tick(&mut app, &mut b, 0);
    assert_eq!(b.nv_saved.map(|r| r.rtc_s), Some(5_000), "the first save");
    // every save from here fails; the machine runs 2 h more
    b.set_flash_faults(false, true);
    for k in 1..2_000u32 {
        b.rtc = Some(5_000 + k * 7_200 / 2_000);
        tick(&mut app, &mut b, k);
    }
    b.power_loss();
    b.set_flash_faults(false, false);
    b.rtc = Some(5_000 + 7_200 + 86_400);
    let mut app = boot(&mut b);
    let r = tick(&mut app, &mut b, 1);
    assert_eq!(r.restore, RestoreKind::Corrupt, "the 2 h stale record: restore {:?}, drain {}", r.restore, r.out.drain_c);
}

/// A valve that does not follow its command (ACTUATOR, detected from the
/// position report) derates: the cooling the estimate needs may be missing
/// (the campaign's stuck-shut valve reached 61.8 °C at the drain).
#[test]
fn a_detected_actuator_fault_derates() {
    let mut b = board();
    let mut app = boot(&mut b);
    let mut last = tick(&mut app, &mut b, 0);
    for k in 1..100u16 {
        // the valve reports open while commanded shut (cold oil; pump at
        // rest, so the sensor cross-check has nothing to compare)
        b.push_rx(&Request { valve_fb: Some(true), speed_rpm: 0.0, ..sample(k, 0.0, 5.0) }.encode());
        app.tick(&mut *b, 0);
        last = *ticks(&replies(&mut b)).last().expect("a tick reply");
    }
    assert!(last.out.faults.contains(faults::ACTUATOR), "{:?}", last.out);
    assert!(last.out.derate && !last.pins.ok_pin, "ACTUATOR must derate: {:?}", last);
}

/// Boots with the parameter block of `c`; (where the constants came from,
/// the faults at boot, the pins at boot).
fn boot_with_block(c: &crate::model::ModelConsts<f32>) -> (ParamSource, crate::Faults, Pins) {
    let mut b = board();
    b.block = Some(super::tests::flash_block(params_block::encode(c, "test-rig")));
    let app = boot(&mut b);
    (app.params(), app.guard().faults(), b.pins)
}

/// `c` with its `Phi` computed for its own model (as the reduction tool
/// does), so that only the checks of the values can refuse it.
fn rediscretised(mut c: crate::model::ModelConsts<f32>) -> crate::model::ModelConsts<f32> {
    let m = crate::model::Model::<f64>::for_linearisation(&c).expect("values within their bounds");
    let j = m.nominal_jacobian_f32().map(|r| r.map(f64::from));
    c.phi = crate::model::etd_matrix(&j, crate::params::S_PER_STEP).map(|r| r.map(|x| x as f32));
    c
}

/// A block whose every loss coefficient is zero (with its own, consistent
/// `Phi`) passed the format and stability checks although its model never
/// heats: refused now (CONFIG: the bounds table), with the valve open, the
/// alarm and the OK pin low from boot; so is a block whose losses are all
/// within their ranges but 50 times too small to heat at the stated minimum
/// rate (the minimum-heating check).
#[test]
fn a_block_whose_model_cannot_heat_is_refused() {
    let mut zero = crate::params::DEFAULT_CONSTS;
    let mut tiny = zero;
    for (z, t) in [
        (&mut zero.k_lf, &mut tiny.k_lf),
        (&mut zero.k_lf_half, &mut tiny.k_lf_half),
        (&mut zero.k_lp, &mut tiny.k_lp),
        (&mut zero.k_mech, &mut tiny.k_mech),
        (&mut zero.k_cu, &mut tiny.k_cu),
        (&mut zero.fe1, &mut tiny.fe1),
        (&mut zero.fe2, &mut tiny.fe2),
        (&mut zero.fe15, &mut tiny.fe15),
        (&mut zero.k_m0, &mut tiny.k_m0),
        (&mut zero.k_mv, &mut tiny.k_mv),
        (&mut zero.r1, &mut tiny.r1),
        (&mut zero.r2, &mut tiny.r2),
        (&mut zero.k_act, &mut tiny.k_act),
    ] {
        *z = 0.0;
        *t *= 0.02;
    }
    // the zero block's Phi: the default one (its own cannot be built: the
    // model refuses its words); the tiny one's: its own
    for (name, c) in [("zero losses", zero), ("losses x 0.02", rediscretised(tiny))] {
        let (src, f, pins) = boot_with_block(&c);
        assert!(f.contains(faults::CONFIG), "{name} accepted: source {src:?}, faults {f:?}");
        assert!(!pins.valve_pin && !pins.ok_pin, "{name}: valve open and OK low from boot: {pins:?}");
    }
}

/// `k_sh = 0` switched the sensor cross-check off without a word: refused.
#[test]
fn a_block_without_a_torque_constant_is_refused() {
    let c = crate::model::ModelConsts { k_sh: 0.0, ..crate::params::DEFAULT_CONSTS };
    let (src, f, _) = boot_with_block(&c);
    assert!(f.contains(faults::CONFIG), "k_sh = 0 accepted: source {src:?}, faults {f:?}");
}

/// The block's cooling bound at rest is checked against its own model: a
/// bound claiming 100 times the cooling is refused, not trusted.
#[test]
fn a_block_claiming_more_cooling_at_rest_than_its_model_is_refused() {
    let mut c = crate::params::DEFAULT_CONSTS;
    for r in c.rest_rate.iter_mut() {
        *r *= 100.0;
    }
    let (src, f, _) = boot_with_block(&c);
    assert!(f.contains(faults::CONFIG), "rest rate x100 accepted: source {src:?}, faults {f:?}");
}

/// A block that fails its header or CRC: CONFIG with the valve open, the
/// alarm and the OK pin low from the first instant (not after the first
/// sample, up to 10 s later).
#[test]
fn a_refused_block_shows_the_alarm_from_the_first_instant() {
    let mut torn = params_block::encode(&crate::params::DEFAULT_CONSTS, "torn");
    torn[500] ^= 0x10;
    let mut b = board();
    b.block = Some(super::tests::flash_block(torn));
    let app = boot(&mut b);
    let out = app.guard().output();
    assert!(out.faults.contains(faults::CONFIG) && out.valve_open && out.alarm, "{out:?}");
    assert!(!b.pins.valve_pin && !b.pins.ok_pin, "valve pin and OK pin low at boot: {:?}", b.pins);
}
