//! The safety case on the product loop: every path that could leave the
//! valve closed while the oil may be hot, or let a fault clear itself, has a
//! test here (thermal memory, commands, configuration, erase stalls).

extern crate std;

use super::tests::{board, replies, sample, ticks};
use super::*;
use crate::faults;
use crate::memory::nv::NvPolicy;
use crate::memory::Restore;
use crate::params_block;
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
    b.rtc_backup = Some(crate::memory::alive_word(1_000, false));
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

/// Saves that fail for two minutes before a power loss: the flash record
/// misses those minutes of heating. The last-alive word carries the
/// failing flag, so the restore is conservative; before, the old record
/// (+2 K) was cooled over the off-time (the campaign's flash-write-fail run
/// under-predicted by 10.0 K).
#[test]
fn a_power_loss_after_failed_saves_is_a_conservative_start() {
    let mut b = nv_board(5_000);
    let mut app = boot(&mut b);
    tick(&mut app, &mut b, 0);
    assert_eq!(b.nv_saved.map(|r| r.rtc_s), Some(5_000), "the first save");
    b.set_flash_faults(false, true);
    for k in 1..12_000u32 {
        b.rtc = Some(5_000 + k / 100);
        tick(&mut app, &mut b, k);
    }
    b.power_loss();
    b.set_flash_faults(false, false);
    b.rtc = Some(5_000 + 120 + 60);
    let mut app = boot(&mut b);
    let r = tick(&mut app, &mut b, 1);
    assert_eq!(r.restore, RestoreKind::Corrupt, "saves failing at the power loss: restore {:?}, drain {}", r.restore, r.out.drain_c);
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
        b.push_rx(&Request { reports: crate::Reports { valve_fb: Some(true), ..crate::Reports::default() }, ..super::tests::at_rest(k, 0.0, 5.0) }.encode());
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
    let mut zero = crate::model::DEFAULT_CONSTS;
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
    let c = crate::model::ModelConsts { k_sh: 0.0, ..crate::model::DEFAULT_CONSTS };
    let (src, f, _) = boot_with_block(&c);
    assert!(f.contains(faults::CONFIG), "k_sh = 0 accepted: source {src:?}, faults {f:?}");
}

/// The block's cooling bound at rest is checked against its own model: a
/// bound claiming 100 times the cooling is refused, not trusted.
#[test]
fn a_block_claiming_more_cooling_at_rest_than_its_model_is_refused() {
    let mut c = crate::model::DEFAULT_CONSTS;
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
    let mut torn = params_block::encode(&crate::model::DEFAULT_CONSTS, "torn");
    torn[500] ^= 0x10;
    let mut b = board();
    b.block = Some(super::tests::flash_block(torn));
    let app = boot(&mut b);
    let out = app.guard().output();
    assert!(out.faults.contains(faults::CONFIG) && out.valve_open && out.alarm, "{out:?}");
    assert!(!b.pins.valve_pin && !b.pins.ok_pin, "valve pin and OK pin low at boot: {:?}", b.pins);
}

/// The motor current of the paper rig's pump at these pressures and speed
/// and this case-oil temperature (the extended eq. 8 with the viscous
/// friction on the oil's viscosity, as the reference plant draws it):
/// consistent sensors for the cross-check.
fn current_a(p_a: f32, p_b: f32, rpm: f32, oil_c: f32) -> f32 {
    let p = &crate::params::DEFAULT;
    let d = p.displacement_m3_per_rad as f32;
    let dp = (p_a - p_b) * 1e5;
    let w = (rpm * core::f32::consts::PI / 30.0).abs();
    let t_f = p.no_load_torque_nm as f32 + (p.viscous_w_s2_per_rad2 * p.visc_ratio_at(f64::from(oil_c))) as f32 * w + p.eta_m as f32 * d * dp.abs();
    let s = if rpm < 0.0 { -1.0 } else { 1.0 };
    (d * dp + s * t_f).abs() / p.torque_constant_nm_per_a as f32
}

