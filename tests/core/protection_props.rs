//! Property tests of the protection layer: no panics / finite outputs for
//! arbitrary input sequences, same-step fail-safe, stale input, valve
//! hysteresis and dwell under noise, latching and the clear rule; the sample
//! and comparison helpers the other protection tests share. The unlatched
//! path under injected faults is in `faulted_runs`, the thermal record in
//! `records`, worked cases in `protection_cases`.

use eha_guard::faults;
use eha_guard::memory::Restore;
use eha_guard::num::Fx;
use eha_guard::protection::{Valve, ValveConfig};
use eha_guard::{GuardConfig, GuardOf, Output, Sample};
use proptest::prelude::*;

/// Case 1 at 60 bar, 500 rpm, the motor current consistent with it (36.2 A; was
/// 30 A, which the sensor cross-check now reports as SENSOR_DISAGREE).
pub(crate) fn nominal() -> Sample {
    Sample {
        current_a: crate::plant::motor_current(65.0, 5.0, 500.0),
        p_a_bar: 65.0,
        p_b_bar: 5.0,
        speed_rpm: 500.0,
        position_mm: 0.0,
        ambient_c: 16.0,
    }
}

/// One unit in the last place of `x` (the spacing above |x|): the regression bound
/// of comparisons that measure exactly 0.
pub(crate) fn ulp32(x: f32) -> f32 {
    f32::from_bits(x.abs().to_bits() + 1) - x.abs()
}

/// Every float output finite.
pub(crate) fn finite(o: &Output) -> bool {
    o.drain_c.is_finite() && o.lng_remaining_kg.is_finite() && o.lng_seconds_left.is_finite()
}

/// Any f32, with the special values strongly represented.
fn any_f32() -> impl Strategy<Value = f32> {
    prop_oneof![
        3 => -400.0f32..400.0,
        1 => Just(f32::NAN),
        1 => Just(f32::INFINITY),
        1 => Just(f32::NEG_INFINITY),
        1 => Just(f32::MAX),
        1 => Just(-f32::MAX),
        1 => any::<f32>(),
    ]
}

fn any_sample() -> impl Strategy<Value = Option<Sample>> {
    prop_oneof![
        1 => Just(None),
        8 => (any_f32(), any_f32(), any_f32(), any_f32(), any_f32(), any_f32()).prop_map(|(a, b, c, d, e, f)| Some(Sample {
            current_a: a, p_a_bar: b, p_b_bar: c, speed_rpm: d * 20.0, position_mm: e * 0.1, ambient_c: f * 0.2
        })),
    ]
}

