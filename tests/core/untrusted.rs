//! Unknown thermal state (issue "No silent protection failure", item 4): when the
//! estimate cannot be trusted — a corrupt thermal record at boot (every node set
//! to the 60 degC alarm temperature), or no sample by the start-up timeout — the
//! alarm and the derate request are raised at once and held, whatever the
//! estimate says, until a successful controller clear (`clear_faults`: the last
//! 1 s of samples valid). The model would need far longer to forget a wrong
//! initial state: a 40 K error of every node still moves the drain estimate by
//! more than 0.5 K after 20 000 s of valid samples (docs/firmware.md).
//! The live status bit `faults::UNTRUSTED` says why the alarm is on.
//!
//! A clear used to restore trust at once, however new the
//! unknown start; it now clears the latched faults and holds UNTRUSTED until
//! the estimate has run `recovery_ticks` (ln(40 K / 0.5 K) over the slowest
//! rest cooling rate: 56.2 h for the paper rig) since its first sample
//! (status bit RECOVERING).

use eha_guard::memory::RecordStatus;
use eha_guard::num::{Fx, Num};
use eha_guard::trace::Trace;
use eha_guard::{faults, ClearResult, GuardConfig, GuardOf, Output, Restore, Sample, ThermalRecord};

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
        // The controller clear (1 s of valid samples behind it) clears the latched
        // fault; trust is held: the estimate is 10 min into a 56 h recovery.
        let left = g.recovery_left();
        assert_eq!(g.clear_faults(), ClearResult::TrustHeld(left));
        assert!(left > 55 * 360_000 && left < 57 * 360_000, "{left} ticks");
        let o = g.tick(&idle());
        assert!(held(&o) && o.faults.contains(faults::RECOVERING) && !o.faults.intersects(faults::MEMORY_CORRUPT), "{o:?}");
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
    assert_eq!(g.clear_faults(), ClearResult::Refused);
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
    // The machine may have run unseen for those 10 s: an unknown start.
    assert!(matches!(g.clear_faults(), ClearResult::TrustHeld(_)));
    assert!(held(&g.output()) && !g.output().faults.intersects(faults::STALE), "{:?}", g.output());
}

/// The trust hold after an unknown start runs its full length from the
/// first sample (56.2 h of the paper rig's rest cooling): a clear one second
/// before its end holds, one after restores trust, and the alarm follows the
/// estimate again. (20 M guard ticks: about 2 s.)
#[test]
fn trust_returns_when_the_estimate_has_recovered() {
    let cfg = GuardConfig::DEFAULT;
    let hold = eha_guard::guard::recovery_ticks(cfg.model);
    let hours = f64::from(hold) / 360_000.0;
    // 55.86 h with the rest rates of the oil on its viscosity line: ln(80) over the slowest rest rate
    assert!((55.8..56.0).contains(&hours), "{hours} h");
    // ln(40 / 0.5) as the guard's constant
    let ln = (eha_guard::guard::TRUST_START_ERROR_K / eha_guard::guard::TRUST_TOLERANCE_K).ln();
    let min_rate = cfg.model.rest_rate.iter().fold(f32::INFINITY, |m, r| m.min(*r));
    assert!((f64::from(hold) / f64::from(ln / min_rate * 100.0) - 1.0).abs() < 1e-6, "{hold} ticks");
    let mut g = GuardOf::<f32>::new(&cfg, Restore::from_record(&corrupt_record()));
    let rest = Sample { current_a: crate::plant::motor_current(5.0, 5.0, 0.0), speed_rpm: 0.0, p_a_bar: 5.0, ..idle() };
    for _ in 1..hold - 100 {
        g.valve_feedback(g.output().valve_open);
        g.tick(&rest);
    }
    assert_eq!(g.clear_faults(), ClearResult::TrustHeld(101));
    // (the status bits refresh at the model steps, every 10 ticks)
    for _ in 0..110 {
        g.valve_feedback(g.output().valve_open);
        g.tick(&rest);
    }
    assert!(!g.output().faults.intersects(faults::RECOVERING), "{:?}", g.output());
    assert!(held(&g.output()), "held until a clear");
    assert_eq!(g.clear_faults(), ClearResult::Cleared);
    let mut o = g.output();
    for _ in 0..10 {
        o = g.tick(&rest);
    }
    // 56 h at rest: the estimate is at the air; the relay follows it.
    assert!(!o.alarm && !o.derate && !o.faults.intersects(faults::UNTRUSTED | faults::RECOVERING | faults::LATCHED), "{o:?}");
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

/// After samples have started, 5 missing samples latch STALE: the valve
/// opens and the alarm and the derate are raised at once and held until a
/// clear (docs/firmware.md's fault table). Before, STALE after the start
/// raised no alarm.
#[test]
fn stale_after_the_start_raises_the_alarm_at_once() {
    let cfg = GuardConfig::DEFAULT;
    let mut g = GuardOf::<f32>::new(&cfg, Restore::Cold);
    for _ in 0..200 {
        g.tick(&idle());
    }
    assert!(!g.output().alarm);
    let mut o = g.output();
    for _ in 0..cfg.stale_ticks {
        o = g.tick_missing();
    }
    assert!(o.faults.contains(faults::STALE) && o.valve_open && o.alarm && o.derate, "{o:?}");
    for k in 0..300 {
        let o = g.tick(&idle());
        assert!(o.alarm && o.derate && o.valve_open, "held until a clear, tick {k}: {o:?}");
    }
    // the estimate ran on the worst case: a clear restores trust at once
    assert_eq!(g.clear_faults(), ClearResult::Cleared);
}