/// Case 1 at 60 bar and 500 rpm with the speed channel reading `speed(k)`,
/// the drive's electrical frequency `elec` (4 pole pairs) and the valve
/// position reported; the tick reply of each tick.
fn run_case1(ticks: u32, speed: impl Fn(u32) -> f32, elec: bool) -> std::vec::Vec<TickReply> {
    let mut b = board();
    let mut app = boot(&mut b);
    let mut out = std::vec::Vec::new();
    let (mut open, mut oil_c) = (false, 20.0f32);
    for k in 0..ticks {
        let r = Request {
            seq: (k & 0xFFFF) as u16,
            sample: crate::Sample { current_a: current_a(65.0, 5.0, 500.0, oil_c), p_a_bar: 65.0, p_b_bar: 5.0, speed_rpm: speed(k), position_mm: 0.0, ambient_c: 20.0 },
            reports: crate::Reports { valve_fb: Some(open), elec_hz: elec.then_some(500.0 / 60.0 * 4.0), lng_supply_bar: None },
        };
        b.push_rx(&r.encode());
        app.tick(&mut *b, 0);
        let t = *ticks_of(&mut b).last().expect("a tick reply");
        open = t.out.valve_open;
        oil_c = t.out.drain_c;
        out.push(t);
    }
    out
}

fn ticks_of(b: &mut MemBoard) -> std::vec::Vec<TickReply> {
    ticks(&replies(b))
}

/// The first tick with SENSOR_DISAGREE and the speed channel latched bad.
fn speed_fault_at(t: &[TickReply]) -> Option<u32> {
    t.iter().position(|r| r.out.faults.contains(faults::SENSOR_DISAGREE | crate::Faults::channels(crate::ChannelSet::SPEED)) && r.out.valve_open).map(|k| k as u32)
}

/// With the drive's electrical frequency as a second speed source, a speed
/// sensor stuck at zero or reading half is seen within 1 s (two 0.5 s
/// windows): SENSOR_DISAGREE, the speed channel's worst case, valve open.
/// Before, the torque cross-check could not see it (both of its sides scale
/// with the measured speed): 5 of 150 campaign runs failed.
#[test]
fn a_speed_sensor_fault_is_seen_against_the_electrical_frequency() {
    for (name, gain) in [("stuck at zero", 0.0f32), ("gain 0.5", 0.5)] {
        let t = run_case1(600, |k| if k < 200 { 500.0 } else { 500.0 * gain }, true);
        let at = speed_fault_at(&t);
        assert!(at.is_some_and(|k| (200..=300).contains(&k)), "{name}: latched at tick {at:?}");
    }
    // consistent sensors: nothing
    let t = run_case1(3000, |_| 500.0, true);
    assert!(t.iter().all(|r| !r.out.faults.intersects(faults::SENSOR_DISAGREE)), "no false alarm: {:?}", t.last());
}

/// Without a second source: the pump drawing well above its no-load current
/// with the speed reading near zero for 2 s is implausible: SENSOR_DISAGREE
/// with the speed's worst case (the rule a load held at standstill for
/// longer also trips: documented).
#[test]
fn a_speed_stuck_at_zero_under_load_is_implausible_without_a_second_source() {
    let t = run_case1(800, |k| if k < 200 { 500.0 } else { 0.0 }, false);
    let at = speed_fault_at(&t);
    // 2 s (200 ticks) after the speed went to zero at tick 200
    assert!(at.is_some_and(|k| (399..=450).contains(&k)), "latched at tick {at:?}");
}

