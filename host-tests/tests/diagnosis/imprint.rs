//! The seven emulator cases of the 2026-11-27 sweep whose imprint ratio r
//! (the calibrated baseline's held-out misfit on the affected channel over
//! the same on the log's effect-free twin) is at least 2, where the
//! diagnosis must name the cause, each with its twin (same machine,
//! mission and noise, nothing hidden), where it must not name one.
//! Every assertion is the outcome measured with the third candidate start
//! (the calibrated baseline with the candidate at its typical magnitude,
//! `diagnosis::analysis::typical_magnitude`): named where named, a miss
//! asserted as a miss, so a change either way fails. Why each miss is
//! missed: docs/diagnosis-limits.md, "Why effects above the floor are
//! missed".
//!
//! Slow tier only: each case is a log and its twin diagnosed in parallel
//! (with the oracle), 50–90 s a case on two shared cores; the two tests
//! together took 969 s at load 7–8 (2026-11-27).

use eha_sim::diagnosis::emu_sweep::{run_emu_case_twin, EmuResult};
use eha_sim::diagnosis::analysis::Structure;
use eha_sim::diagnosis::{Candidate, DiagnoseOptions};
use eha_sim::emulator::missions::EmuScenario::{self, ConstantThrottle, IdentRun, LoadCycles, SpeedSteps};
use eha_sim::emulator::EmuCase;

/// The case under `--structure off`, as the first two tests measured it
/// (the default is `no-case-held` since 2026-11-28).
fn run(hidden: &str, scenario: EmuScenario, seed: u64) -> EmuResult {
    run_with(hidden, scenario, seed, &DiagnoseOptions { structure: Structure::Off, ..DiagnoseOptions::default() })
}

fn run_with(hidden: &str, scenario: EmuScenario, seed: u64, o: &DiagnoseOptions) -> EmuResult {
    let c = EmuCase { hidden: Candidate::from_name(hidden).expect("candidate"), scenario, seed, duration_s: 1200.0 };
    let r = run_emu_case_twin(c, o, true).expect("emulated log diagnoses");
    eprintln!("{}", eha_sim::diagnosis::emu_sweep::table_row(&r));
    r
}

/// The imprint ratio against the twin, and the twin's answer.
fn twin(r: &EmuResult) -> (f64, String) {
    let t = r.twin.as_ref().expect("twin diagnosed");
    (t.misfit_k / t.twin_misfit_k, t.twin_answer.clone())
}

/// A hidden effect named: the answer, r within 20 % of the measured value
/// (the calibrated baselines of log and twin move with the fits' last
/// digits), the held-out RMSE on the affected channel within ±0.1 K of the
/// measured after-value, and the twin names no cause.
fn assert_named(r: &EmuResult, ratio: f64, after_k: f64) {
    assert!(r.hit(), "answer {} (measured: named)", r.answer);
    let (rr, ta) = twin(r);
    assert!((rr / ratio - 1.0).abs() < 0.2, "r {rr:.2} (measured {ratio})");
    let (_, a) = r.affected_heldout_k.expect("affected channel");
    assert!((a - after_k).abs() <= 0.1, "affected held-out after {a:.2} K (measured {after_k})");
    assert!(ta == "none" || ta == "unexplained", "twin answered {ta}: a false discovery");
}

/// A measured miss: no cause named (`unexplained` or `none`, as measured),
/// in particular no wrong cause, and no discovery on the twin.
fn assert_missed(r: &EmuResult, answer: &str, ratio: f64) {
    assert_eq!(r.answer, answer, "measured outcome changed");
    let (rr, ta) = twin(r);
    assert!((rr / ratio - 1.0).abs() < 0.2, "r {rr:.2} (measured {ratio})");
    assert!(ta == "none" || ta == "unexplained", "twin answered {ta}: a false discovery");
}

