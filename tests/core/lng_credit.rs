//! The LNG exchanger's cooling credit: only when the cooling is real
//! (issue "No silent protection failure", item 2).

use eha_guard::model::{Model, ModelInputN, HBAR_PER_BAR, HRADS_PER_RPM};
use eha_guard::num::{Fx, Num};
use eha_guard::params::{DEFAULT, N_TABLE, TICKS_PER_STEP};

/// Flow at the LNG table's second point, L/s: `q_max / (N_TABLE - 1)^2` =
/// 1.98e-3 L/s, the pump's geometric flow at 6.2 rpm.
fn q1_lps() -> f64 {
    DEFAULT.flow_table_max_m3_per_s * 1e3 / ((N_TABLE - 1) * (N_TABLE - 1)) as f64
}

fn input<N: Num>(p_a_bar: f64, rpm: f64) -> ModelInputN<N> {
    let f = N::from_f64;
    ModelInputN {
        current_ha: N::ZERO,
        p_a_hbar: f(p_a_bar * HBAR_PER_BAR),
        p_b_hbar: f(5.0 * HBAR_PER_BAR),
        speed_hrads: f(rpm * HRADS_PER_RPM),
        dpos_mm: N::ZERO,
        ambient_c: f(20.0),
    }
}

/// Model at the state of the reference LNG run just before its pump stops (drain 38.7,
/// loop 19.8 degC, exchanger open), 10 s at 60 bar / 500 rpm with the exchanger open,
/// then the pump stopped with the ports decaying from 30 to 5 bar over 3 s (as the
/// reference's do) and the exchanger still commanded open. Returns, per model step
/// after the stop: (pump flow L/s, LNG credit kW, links, nodes).
fn stop_with_valve_open<N: Num>() -> Vec<(f64, f64, [f64; 3], [f64; 6])> {
    let mut m = Model::<N>::new(&DEFAULT).expect("model");
    m.set_temperatures(&[18.1, 38.7, 19.8, 17.2, 16.7, 16.0], 20.0);
    for _ in 0..100 {
        m.step(&input::<N>(65.0, 500.0), true);
    }
    let mut out = vec![];
    for s in 0..100u32 {
        let t = s as f64 * TICKS_PER_STEP as f64 * 0.01;
        let p = 5.0 + 25.0 * (-t / 1.0).exp();
        m.step(&input::<N>(p, 0.0), true);
        let q = DEFAULT.k_leak_m3_per_s_pa * (p - 5.0) * 1e5 * 1e3;
        let f = |x: &[N]| x.iter().map(|v| v.to_f64()).collect::<Vec<_>>();
        let l = f(&m.links_c());
        let n = f(&m.temperatures_c());
        out.push((q, m.last_lng_kw().to_f64(), [l[0], l[1], l[2]], [n[0], n[1], n[2], n[3], n[4], n[5]]));
    }
    out
}

#[test]
fn stopped_pump_gets_no_exchanger_credit_and_keeps_its_links_physical() {
    // With the pump stopped the only oil through the exchanger is the ports'
    // leakage (≤ 8e-4 L/s, below the table's second point 1.98e-3 L/s). Before: the
    // table's first interval (linear in sqrt(q)) credited 0.38 kW to a stream carrying
    // about 1 W/K, the quasi-steady links went to -280 degC (120 K below the LNG
    // itself) and the case oil, fed by that leakage, fell 0.7 K below the reference
    // within 3 s (closed-loop LNG run with the pump stopped at 300 s,
    // `host-tests/tests/firmware`). Now: no credit below the second table point (hot
    // side: the few watts the real exchanger takes from a stream that slow are not
    // credited), and no link is colder than the LNG inlet.
    for (name, run) in [("f64", stop_with_valve_open::<f64>()), ("f32", stop_with_valve_open::<f32>()), ("Fx", stop_with_valve_open::<Fx>())] {
        for (s, (q, lng, links, _)) in run.iter().enumerate() {
            assert!(*q < q1_lps(), "{name} step {s}: leakage {q} L/s not below the table's second point {}", q1_lps());
            assert_eq!(*lng, 0.0, "{name} step {s}: {lng} kW credited with the pump stopped");
            for l in links {
                assert!(*l >= DEFAULT.lng_inlet_c, "{name} step {s}: link {l} degC colder than the LNG inlet {} degC", DEFAULT.lng_inlet_c);
            }
        }
    }
}

use eha_guard::protection::{LngBudget, LngConfig};
use eha_guard::trace::Trace;
use eha_guard::{faults, GuardConfig, GuardOf, Output, Restore, Sample, ThermalRecord};

