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
//! Measured: no wrong cause; 1708's churning named (r 1.72, t_pump_c
//! 0.45 → 0.21 K held out); three misses at r ≥ 2, each asserted as
//! measured: 1710 (conduction at one operating point, r 2.89: its fit
//! gains 68 % on t_pump_c but ΔBIC 11.8 < 25 and one operating point
//! cannot tell a housing path from the housings' outer transfer), 1712
//! (a draught at constant air speed, r 2.44: its fit gains 12 %), 2712
//! (a draught in an identification run, r 2.89: its fit gains 1 %;
//! `sensor-lag` ΔBIC 110 but does not qualify). docs/diagnosis-numbers.md,
//! "Current numbers".
//!
//! Re-measured on the fixed reference (b36ffe3's replay; 2026-11-28
//! evening) for 1710, 1712 and 2712 only, the three that were at r ≥ 2:
//! 1710 `none` (t_pump_c 0.376 → 0.297 K held out, twin 0.13 K, r 2.28: a
//! miss), 1712 `none` (0.268 → 0.246 K, twin 0.10 K, r 2.46: a miss),
//! 2712 `unexplained` (1.793 → 1.796 K; its twin's floor rose 0.62 →
//! 3.07 K, so r 0.59). The other 14 rows are the measurements before the
//! fix, not re-run (docs/diagnosis-numbers.md, "On the fixed reference").
//! With the physical tier's baseline restarted also from every candidate's
//! nominal-start fit (`analysis::NOMINAL_RESTARTS`; basin18, `--only 2712`
//! with its twin, 134 s): 2712 `unexplained`, t_pump_c 1.97 K held out,
//! its twin's 0.64 K (pooled 2.486 → 0.852 K), so **r 3.10: a miss at
//! r ≥ 2 again** (the draught's fit ΔBIC −3.5, gain −2 %).
//!
//! Slow tier only: 17 diagnoses, 15–58 s each; 380 s on two shared cores
//! (2026-11-28, passes).

use eha_sim::diagnosis::emu_sweep::{case_of_seed, run_emu_case_with};
use eha_sim::diagnosis::DiagnoseOptions;

/// Seed, answer, the calibrated baseline's held-out RMSE on the affected
/// channel (K) and the same on the log's effect-free twin under
/// `no-case-held` (K, `effect_free.rs`'s run), as measured.
const MEASURED: [(u64, &str, f64, f64); 17] = [
    (1700, "unexplained", 0.748, 0.51),
    (1701, "unexplained", 0.446, 0.40),
    (1706, "none", 0.139, 0.22),
    (1707, "none", 0.194, 0.34),
    (1708, "churning-loss", 0.448, 0.26),
    (1709, "unexplained", 0.461, 0.47),
    (1710, "none", 0.297, 0.13),
    (1712, "none", 0.246, 0.10),
    (1713, "none", 0.228, 0.33),
    (2700, "unexplained", 0.341, 0.24),
    (2701, "unexplained", 0.508, 0.49),
    (2706, "none", 0.200, 0.18),
    (2707, "none", 0.247, 0.16),
    (2708, "unexplained", 2.900, 2.06),
    (2710, "unexplained", 0.971, 0.64),
    (2712, "unexplained", 1.970, 0.64),
    (2713, "none", 0.646, 0.55),
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