/// Cooling is credited only when the valve reports open: without the
/// position report the estimate takes no credit (NO_VALVE_FEEDBACK while
/// commanded open); with it and no supply pressure, LNG_UNCONFIRMED.
#[test]
fn no_cooling_credit_without_valve_feedback() {
    let cfg = GuardConfig::DEFAULT;
    // 300 s of Case 1 at 60 bar: (mean drain estimate over the last 100 s,
    // the status bits seen while the valve was open)
    let hot = |report: bool| {
        let mut g = crate::Guard::new(&cfg, Restore::Cold);
        let mut o = g.output();
        let (mut sum, mut n, mut seen) = (0.0f64, 0u32, crate::Faults::NONE);
        for k in 0..30_000 {
            if report {
                g.valve_feedback(o.valve_open);
            }
            o = g.tick(&crate::Sample { current_a: current_a(65.0, 5.0, 500.0, o.drain_c), p_a_bar: 65.0, p_b_bar: 5.0, speed_rpm: 500.0, position_mm: 0.0, ambient_c: 20.0 });
            if o.valve_open {
                seen |= o.faults;
            }
            if k >= 20_000 {
                sum += f64::from(o.drain_c);
                n += 1;
            }
        }
        (sum / f64::from(n), seen)
    };
    let (with, with_seen) = hot(true);
    let (without, without_seen) = hot(false);
    assert!(without > with + 1.0, "no credit without the report: {without} vs {with} degC");
    assert!(without_seen.contains(faults::NO_VALVE_FEEDBACK), "{without_seen:?}");
    assert!(with_seen.contains(faults::LNG_UNCONFIRMED) && !with_seen.contains(faults::NO_VALVE_FEEDBACK), "{with_seen:?}");
}

/// A supply pressure below its minimum: the tank is empty whatever the
/// budget says, no credit, LNG_LOW.
#[test]
fn no_cooling_credit_with_the_supply_pressure_low() {
    let cfg = GuardConfig::DEFAULT;
    let hot = |supply: f32| {
        let mut g = crate::Guard::new(&cfg, Restore::Cold);
        let mut o = g.output();
        let (mut sum, mut n, mut seen) = (0.0f64, 0u32, crate::Faults::NONE);
        for k in 0..30_000 {
            g.valve_feedback(o.valve_open);
            g.lng_supply(Some(supply));
            o = g.tick(&crate::Sample { current_a: current_a(65.0, 5.0, 500.0, o.drain_c), p_a_bar: 65.0, p_b_bar: 5.0, speed_rpm: 500.0, position_mm: 0.0, ambient_c: 20.0 });
            seen |= o.faults;
            if k >= 20_000 {
                sum += f64::from(o.drain_c);
                n += 1;
            }
        }
        (sum / f64::from(n), seen)
    };
    let ((full, full_seen), (empty, empty_seen)) = (hot(5.0), hot(0.0));
    assert!(empty > full + 1.0, "{empty} vs {full} degC");
    assert!(empty_seen.contains(faults::LNG_LOW) && !full_seen.intersects(faults::LNG_UNCONFIRMED | faults::LNG_LOW), "{empty_seen:?} {full_seen:?}");
}

/// Ticks `n` valid nominal samples (pump at rest, consistent sensors) and
/// returns the last tick reply; `cmds` are sent in the first tick.
fn settle(app: &mut App, b: &mut MemBoard, from: u16, n: u16, cmds: &[&[u8]]) -> TickReply {
    let mut last = None;
    for k in 0..n {
        if k == 0 {
            for c in cmds {
                b.push_rx(c);
            }
        }
        b.push_rx(&super::tests::at_rest(from.wrapping_add(k), 0.0, 5.0).encode());
        app.tick(b, 0);
        last = ticks_of(b).last().copied();
    }
    last.expect("a tick reply")
}

/// A CRC-valid clear frame (line noise that passes CRC-16, or a controller
/// bug) cleared every latched fault: it must not.
#[test]
fn one_crc_valid_frame_does_not_clear_faults() {
    let mut b = board();
    let mut app = boot(&mut b);
    b.push_rx(&super::tests::sample(0, f32::NAN, 5.0).encode());
    app.tick(&mut *b, 0);
    let r = settle(&mut app, &mut b, 1, 150, &[]);
    assert!(r.out.faults.contains(faults::NON_FINITE));
    // the frame the old protocol took as "clear faults": kind, token, code 1
    let raw = crate::protocol::frame(&[wire::KIND_COMMAND, 7, 0, 1], false);
    let r = settle(&mut app, &mut b, 151, 5, &[&raw]);
    assert!(r.out.faults.contains(faults::NON_FINITE), "a single CRC-valid frame cleared the faults: {:?}", r.out.faults);
}

