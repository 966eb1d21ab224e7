//! The third and fourth repetitions of both emulator case sets
//! (1900–1917, 2900–2917; 2000–2017, 3000–3017), which no admission rule
//! or threshold was set with: every
//! case log, its effect-free twin and every effect-free case, diagnosed
//! as `emulator-sweep` diagnoses them under the default options, each
//! answer asserted as measured (2026-11-29, `--example ranking_dump`,
//! `docs/data/ranking-1900-2900.jsonl`; docs/diagnosis-numbers.md, "A
//! third seed set"): **named at r ≥ 2 1 of 9** (2905's lag), 2904's lag
//! named at r 1.98, **no wrong cause, no false discovery** on the 32
//! effect-free logs. The misses stay asserted as misses: a change that
//! names one of them (or names anything on an effect-free log) fails
//! here and must be measured on the whole set. The fourth set the same way
//! (`docs/data/ranking-2000-3000.jsonl`, "A fourth seed set"): **2 of 5**
//! named at r ≥ 2 (the lags of 2004 and 3005), no wrong cause, no false
//! discovery on its 32 effect-free logs.
//!
//! Slow tier only: 56 diagnoses a set, 6–18 s each (the third set's test
//! passes as committed: 676 s wall on a quiet 2-core machine, 2026-11-29;
//! the fourth's, 656 s).

use eha_sim::diagnosis::emu_sweep::{case_of_seed, effect_free_log};
use eha_sim::diagnosis::reference::ReferenceModel;
use eha_sim::diagnosis::{diagnose, Candidate, DiagnoseOptions};
use eha_sim::emulator::generate;
use eha_sim::rig::Rig;

/// Seed, log ("case": the hidden effect in; "twin": the same without it;
/// "effect-free": a case that hides nothing), answer and the calibrated
/// baseline's pooled held-out RMSE (K), as measured.
const MEASURED_THIRD: [(u64, &str, &str, f64); 56] = [
    (1900, "case", "unexplained", 1.362),
    (1900, "twin", "unexplained", 1.255),
    (1901, "case", "unexplained", 1.208),
    (1901, "twin", "unexplained", 1.235),
    (1904, "case", "none", 0.453),
    (1904, "twin", "none", 0.503),
    (1905, "case", "none", 0.385),
    (1905, "twin", "none", 0.292),
    (1906, "case", "none", 0.131),
    (1906, "twin", "none", 0.137),
    (1907, "case", "none", 0.128),
    (1907, "twin", "none", 0.129),
    (1908, "case", "unexplained", 0.636),
    (1908, "twin", "unexplained", 0.660),
    (1909, "case", "unexplained", 1.548),
    (1909, "twin", "unexplained", 1.674),
    (1910, "case", "unexplained", 0.346),
    (1910, "twin", "none", 0.208),
    (1911, "case", "unexplained", 0.988),
    (1911, "twin", "unexplained", 0.918),
    (1912, "case", "none", 0.205),
    (1912, "twin", "none", 0.129),
    (1913, "case", "none", 0.188),
    (1913, "twin", "none", 0.247),
    (1914, "effect-free", "none", 0.346),
    (1915, "effect-free", "unexplained", 0.871),
    (1916, "effect-free", "unexplained", 0.886),
    (1917, "effect-free", "none", 0.133),
    (2900, "case", "unexplained", 0.831),
    (2900, "twin", "unexplained", 0.540),
    (2901, "case", "none", 0.440),
    (2901, "twin", "none", 0.415),
    (2904, "case", "sensor-lag", 1.481),
    (2904, "twin", "unexplained", 0.636),
    (2905, "case", "sensor-lag", 2.146),
    (2905, "twin", "none", 0.507),
    (2906, "case", "none", 0.138),
    (2906, "twin", "none", 0.140),
    (2907, "case", "none", 0.164),
    (2907, "twin", "none", 0.179),
    (2908, "case", "unexplained", 0.744),
    (2908, "twin", "unexplained", 0.893),
    (2909, "case", "unexplained", 1.080),
    (2909, "twin", "unexplained", 2.539),
    (2910, "case", "unexplained", 1.005),
    (2910, "twin", "unexplained", 1.067),
    (2911, "case", "unexplained", 1.930),
    (2911, "twin", "none", 0.722),
    (2912, "case", "unexplained", 1.049),
    (2912, "twin", "unexplained", 1.074),
    (2913, "case", "none", 0.575),
    (2913, "twin", "unexplained", 0.711),
    (2914, "effect-free", "unexplained", 1.185),
    (2915, "effect-free", "unexplained", 1.003),
    (2916, "effect-free", "unexplained", 1.103),
    (2917, "effect-free", "none", 0.156),
];

