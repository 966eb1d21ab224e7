//! Diagnosis on logs of the independent rig emulator (`eha_sim::emulator`):
//! a machine built to the paper's tables with its own node
//! split, correlations, parameters (up to ×2.8 off the rig file) and sensor
//! placement, one hidden effect or none. The diagnosis runs blind with the
//! rig file as baseline. Every assertion is the outcome measured with
//! `eha-sim emulator-sweep` (tables in docs/diagnosis-off.md), so a test fails
//! when the outcome changes either way; misses are asserted as misses.
//!
//! Fast tier: a `none` Case 1 log answered `none` (~10 s); slow tier
//! (`--ignored`): a named sensor lag, a conduction below the imprint ratio
//! at which it must be named, a churning miss, two effect-free logs and a
//! hidden forced convection, a speed-step log without discovery, a
//! conduction miss above the floor, a forced convection at one operating
//! point not named as conduction, and an identification run with nothing
//! hidden that the reference's structure cannot follow (`unexplained`).
//! Each case is one 1200 s throttle log at 2 s, 6–40 s to diagnose.

use eha_sim::diagnosis::analysis::Structure;
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

/// The case diagnosed as these outcomes were measured: `--structure off`
/// (the default is `no-case-held` since 2026-11-28; its answers on the
/// sweep's logs are asserted in `imprint.rs`, `effect_free.rs` and
/// `hidden.rs`).
fn run(c: EmuCase) -> EmuResult {
    let o = DiagnoseOptions { structure: Structure::Off, ..DiagnoseOptions::default() };
    let r = run_emu_case(c, &o).expect("emulated log diagnoses");
    eprintln!("{}", eha_sim::diagnosis::emu_sweep::table_row(&r));
    r
}

/// The channels the calibrated baseline misfits, with their held-out RMSE, K.
fn misfits(r: &EmuResult) -> Vec<(&str, f64)> {
    r.channels.iter().filter(|c| c.4).map(|c| (c.0.as_str(), c.1)).collect()
}

/// The hidden effect's own candidate, as the diagnosis fitted it, gains
/// less than `max` on the affected channel (`measured` quoted): the miss is
/// the calibration set absorbing the effect, not a rule failing a fit that
/// would meet the 50 % bar.
fn assert_oracle_under(r: &EmuResult, max: f64, measured: &str) {
    let h = r.hidden_fit.as_ref().expect("hidden candidate fitted");
    let g = h.affected_gain().expect("affected channel");
    assert!(g < max, "hidden candidate's own gain {:.0} % (measured {measured})", 100.0 * g);
}

/// The best candidate by BIC, if any, does not qualify.
fn assert_no_qualifying_candidate(r: &EmuResult) {
    assert!(r.best_candidate.as_ref().is_none_or(|b| !b.3), "best candidate qualifies: {:?}", r.best_candidate);
}

/// `none` on a Case 1 log (seed 1714): with the pump's energy balance the
/// global baseline itself fits (pooled held-out 0.280 K measured) and the
/// answer is `none` without escalation (no false discovery). Tolerances: pooled held-out ≤ 0.3 K (the noise is 0.1 K), the
/// block ≤ 0.3 K and not flagged.
#[test]
fn emulator_none_case1_log_is_none() {
    let (log, _) = generate(&case("none", ConstantThrottle, 1714)).expect("log");
    let model = ReferenceModel::new(Rig::default(), &log).expect("model");
    let d = diagnose(&log, &model, &DiagnoseOptions::default()).expect("diagnosis");
    let j = DiagnosisJson::from_diagnosis(&d);
    eprintln!("cause {} set {} held-out {:.3} K", j.cause, d.nuisance_set, d.before.heldout_rmse_k);
    eprintln!("probabilities {:?}", j.probabilities.iter().map(|p| (p.cause.as_str(), p.probability)).collect::<Vec<_>>());
    assert_eq!(j.cause, "none");
    // An effect-free log: no cause at P >= 0.9, and the probabilities
    // (none, unexplained, six candidates) sum to one.
    assert!(d.posterior.named().is_none(), "{:?}", j.probabilities);
    assert_eq!(j.probabilities.len(), 8);
    assert!((j.probabilities.iter().map(|p| p.probability).sum::<f64>() - 1.0).abs() < 1e-9);
    assert!(j.unexplained.is_none());
    assert!(d.before.heldout_rmse_k <= 0.3, "pooled held-out {:.3} K", d.before.heldout_rmse_k);
    let block = d.adequacy.channels.iter().find(|c| c.channel == "t_block_c").expect("t_block_c");
    assert!(block.heldout_rmse_k <= 0.3 && !block.misfit, "t_block_c {:.3} K", block.heldout_rmse_k);
}

