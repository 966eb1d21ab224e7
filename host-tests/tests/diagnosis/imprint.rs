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

/// The mismatches of one test's cases against their measured outcome,
/// collected and asserted at the end ([`Checks::done`]), so that one run
/// reports every case (a re-measurement needs them all).
#[derive(Default)]
struct Checks(Vec<String>);

impl Checks {
    /// A hidden effect named: the answer, r within 20 % of the measured
    /// value (the calibrated baselines of log and twin move with the fits'
    /// last digits), the held-out RMSE on the affected channel within
    /// ±0.1 K of the measured after-value, and the twin names no cause.
    fn named(&mut self, r: &EmuResult, ratio: f64, after_k: f64) {
        let seed = r.case.seed;
        if !r.hit() {
            self.0.push(format!("{seed}: answer {} (measured: named)", r.answer));
        }
        self.ratio_and_twin(r, ratio, None);
        let (_, a) = r.affected_heldout_k.expect("affected channel");
        if (a - after_k).abs() > 0.1 {
            self.0.push(format!("{seed}: affected held-out after {a:.2} K (measured {after_k})"));
        }
    }

    /// A measured miss: no cause named (`unexplained` or `none`, as
    /// measured), in particular no wrong cause, and no discovery on the twin.
    fn missed(&mut self, r: &EmuResult, answer: &str, ratio: f64) {
        self.missed_with_twin(r, answer, ratio, None);
    }

    /// [`Self::missed`] with a measured false discovery on the twin: its
    /// answer `twin_cause`.
    fn missed_twin_named(&mut self, r: &EmuResult, answer: &str, ratio: f64, twin_cause: &str) {
        self.missed_with_twin(r, answer, ratio, Some(twin_cause));
    }

    /// The body of both: the answer as measured, then r and the twin.
    fn missed_with_twin(&mut self, r: &EmuResult, answer: &str, ratio: f64, twin_cause: Option<&str>) {
        if r.answer != answer {
            self.0.push(format!("{}: answer {} (measured {answer})", r.case.seed, r.answer));
        }
        self.ratio_and_twin(r, ratio, twin_cause);
    }

    /// r within 20 % of `ratio`; the twin's answer `twin_cause` when given
    /// (a measured false discovery), else no cause.
    fn ratio_and_twin(&mut self, r: &EmuResult, ratio: f64, twin_cause: Option<&str>) {
        let (rr, ta) = twin(r);
        eprintln!("{}: {} r {rr:.2} (asserted {ratio}), twin {ta}", r.case.seed, r.answer);
        if (rr / ratio - 1.0).abs() >= 0.2 {
            self.0.push(format!("{}: r {rr:.2} (measured {ratio})", r.case.seed));
        }
        match twin_cause {
            Some(c) if ta != c => self.0.push(format!("{}: twin answered {ta} (measured {c})", r.case.seed)),
            None if !(ta == "none" || ta == "unexplained") => self.0.push(format!("{}: twin answered {ta}: a false discovery", r.case.seed)),
            _ => {}
        }
    }

    /// Fails with every mismatch.
    fn done(self) {
        assert!(self.0.is_empty(), "measured outcomes changed:\n{}", self.0.join("\n"));
    }
}

/// Dead-end oil pockets under `--structure off`, re-measured 2026-11-29
/// (the values asserted before were measured on 2026-11-27, before the
/// reference's replay fix b36ffe3, and the test had failed since; 1704's
/// within the tolerance and kept): 1704 (Case 1, τ 203 s, r 3.1), 1705
/// (speed steps, τ 117 s, r 3.29), 2705 (identification run, τ 145 s,
/// r 2.54) and now 2704 (identification run, τ 69 s, r ≈ 2.1, a miss
/// before: the lag qualifies, pooled 2.46 → 1.54 K) named `sensor-lag`
/// (t_oil_c held out 0.36 → 0.22, 0.76 → 0.37, 3.54 → 2.02, 3.78 → 1.71 K).
#[test]
#[ignore = "slow tier: emulator cases with twins (minutes)"]
#[allow(clippy::approx_constant)] // 3.14 is 1704's measured imprint ratio, not π
fn slow_imprint_ratio_above_two_sensor_lag() {
    let mut c = Checks::default();
    c.named(&run("sensor-lag", ConstantThrottle, 1704), 3.14, 0.24);
    c.named(&run("sensor-lag", SpeedSteps, 1705), 3.29, 0.37);
    c.named(&run("sensor-lag", IdentRun, 2705), 2.54, 2.02);
    c.named(&run("sensor-lag", IdentRun, 2704), 2.10, 1.71);
    c.done();
}

/// Motor–pump conduction (1711, load cycles, 5.3 W/K; 2711,
/// identification run, 5.7 W/K), churning (2709, identification run,
/// 4.9e-4 W/(rad/s)^2.5) and the winding's coefficient (2700), under
/// `--structure off`: `unexplained` all four. Re-measured 2026-11-29 (the
/// values asserted before were measured on 2026-11-27, before the
/// reference's replay fix b36ffe3, and the test had failed since): 1711
/// at r 9.71 (6.36 then), a miss at r ≥ 2; 2711 r 0.79, 2709 r 0.43 and
/// 2700 r 0.61 now below r = 2 (2.83, 4.73, 1.37 then), where no cause is
/// right. No twin names a cause (the twin of 2700 was once `sensor-lag`,
/// with two candidate starts). docs/diagnosis-limits.md.
#[test]
#[ignore = "slow tier: emulator cases with twins (minutes), measured misses"]
fn slow_imprint_ratio_above_two_housing_paths_and_churning_missed() {
    let mut c = Checks::default();
    c.missed(&run("motor-pump-conduction", LoadCycles, 1711), "unexplained", 9.71);
    c.missed(&run("motor-pump-conduction", IdentRun, 2711), "unexplained", 0.79);
    c.missed(&run("churning-loss", IdentRun, 2709), "unexplained", 0.43);
    // The former false discovery: the twin of 2700 (winding, an
    // identification run) was named `sensor-lag` at P 1.00 with two
    // starts; with three the lag no longer qualifies there.
    c.missed(&run("winding-resistance-temperature", IdentRun, 2700), "unexplained", 0.61);
    c.done();
}