/// Case 1 at 60 bar, 500 rpm, with the motor current of the loss model (1.5
/// hydraulic torque / 0.75 N m/A); 20 degC air.
fn load() -> Sample {
    Sample { current_a: crate::plant::motor_current(65.0, 5.0, 500.0), p_a_bar: 65.0, p_b_bar: 5.0, speed_rpm: 500.0, position_mm: 0.0, ambient_c: 20.0 }
}

/// Warm restore at 45 degC (the valve opens at the first sample), `used_cj` of the
/// LNG charge already used.
fn warm45(cfg: &GuardConfig, used_cj: u32) -> GuardOf<f32> {
    let rec = ThermalRecord::new([45.0; eha_guard::params::N_NODES], 20.0, used_cj, 0, 1);
    GuardOf::<f32>::new(cfg, Restore::from_record(&rec))
}

/// LNG credit of the model step that ended at this tick, kW (None between steps).
fn credit_kw(g: &GuardOf<f32>) -> Option<f32> {
    let m = g.model().unwrap();
    (m.pending_ticks() == 0).then(|| m.last_lng_kw())
}

#[test]
fn no_credit_while_the_lng_budget_is_empty() {
    // Before: the model credited the exchanger whenever the valve was commanded
    // open, also with the LNG used up. Here the charge is 0.001 L (0.43 g, 443 J):
    // at the 60 bar load (1.7 kW of losses booked while open) it is used up in the
    // first 0.3 s. From the model step after the one that emptied it the credit is
    // exactly 0; before, it stayed at about 3.2 kW ("tick 39: 3.1659641 kW credited,
    // LNG empty since tick 29").
    let cfg = GuardConfig { lng: LngConfig { charge_l: 0.001, ..LngConfig::DEFAULT }, ..GuardConfig::DEFAULT };
    let mut g = warm45(&cfg, 0);
    let mut empty_since = None;
    let mut first_credit = None;
    for k in 0..3000u32 {
        g.valve_feedback(g.output().valve_open);
        let o = g.tick(&load());
        crate::plant::follow(&g);
        assert!(o.valve_open, "tick {k}: {o:?}");
        if let Some(c) = credit_kw(&g) {
            first_credit.get_or_insert(c);
            if let Some(k0) = empty_since {
                assert_eq!(c, 0.0, "tick {k}: {c} kW credited, LNG empty since tick {k0}");
            }
            if o.lng_remaining_kg == 0.0 && empty_since.is_none() {
                empty_since = Some(k);
            }
        }
    }
    let k0 = empty_since.expect("the 0.43 g charge must run out");
    println!("first step's credit {:?} kW; LNG empty at tick {k0}", first_credit);
    assert!(first_credit.unwrap() > 1.0, "the exchanger is credited while LNG is left");
    assert!(k0 < 100, "emptied at tick {k0}");
    // A warm restore with the budget already used up never credits it; a refill
    // (new charge) brings the credit back at the next model step.
    // (More than the 2.2e8 cJ of the default charge.)
    let mut g = warm45(&GuardConfig::DEFAULT, u32::MAX);
    assert!(LngBudget::new(&LngConfig::DEFAULT).remaining_j() < u32::MAX as f32 * 0.01);
    for k in 0..500u32 {
        g.valve_feedback(g.output().valve_open);
        g.tick(&load());
        crate::plant::follow(&g);
        if let Some(c) = credit_kw(&g) {
            assert_eq!(c, 0.0, "tick {k}: credited with the LNG used up");
        }
    }
    g.refill_lng(&LngConfig::DEFAULT);
    for _ in 0..10 {
        g.valve_feedback(g.output().valve_open);
        g.tick(&load());
        crate::plant::follow(&g);
    }
    assert!(credit_kw(&g).unwrap() > 1.0);
}

/// Runs `ticks` ticks of the load, reporting `fb(k, commanded_before)` as the valve
/// position before each tick (None: no report). Returns the outputs.
fn with_feedback(g: &mut GuardOf<f32>, ticks: u32, fb: impl Fn(u32, bool) -> Option<bool>) -> Vec<Output> {
    let mut out = vec![];
    let mut commanded = g.output().valve_open;
    for k in 0..ticks {
        if let Some(v) = fb(k, commanded) {
            g.valve_feedback(v);
        }
        let o = g.tick(&load());
        crate::plant::follow(g);
        commanded = o.valve_open;
        out.push(o);
    }
    out
}

