//! The thermal memory: flash records that cannot be read, failed saves,
//! power losses, LNG bookkeeping and flash erase stalls.

use super::*;

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
