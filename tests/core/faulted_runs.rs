//! The normal (unlatched) path under mostly valid, rate-limited input with
//! injected faults: a generated run of ticks within every channel's range
//! and rate, faults placed in it, the invariants checked at every tick in
//! the three number types.

use eha_guard::faults;
use eha_guard::memory::Restore;
use eha_guard::num::Fx;
use eha_guard::protection::LngBudget;
use eha_guard::validate::InputLimits;
use eha_guard::{GuardConfig, GuardOf, Sample};
use proptest::prelude::*;

use crate::protection_props::finite;

/// One channel of [`InputLimits::DEFAULT`] in wire units: range and per-tick rate.
#[derive(Clone, Copy, Debug)]
struct Chan {
    lo: f32,
    hi: f32,
    rate: f32,
}

/// The six channels in `Sample` order (current, p_A, p_B, speed, position, ambient).
fn channels() -> [Chan; 6] {
    let l = InputLimits::DEFAULT;
    let p = Chan { lo: l.pressure_bar_min, hi: l.pressure_bar_max, rate: l.pressure_bar_per_tick };
    [
        Chan { lo: -l.current_a_max, hi: l.current_a_max, rate: l.current_a_per_tick },
        p,
        p,
        Chan { lo: -l.speed_rpm_max, hi: l.speed_rpm_max, rate: l.speed_rpm_per_tick },
        Chan { lo: l.position_mm_min, hi: l.position_mm_max, rate: l.position_mm_per_tick },
        Chan { lo: l.ambient_c_min, hi: l.ambient_c_max, rate: l.ambient_c_per_tick },
    ]
}

fn to_sample(x: &[f32; 6]) -> Sample {
    let [current_a, p_a_bar, p_b_bar, speed_rpm, position_mm, ambient_c] = *x;
    Sample { current_a, p_a_bar, p_b_bar, speed_rpm, position_mm, ambient_c }
}

/// A fault injected on purpose at one tick of a valid run.
#[derive(Clone, Copy, Debug)]
enum Fault {
    /// This tick's value of channel `ch` is NaN or ±inf (one tick).
    NonFinite { ch: usize, v: f32 },
    /// This tick's value of `ch` lies `excess` × the range width outside the range
    /// (above when `high`), one tick.
    Range { ch: usize, excess: f32, high: bool },
    /// `ch` jumps by `factor` × its rate limit towards the middle of its range and
    /// the run goes on from there (a step change).
    Rate { ch: usize, factor: f32 },
    /// `ticks` ticks without a sample (STALE from `stale_ticks` = 5 on).
    Missing { ticks: u32 },
}

fn fault() -> impl Strategy<Value = Fault> {
    prop_oneof![
        (0usize..6, prop_oneof![Just(f32::NAN), Just(f32::INFINITY), Just(f32::NEG_INFINITY)])
            .prop_map(|(ch, v)| Fault::NonFinite { ch, v }),
        (0usize..6, 0.02f32..1.0, any::<bool>()).prop_map(|(ch, excess, high)| Fault::Range { ch, excess, high }),
        (0usize..6, 1.1f32..2.0).prop_map(|(ch, factor)| Fault::Rate { ch, factor }),
        (1u32..10).prop_map(|ticks| Fault::Missing { ticks }),
    ]
}

/// A mostly valid input run: a start inside every range, then piecewise-linear
/// ramps whose per-tick change is at most 0.9 × the channel's rate limit, reflected
/// at the range (inset by 0.5 % of its width), so every sample is valid and
/// rate-limited with a margin that holds in all three number types; the current
/// follows the pressures and the speed (`plant::motor_current`). On top: in one
/// case of three, 1-3 faults at chosen ticks; in half of the cases a maintenance
/// `clear_faults` every `clear_every` ticks.
#[derive(Clone, Debug)]
struct Run {
    start: [f32; 6],
    /// (ticks, per-channel slope as a fraction of the rate limit, in [-0.9, 0.9]).
    ramps: Vec<(u32, [f32; 6])>,
    /// (position in the run as a fraction of its length, fault).
    faults: Vec<(f64, Fault)>,
    clear_every: Option<u32>,
}