/// The same seven cases with the physical tier's commissioning structure
/// (`--structure full`: `eta_m` from the motor current, `pump_friction`
/// held, the friction heat's case share and speed law and the housing
/// probes' reading towards the air fitted). Re-measured 2026-11-29 (the
/// values asserted before were measured on 2026-11-27, before the
/// reference's replay fix b36ffe3, when this variant named 1705, 2704,
/// 2705 and 2711; the test had failed since): named only 1705 (r 3.29);
/// misses at r ≥ 2: 2705 (r 2.01), 1711 (r 3.31), 2709 (r 2.81), all
/// `unexplained`; below r = 2: 1704 (`none`, r 1.8), 2704 (r 1.67), 2711
/// (r 0.61) — and **2711's twin is named `motor-pump-conduction`, a false
/// discovery** under this variant (not the default). Asserted as measured.
/// docs/diagnosis-limits.md, "The structure option".
#[test]
#[ignore = "slow tier: emulator cases with twins (minutes), the structure option"]
fn slow_imprint_ratio_with_structure() {
    let o = DiagnoseOptions { structure: true.into(), ..DiagnoseOptions::default() };
    let mut c = Checks::default();
    c.named(&run_with("sensor-lag", SpeedSteps, 1705, &o), 3.29, 0.37);
    c.missed(&run_with("sensor-lag", IdentRun, 2704, &o), "unexplained", 1.67);
    c.missed(&run_with("sensor-lag", IdentRun, 2705, &o), "unexplained", 2.01);
    c.missed_twin_named(&run_with("motor-pump-conduction", IdentRun, 2711, &o), "unexplained", 0.61, "motor-pump-conduction");
    c.missed(&run_with("sensor-lag", ConstantThrottle, 1704, &o), "none", 1.82);
    c.missed(&run_with("motor-pump-conduction", LoadCycles, 1711, &o), "unexplained", 3.31);
    c.missed(&run_with("churning-loss", IdentRun, 2709, &o), "unexplained", 2.81);
    c.done();
}

/// The same seven cases with the structure option's `no-case` variant
/// (`Structure::NoCase`: as `full` but without the friction heat's case
/// share and the pump probe's placement, which only a drain thermocouple
/// separates). Re-measured 2026-11-29 (the values asserted before were
/// measured on 2026-11-27/28, before the reference's replay fix b36ffe3,
/// when this variant named 1705, 2704 and 2709; the test had failed
/// since): named 1705 (r 3.29) and 2711 (`motor-pump-conduction`, r 3.62,
/// t_pump_c 1.58 → 1.23 K); misses at r ≥ 2: 2705 (r 2.35), 2709
/// (r 4.13), `unexplained`; below r = 2: 1704 (`none`, r 1.7), 2704
/// (r 1.44), 1711 (r 1.47). No twin names a cause. Asserted as measured.
/// docs/diagnosis-limits.md, "The structure option".
#[test]
#[ignore = "slow tier: emulator cases with twins (minutes), the structure option's no-case variant"]
fn slow_imprint_ratio_with_structure_no_case() {
    let o = DiagnoseOptions { structure: Structure::NoCase, ..DiagnoseOptions::default() };
    let mut c = Checks::default();
    c.named(&run_with("sensor-lag", SpeedSteps, 1705, &o), 3.29, 0.37);
    c.missed(&run_with("sensor-lag", IdentRun, 2704, &o), "unexplained", 1.44);
    c.missed(&run_with("sensor-lag", IdentRun, 2705, &o), "unexplained", 2.35);
    c.missed(&run_with("churning-loss", IdentRun, 2709, &o), "unexplained", 4.13);
    c.missed(&run_with("sensor-lag", ConstantThrottle, 1704, &o), "none", 1.70);
    c.missed(&run_with("motor-pump-conduction", LoadCycles, 1711, &o), "unexplained", 1.47);
    c.named(&run_with("motor-pump-conduction", IdentRun, 2711, &o), 3.62, 1.23);
    c.done();
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
    let mut c = Checks::default();
    c.named(&run_with("sensor-lag", ConstantThrottle, 1704, &o), 6.01, 0.33);
    c.named(&run_with("sensor-lag", SpeedSteps, 1705, &o), 3.29, 0.37);
    c.named(&run_with("sensor-lag", IdentRun, 2704, &o), 3.95, 1.45);
    c.missed(&run_with("sensor-lag", IdentRun, 2705, &o), "unexplained", 3.32);
    c.missed(&run_with("motor-pump-conduction", LoadCycles, 1711, &o), "unexplained", 0.91);
    c.missed(&run_with("churning-loss", IdentRun, 2709, &o), "unexplained", 0.46);
    c.missed(&run_with("motor-pump-conduction", IdentRun, 2711, &o), "unexplained", 0.48);
    c.done();
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
    let mut c = Checks::default();
    c.missed(&r, "unexplained", 3.10);
    c.done();
    let t = r.twin.as_ref().expect("twin diagnosed");
    // The twin's t_pump_c held out: 3.07 K under the default, 0.64 K here.
    assert!((t.twin_misfit_k - 0.64).abs() < 0.1, "twin t_pump_c held out {:.3} K (measured 0.64)", t.twin_misfit_k);
}