/// After a start from an unknown thermal state (a corrupt record: every
/// node at 60 °C) a clear one second later restored trust at once; the
/// estimate needs hours to forget its start. The clear must not restore
/// trust before then.
#[test]
fn a_clear_does_not_restore_trust_faster_than_the_estimate_recovers() {
    let mut b = board();
    let mut torn = ThermalRecord::new([40.0; 6], 20.0, 0, 0, 1).with_seq(1, false);
    torn.crc ^= 1;
    b.records = [torn, torn];
    let mut app = boot(&mut b);
    let r = settle(&mut app, &mut b, 0, 150, &[]);
    assert!(r.out.faults.contains(faults::UNTRUSTED | faults::MEMORY_CORRUPT), "{:?}", r.out.faults);
    assert!(app.guard.clear_faults() != crate::ClearResult::Cleared || app.guard.faults().contains(faults::UNTRUSTED), "trust restored 1.5 s after an unknown start");
}

/// A refill with the valve open or the guard in alarm undid the empty-tank
/// and corrupt-boot rules: refused.
#[test]
fn a_refill_while_the_valve_is_open_is_refused() {
    let mut b = board();
    let mut torn = ThermalRecord::new([40.0; 6], 20.0, 0, 0, 1).with_seq(1, false);
    torn.crc ^= 1;
    b.records = [torn, torn];
    let mut app = boot(&mut b);
    let r = settle(&mut app, &mut b, 0, 50, &[]);
    assert!(r.out.valve_open && r.out.alarm && r.out.lng_remaining_kg == 0.0, "{:?}", r.out);
    let refill = crate::protocol::frame(&[wire::KIND_COMMAND, 8, 0, 2], false);
    let r = settle(&mut app, &mut b, 50, 5, &[&refill]);
    assert_eq!(r.out.lng_remaining_kg, 0.0, "refilled with the valve open and the alarm on");
    // armed and keyed: refused by the rule
    let a = super::tests::arm_confirm(&mut app, &mut b, 9, wire::Cmd::RefillArm, wire::Cmd::RefillConfirm, 55, &super::tests::at_rest(0, 0.0, 5.0));
    assert_eq!((a.result, a.value), (wire::AckResult::Refused, wire::Refusal::Rule as u32), "{a:?}");
    assert_eq!(app.guard.output().lng_remaining_kg, 0.0);
}