fn valid_run() -> impl Strategy<Value = Run> {
    (
        proptest::array::uniform6(0.0f32..1.0),
        proptest::collection::vec((1u32..250, proptest::array::uniform6(-0.9f32..0.9)), 1..8),
        prop_oneof![2 => Just(vec![]), 1 => proptest::collection::vec((0.0f64..1.0, fault()), 1..4)],
        proptest::option::weighted(0.5, 100u32..400),
    )
        .prop_map(|(u, ramps, faults, clear_every)| {
            let mut start = [0.0f32; 6];
            for ((x, c), u) in start.iter_mut().zip(channels()).zip(u) {
                let m = 0.005 * (c.hi - c.lo);
                *x = c.lo + m + u * (c.hi - c.lo - 2.0 * m);
            }
            Run { start, ramps, faults, clear_every }
        })
}

/// What one tick of a [`Run`] feeds the guard.
#[derive(Clone, Copy, Debug)]
enum Tick {
    Sample(Sample),
    Missing,
}

/// The ticks of a run, each with the fault injected at it (if any).
fn expand(run: &Run) -> Vec<(Tick, Option<Fault>)> {
    let chans = channels();
    let len: u32 = run.ramps.iter().map(|r| r.0).sum();
    let mut at: Vec<(usize, Fault)> =
        run.faults.iter().map(|(f, k)| (((*f * len as f64) as usize).min(len as usize - 1), *k)).collect();
    at.sort_by_key(|a| a.0);
    let mut x = run.start;
    let mut out = Vec::with_capacity(len as usize + 32);
    let mut k = 0usize;
    for (n, slope) in &run.ramps {
        let mut slope = *slope;
        for _ in 0..*n {
            let mut injected = None;
            for (_, f) in at.iter().filter(|a| a.0 == k) {
                injected = Some(*f);
            }
            // Reflecting ramp: |x' - x| <= |slope| rate <= 0.9 rate.
            for ((x, s), c) in x.iter_mut().zip(slope.iter_mut()).zip(chans) {
                let m = 0.005 * (c.hi - c.lo);
                let (lo, hi) = (c.lo + m, c.hi - m);
                let mut y = *x + *s * c.rate;
                if y > hi {
                    y = 2.0 * hi - y;
                    *s = -*s;
                } else if y < lo {
                    y = 2.0 * lo - y;
                    *s = -*s;
                }
                *x = y;
            }
            // The current is not free: a machine with consistent sensors draws the
            // current of its pressures and speed (else the sensor cross-check rightly
            // latches SENSOR_DISAGREE). Per tick it changes by at most 197 A (a 270 bar
            // swing of dp with the speed's sign flipping) against the 200 A rate limit.
            x[0] = crate::plant::motor_current(x[1], x[2], x[3]);
            match injected {
                None => out.push((Tick::Sample(to_sample(&x)), None)),
                Some(f @ Fault::Missing { ticks }) => {
                    out.push((Tick::Missing, Some(f)));
                    out.extend((1..ticks).map(|_| (Tick::Missing, None)));
                }
                Some(f @ Fault::Rate { ch, factor }) => {
                    let c = chans[ch];
                    let dir = if x[ch] > 0.5 * (c.lo + c.hi) { -1.0 } else { 1.0 };
                    x[ch] += dir * factor * c.rate;
                    out.push((Tick::Sample(to_sample(&x)), Some(f)));
                }
                Some(f @ Fault::NonFinite { ch, v }) => {
                    let mut y = x;
                    y[ch] = v;
                    out.push((Tick::Sample(to_sample(&y)), Some(f)));
                }
                Some(f @ Fault::Range { ch, excess, high }) => {
                    let c = chans[ch];
                    let mut y = x;
                    y[ch] = if high { c.hi + excess * (c.hi - c.lo) } else { c.lo - excess * (c.hi - c.lo) };
                    out.push((Tick::Sample(to_sample(&y)), Some(f)));
                }
            }
            k += 1;
        }
    }
    out
}

