//! Unknown thermal state (issue "No silent protection failure", item 4): when the
//! estimate cannot be trusted — a corrupt thermal record at boot (every node set
//! to the 60 degC alarm temperature), or no sample by the start-up timeout — the
//! alarm and the derate request are raised at once and held, whatever the
//! estimate says, until a successful controller clear (`clear_faults`: the last
//! 1 s of samples valid). The model would need far longer to forget a wrong
//! initial state: a 40 K error of every node still moves the drain estimate by
//! more than 0.5 K after 20 000 s of valid samples (docs/firmware.md).
//! The live status bit `faults::UNTRUSTED` says why the alarm is on.

use eha_guard::memory::RecordStatus;
use eha_guard::num::{Fx, Num};
use eha_guard::trace::Trace;
use eha_guard::{faults, GuardConfig, GuardOf, Output, Restore, Sample, ThermalRecord};

/// Pump turning, little load (the consistent motor current), 20 degC air.
fn idle() -> Sample {
    Sample { current_a: crate::plant::motor_current(10.0, 5.0, 500.0), p_a_bar: 10.0, p_b_bar: 5.0, speed_rpm: 500.0, position_mm: 0.0, ambient_c: 20.0 }
}

fn corrupt_record() -> ThermalRecord {
    let mut r = ThermalRecord::new([40.0; eha_guard::params::N_NODES], 20.0, 0, 0, 7);
    r.crc ^= 1;
    assert_eq!(r.classify(), RecordStatus::Corrupt);
    r
}

fn held(o: &Output) -> bool {
    o.alarm && o.derate && o.faults.intersects(faults::UNTRUSTED)
}

#[test]
fn corrupt_record_raises_alarm_and_derate_until_a_clear() {
    // Before: every node at exactly 60 degC and the alarm fires only above 60 degC:
    // no alarm, no derate at boot ("at boot: Output { drain_c: 60.0, .. alarm:
    // false, derate: false, faults: 16 ..}").
    fn run<N: Num>(name: &str) {
        let cfg = GuardConfig::DEFAULT;
        let mut g = GuardOf::<N>::new(&cfg, Restore::from_record(&corrupt_record()));
        // The same temperatures from a valid record: a trusted estimate, whose alarm
        // follows the 60/58 degC relay.
        let rec = ThermalRecord::new([60.0; eha_guard::params::N_NODES], 60.0, 0, 0, 7);
        let mut trusted = GuardOf::<N>::new(&cfg, Restore::from_record(&rec));
        let o = g.output();
        assert!(held(&o) && o.valve_open && o.faults.intersects(faults::MEMORY_CORRUPT), "at boot: {o:?}");
        assert!(!trusted.output().alarm, "60.0 degC is not above the alarm threshold");
        assert!(g.trace().iter().any(|e| matches!(e, Trace::Alarm { tick: 0, .. })));
        // 10 minutes of light load: held at every tick, whatever the estimate does.
        let mut o = o;
        let mut trusted_off = 0;
        for k in 0..60_000 {
            o = g.tick(&idle());
            crate::plant::follow(&g);
            assert!(held(&o), "tick {k}: {o:?}");
            trusted_off += u32::from(!trusted.tick(&idle()).alarm);
        }
        println!("{name}: estimate {} degC after 10 min; the trusted twin's alarm was off for {trusted_off} ticks", o.drain_c);
        // The controller clear (1 s of valid samples behind it) restores trust; with a
        // new LNG charge (the corrupt record took it as used up) the open exchanger
        // cools the drain and the alarm follows the estimate again: cleared at the
        // first model step below 58 degC.
        assert!(g.clear_faults());
        let o = g.output();
        assert!(!o.faults.intersects(faults::UNTRUSTED | faults::MEMORY_CORRUPT), "{o:?}");
        g.refill_lng(&eha_guard::protection::LngConfig::DEFAULT);
        let th = N::from_f64(cfg.alarm.clear_c as f64);
        let mut cleared = false;
        for k in 0..60_000u32 {
            let o = g.tick(&idle());
            crate::plant::follow(&g);
            let m = g.model().unwrap();
            if m.pending_ticks() == 0 {
                // The relay on the estimate (it was on at the clear: off only below 58).
                if m.drain_c() < th {
                    assert!(!o.alarm, "tick {k}: {o:?}");
                    cleared = true;
                    break;
                }
                assert!(o.alarm, "tick {k}: {o:?}");
            }
        }
        assert!(cleared, "the exchanger must cool the drain below 58 degC");
        assert!(g.trace().iter().any(|e| matches!(e, Trace::AlarmClear { .. })));
    }
    run::<f32>("f32");
    run::<Fx>("Fx");
    run::<f64>("f64");
}

#[test]
fn a_rejected_clear_keeps_the_alarm() {
    let mut g = GuardOf::<f32>::new(&GuardConfig::DEFAULT, Restore::from_record(&corrupt_record()));
    for _ in 0..50 {
        g.tick(&idle());
        crate::plant::follow(&g);
    }
    // 50 valid samples < clear_valid_ticks (100): the clear is refused.
    assert!(!g.clear_faults());
    assert!(held(&g.tick(&idle())));
}

#[test]
fn no_sample_by_the_startup_timeout_raises_alarm_and_derate() {
    // No estimate exists: the alarm and the derate request come with STALE at the
    // start-up timeout and stay after samples arrive, until a clear.
    let cfg = GuardConfig::DEFAULT;
    let mut g = GuardOf::<f32>::new(&cfg, Restore::Cold);
    for k in 0..cfg.startup_timeout_ticks {
        let o = g.tick_missing();
        assert_eq!(held(&o), k + 1 == cfg.startup_timeout_ticks, "tick {k}: {o:?}");
    }
    for k in 0..200 {
        let o = g.tick(&idle());
        crate::plant::follow(&g);
        assert!(held(&o) && o.faults.intersects(faults::STALE), "tick {k}: {o:?}");
    }
    assert!(g.clear_faults());
    assert!(!g.output().faults.intersects(faults::UNTRUSTED));
}

#[test]
fn untrusted_survives_a_warm_reset() {
    // The record saved while untrusted carries the status, so a warm reset (watchdog)
    // before the clear does not turn the relaxed 60 degC start into a trusted one.
    let mut g = GuardOf::<f32>::new(&GuardConfig::DEFAULT, Restore::from_record(&corrupt_record()));
    for _ in 0..1000 {
        g.tick(&idle());
        crate::plant::follow(&g);
    }
    let rec = g.snapshot();
    assert_eq!(rec.classify(), RecordStatus::Valid);
    let mut g2 = GuardOf::<f32>::new(&GuardConfig::DEFAULT, Restore::from_record(&rec));
    assert!(held(&g2.output()), "{:?}", g2.output());
    assert!(held(&g2.tick(&idle())));
    // A normal warm record is trusted.
    let rec = ThermalRecord::new([30.0; eha_guard::params::N_NODES], 20.0, 0, 0, 1);
    let g3 = GuardOf::<f32>::new(&GuardConfig::DEFAULT, Restore::from_record(&rec));
    assert!(!g3.output().alarm && g3.output().faults.is_empty(), "{:?}", g3.output());
}
