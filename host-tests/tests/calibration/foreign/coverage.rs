//! Where the held-out miss lies against the training envelope
//! (`eha_sim::calibration::envelope`): leaky-heavy commissioned by the
//! procedure, and big-pump's margin inside it (docs/commissioning-foreign.md,
//! "The training envelope in the report").

use super::{commission_as_measured, near};
use eha_sim::calibration::envelope_report::{not_validated, NOT_VALIDATED};
use eha_sim::calibration::commission::Commissioning;
use eha_sim::calibration::paths::PathKind;
use eha_sim::emulator::bench::{big_pump, commissioning_set, leaky_heavy};

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
    print_split(&c);
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

/// Big-pump, the procedure's training set (seed 3600), the flashed
/// (reduction) block with its 1.722 K margin: neither held-out log reads
/// low on either side of the envelope, so the report writes no line; the
/// margin's worst fold (the soak log's start, fitted on the rest: big-pump's
/// cold start, docs/commissioning-foreign.md) lies inside the envelope: the
/// margin comes from a start, not from an untrained operating point.
/// Measured (7b95178 + this test, 50.6 s wall on idle cores): envelope `Δp
/// 0–5 bar: 250–450 rpm; Δp 5–15 bar: 250–450 rpm; Δp 15–25 bar: 0–50,
/// 450–1250 rpm; Δp 25–35 bar: 50–250, 650–850 rpm; Δp 35–45 bar: 650–850
/// rpm; Δp 45–55 bar: 450–650 rpm; drain 25.2–59.4 °C`; the servo log
/// 100 s inside, under −1.13 K, 1100 s outside, −1.01 K; the mix 485 s
/// inside, −0.12 K, 1315 s outside, −0.17 K; the worst fold 1.522 K under
/// inside, nothing scored outside (its start never leaves the envelope).
/// Tolerances: the harness's `AS_MEASURED_K` (the fit's run-to-run spread).
#[test]
#[ignore = "slow tier: one commissioning on emulator bench logs (~1 min wall)"]
fn slow_big_pump_margin_comes_from_inside_the_training_envelope() {
    let m = big_pump();
    let s = commissioning_set(&m, 3600).expect("bench");
    let c = commission_as_measured(&m, &s, (1.722, PathKind::Reduction, [(2.201, 0.000), (2.676, 0.000)], [1405.0, 1519.0]));
    print_split(&c);
    for h in &c.holdout_with_margin {
        assert_eq!(not_validated(&c.envelope, h), None, "{}", h.log);
    }
    let under = |d: &eha_sim::calibration::envelope::Side| d.max_under_k.expect("scored");
    let measured = [(-1.132, -1.013), (-0.119, -0.166)];
    for (h, (want_in, want_out)) in c.holdout_with_margin.iter().zip(measured) {
        let (i, o) = c.envelope.split(&h.cells);
        near(&format!("{} under-prediction inside, margin counted", h.log), under(&i), want_in);
        near(&format!("{} under-prediction outside, margin counted", h.log), under(&o), want_out);
    }
    let worst = c.margin.as_ref().and_then(|v| v.worst()).expect("margin folds");
    let (wi, wo) = c.envelope.split(&worst.cells);
    eprintln!("worst fold {}: in {:?} out {:?}", worst.log, wi.max_under_k, wo.max_under_k);
    near("the worst fold's under-prediction inside the envelope", under(&wi), 1.522);
    assert_eq!(wo.max_under_k, None, "the worst fold scored nothing outside the envelope");
}

/// Prints `c`'s envelope and each held-out log's and margin fold's drain
/// error inside and outside it.
fn print_split(c: &Commissioning) {
    eprintln!("envelope: {}", c.envelope.describe());
    for r in c.holdout_with_margin.iter().chain(c.margin.iter().flat_map(|v| &v.folds)) {
        let (i, o) = c.envelope.split(&r.cells);
        eprintln!("{} (margin {:.3} K): inside {:.0} s max |e| {:?} under {:?}; outside {:.0} s max |e| {:?} under {:?}, low {:?} ({:.0} s)", r.log, r.margin_k, i.dwell_s, i.max_abs_k, i.max_under_k, o.dwell_s, o.max_abs_k, o.max_under_k, o.low, o.low_dwell_s);
    }
}