/// The fourth repetition, as [`MEASURED_THIRD`].
const MEASURED_FOURTH: [(u64, &str, &str, f64); 56] = [
    (2000, "case", "unexplained", 1.168),
    (2000, "twin", "unexplained", 1.215),
    (2001, "case", "unexplained", 1.313),
    (2001, "twin", "unexplained", 1.337),
    (2004, "case", "sensor-lag", 0.999),
    (2004, "twin", "none", 0.246),
    (2005, "case", "unexplained", 0.810),
    (2005, "twin", "unexplained", 0.639),
    (2006, "case", "none", 0.137),
    (2006, "twin", "none", 0.141),
    (2007, "case", "none", 0.149),
    (2007, "twin", "none", 0.151),
    (2008, "case", "unexplained", 0.637),
    (2008, "twin", "none", 0.544),
    (2009, "case", "unexplained", 1.284),
    (2009, "twin", "unexplained", 1.281),
    (2010, "case", "none", 0.190),
    (2010, "twin", "none", 0.124),
    (2011, "case", "unexplained", 0.771),
    (2011, "twin", "unexplained", 0.785),
    (2012, "case", "none", 0.152),
    (2012, "twin", "none", 0.149),
    (2013, "case", "none", 0.213),
    (2013, "twin", "none", 0.251),
    (2014, "effect-free", "none", 0.133),
    (2015, "effect-free", "unexplained", 0.692),
    (2016, "effect-free", "unexplained", 0.668),
    (2017, "effect-free", "none", 0.120),
    (3000, "case", "unexplained", 1.056),
    (3000, "twin", "unexplained", 0.905),
    (3001, "case", "none", 0.551),
    (3001, "twin", "unexplained", 0.634),
    (3004, "case", "unexplained", 2.646),
    (3004, "twin", "unexplained", 1.633),
    (3005, "case", "sensor-lag", 1.493),
    (3005, "twin", "unexplained", 0.832),
    (3006, "case", "none", 0.150),
    (3006, "twin", "none", 0.152),
    (3007, "case", "none", 0.155),
    (3007, "twin", "none", 0.156),
    (3008, "case", "unexplained", 1.713),
    (3008, "twin", "unexplained", 1.486),
    (3009, "case", "unexplained", 0.928),
    (3009, "twin", "unexplained", 2.180),
    (3010, "case", "none", 0.733),
    (3010, "twin", "unexplained", 0.733),
    (3011, "case", "unexplained", 1.430),
    (3011, "twin", "unexplained", 1.965),
    (3012, "case", "unexplained", 0.855),
    (3012, "twin", "unexplained", 0.929),
    (3013, "case", "unexplained", 1.167),
    (3013, "twin", "unexplained", 1.457),
    (3014, "effect-free", "unexplained", 1.147),
    (3015, "effect-free", "unexplained", 1.081),
    (3016, "effect-free", "unexplained", 1.474),
    (3017, "effect-free", "none", 0.177),
];

/// Every log above: the answer as measured, and the pooled held-out
/// misfit within 20 % of the measured value (the calibrated baselines move
/// with the fits' last digits, as in `effect_free.rs`). All logs run
/// before the assertion, so one run lists every change.
#[test]
#[ignore = "slow tier: 56 emulator diagnoses (~11 min), the third seed set as measured"]
fn slow_third_seed_set_answers_as_measured() {
    assert_as_measured(&MEASURED_THIRD);
}

/// The fourth set's logs, as [`slow_third_seed_set_answers_as_measured`].
#[test]
#[ignore = "slow tier: 56 emulator diagnoses (~11 min), the fourth seed set as measured"]
fn slow_fourth_seed_set_answers_as_measured() {
    assert_as_measured(&MEASURED_FOURTH);
}

fn assert_as_measured(table: &[(u64, &str, &str, f64)]) {
    let o = DiagnoseOptions::default();
    let mut changed = Vec::new();
    for &(seed, kind, answer, pooled) in table {
        let c = case_of_seed(1200.0, seed).expect("a case of the repetition");
        let run = if kind == "case" { generate(&c).map(|r| r.0) } else { effect_free_log(&c) }.expect("emulated log");
        assert_eq!(kind == "effect-free", c.hidden == Candidate::None, "{seed}: the table's kind");
        let model = ReferenceModel::new(Rig::default(), &run).expect("model").with_structure(&run, o.structure);
        let d = diagnose(&run, &model, &o).expect("diagnosis");
        let p = d.before.heldout_rmse_k;
        eprintln!("{seed} {kind}: {} (measured {answer}), pooled held out {p:.3} K (measured {pooled})", d.answer());
        if d.answer() != answer || (p / pooled - 1.0).abs() > 0.2 {
            changed.push(format!("{seed} {kind}: {} pooled {p:.3} K (measured {answer}, {pooled} K)", d.answer()));
        }
    }
    assert!(changed.is_empty(), "changed against the measurement: {changed:#?}");
}
