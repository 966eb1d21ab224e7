//! Every emulator log with a hidden effect of the sweep's two case sets
//! outside the seven of `imprint.rs` (seeds 1700–1713 and 2700–2713 with
//! an effect), diagnosed under the default structure
//! (`Structure::NoCaseHeld`) as `emulator-sweep` diagnoses them. Measured
//! with `eha-sim emulator-sweep --cases original,ident --only SEEDS
//! --no-twins --no-oracle --structure no-case-held` (2026-11-28, 15–58 s
//! a log on two shared cores). The imprint ratio r is the case's held-out
//! misfit on the affected channel over its twin's under the same variant
//! (the twins' floors as `effect_free.rs` measured them, quoted below).
//!
//! Measured on the fixed reference (b36ffe3's replay; 2026-11-28
//! evening, all 17): no wrong cause, no cause named; three misses at
//! r ≥ 2, each asserted as measured: 1708 (churning in speed steps,
//! r 2.39: its fit gains 47 % on t_pump_c but 19 % pooled, under the
//! 20 % bar; it was named at r 1.72 before the fix), 1710 (conduction at
//! one operating point, r 2.28: one operating point cannot tell a housing
//! path from the housings' outer transfer), 1712 (a draught at constant
//! air speed, r 2.46). 2712 fell to r 0.59 by its twin's floor (t_pump_c
//! 0.62 → 3.07 K); 2713 `none` → `unexplained`. docs/diagnosis-numbers.md,
//! "The other 17 logs with a hidden effect".
//!
//! Slow tier only: 17 diagnoses, 17–63 s each; the values below are the
//! `emulator-sweep` run's, which diagnoses each log as this test does.
//! Passes on the fixed reference (2026-11-28; with `effect_free.rs`'s
//! test, one test thread, 1467 s for both at load 5–6).

use eha_sim::diagnosis::emu_sweep::{case_of_seed, run_emu_case_with};
use eha_sim::diagnosis::DiagnoseOptions;

/// Seed, answer, the calibrated baseline's held-out RMSE on the affected
/// channel (K) and the same on the log's effect-free twin under
/// `no-case-held` (K, `effect_free.rs`'s run), as measured.
const MEASURED: [(u64, &str, f64, f64); 17] = [
    (1700, "unexplained", 0.410, 0.52),
    (1701, "unexplained", 0.393, 0.44),
    (1706, "none", 0.127, 0.14),
    (1707, "none", 0.158, 0.14),
    (1708, "none", 0.478, 0.20),
    (1709, "unexplained", 0.199, 0.25),
    (1710, "none", 0.297, 0.13),
    (1712, "none", 0.246, 0.10),
    (1713, "none", 0.322, 0.40),
    (2700, "unexplained", 0.138, 0.16),
    (2701, "unexplained", 0.343, 0.54),
    (2706, "none", 0.130, 0.13),
    (2707, "none", 0.185, 0.22),
    (2708, "unexplained", 2.680, 1.99),
    (2710, "unexplained", 0.702, 1.25),
    (2712, "unexplained", 1.796, 3.07),
    (2713, "unexplained", 0.549, 0.75),
];

/// Each log: the answer as measured (a named cause only where measured, and
/// then the hidden one), and the affected channel's held-out misfit within
/// 20 % of the measured value (the calibrated baselines move with the
/// fits' last digits, as in `imprint.rs`), so r stays on its side of 2
/// except within that band. All logs run before the assertion.
#[test]
#[ignore = "slow tier: 17 emulator diagnoses (minutes), the default structure"]
fn slow_hidden_effects_outside_the_seven_under_the_default_structure() {
    let o = DiagnoseOptions::default();
    let mut wrong = Vec::new();
    for (seed, answer, misfit, twin) in MEASURED {
        let c = case_of_seed(1200.0, seed).expect("case of the sweep");
        let r = run_emu_case_with(c, &o, false, false).expect("emulated log diagnoses");
        let (m, _) = r.affected_heldout_k.expect("affected channel");
        eprintln!("{seed}: {} (measured {answer}), affected held out {m:.3} K (measured {misfit}), r {:.2}", r.answer, m / twin);
        let named_wrong = !matches!(r.answer.as_str(), "none" | "unexplained") && !r.hit();
        if r.answer != answer || named_wrong || (m / misfit - 1.0).abs() > 0.2 {
            wrong.push(format!("{seed}: {} held out {m:.3} K (measured {answer}, {misfit} K)", r.answer));
        }
    }
    assert!(wrong.is_empty(), "changed against the measurement: {wrong:#?}");
}