/// Dead-end oil pockets: 1704 (Case 1, τ 203 s, r 3.1), 1705 (speed
/// steps, τ 117 s, r 2.6) and 2705 (identification run, τ 145 s, r 3.8)
/// named `sensor-lag` at P 1.00 (t_oil_c held out 0.45 → 0.24, 0.94 →
/// 0.45, 5.58 → 3.71 K); 1705 and 2705 were `none` and `unexplained` with
/// two starts. 2704 (identification run, τ 69 s, r 2.1) stays
/// `unexplained`: the lag gains 23 % on t_oil_c (3.04 → 2.35 K) but the
/// pooled held-out RMSE rises 2.12 → 2.22 K (the joint nuisance refit
/// trades t_block_c's 3–4 K structure floor), a measured miss.
#[test]
#[ignore = "slow tier: emulator cases with twins (minutes)"]
#[allow(clippy::approx_constant)] // 3.14 is 1704's measured imprint ratio, not π
fn slow_imprint_ratio_above_two_sensor_lag() {
    assert_named(&run("sensor-lag", ConstantThrottle, 1704), 3.14, 0.24);
    assert_named(&run("sensor-lag", SpeedSteps, 1705), 2.60, 0.45);
    assert_named(&run("sensor-lag", IdentRun, 2705), 3.78, 3.71);
    let r = run("sensor-lag", IdentRun, 2704);
    assert_missed(&r, "unexplained", 2.10);
    let h = r.hidden_fit.as_ref().expect("hidden candidate fitted");
    assert!(!h.qualifies && h.pooled_heldout_k.1 > h.pooled_heldout_k.0, "lag fit {h:?} (measured pooled 2.12 -> 2.22 K)");
}

/// Motor–pump conduction (1711, load cycles, 5.3 W/K, r 6.4; 2711,
/// identification run, 5.7 W/K, r 2.8) and churning (2709, identification
/// run, 4.9e-4 W/(rad/s)^2.5, r 4.7): measured misses, `unexplained`.
/// The training window does not prefer the effect over the per-housing
/// outer transfer and the pump's friction and case film (with the
/// nuisance refitted, the conduction held at its true value fits the
/// training window no better than at 0.4 W/K; churning's fit gains −6 % on
/// t_pump_c against the baseline restarted from its own nuisance values):
/// docs/diagnosis-limits.md. Asserted as measured: no cause, no wrong cause, no
/// discovery on the twins; and the twin of 2700, once a false discovery.
#[test]
#[ignore = "slow tier: emulator cases with twins (minutes), measured misses"]
fn slow_imprint_ratio_above_two_housing_paths_and_churning_missed() {
    assert_missed(&run("motor-pump-conduction", LoadCycles, 1711), "unexplained", 6.36);
    assert_missed(&run("motor-pump-conduction", IdentRun, 2711), "unexplained", 2.83);
    assert_missed(&run("churning-loss", IdentRun, 2709), "unexplained", 4.73);
    // The former false discovery: the twin of 2700 (winding, r 1.4, an
    // identification run) was named `sensor-lag` at P 1.00 with two
    // starts; with three the lag no longer qualifies there (measured:
    // `unexplained`, the case itself `unexplained` too, right below r = 2).
    assert_missed(&run("winding-resistance-temperature", IdentRun, 2700), "unexplained", 1.37);
}

/// The same seven cases with the physical tier's commissioning structure
/// (`DiagnoseOptions::structure`: `eta_m` from the motor current,
/// `pump_friction` held, the friction heat's case share and speed law and
/// the housing probes' reading towards the air fitted), as measured
/// (`eha-sim emulator-sweep --cases original,ident --only
/// 1704,1705,1711,2704,2705,2709,2711 --no-oracle --structure true`).
/// r is on the calibrated baseline, which changes with the set: named at
/// r >= 2, all four: 1705 (no loaded current rows, unchanged, r 2.60),
/// 2704 (r 2.98, t_oil_c 4.02 -> 2.27 K, a miss without), 2705 (r 3.18,
/// 4.41 -> 2.09 K), 2711 (conduction, r 3.17, t_pump_c 3.24 -> 0.77 K, a
/// miss without). Absorbed by the richer set, so below r = 2 and no cause
/// is right by the rule, though the effects were seen without it: 1704
/// (lag, r 1.82, named at r 3.14 without), 1711 (conduction, r 1.06, was
/// 6.36), 2709 (churning, r 0.55, was 4.73: its loss is in the current and
/// so in `eta_m`). No twin names a cause. docs/diagnosis-limits.md, "The
/// structure option". 467 s at load 2–5 on two shared cores (2026-11-27).
#[test]
#[ignore = "slow tier: emulator cases with twins (minutes), the structure option"]
fn slow_imprint_ratio_with_structure() {
    let o = DiagnoseOptions { structure: true.into(), ..DiagnoseOptions::default() };
    assert_named(&run_with("sensor-lag", SpeedSteps, 1705, &o), 2.60, 0.45);
    assert_named(&run_with("sensor-lag", IdentRun, 2704, &o), 2.98, 2.27);
    assert_named(&run_with("sensor-lag", IdentRun, 2705, &o), 3.18, 2.09);
    assert_named(&run_with("motor-pump-conduction", IdentRun, 2711, &o), 3.17, 0.77);
    assert_missed(&run_with("sensor-lag", ConstantThrottle, 1704, &o), "none", 1.82);
    assert_missed(&run_with("motor-pump-conduction", LoadCycles, 1711, &o), "unexplained", 1.06);
    assert_missed(&run_with("churning-loss", IdentRun, 2709, &o), "unexplained", 0.55);
}