#[test]
fn valve_reported_shut_while_commanded_open_gets_no_credit_and_latches_actuator_after_the_mismatch_time() {
    // Commanded open (45 degC), the position feedback says shut (a valve stuck shut).
    // No credit from the first report on; after 0.5 s (actuator_mismatch_ticks = 50
    // reports) ACTUATOR latches, the valve stays commanded open. Before: the credit
    // stayed ("tick 9: 3.1571724 kW credited with the valve reported shut") and
    // nothing latched.
    let cfg = GuardConfig::DEFAULT;
    assert_eq!(cfg.actuator_mismatch_ticks, 50);
    let mut g = warm45(&cfg, 0);
    let mut latched_at = None;
    for k in 0..400u32 {
        g.valve_feedback(false);
        let o = g.tick(&load());
        crate::plant::follow(&g);
        assert!(o.valve_open, "tick {k}: {o:?}");
        if let Some(c) = credit_kw(&g) {
            assert_eq!(c, 0.0, "tick {k}: {c} kW credited with the valve reported shut");
        }
        if o.faults.intersects(faults::ACTUATOR) && latched_at.is_none() {
            latched_at = Some(k);
        }
    }
    // Reports at ticks 0..: the 50th mismatching one is at tick 49.
    assert_eq!(latched_at, Some(49));
    assert!(g.trace().iter().any(|e| matches!(e, Trace::Fault { tick: 49, new_bits } if *new_bits == faults::ACTUATOR)));
}

#[test]
fn valve_reported_open_while_commanded_shut_latches_actuator_and_forces_it_open() {
    // Cold start at 20 degC: commanded shut; the feedback says open (stuck open). The
    // exchanger is running but not credited (hot side); after 0.5 s ACTUATOR latches and
    // the valve is commanded open (fail-safe), which then matches the feedback.
    let mut g = GuardOf::<f32>::new(&GuardConfig::DEFAULT, Restore::Cold);
    let out = with_feedback(&mut g, 400, |k, _| (k > 0).then_some(true));
    let k = out.iter().position(|o| o.faults.intersects(faults::ACTUATOR)).expect("ACTUATOR must latch");
    assert_eq!(k, 50, "latched at tick {k}");
    assert!(out[..50].iter().all(|o| !o.valve_open));
    assert!(out[50..].iter().all(|o| o.valve_open && o.faults.intersects(faults::ACTUATOR)));
}

#[test]
fn matching_feedback_raises_nothing_and_leaves_the_estimate_unchanged() {
    // A valve that follows its command one tick late (the plant applies the command
    // during the next tick): no fault over an hour of the 60 bar load with the valve
    // cycling (the LNG runs out after 2467 s); the estimate equals that of a guard
    // whose report starts one tick earlier (measured: identical; bound 0.01 K, about
    // the loop-oil effect of one tick of credit, 30 J into 2.8 kJ/K). (Without any
    // report there is no credit: `product::safety_tests`.)
    let cfg = GuardConfig::DEFAULT;
    let mut a = GuardOf::<f32>::new(&cfg, Restore::Cold);
    let mut b = GuardOf::<f32>::new(&cfg, Restore::Cold);
    let oa = with_feedback(&mut a, 360_000, |k, c| (k > 0).then_some(c));
    let ob = with_feedback(&mut b, 360_000, |_, c| Some(c));
    let events = oa.windows(2).filter(|w| w[0].valve_open != w[1].valve_open).count();
    let worst = oa.iter().zip(&ob).map(|(x, y)| (x.drain_c - y.drain_c).abs()).fold(0.0f32, f32::max);
    let empty = oa.iter().position(|o| o.lng_remaining_kg == 0.0).map(|k| k as f64 * 0.01);
    println!("{events} valve events; LNG used up at {empty:?} s; max |estimate with feedback - without| {worst:.2e} K");
    assert!(events >= 4, "the valve must cycle: {events} events");
    assert!(oa.iter().all(|o| !o.faults.intersects(faults::LATCHED)));
    assert!(worst < 0.01, "{worst} K");
}

#[test]
fn mismatch_time_is_configurable() {
    let cfg = GuardConfig { actuator_mismatch_ticks: 50, ..GuardConfig::DEFAULT };
    let mut g = GuardOf::<f32>::new(&cfg, Restore::Cold);
    let out = with_feedback(&mut g, 100, |k, _| (k > 0).then_some(true));
    assert_eq!(out.iter().position(|o| o.faults.intersects(faults::ACTUATOR)), Some(50));
}