/// Runs `ticks` through a cold guard in number type `N`, checks the invariants at
/// every tick and returns (ticks without a latched fault, ticks).
fn run_valid<N: eha_guard::num::Num>(ticks: &[(Tick, Option<Fault>)], clear_every: Option<u32>) -> Result<(u64, u64), TestCaseError> {
    let cfg = GuardConfig::DEFAULT;
    let full = LngBudget::new(&cfg.lng).remaining_kg();
    let mut g = GuardOf::<N>::new(&cfg, Restore::Cold);
    let mut unlatched = 0u64;
    // A latched bit is only allowed after a fault that can latch one (non-finite,
    // range, a rate jump, a missing burst reaching `stale_ticks`) since the last
    // successful clear: valid, rate-limited input never latches anything.
    let mut may_latch = false;
    let mut missing_run = 0u32;
    let mut prev_current: Option<f32> = None;
    let mut cold_until = 0usize;
    // the plant's oil starts at the air, as the model does
    if let Some(Tick::Sample(s)) = ticks.iter().map(|t| t.0).find(|t| matches!(t, Tick::Sample(_))) {
        crate::plant::set_case_oil(s.ambient_c);
    }
    for (k, (t, f)) in ticks.iter().enumerate() {
        if let Some(p) = clear_every {
            if k > 0 && (k as u32).is_multiple_of(p) && g.clear_faults().cleared() {
                prop_assert!(!g.faults().intersects(faults::LATCHED), "cleared at tick {}", k);
                may_latch = false;
            }
        }
        let o = match t {
            Tick::Sample(s) => {
                missing_run = 0;
                // a valid sample's current follows the plant's oil (its viscous
                // friction), as the generator's note above says
                let mut s = *s;
                let current_faulted = matches!(f, Some(Fault::NonFinite { ch: 0, .. } | Fault::Range { ch: 0, .. } | Fault::Rate { ch: 0, .. }));
                if !current_faulted {
                    let i = crate::plant::motor_current(s.p_a_bar, s.p_b_bar, s.speed_rpm);
                    // in oil colder than the model's range (the viscous friction held at
                    // its -20 degC value) a fast shaft would need more current than the
                    // sensor reads: the drive limits it, the sensors disagree
                    // (and its change per tick can pass the rate limit when the speed's
                    // sign flips)
                    let max = 0.99 * cfg.limits.current_a_max;
                    let i = i.clamp(-max, max);
                    // (and below the oil's validity the cross-check may disagree: the
                    // plant's laws stop holding there, docs/reduction.md)
                    if crate::plant::case_oil_c() < crate::plant::COLDEST_VALID_C {
                        // the cross-check remembers its windows: inconsistent for as long
                        cold_until = k + (cfg.crosscheck.persist_windows + 1) as usize * cfg.crosscheck.window_ticks as usize;
                    }
                    if k < cold_until || i.abs() >= max || prev_current.is_some_and(|p: f32| (i - p).abs() > cfg.limits.current_a_per_tick) {
                        may_latch = true;
                    }
                    s.current_a = i;
                }
                prev_current = Some(s.current_a).filter(|c| c.is_finite());
                let o = g.tick(&s);
                crate::plant::follow(&g);
                o
            }
            Tick::Missing => {
                missing_run += 1;
                let o = g.tick_missing();
                // a model step can end in the gap: the plant's oil follows it too
                crate::plant::follow(&g);
                o
            }
        };
        match f {
            Some(Fault::NonFinite { ch, .. }) | Some(Fault::Range { ch, .. }) => {
                may_latch = true;
                let class = if matches!(f, Some(Fault::NonFinite { .. })) { faults::NON_FINITE } else { faults::RANGE };
                prop_assert!(o.valve_open && o.faults.intersects(class), "tick {}: {:?} not latched: {:?}", k, f, o);
                prop_assert!(o.faults.channel_set().contains(eha_guard::ChannelSet::channel(*ch)), "tick {}: channel bit of {:?} missing: {:?}", k, f, o);
            }
            Some(Fault::Rate { .. }) => may_latch = true,
            _ => {}
        }
        if missing_run >= cfg.stale_ticks {
            may_latch = true;
        }
        prop_assert!(finite(&o), "tick {}: non-finite output {:?}", k, o);
        prop_assert!(o.lng_remaining_kg >= 0.0 && o.lng_remaining_kg <= full, "tick {}: LNG {}", k, o.lng_remaining_kg);
        prop_assert_eq!(o.alarm, o.derate, "tick {}: derate must follow the alarm", k);
        if o.faults.intersects(faults::LATCHED) {
            prop_assert!(o.valve_open, "tick {}: latched fault {:#x} but valve closed", k, o.faults);
            prop_assert!(may_latch, "tick {}: fault {:#x} latched on valid, rate-limited input", k, o.faults);
        } else {
            unlatched += 1;
        }
    }
    Ok((unlatched, ticks.len() as u64))
}