/// The same seven cases with the structure option's `no-case` variant
/// (`Structure::NoCase`: as `full` but without the friction heat's case
/// share and the pump probe's placement, which only a drain thermocouple
/// separates), as measured (`eha-sim emulator-sweep --cases original,ident
/// --only 1704,1705,1711,2704,2705,2709,2711 --no-oracle --structure
/// no-case`). Named at r >= 2, three of four: 1705 (unchanged, r 2.60),
/// 2704 (r 2.52, t_oil_c 3.38 -> 2.00 K), 2709 (churning, r 6.97, t_pump_c 2.16 -> 0.74 K: absorbed under `full`,
/// a miss under `off`). Below r = 2, no cause right by the rule: 1704
/// (lag, r 1.70, loop-oil capacity and oil probe at their upper bounds),
/// 1711 (conduction, r 0.64, the pump's outer film and case film at their
/// upper bounds), 2711 (conduction, r 1.88, answered `none`; named at r
/// 3.17 under `full`). No twin names a cause. docs/diagnosis-limits.md, "The
/// structure option". 261 s on two shared cores (2026-11-27, passes).
/// Missed at r >= 2 since the per-channel held-out check counts only the
/// channels a candidate touches: 2705 (r 2.35, `unexplained`; its lag
/// makes t_oil_c worse held out, 2.46 -> 2.80 K, and was named on the
/// pooled 2.21 -> 1.55 K; `eha-sim emulator-sweep --cases ident --only
/// 2705 --no-oracle --structure no-case`, 2026-11-28, diag14; the other
/// six not re-run under this variant).
#[test]
#[ignore = "slow tier: emulator cases with twins (minutes), the structure option's no-case variant"]
fn slow_imprint_ratio_with_structure_no_case() {
    let o = DiagnoseOptions { structure: Structure::NoCase, ..DiagnoseOptions::default() };
    assert_named(&run_with("sensor-lag", SpeedSteps, 1705, &o), 2.60, 0.45);
    assert_named(&run_with("sensor-lag", IdentRun, 2704, &o), 2.52, 2.00);
    assert_missed(&run_with("sensor-lag", IdentRun, 2705, &o), "unexplained", 2.35);
    assert_named(&run_with("churning-loss", IdentRun, 2709, &o), 6.97, 0.74);
    assert_missed(&run_with("sensor-lag", ConstantThrottle, 1704, &o), "none", 1.70);
    assert_missed(&run_with("motor-pump-conduction", LoadCycles, 1711, &o), "unexplained", 0.64);
    assert_missed(&run_with("motor-pump-conduction", IdentRun, 2711, &o), "none", 1.88);
}

