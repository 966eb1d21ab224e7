//! The effect-free emulator logs under `--structure no-case-held`
//! (`Structure::NoCaseHeld`): every effect-free twin of the sweep's cases
//! and every effect-free case (seeds 1700–1717 and 2700–2717 without the
//! retired slots), diagnosed as `emulator-sweep` diagnoses them. A cause
//! named on any of them is a false discovery, wrong at any imprint ratio;
//! before a variant may become the default it must hold here. Measured
//! with `cargo run --profile fast -p eha-sim --example twin_floor --
//! no-case-held SEED…` (2026-11-28): no log names a cause; every
//! candidate's posterior probability is 0 (none qualifies: `sensor-lag`
//! lowers the BIC by 33–132 on the loaded and servo logs but the pooled
//! held-out misfit by at most 15 %, against the 20 % bar). The answers and
//! the calibrated baseline's pooled held-out misfit are asserted as
//! measured. docs/diagnosis-numbers.md, "Effect-free logs".
//!
//! Re-measured on the fixed reference (b36ffe3's replay; 2026-11-28
//! evening), each as measured then: 1714–1717, 2714–2717 and the twins of
//! 1710, 1712, 2712 (`twin_floor`), the twins of 1704, 1705, 1711, 2704,
//! 2705, 2709, 2711 (their `emulator-sweep` runs with twins); still no
//! cause named. 2712's twin moved `none` 0.497 K → `unexplained` 2.486 K,
//! 1711's 1.130 → 1.578 K. The other 14 rows (twins of 1700, 1701,
//! 1706–1709, 1713, 2700, 2701, 2706–2708, 2710, 2713) are the measurements
//! before the fix, not re-run (docs/diagnosis-numbers.md).
//!
//! Re-measured with the physical tier's baseline restarted also from every
//! candidate's nominal-start fit (`analysis::NOMINAL_RESTARTS`; 2026-11-28,
//! basin18), each as measured then: 1714–1717, 2714–2717 and the twins of
//! 2704, 2708, 2709, 2713 (`twin_floor`), the twins of 1704, 1705, 1711,
//! 2705, 2711, 2712 (their `emulator-sweep` runs with twins); still no
//! cause named. 2712's
//! twin 2.486 → 0.852 K (its restarts had stayed in the baseline's own
//! basin; docs/diagnosis-limits.md, "The calibration's basins"), 2705's
//! 1.099 → 1.333 K, 2714's 0.825 → 0.726 K, 2715's 0.968 → 1.106 K; the
//! others within 4 % of the fixed reference's value (2708's and 2713's
//! twins, last measured before the fix: 1.622 → 1.381 K, 1.963 →
//! 2.012 K). The twins of 1700, 1701, 1706–1710, 1712, 1713, 2700, 2701,
//! 2706, 2707, 2710 not re-run with it.
//!
//! Slow tier only: 32 diagnoses, 3–50 s each; 475 s on two cores shared
//! with another helper (2026-11-28, passes).

use eha_sim::diagnosis::analysis::Structure;
use eha_sim::diagnosis::emu_sweep::{case_of_seed, effect_free_log};
use eha_sim::diagnosis::reference::ReferenceModel;
use eha_sim::diagnosis::{diagnose, DiagnoseOptions};
use eha_sim::rig::Rig;

/// Seed, answer and the calibrated baseline's pooled held-out RMSE (K) of
/// the effect-free log of that seed (the case itself when nothing is
/// hidden, else its twin), as measured under `no-case-held`.
const MEASURED: [(u64, &str, f64); 32] = [
    (1700, "unexplained", 1.860),
    (1701, "unexplained", 0.816),
    (1704, "none", 0.156),
    (1705, "none", 0.235),
    (1706, "none", 0.161),
    (1707, "none", 0.228),
    (1708, "none", 0.407),
    (1709, "unexplained", 1.365),
    (1710, "none", 0.122),
    (1711, "unexplained", 1.578),
    (1712, "none", 0.132),
    (1713, "none", 0.195),
    (1714, "none", 0.155),
    (1715, "unexplained", 1.237),
    (1716, "none", 0.236),
    (1717, "none", 0.192),
    (2700, "unexplained", 0.649),
    (2701, "unexplained", 0.927),
    (2704, "unexplained", 1.347),
    (2705, "unexplained", 1.333),
    (2706, "none", 0.147),
    (2707, "none", 0.206),
    (2708, "unexplained", 1.381),
    (2709, "unexplained", 1.389),
    (2710, "unexplained", 0.791),
    (2711, "unexplained", 1.045),
    (2712, "unexplained", 0.852),
    (2713, "unexplained", 2.012),
    (2714, "unexplained", 0.726),
    (2715, "unexplained", 1.106),
    (2716, "unexplained", 1.106),
    (2717, "none", 0.187),
];

/// Every effect-free log above: the answer as measured (so no cause, and
/// no change between `none` and `unexplained`), no candidate at the
/// naming bar (posterior ≥ 0.9), and the pooled held-out misfit within
/// 20 % of the measured value (the calibrated baselines move with the
/// fits' last digits, as in `imprint.rs`). All logs are run before the
/// assertion, so one run lists every change.
#[test]
#[ignore = "slow tier: 32 emulator diagnoses (minutes), the structure option's no-case-held variant"]
fn slow_effect_free_logs_name_no_cause_under_no_case_held() {
    let o = DiagnoseOptions { structure: Structure::NoCaseHeld, ..DiagnoseOptions::default() };
    let mut wrong = Vec::new();
    for (seed, answer, pooled) in MEASURED {
        let c = case_of_seed(1200.0, seed).expect("case of the sweep");
        let run = effect_free_log(&c).expect("emulated log");
        let model = ReferenceModel::new(Rig::default(), &run).expect("model").with_structure(&run, o.structure);
        let d = diagnose(&run, &model, &o).expect("diagnosis");
        let named = d.posterior.causes.iter().filter(|p| p.cause != "none" && p.cause != "unexplained").map(|p| p.probability).fold(0.0, f64::max);
        let p = d.before.heldout_rmse_k;
        eprintln!("{seed}: {} (measured {answer}), pooled held out {p:.3} K (measured {pooled}), top candidate P {named:.3}", d.answer());
        if d.answer() != answer || named >= 0.9 || (p / pooled - 1.0).abs() > 0.2 {
            wrong.push(format!("{seed}: {} P {named:.3} pooled {p:.3} K (measured {answer}, {pooled} K)", d.answer()));
        }
    }
    assert!(wrong.is_empty(), "changed against the measurement: {wrong:#?}");
}