/// Runs an arbitrary sequence: samples or missing ticks, each with an optional
/// valve-position report before it, and now and then a maintenance clear.
fn run_all<N: eha_guard::num::Num>(seq: &[(Option<Sample>, Option<bool>)]) -> Result<(), TestCaseError> {
    let mut g = GuardOf::<N>::new(&GuardConfig::DEFAULT, Restore::Cold);
    for (k, (s, fb)) in seq.iter().enumerate() {
        if let Some(v) = fb {
            g.valve_feedback(*v);
        }
        if k % 97 == 96 {
            let _ = g.clear_faults();
        }
        let o = match s {
            Some(s) => g.tick(s),
            None => g.tick_missing(),
        };
        prop_assert!(finite(&o), "non-finite output {:?}", o);
        prop_assert!(o.lng_remaining_kg >= 0.0 && o.lng_remaining_kg <= 2.1501);
        if o.faults.intersects(faults::LATCHED) {
            prop_assert!(
                o.valve_open,
                "latched fault {:#x} but valve closed",
                o.faults
            );
        }
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 64, ..ProptestConfig::default() })]

    #[test]
    fn arbitrary_inputs_never_panic_and_stay_finite(seq in proptest::collection::vec((any_sample(), proptest::option::of(any::<bool>())), 1..300)) {
        run_all::<f32>(&seq)?;
        run_all::<Fx>(&seq)?;
        run_all::<f64>(&seq)?;
    }

    #[test]
    fn out_of_range_or_non_finite_opens_valve_in_same_step(
        warm in 1usize..50, ch in 0usize..6,
        bad in prop_oneof![Just(f32::NAN), Just(f32::INFINITY), Just(1e6f32), Just(-1e6f32)],
    ) {
        let mut g = GuardOf::<f32>::new(&GuardConfig::DEFAULT, Restore::Cold);
        for _ in 0..warm {
            let o = g.tick(&nominal());
            crate::plant::follow(&g);
            prop_assert!(!o.valve_open && o.faults.is_empty(), "nominal must be quiet: {:?}", o);
        }
        let mut s = nominal();
        match ch {
            0 => s.current_a = bad, 1 => s.p_a_bar = bad, 2 => s.p_b_bar = bad,
            3 => s.speed_rpm = bad, 4 => s.position_mm = bad, _ => s.ambient_c = bad,
        }
        let o = g.tick(&s);
        crate::plant::follow(&g);
        prop_assert!(o.valve_open, "valve must open in the faulting step");
        let class = if bad.is_finite() { faults::RANGE } else { faults::NON_FINITE };
        prop_assert!(o.faults.intersects(class), "fault bits {:#x}", o.faults);
        prop_assert!(o.faults.channel_set().contains(eha_guard::ChannelSet::channel(ch)), "channel bit missing {:#x}", o.faults);
    }

    #[test]
    fn stale_input_opens_valve_when_declared(warm in 1usize..50) {
        let cfg = GuardConfig::DEFAULT;
        let mut g = GuardOf::<f32>::new(&cfg, Restore::Cold);
        for _ in 0..warm {
            g.tick(&nominal());
            crate::plant::follow(&g);
        }
        for k in 1..=cfg.stale_ticks {
            let o = g.tick_missing();
            if k < cfg.stale_ticks {
                prop_assert!(!o.valve_open && !o.faults.intersects(faults::STALE), "not stale yet at {}", k);
            } else {
                prop_assert!(o.valve_open && o.faults.intersects(faults::STALE), "stale at {} must open: {:?}", k, o);
            }
        }
    }

    #[test]
    fn noise_gives_at_most_one_toggle_per_dwell(seed in any::<u64>(), mean in 37.0f32..41.0) {
        // Gaussian noise sigma = 0.5 K (Box-Muller on a 64-bit LCG) around `mean`.
        let cfg = ValveConfig::DEFAULT;
        let mut v = Valve::new();
        let mut x = seed | 1;
        let mut uni = move || { x = x.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407); ((x >> 11) as f64 + 0.5) / (1u64 << 53) as f64 };
        let mut toggles: Vec<usize> = Vec::new();
        for k in 0..20_000 {
            let n = (-2.0 * uni().ln()).sqrt() * (2.0 * std::f64::consts::PI * uni()).cos();
            let t = mean + 0.5 * n as f32;
            if v.update(t, false, &cfg).is_some() {
                toggles.push(k);
            }
        }
        for w in toggles.windows(2) {
            prop_assert!(w[1] - w[0] >= cfg.dwell_ticks as usize, "toggles {} steps apart < dwell {}", w[1] - w[0], cfg.dwell_ticks);
        }
    }

    #[test]
    fn hysteresis_band(ts in proptest::collection::vec(30.0f32..50.0, 1..2000)) {
        // With the dwell at zero the valve state must be exactly the hysteresis relay.
        let cfg = ValveConfig { dwell_ticks: 0, ..ValveConfig::DEFAULT };
        let mut v = Valve::new();
        let mut open = false;
        for t in ts {
            v.update(t, false, &cfg);
            if t > 40.0 { open = true; }
            if t < 38.0 { open = false; }
            prop_assert_eq!(v.is_open(), open, "t = {}", t);
        }
    }

    #[test]
    fn faults_latch_until_explicit_clear(valid_after in 0u32..250) {
        let cfg = GuardConfig::DEFAULT;
        let mut g = GuardOf::<f32>::new(&cfg, Restore::Cold);
        g.tick(&nominal());
        crate::plant::follow(&g);
        let mut s = nominal();
        s.p_a_bar = f32::NAN;
        g.tick(&s);
        crate::plant::follow(&g);
        for _ in 0..valid_after {
            let o = g.tick(&nominal());
            crate::plant::follow(&g);
            prop_assert!(o.valve_open && o.faults.intersects(faults::NON_FINITE), "fault must stay latched");
        }
        let cleared = g.clear_faults().cleared();
        prop_assert_eq!(cleared, valid_after >= cfg.clear_valid_ticks, "clear rule: {} valid steps", valid_after);
        let o = g.tick(&nominal());
        crate::plant::follow(&g);
        prop_assert_eq!(!o.faults.intersects(faults::LATCHED), cleared);
    }
}