/// The same seven cases with the `no-case-held` variant
/// (`Structure::NoCaseHeld`: `no-case` with the loop oil's capacity and the
/// oil probe's response time held at the rig file, the two parameters that
/// carried 1704's lag to their upper bounds under `no-case`), as measured
/// (`eha-sim emulator-sweep --cases original,ident --only
/// 1704,1711,2704,2705,2709,2711 --no-oracle --structure no-case-held`;
/// 1705 has no loaded current rows, unchanged). Named: 1704 (lag, r 6.18,
/// t_oil_c 0.93 -> 0.18 K; absorbed under `full` and `no-case`), 1705
/// (r 2.60), 2704 (r 3.09, 4.92 -> 3.19 K). Below r = 2, no cause right
/// by the rule: 2705 (lag, r 1.82: the twin's t_oil_c floor rose, 1.05 ->
/// 1.23 K; `unexplained` since the per-channel held-out check counts only
/// the channels a candidate touches — the lag's fit makes t_oil_c worse
/// held out, 2.23 -> 3.25 K, and was named before on its gain elsewhere),
/// 1711 (conduction, r 1.81), 2709 (churning, r 0.75, named under
/// `no-case`), 2711 (conduction, r 1.94). No twin names a cause.
/// docs/diagnosis-limits.md, "The structure option". 639 s at load 6–9 on
/// two shared cores (2026-11-28, passes); re-measured with the
/// touched-channel rule by the sweep command above with 1705 and 1708
/// added (2026-11-28, diag14: the same answers but 2705's). Re-measured on
/// the fixed reference (b36ffe3's replay; 2026-11-28, the same
/// command, 331 s for the seven): the same answers; 1704 r 6.01 (t_oil_c
/// 0.90 -> 0.33 K), 1705 r 3.29 (0.76 -> 0.37), 2704 r 3.95 (6.59 -> 1.45);
/// 2705 `unexplained` at r 3.32 now (its twin's t_oil_c floor fell to
/// 0.89 K): a measured miss at r >= 2; 1711 r 0.91, 2709 r 0.46, 2711
/// r 0.48 (their twins' t_pump_c floors rose). Asserted as measured then.
#[test]
#[ignore = "slow tier: emulator cases with twins (minutes), the structure option's no-case-held variant"]
fn slow_imprint_ratio_with_structure_no_case_held() {
    let o = DiagnoseOptions { structure: Structure::NoCaseHeld, ..DiagnoseOptions::default() };
    assert_named(&run_with("sensor-lag", ConstantThrottle, 1704, &o), 6.01, 0.33);
    assert_named(&run_with("sensor-lag", SpeedSteps, 1705, &o), 3.29, 0.37);
    assert_named(&run_with("sensor-lag", IdentRun, 2704, &o), 3.95, 1.45);
    assert_missed(&run_with("sensor-lag", IdentRun, 2705, &o), "unexplained", 3.32);
    assert_missed(&run_with("motor-pump-conduction", LoadCycles, 1711, &o), "unexplained", 0.91);
    assert_missed(&run_with("churning-loss", IdentRun, 2709, &o), "unexplained", 0.46);
    assert_missed(&run_with("motor-pump-conduction", IdentRun, 2711, &o), "unexplained", 0.48);
}

/// `DiagnoseOptions::nominal_restarts` (off by default) on emulator log
/// 2712 (a draught in an identification run): the physical tier's baseline
/// restarted also from every candidate's nominal-start fit finds the twin's
/// better basin (its pooled held-out misfit 2.486 → 0.852 K, t_pump_c
/// 3.07 → 0.64 K, under the option; docs/diagnosis-limits.md, "The calibration's basins"), so r rises
/// from 0.59 (the default, `hidden.rs`) to 3.10 and 2712 becomes a miss at
/// r ≥ 2 (`unexplained`; the draught's fit gains nothing). Asserted as
/// measured (r within 20 %, as the other rows here), and no cause named on
/// the twin.
#[test]
#[ignore = "slow tier: one emulator case with its twin (~2 min)"]
fn slow_nominal_restarts_find_the_twin_of_2712_a_better_basin() {
    let o = DiagnoseOptions { structure: Structure::NoCaseHeld, nominal_restarts: true, ..DiagnoseOptions::default() };
    // (2712: the forced convection in an identification run, `ident_cases`.)
    let r = run_with("forced-convection", IdentRun, 2712, &o);
    assert_missed(&r, "unexplained", 3.10);
    let t = r.twin.as_ref().expect("twin diagnosed");
    // The twin's t_pump_c held out: 3.07 K under the default, 0.64 K here.
    assert!((t.twin_misfit_k - 0.64).abs() < 0.1, "twin t_pump_c held out {:.3} K (measured 0.64)", t.twin_misfit_k);
}
