//! The commissioning margin on the drain estimate (`drain_margin_k`): the
//! guard adds it to the model's case oil for every decision (valve at 40 °C,
//! alarm at 60 °C) and every report (outputs, trace), and it never feeds back
//! into the model's state or the thermal record.

use eha_guard::model::ModelConsts;
use eha_guard::num::Num;
use eha_guard::model::DEFAULT_CONSTS;
use eha_guard::params::TICKS_PER_STEP;
use eha_guard::trace::Trace;
use eha_guard::{faults, GuardConfig, GuardOf, Restore, Sample};

/// The margin of the test, K.
const MARGIN_K: f32 = 2.5;

/// Where the threshold crossing is located, K: the guard compares
/// `model + margin` with 40 °C in its number type, the test compares the
/// model with 40 − margin; the two differ by the rounding of the sum (one
/// f32 ulp at 40-60 °C is 3.8e-6 K; the fixed-point value step 1.2e-7 K).
/// Below the model's step at the crossings (asserted ≤ 0.02 K and printed),
/// which bounds how far off a threshold can be and pass; far below the 2.5 K
/// a missing or doubled margin would show.
const TOL_K: f64 = 1e-5;

fn sample(p_a: f32, rpm: f32) -> Sample {
    Sample {
        current_a: crate::plant::motor_current(p_a, 5.0, rpm),
        p_a_bar: p_a,
        p_b_bar: 5.0,
        speed_rpm: rpm,
        position_mm: 0.0,
        ambient_c: 20.0,
    }
}

/// The first tick at which `on` holds, checked to be a tick where the case
/// oil `m` has just passed `at` (within [`TOL_K`]), never earlier; with the
/// model's step there, K.
fn first_above(name: &str, what: &str, m: &[f64], on: &[bool], at: f64) -> (usize, f64) {
    let tick = on.iter().position(|x| *x).unwrap_or_else(|| panic!("{name}: {what} never happened"));
    assert!(m[tick] > at - TOL_K, "{name}: {what} at tick {tick} with the model's case oil {} <= {at}", m[tick]);
    if let Some(k) = m[..tick].iter().position(|x| *x > at + TOL_K) {
        panic!("{name}: the model's case oil {} passed {at} at tick {k}, but {what} only at tick {tick}", m[k]);
    }
    let step = m[tick] - m[tick.saturating_sub(TICKS_PER_STEP as usize)];
    (tick, step)
}