/// Dead-end oil sensor (τ 203 s hidden) on a Case 1 log (seed 1704): named.
#[test]
#[ignore = "slow tier: emulator case"]
fn slow_emulator_sensor_lag_is_named() {
    // Measured with the oils on their viscosity lines and the oil probe's
    // response time in the physical set (the 1700 sweep, twice, same
    // numbers): named, t_oil_c held out 0.45 -> 0.24 K, 46 % (the
    // calibrated probe takes up part of the pocket's lag; r = 3.1 against
    // its twin). Asserted: named, gain 35-50 %, so a change either way shows.
    let r = run(case("sensor-lag", ConstantThrottle, 1704));
    assert!(r.hit(), "answer {}", r.answer);
    let g = r.affected_gain().expect("affected channel");
    assert!((0.35..0.5).contains(&g), "held-out gain {:.0} % (measured 46 %)", 100.0 * g);
}

/// Motor–pump conduction (4.0 W/K) on a Case 1 log (seed 1710). This log
/// once had two qualifying candidates (forced convection with the lower
/// BIC, conduction with the lower held-out error); where two qualify, the
/// posterior probability decides (`diagnosis::evidence`). Its answer now is
/// `none` (below).
#[test]
#[ignore = "slow tier: emulator case"]
fn slow_emulator_conduction_is_named_over_a_qualifying_forced_convection() {
    // Measured since the oils are on their viscosity lines (1700 sweep,
    // twice): `none`. The conduction fit gains 53 % on t_pump_c but does not
    // qualify: at one operating point a motor-pump path is a change of both
    // housings' heat paths, which the physical set carries (the
    // identifiability rule). Its imprint ratio against the twin is 1.8,
    // under the r >= 2 at which a diagnosis must name it, so `none` is a
    // right answer here; the test keeps its name as the record of the case.
    let r = run(case("motor-pump-conduction", ConstantThrottle, 1710));
    assert_eq!(r.answer, "none", "measured outcome changed");
    let h = r.hidden_fit.as_ref().expect("hidden candidate fitted");
    assert!(!h.qualifies && h.note.contains("one operating point"), "oracle {h:?} (measured: not qualifying, one operating point)");
    assert_no_qualifying_candidate(&r);
}

/// Churning (4.8e-4 W/(rad/s)^2.5) in speed steps (seed 1708, r 1.4 against
/// its twin, below the r = 2 at which it must be named). **Measured
/// miss**: answered `none`. The baseline refitted from the best candidates'
/// nuisance values fits t_pump_c to 0.36 K held out, its viscous pump
/// friction (C_v·μ·D·ω², scaled by `pump_friction`) taking up most of the
/// ω^2.5 loss. With the third candidate start (the calibrated baseline with
/// churning at its typical magnitude) the churning fit finds the effect:
/// best candidate, ΔBIC 44.9, t_pump_c 0.36 → 0.17 K held out (53 %), but
/// the pooled held-out RMSE falls only 0.448 → 0.407 K (9 %, under the
/// 20 % pooled bar), so it does not qualify (with two starts it gained −3 %).
/// Asserted: `none`, the best candidate churning and not qualifying, its
/// gain on t_pump_c 40–65 % (measured 53 %), t_pump_c calibrated ≤ 0.4 K
/// held out (4σ of the 0.1 K noise).
#[test]
#[ignore = "slow tier: emulator case, measured miss"]
fn slow_emulator_churning_measured_miss() {
    let r = run(case("churning-loss", SpeedSteps, 1708));
    assert_eq!(r.answer, "none", "measured outcome changed");
    let (name, _, _, qualifies) = r.best_candidate.clone().expect("a best candidate");
    assert!(name == "churning-loss" && !qualifies, "best candidate {name} qualifies {qualifies} (measured: churning-loss, not qualifying)");
    let (before, _) = r.affected_heldout_k.expect("affected channel");
    assert!(before <= 0.4, "t_pump_c calibrated held-out {before:.3} K (measured 0.36)");
    let h = r.hidden_fit.as_ref().expect("hidden candidate fitted");
    let g = h.affected_gain().expect("affected channel");
    assert!((0.4..0.65).contains(&g), "churning's own gain on t_pump_c {:.0} % (measured 53 %)", 100.0 * g);
    assert!(h.pooled_heldout_k.1 > 0.8 * h.pooled_heldout_k.0, "pooled {:?} (measured 0.448 -> 0.407 K, under the 20 % bar)", h.pooled_heldout_k);
}

