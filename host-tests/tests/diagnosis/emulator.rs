//! Diagnosis on logs of the independent rig emulator (`eha_sim::emulator`,
//! issue 17): a machine built to the paper's tables with its own node
//! split, correlations, parameters (up to ×2.8 off the rig file) and sensor
//! placement, one hidden effect or none. The diagnosis runs blind with the
//! rig file as baseline. Every assertion is the outcome measured with
//! `eha-sim emulator-sweep` (table in docs/diagnosis.md), so a test fails
//! when the outcome changes either way; misses are asserted as misses.
//!
//! Fast tier: the `unexplained` answer on a `none` Case 1 log, with its
//! evidence (~9 s); slow tier (`--ignored`): two named effects, the
//! viscosity case that is named under the 50 % gain bar, and two more
//! `unexplained` answers (one of them a hidden effect that is missed).
//! Each case is one 1200 s throttle log at 2 s, 6–20 s to diagnose.

use eha_sim::diagnosis::emu_sweep::{run_emu_case, EmuResult};
use eha_sim::diagnosis::reference::ReferenceModel;
use eha_sim::diagnosis::report::DiagnosisJson;
use eha_sim::diagnosis::{diagnose, Candidate, DiagnoseOptions};
use eha_sim::emulator::missions::EmuScenario::{self, ConstantThrottle, LoadCycles, SpeedSteps};
use eha_sim::emulator::{generate, EmuCase};
use eha_sim::rig::Rig;

fn case(hidden: &str, scenario: EmuScenario, seed: u64) -> EmuCase {
    EmuCase { hidden: Candidate::from_name(hidden).expect("candidate"), scenario, seed, duration_s: 1200.0 }
}

fn run(c: EmuCase) -> EmuResult {
    let r = run_emu_case(c, &DiagnoseOptions::default()).expect("emulated log diagnoses");
    eprintln!("{}", eha_sim::diagnosis::emu_sweep::table_row(&r));
    r
}

/// A named effect: the answer is the hidden cause and the affected
/// channel's held-out RMSE falls by ≥ 50 % (issue 5's bar).
fn assert_named(r: &EmuResult) {
    assert!(r.hit(), "answer {} for hidden {}", r.answer, r.case.hidden.name());
    let g = r.affected_gain().expect("affected channel");
    assert!(g >= 0.5, "held-out gain {:.0} % < 50 %", 100.0 * g);
}

/// `none` on a Case 1 log (seed 1714): the calibrated baseline misfits
/// t_block_c by 1.04 K held out (12σ of its noise, 37 % of its 2.8 K
/// rise), no candidate qualifies, so the answer is `unexplained`, with the
/// misfit channel, the noise estimate, `outer_scale` on its lower bound and
/// advice in diagnosis.json. Tolerances: the block misfit within
/// 0.7–1.5 K (±35 % of the measured 1.04 K, room for changes of the fit
/// that keep the structural misfit), the noise estimate 0.07–0.13 K (the
/// emulator's σ is 0.1 K plus 12-bit quantisation).
#[test]
fn emulator_none_case1_log_is_unexplained_with_evidence() {
    let (log, _) = generate(&case("none", ConstantThrottle, 1714)).expect("log");
    let model = ReferenceModel::new(Rig::default(), &log).expect("model");
    let d = diagnose(&log, &model, &DiagnoseOptions::default()).expect("diagnosis");
    let j = DiagnosisJson::from_diagnosis(&d);
    assert_eq!(j.cause, "unexplained");
    assert!(d.ranking.iter().all(|r| !r.qualifies), "no candidate qualifies");
    let u = j.unexplained.as_ref().expect("unexplained evidence");
    let block = u.misfit_channels.iter().find(|c| c.channel == "t_block_c").expect("t_block_c misfits");
    assert!((0.7..1.5).contains(&block.heldout_rmse_k), "t_block_c {:.3} K", block.heldout_rmse_k);
    assert!((0.07..0.13).contains(&block.noise_k), "noise {:.3} K", block.noise_k);
    assert!(block.heldout_rmse_k > 5.0 * block.noise_k);
    assert!(!block.correlates_with.is_empty());
    assert!(u.parameters_at_bounds.contains_key("outer_scale"), "{:?}", u.parameters_at_bounds);
    assert!(u.check.iter().any(|c| c.contains("t_block_c")), "{:?}", u.check);
    let text = serde_json::to_string(&j).expect("json");
    assert!(text.contains("\"unexplained\":{"), "the evidence is in diagnosis.json");
}

/// Dead-end oil sensor (τ 203 s hidden) on a Case 1 log (seed 1704):
/// named, t_oil_c held out 1.40 → 0.10 K (93 %) measured.
#[test]
#[ignore = "slow tier: emulator case"]
fn slow_emulator_sensor_lag_is_named() {
    assert_named(&run(case("sensor-lag", ConstantThrottle, 1704)));
}

/// Churning (4.8e-4 W/(rad/s)^2.5) in speed steps (seed 1708): named,
/// t_pump_c 4.72 → 1.22 K (74 %) measured.
#[test]
#[ignore = "slow tier: emulator case"]
fn slow_emulator_churning_is_named() {
    assert_named(&run(case("churning-loss", SpeedSteps, 1708)));
}

/// Viscosity in load cycles (seed 1702): named, but t_oil_c only
/// 10.71 → 5.78 K (46 %, under the 50 % bar) measured: the remaining
/// structural misfit stays. Asserts the measured outcome: named, gain in
/// 35–50 %.
#[test]
#[ignore = "slow tier: emulator case, measured shortfall"]
fn slow_emulator_viscosity_is_named_under_the_gain_bar() {
    let r = run(case("viscosity-temperature", LoadCycles, 1702));
    assert!(r.hit(), "answer {}", r.answer);
    let g = r.affected_gain().expect("affected");
    assert!((0.35..0.5).contains(&g), "gain {:.0} % (measured 46 %)", 100.0 * g);
}

/// `unexplained` where the misfit is large (load cycles, seed 1715: pooled
/// held-out 3.21 K, t_block_c 4.82 K) and a measured miss: the hidden
/// forced convection (7.9 m/s) on a Case 1 log (seed 1712) is not named
/// (its imprint, 0.94 K on t_pump_c, is taken up by the calibration; the
/// block misfits by 0.91 K), answer `unexplained`.
#[test]
#[ignore = "slow tier: emulator cases, measured miss"]
fn slow_emulator_unexplained_answers() {
    let a = run(case("none", LoadCycles, 1715));
    assert_eq!(a.answer, "unexplained");
    assert!(a.pooled_heldout_k[1] > 2.0, "pooled {:.2} K (measured 3.21)", a.pooled_heldout_k[1]);
    let b = run(case("forced-convection", ConstantThrottle, 1712));
    assert_eq!(b.answer, "unexplained", "measured miss changed");
}