/// Arm-then-confirm: a wrong key, a confirmation after the arm's window, a
/// confirmation of the other command and a second clear within the
/// interval are refused, each with its reason in the ack and in the trace.
#[test]
fn armed_commands_need_the_key_the_window_and_the_interval() {
    use super::tests::arm_confirm;
    use wire::{Ack, AckResult, Cmd, Command, FromGuard, Refusal};
    let mut b = board();
    let mut app = boot(&mut b);
    let rest = |k: u16| super::tests::at_rest(k, 0.0, 5.0);
    settle(&mut app, &mut b, 0, 200, &[]);
    let ack = |b: &mut MemBoard, token: u16| -> Ack {
        replies(b).iter().find_map(|f| match f {
            FromGuard::Ack(a) if a.token == token => Some(*a),
            _ => None,
        }).expect("an ack")
    };
    let arm = |app: &mut App, b: &mut MemBoard, token: u16, cmd: Cmd, seq: u16| -> u32 {
        b.push_rx(&Command { token, cmd, arg: 0 }.encode());
        b.push_rx(&rest(seq).encode());
        app.tick(&mut *b, 0);
        ack(b, token).value
    };
    let confirm = |app: &mut App, b: &mut MemBoard, token: u16, cmd: Cmd, arg: u32, seq: u16| -> Ack {
        b.push_rx(&Command { token, cmd, arg }.encode());
        b.push_rx(&rest(seq).encode());
        app.tick(&mut *b, 0);
        ack(b, token)
    };
    let refused = |a: Ack, r: Refusal| a.result == AckResult::Refused && a.value == r as u32;
    // no arm
    let a = confirm(&mut app, &mut b, 1, Cmd::ClearConfirm, 0, 200);
    assert!(refused(a, Refusal::NotArmed), "{a:?}");
    // a wrong key (the key of another nonce); the arm is used up
    let n = arm(&mut app, &mut b, 2, Cmd::ClearArm, 201);
    let a = confirm(&mut app, &mut b, 3, Cmd::ClearConfirm, wire::command_key(&[0; 16], n ^ 2, Cmd::ClearConfirm), 202);
    assert!(refused(a, Refusal::Key), "{a:?}");
    let a = confirm(&mut app, &mut b, 4, Cmd::ClearConfirm, wire::command_key(&[0; 16], n, Cmd::ClearConfirm), 203);
    assert!(refused(a, Refusal::NotArmed), "one try per arm: {a:?}");
    // the key of another rig
    let n = arm(&mut app, &mut b, 5, Cmd::ClearArm, 204);
    let a = confirm(&mut app, &mut b, 6, Cmd::ClearConfirm, wire::command_key(&[1; 16], n, Cmd::ClearConfirm), 205);
    assert!(refused(a, Refusal::Key), "{a:?}");
    // a refill confirmed on a clear's arm
    let n = arm(&mut app, &mut b, 7, Cmd::ClearArm, 206);
    let a = confirm(&mut app, &mut b, 8, Cmd::RefillConfirm, wire::command_key(&[0; 16], n, Cmd::RefillConfirm), 207);
    assert!(refused(a, Refusal::NotArmed), "{a:?}");
    // the window: 1 s
    let n = arm(&mut app, &mut b, 9, Cmd::ClearArm, 208);
    settle(&mut app, &mut b, 209, 101, &[]);
    let a = confirm(&mut app, &mut b, 10, Cmd::ClearConfirm, wire::command_key(&[0; 16], n, Cmd::ClearConfirm), 310);
    assert!(refused(a, Refusal::NotArmed), "{a:?}");
    // done, then a second one within 10 s is refused, after 10 s done
    let a = arm_confirm(&mut app, &mut b, 11, Cmd::ClearArm, Cmd::ClearConfirm, 311, &rest(0));
    assert_eq!(a.result, AckResult::Done, "{a:?}");
    let a = arm_confirm(&mut app, &mut b, 13, Cmd::ClearArm, Cmd::ClearConfirm, 313, &rest(0));
    assert!(refused(a, Refusal::TooSoon), "{a:?}");
    settle(&mut app, &mut b, 315, 1000, &[]);
    let a = arm_confirm(&mut app, &mut b, 15, Cmd::ClearArm, Cmd::ClearConfirm, 1315, &rest(0));
    assert_eq!(a.result, AckResult::Done, "{a:?}");
    // every one is in the trace (code, result)
    let t: std::vec::Vec<(u8, u8)> = app.guard.trace().iter().filter_map(|e| match *e {
        crate::trace::Trace::Command { code, result, .. } => Some((code, result)),
        _ => None,
    }).collect();
    let (k, na, too) = (Refusal::Key as u8, Refusal::NotArmed as u8, Refusal::TooSoon as u8);
    assert_eq!(t, [(5, na), (1, 0), (5, k), (5, na), (1, 0), (5, k), (1, 0), (6, na), (1, 0), (5, na), (1, 0), (5, 0), (1, 0), (5, too), (1, 0), (5, 0)]);
}

