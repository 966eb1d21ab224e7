//! The rate check with samples slower than the tick: a missing tick had
//! dropped the previous values, so with a sample every 20 ms no sample
//! was ever rate-checked (`tick.rs`, "samples slower than 10 ms disable the
//! rate check"). The next sample is now checked against the last one over
//! the gap: the per-tick rates times the ticks between them.

use eha_guard::{faults, GuardConfig, GuardOf, Sample};

fn at(ambient_c: f32) -> Sample {
    Sample { current_a: crate::plant::motor_current(10.0, 5.0, 500.0), p_a_bar: 10.0, p_b_bar: 5.0, speed_rpm: 500.0, position_mm: 0.0, ambient_c }
}

/// Samples every `every` ticks, the ambient stepping by `step_k` at sample
/// 50; the faults after 100 samples.
fn run(every: u32, step_k: f32) -> eha_guard::Faults {
    let cfg = GuardConfig::DEFAULT;
    let mut g = GuardOf::<f32>::new(&cfg, eha_guard::Restore::Cold);
    let mut o = g.output();
    for k in 0..100 {
        o = g.tick(&at(if k < 50 { 20.0 } else { 20.0 + step_k }));
        for _ in 1..every {
            o = g.tick_missing();
        }
    }
    o.faults
}

#[test]
fn samples_slower_than_the_tick_are_rate_checked_over_the_gap() {
    // 1 K per 10 ms: a 3 K step is too fast for one tick, for two (20 ms)
    // and fine over three
    assert!(run(1, 3.0).contains(faults::RATE | faults::Faults::channels(eha_guard::ChannelSet::AMBIENT)));
    let f = run(2, 3.0);
    assert!(f.contains(faults::RATE | faults::Faults::channels(eha_guard::ChannelSet::AMBIENT)), "a 3 K step in 20 ms passed: {f:?}");
    let f = run(4, 3.0);
    assert!(!f.intersects(faults::RATE), "3 K in 40 ms is within the rate: {f:?}");
    let f = run(2, 1.5);
    assert!(!f.intersects(faults::RATE), "1.5 K in 20 ms is within the rate: {f:?}");
}