#[test]
fn the_margin_moves_every_decision_and_report_by_itself_and_not_the_model() {
    fn run<N: Num>(name: &str) {
        let c0 = DEFAULT_CONSTS;
        let c1 = ModelConsts { drain_margin_k: MARGIN_K, ..DEFAULT_CONSTS };
        let cfg0 = GuardConfig { model: &c0, ..GuardConfig::DEFAULT };
        let cfg1 = GuardConfig { model: &c1, ..GuardConfig::DEFAULT };
        let mut g0 = GuardOf::<N>::new(&cfg0, Restore::Cold);
        let mut g1 = GuardOf::<N>::new(&cfg1, Restore::Cold);
        crate::plant::set_case_oil(20.0);
        // 40 bar at 500 rpm from a cold start (20 °C), ramped over 1 s (rate
        // limits): the case oil passes 37.5 and 40 °C within three minutes,
        // 57.5 and 60 °C after half an hour (with the housing), slowly enough
        // that one model step moves it by at most 0.02 K there. No valve position
        // report: neither guard credits the exchanger, so their models must
        // stay identical whatever their valves do.
        let (mut m, mut open0, mut open1, mut alarm0, mut alarm1) = (vec![], vec![], vec![], vec![], vec![]);
        for k in 0..2_000_000usize {
            let f = (k as f32 / 100.0).min(1.0);
            let s = sample(5.0 + 35.0 * f, 300.0 + 200.0 * f);
            let o0 = g0.tick(&s);
            let o1 = g1.tick(&s);
            crate::plant::follow(&g0);
            assert!(!(o0.faults | o1.faults).intersects(faults::LATCHED), "{name} tick {k}: {o0:?} {o1:?}");
            let (t0, t1) = (g0.model().unwrap().temperatures_c(), g1.model().unwrap().temperatures_c());
            // The margin never feeds back: the same model state, bit for bit,
            // and the same thermal record temperatures.
            assert!(t0.iter().zip(&t1).all(|(a, b)| a.to_f64().to_bits() == b.to_f64().to_bits()), "{name} tick {k}: models differ");
            assert_eq!(g0.snapshot().temps_c, g1.snapshot().temps_c, "{name} tick {k}");
            // The reported estimate is the model's plus the margin (one or two
            // f32 roundings of the sum: 1 ulp at 64 °C is 3.8e-6 K).
            assert!((f64::from(o1.drain_c) - f64::from(o0.drain_c) - f64::from(MARGIN_K)).abs() <= 4e-6, "{name} tick {k}: {} vs {}", o1.drain_c, o0.drain_c);
            m.push(g0.model().unwrap().drain_c().to_f64());
            open0.push(o0.valve_open && k > 0);
            open1.push(o1.valve_open && k > 0);
            alarm0.push(o0.alarm);
            alarm1.push(o1.alarm);
            if o0.alarm {
                break;
            }
        }
        let (v1, s1) = first_above(name, "margin 2.5 K: valve open", &m, &open1, 40.0 - f64::from(MARGIN_K));
        let (v0, s0) = first_above(name, "margin 0: valve open", &m, &open0, 40.0);
        let (a1, s2) = first_above(name, "margin 2.5 K: alarm", &m, &alarm1, 60.0 - f64::from(MARGIN_K));
        let (a0, s3) = first_above(name, "margin 0: alarm", &m, &alarm0, 60.0);
        println!(
            "{name}: valve open at {:.1} s (margin 2.5 K) and {:.1} s (margin 0), alarm at {:.1} s and {:.1} s; the model's step at these {s1:.1e}, {s0:.1e}, {s2:.1e}, {s3:.1e} K",
            v1 as f64 * 0.01,
            v0 as f64 * 0.01,
            a1 as f64 * 0.01,
            a0 as f64 * 0.01
        );
        assert!(v1 < v0 && a1 < a0, "{name}: the margin must make both earlier");
        // The crossings are located to the model's step there: a threshold
        // off by more than that would open or alarm at a step the checks in
        // `first_above` refuse.
        assert!([s1, s0, s2, s3].iter().all(|s| *s <= 0.02), "{name}: the model's steps at the crossings are too coarse to locate them");
        // The trace holds the margin's estimate at the opening.
        let est = g1.trace().iter().find_map(|e| match e {
            Trace::ValveOpen { tick, drain_c, forced: false } if *tick as usize == v1 => Some(*drain_c),
            _ => None,
        });
        let est = est.unwrap_or_else(|| panic!("{name}: no ValveOpen at tick {} in the trace", v1));
        assert!((f64::from(est) - m[v1] - f64::from(MARGIN_K)).abs() <= 4e-6, "{name}: trace {est} vs model {}", m[v1]);
    }
    run::<f32>("f32");
    run::<eha_guard::num::Fx>("Fx");
    run::<f64>("f64");
}

/// A margin below 0 (the cold side), NaN, or above its 10 K bound is refused:
/// CONFIG, valve open, alarm, no estimate; 0 and 10 K are accepted.
#[test]
fn a_negative_nan_or_too_large_margin_is_refused() {
    for (m, ok) in [(0.0, true), (10.0, true), (-1e-6, false), (-2.5, false), (f32::NAN, false), (10.001, false), (f32::INFINITY, false)] {
        let c = ModelConsts { drain_margin_k: m, ..DEFAULT_CONSTS };
        let g = eha_guard::Guard::new(&GuardConfig { model: &c, ..GuardConfig::DEFAULT }, Restore::Cold);
        let o = g.output();
        assert_eq!(!o.faults.contains(faults::CONFIG), ok, "margin {m}: {o:?}");
        if !ok {
            assert!(o.valve_open && o.alarm && o.drain_c == eha_guard::guard::DRAIN_C_UNKNOWN, "margin {m}: {o:?}");
        }
    }
}