// (No viscosity case: the emulator's and the reference's oil both follow
// their viscosity lines in the baseline, so there is no candidate for it.)

/// Two logs: the effect-free load-cycle log (seed 1715) and a hidden forced
/// convection (7.9 m/s) on a Case 1 log (seed 1712). The oil probe's
/// response time is in the physical set because the emulator's oil
/// thermowell answers in 6 s and the reference's probe in 2 s. The forced
/// convection is answered `none`: the calibrated baseline fits every
/// channel to 1–3σ (pooled held-out 0.15 K), the ram-air share of the pump
/// housing and `h_out_pump` having taken the imprint up — a miss, not a
/// false discovery, asserted as measured.
#[test]
#[ignore = "slow tier: emulator cases, measured shortfall"]
fn slow_emulator_former_unexplained_answers() {
    // Measured since the oils are on their viscosity lines (1700 sweep,
    // twice): the effect-free load-cycle log 1715 is `unexplained` again,
    // t_oil_c misfitting by 1.58 K held out (18σ; pooled 0.84 K): the oil
    // channel's structural miss at high flow. Asserted as measured: no
    // cause named, t_oil_c flagged.
    let a = run(case("none", LoadCycles, 1715));
    assert_eq!(a.answer, "unexplained", "measured outcome changed");
    assert!(misfits(&a).iter().any(|(c, k)| *c == "t_oil_c" && *k >= 1.0), "misfits {:?} (measured t_oil_c 1.58 K)", misfits(&a));
    let b = run(case("forced-convection", ConstantThrottle, 1712));
    assert_eq!(b.answer, "none", "measured outcome changed");
    assert!(b.pooled_heldout_k[1] <= 0.2, "pooled {:.2} K (measured 0.15)", b.pooled_heldout_k[1]);
}

/// The speed-step `none` log (seed 1716): no discovery. A baseline fitted
/// from a single start sat in a worse basin of the physical set than a
/// conduction fit, which then qualified (a false discovery); refitted from
/// the best candidates' nuisance values once a candidate qualifies, the
/// baseline fits and conduction does not qualify. Asserted: `none`, the
/// best candidate not qualifying.
#[test]
#[ignore = "slow tier: emulator case, former false discovery"]
fn slow_emulator_speed_steps_none_log_is_no_discovery() {
    let r = run(case("none", SpeedSteps, 1716));
    assert_eq!(r.answer, "none", "measured outcome changed");
    let calibrated = r.pooled_heldout_k[1];
    // Re-measured with the oils on their viscosity lines: 0.27 K (was 0.22);
    // bound 0.3 K, three times the 0.1 K sensor noise.
    assert!(calibrated <= 0.3, "calibrated pooled held-out {calibrated:.3} K (measured 0.27)");
    assert_no_qualifying_candidate(&r);
}

/// Motor–pump conduction (5.3 W/K) in load cycles (seed 1711). A global
/// baseline that passes a loose adequacy rule must still escalate to the
/// physical set when a channel misfits: the answer is never `none` next
/// to a misfit.
#[test]
#[ignore = "slow tier: emulator case, measured miss"]
fn slow_emulator_conduction_in_load_cycles_is_absorbed() {
    // Measured since the oils are on their viscosity lines (1700 sweep,
    // twice): `unexplained`, not absorbed. The calibrated baseline misfits
    // t_pump_c by 2.38 K held out (20σ), the block and the oil too; the
    // conduction candidate's own fit gains nothing on t_pump_c. Its imprint
    // ratio against the twin is 6.5: the effect stands clear of the floor
    // and should be named — a measured miss of the diagnosis, asserted as
    // measured (no wrong cause; t_pump_c flagged; the oracle under 30 %).
    let r = run(case("motor-pump-conduction", LoadCycles, 1711));
    assert_eq!(r.answer, "unexplained", "measured outcome changed");
    assert!(misfits(&r).iter().any(|(c, k)| *c == "t_pump_c" && *k >= 1.5), "misfits {:?} (measured t_pump_c 2.38 K)", misfits(&r));
    assert_oracle_under(&r, 0.3, "-1 %");
}