/// A clear cannot be a self-resetting latch: a controller confirming a
/// clear every tick clears at most once per 10 s.
#[test]
fn a_controller_clearing_in_a_loop_clears_at_most_every_ten_seconds() {
    use wire::{AckResult, Cmd, Command, FromGuard};
    let mut b = board();
    let mut app = boot(&mut b);
    let (mut done, mut rule) = (0u32, 0u32);
    let mut nonce = None;
    for k in 0..3000u16 {
        // arm and confirm on alternate ticks, the right key every time
        let c = match nonce.take() {
            Some(n) => Command { token: k, cmd: Cmd::ClearConfirm, arg: wire::command_key(&[0; 16], n, Cmd::ClearConfirm) },
            None => Command { token: k, cmd: Cmd::ClearArm, arg: 0 },
        };
        b.push_rx(&c.encode());
        b.push_rx(&super::tests::at_rest(k, 0.0, 5.0).encode());
        app.tick(&mut *b, 0);
        for f in replies(&mut b) {
            if let FromGuard::Ack(a) = f {
                match (a.cmd, a.result) {
                    (Cmd::ClearArm, AckResult::Done) => nonce = Some(a.value),
                    (Cmd::ClearConfirm, AckResult::Done) => done += 1,
                    (Cmd::ClearConfirm, AckResult::Refused) if a.value == wire::Refusal::Rule as u32 => rule += 1,
                    _ => {}
                }
            }
        }
    }
    // at ticks 1 (the clear rule's 1 s of valid samples not yet there),
    // 1001 and 2001
    assert_eq!((rule, done), (1, 2), "30 s of clears every 20 ms");
}

/// A flash erase stalls the core (the STM32F411: up to 4 s per 128 KiB
/// sector). The periods it swallowed were replayed as missing ticks, so an
/// erase latched STALE (valve open, alarm until a clear) about once per
/// 1 950 writes. They are now blind ticks: the last inputs held, no credit,
/// no STALE. Simulated here: 300 periods (3 s) per 1 KiB page erase of the
/// in-memory store, a Case 1 run at 60 bar that writes the record often.
#[test]
fn a_flash_erase_stall_is_accounted_without_stale() {
    let mut b = Box::new(MemBoard::new().with_nv());
    // fill the store until it has wrapped once: from here on, every page
    // it opens must be erased first
    let mut n = 0u32;
    while b.flash_erases() == 0 && n < 10_000 {
        let r = ThermalRecord::new([20.0; 6], 20.0, 0, 0, n).with_seq(n, false);
        b.nv.as_mut().map(|s| s.save(&r));
        n += 1;
    }
    assert!(b.flash_erases() > 0, "the store wrapped after {n} writes");
    b.erase_stall_ticks = 300;
    let mut app = boot(&mut b);
    let mut seen = b.ticks;
    let (mut open, mut worst, mut stalls, mut oil_c) = (false, crate::Faults::NONE, 0u32, 20.0f32);
    let erases0 = b.flash_erases();
    for k in 0..60_000u32 {
        let r = Request {
            seq: (k & 0xFFFF) as u16,
            sample: crate::Sample { current_a: current_a(65.0, 5.0, 500.0, oil_c), p_a_bar: 65.0, p_b_bar: 5.0, speed_rpm: 500.0, position_mm: 0.0, ambient_c: 20.0 },
            reports: crate::Reports { valve_fb: Some(open), elec_hz: None, lng_supply_bar: None },
        };
        b.push_rx(&r.encode());
        let before = b.ticks;
        app.run_once(&mut *b, &mut seen);
        stalls += u32::from(b.ticks.wrapping_sub(before) > 1);
        if let Some(t) = ticks_of(&mut b).last() {
            open = t.out.valve_open;
            oil_c = t.out.drain_c;
            worst |= t.out.faults;
        }
    }
    let erased = b.flash_erases() - erases0;
    assert!(erased >= 1 && stalls >= 1, "{erased} erases, {stalls} stalls");
    assert!(!worst.intersects(faults::STALE | faults::LATCHED), "an erase stall latched {worst:?}");
    let st = app.status(&*b, 0);
    assert!(st.counters.overruns >= 300 * erased, "the stalls are counted as overruns: {}", st.counters.overruns);
}