/// The normal (unlatched) path under mostly valid input, in all three number types:
/// the invariants at every tick, and at least half of all generated ticks must run
/// without a latched fault (the fully arbitrary test above reaches that path on
/// about one sample in 10,000).
#[test]
fn valid_inputs_with_injected_faults_keep_invariants() {
    use std::cell::Cell;
    const CASES: u32 = 256;
    // No failure persistence: a runner outside `proptest!` has no source file to
    // name the regressions file after (proptest would only warn).
    let config = ProptestConfig { cases: CASES, failure_persistence: None, ..ProptestConfig::default() };
    let mut runner = proptest::test_runner::TestRunner::new(config);
    // (unlatched, total) ticks per number type: f32, Fx, f64.
    let counts = Cell::new([(0u64, 0u64); 3]);
    let faulty = Cell::new(0u32);
    let result = runner.run(&valid_run(), |run| {
        let ticks = expand(&run);
        let r = [
            run_valid::<f32>(&ticks, run.clear_every)?,
            run_valid::<Fx>(&ticks, run.clear_every)?,
            run_valid::<f64>(&ticks, run.clear_every)?,
        ];
        let mut c = counts.get();
        for (c, r) in c.iter_mut().zip(r) {
            c.0 += r.0;
            c.1 += r.1;
        }
        counts.set(c);
        faulty.set(faulty.get() + u32::from(!run.faults.is_empty()));
        Ok(())
    });
    if let Err(e) = result {
        panic!("{e}");
    }
    for (name, (u, n)) in ["f32", "Fx", "f64"].iter().zip(counts.get()) {
        let share = u as f64 / n as f64;
        println!("{name}: {u} of {n} ticks without a latched fault ({:.1} %), {} of {CASES} runs with faults", 100.0 * share, faulty.get());
        assert!(share >= 0.5, "{name}: only {:.1} % of the ticks reach the unlatched path", 100.0 * share);
    }
}

/// The run the CI's proptest found (2026-11-29): from -33 degC air, a rate
/// fault on the current (the cold oil's friction) cleared 5 ticks into a model
/// step, later a 3-tick gap with a model step ending in it. Two windows
/// disagreed on sensors that agreed: the one with the mixed step (the worst-case
/// current before the clear, 3 kW over the step; the guard drops that step
/// now, `crosscheck::a_clear_mid_step_does_not_count_the_worst_case_ticks_before_it`)
/// and the one after the gap (92 W: this harness's plant did not follow the
/// model's oil across the gap). Kept as a fixed case.
#[test]
fn ci_found_run_with_a_clear_mid_step_and_a_gap() {
    let run = Run {
        start: [-337.095, 150.91223, -3.225, 5045.635, -54.45, -33.149136],
        ramps: vec![
            (107, [0.0, -0.056467574, -0.48777962, -0.6043092, 0.0, 0.0]),
            (127, [0.0; 6]),
            (70, [0.0; 6]),
            (148, [0.0, 0.0, 0.0, 0.4279835, 0.0, 0.0]),
            (71, [0.0; 6]),
            (183, [0.0; 6]),
            (136, [0.0; 6]),
        ],
        faults: vec![(0.36500540943234944, Fault::Missing { ticks: 3 })],
        clear_every: Some(231),
    };
    let ticks = expand(&run);
    for r in [run_valid::<f32>(&ticks, run.clear_every), run_valid::<Fx>(&ticks, run.clear_every), run_valid::<f64>(&ticks, run.clear_every)] {
        let (unlatched, n) = r.unwrap_or_else(|e| panic!("{e}"));
        // measured: 616 of 844 ticks unlatched (the rate fault latches at the
        // start, the clear at tick 231 succeeds); a latch after it leaves fewer
        assert_eq!((unlatched, n), (616, 844));
    }
}