/// Forced convection (7.3 m/s) hidden in a constant-throttle log of the
/// second seed set (seed 1812). Both forced convection and motor–pump
/// conduction add a heat path out of the pump housing, and the log has one
/// operating point: conduction was once named here (73 % on t_pump_c), a
/// wrong cause. With conduction not identifiable there under the
/// per-housing set (`diagnosis::identify`) the answer is `none` (measured;
/// pooled calibrated held-out 0.33 K).
/// Asserted: `none`, no qualifying candidate.
#[test]
#[ignore = "slow tier: emulator case, former wrong cause"]
fn slow_emulator_forced_convection_at_one_point_is_not_named_conduction() {
    let r = run(case("forced-convection", ConstantThrottle, 1812));
    assert_eq!(r.answer, "none", "measured outcome changed");
    assert_no_qualifying_candidate(&r);
}

/// An identification run with nothing hidden (seed 2714: speed, load and
/// ram air stepped independently, the campaign a thermal engineer would
/// design): the emulator's structure shows and the answer is `unexplained`,
/// not `none` and not a false discovery. The model is built without
/// `with_structure`, so this is the physical set as under `off`.
/// Measured on the fixed reference (b36ffe3's replay; 2026-11-28): the
/// physical set fits the training window to 0.468 K pooled and misses the
/// held-out window by 1.140 K: t_pump_c 1.903 K (reads colder than the
/// model) and t_oil_c 1.103 K (warmer) flagged as misfits, t_block_c
/// 0.882 K no longer flagged; the oil's residuals follow the motor–pump
/// temperature difference (ρ +0.68) and the report sends the user to metal
/// paths from the pump to the motor flange and the valve block — the
/// emulator's bolted pump end cap ↔ manifold plate, a metal path the
/// reference does not have. Before the fix: training 0.415 K, held-out
/// 0.929 K, t_pump_c 1.258 K, t_block_c 1.043 K and t_oil_c 1.198 K
/// flagged, the advice naming the pump's mounting on the block.
/// Tolerances: held-out pooled ≥ 0.85 K, the pump ≥ 1.4 K and the oil
/// ≥ 0.8 K flagged as misfits (a structure floor 8–14σ above the 0.1 K
/// noise, each about a quarter below the measured value), training ≤
/// 0.50 K (7 % above the measured value, as 0.45 K was above 0.415 K).
#[test]
#[ignore = "slow tier: emulator identification run, measured structure floor"]
fn slow_emulator_identification_run_none_is_unexplained() {
    let (log, _) = generate(&case("none", EmuScenario::IdentRun, 2714)).expect("log");
    let model = ReferenceModel::new(Rig::default(), &log).expect("model");
    let d = diagnose(&log, &model, &DiagnoseOptions::default()).expect("diagnosis");
    let j = DiagnosisJson::from_diagnosis(&d);
    eprintln!("cause {} training {:.3} K held-out {:.3} K", j.cause, d.before.train_rmse_k, d.before.heldout_rmse_k);
    for c in &d.adequacy.channels {
        eprintln!("  {} held-out {:.3} K misfit {}", c.channel, c.heldout_rmse_k, c.misfit);
    }
    if let Some(u) = &j.unexplained {
        eprintln!("  advice:\n{}", u.check.join("\n"));
    }
    assert_eq!(j.cause, "unexplained", "measured outcome changed");
    assert!(d.before.heldout_rmse_k >= 0.85, "pooled held-out {:.3} K (measured 1.140)", d.before.heldout_rmse_k);
    assert!(d.before.train_rmse_k <= 0.50, "pooled training {:.3} K (measured 0.468)", d.before.train_rmse_k);
    let ch = |n: &str| d.adequacy.channels.iter().find(|c| c.channel == n).expect("channel");
    let (pump, oil) = (ch("t_pump_c"), ch("t_oil_c"));
    assert!(pump.misfit && pump.heldout_rmse_k >= 1.4, "t_pump_c {:.3} K (measured 1.903)", pump.heldout_rmse_k);
    assert!(oil.misfit && oil.heldout_rmse_k >= 0.8, "t_oil_c {:.3} K (measured 1.103)", oil.heldout_rmse_k);
    let check = j.unexplained.expect("unexplained section").check.join("\n");
    assert!(check.contains("flange") && check.contains("valve block"), "advice:\n{check}");
}
