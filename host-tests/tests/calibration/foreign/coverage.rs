//! Where the held-out miss lies against the training envelope
//! (`eha_sim::calibration::envelope`): leaky-heavy commissioned by the
//! procedure (docs/commissioning-foreign.md, "The training envelope in the
//! report").

use super::{commission_as_measured, near};
use eha_sim::calibration::envelope_report::{not_validated, NOT_VALIDATED};
use eha_sim::calibration::paths::PathKind;
use eha_sim::emulator::bench::{commissioning_set, leaky_heavy};

/// Leaky-heavy, the procedure's training set (seed 3600), the flashed
/// (direct) block with its 1.191 K margin on the held-out throttle mix: the
/// under-prediction lies outside the training envelope, in the hot corner
/// the procedure never holds, and the report says the margin is not
/// validated there. Measured (5806964, 111.8 s
/// wall on the shared cores): envelope `Δp 0–5 bar: 0–50 rpm; Δp 5–15 bar:
/// 0–50, 250–450 rpm; Δp 15–25 bar: 50–250, 450–1250 rpm; Δp 25–35 bar:
/// 650–850 rpm; Δp 35–45 bar: 450–850 rpm; Δp 45–55 bar: 450–650 rpm; drain
/// 25.2–52.7 °C`; mix inside 676 s, max |e| 2.334 K, under 0.018 K; outside
/// 1124 s, max |e| 2.157 K, under 0.617 K at t 903–1083 s, 949–1141 rpm ×
/// 35–53 bar (443 s in those cells); the servo log reads low on neither
/// side (−0.33 / −0.22 K); the margin's worst fold (0.991 K under) inside.
/// Tolerances: the under-predictions within the harness's `AS_MEASURED_K`
/// (the fit's run-to-run spread); the seconds within 60 s and the low
/// region's times within 60 s (the replay's speed and Δp, which decide the
/// cells, are the commissioned rig's, and the region's ticks are those
/// within half of the largest miss, both moving with the fit).
#[test]
#[ignore = "slow tier: one commissioning on emulator bench logs (~2 min wall)"]
fn slow_held_out_miss_lies_outside_the_training_envelope() {
    let m = leaky_heavy();
    let s = commissioning_set(&m, 3600).expect("bench");
    // The headline as `slow_commissioning_with_margin_on_foreign_machines` measured it.
    let c = commission_as_measured(&m, &s, (1.191, PathKind::Direct, [(1.471, 0.000), (2.334, 0.617)], [1550.0, 1560.0]));
    eprintln!("envelope: {}", c.envelope.describe());
    for r in c.holdout_with_margin.iter().chain(c.margin.iter().flat_map(|v| &v.folds)) {
        let (i, o) = c.envelope.split(&r.cells);
        eprintln!("{} (margin {:.3} K): inside {:.0} s max |e| {:?} under {:?}; outside {:.0} s max |e| {:?} under {:?}, low {:?} ({:.0} s)", r.log, r.margin_k, i.dwell_s, i.max_abs_k, i.max_under_k, o.dwell_s, o.max_abs_k, o.max_under_k, o.low, o.low_dwell_s);
    }
    let mix = &c.holdout_with_margin[1];
    let (inside, outside) = c.envelope.split(&mix.cells);
    let under = |d: &eha_sim::calibration::envelope::Side| d.max_under_k.expect("scored");
    near("mix under-prediction inside the envelope, margin counted", under(&inside), 0.018);
    near("mix under-prediction outside the envelope, margin counted", under(&outside), 0.617);
    assert!(under(&outside) > under(&inside) + 0.3, "the miss lies outside: {:.3} K out, {:.3} K in", under(&outside), under(&inside));
    assert!((outside.dwell_s - 1124.0).abs() <= 60.0 && (inside.dwell_s - 676.0).abs() <= 60.0, "mix {:.0} s outside, {:.0} s inside", outside.dwell_s, inside.dwell_s);
    let g = outside.low.as_ref().expect("where the mix reads low outside");
    assert!((g.t_s.0 - 903.0).abs() <= 60.0 && (g.t_s.1 - 1083.0).abs() <= 60.0, "low at t {:?}", g.t_s);
    // The hot corner (docs/commissioning-foreign.md: ≥ 850 rpm at ≥ 40 bar, never trained).
    assert!(g.speed_rpm.0 >= 850.0 && g.dp_bar.1 >= 40.0, "low at {:?} rpm × {:?} bar", g.speed_rpm, g.dp_bar);
    let line = not_validated(&c.envelope, mix).expect("the report's line");
    eprintln!("{line}");
    assert!(line.starts_with(NOT_VALIDATED) && line.contains(&mix.log), "{line}");
    // The servo log reads low on neither side; the margin's worst fold inside.
    assert_eq!(not_validated(&c.envelope, &c.holdout_with_margin[0]), None);
    let worst = c.margin.as_ref().and_then(|v| v.worst()).expect("margin folds");
    let (wi, wo) = c.envelope.split(&worst.cells);
    assert!(wi.max_under_k >= wo.max_under_k, "the worst fold's miss inside the envelope: {:?} in, {:?} out", wi.max_under_k, wo.max_under_k);
}
