//! Recovery on synthetic logs of the reference model whose rig differs from
//! the rig file by known multipliers of the calibration set (per-housing,
//! not global), two training missions, one held-out mission of another kind.

use eha_sim::calibration::synthetic::{log, mission, Kind};
use eha_sim::calibration::{apply, calibrate, channel_errors, set, CalLog, CalOptions, Status};
use eha_sim::rig::Rig;

const TRUTH: [(&str, f64); 8] = [
    ("h_out_pump", 1.4),
    ("h_out_main_block", 0.7),
    ("film_loop", 0.6),
    ("cap_main_block", 1.3),
    ("cap_pump", 0.8),
    ("winding_r", 1.15),
    ("pump_friction", 0.7),
    ("film_case", 1.8),
];

fn cal_log(truth: &Rig, kind: Kind, seed: u64) -> CalLog {
    CalLog::new(&format!("{kind:?}-{seed}"), log(truth, &mission(kind, 1800.0, seed), 2.0, seed, true).expect("log"), 120).expect("cal log")
}

/// Pressure steps + speed steps (30 min each, 2 s, drain thermocouple)
/// from a rig with eight multipliers off; held out: a soak then mixed
/// segments. Measured with the oil on its viscosity line (one run, 8 s, 536
/// model runs): χ² 3.7e5 → 570 on 1449 points (σ_d = 0.2 K; the truth gives
/// 831), the four well-excited parameters within 8 % of the truth in ln, the
/// pump triad's ratios within 5 % (its common factor +22 %, see below),
/// held-out RMSE 0.11–0.16 K per channel (rig as given 0.55–5.4 K). `winding_r` is held (the motor sensor
/// sees it only together with the motor capacity: posterior/prior 74 %).
#[test]
fn recovers_multipliers_from_two_missions() {
    let base = Rig::default();
    let mut th = set::nominal();
    for (name, v) in TRUTH {
        th[set::index(name).expect(name)] = v;
    }
    let truth = apply(&base, &th);
    let logs = [cal_log(&truth, Kind::PressureSteps, 11), cal_log(&truth, Kind::SpeedSteps, 12)];
    let chi2_truth: f64 = logs.iter().map(|l| l.residuals(&l.simulate(&truth).expect("sim")).iter().map(|x| (x / 0.2).powi(2)).sum::<f64>()).sum();
    let c = calibrate(&base, &logs, &CalOptions::default()).expect("calibration");
    eprintln!("{} runs, chi2 {:.0} -> {:.0} (truth {chi2_truth:.0}) over {}", c.model_runs, c.chi2_before_after.0, c.chi2_before_after.1, c.n_points);
    for (p, t) in c.params.iter().zip(&th) {
        eprintln!("{:18} true {:5.2} fit {:6.3} [{:6.3}, {:6.3}] {:?}", p.name, t, p.value, p.interval95.0, p.interval95.1, p.status);
    }
    // The fit reaches the noise level: within 1.5× of the truth's own χ²
    // (the noise floor; 1.5× leaves room for the replay's interpolation).
    assert!(c.chi2_before_after.1 <= 1.5 * chi2_truth, "chi2 {:.0} vs truth {chi2_truth:.0}", c.chi2_before_after.1);
    // Well-excited parameters: within 15 % (ln) of the truth — two 30-min
    // missions with 0.1 K noise pin these to a few %; measured ≤ 7.5 %.
    for name in ["h_out_main_block", "film_loop", "cap_pump", "cap_main_block"] {
        let k = set::index(name).expect(name);
        assert_eq!(c.params[k].status, Status::Fitted, "{name} fitted");
        let e = (c.params[k].value / th[k]).ln().abs();
        assert!(e <= 0.15, "{name}: fit {:.3} true {:.3}", c.params[k].value, th[k]);
    }
    // The pump housing's triad h_out_pump / film_case / pump_friction: the
    // friction heat enters the pump and leaves through the housing's outer
    // transfer and the case film, so scaling all three (and the pump's
    // capacities) by one factor leaves the temperatures nearly unchanged. The
    // data pin the ratios, not the common factor. Measured with the oil on its
    // viscosity line: the three 25 / 21 / 21 % high together (ln 0.254 /
    // 0.206 / 0.208; 17 % with the constant-viscosity oil), cap_pump +13 %,
    // cap_case_oil +20 % (reported correlations: film_case–pump_friction
    // 0.99, cap_case_oil–pump_friction 0.98, h_out_pump–pump_friction 0.94),
    // χ² below the truth's; the ratios
    // h_out_pump/pump_friction and film_case/pump_friction within 4.6 % and
    // 0.1 %. Asserted: each fitted; the two ratios within 10 % (ln) (the
    // well-excited parameters' bound is 15 %; the ratios are pinned as well);
    // the common factor (mean ln error of the three) within 25 % (the bound
    // each member had, now on what the members share: measured 22.3 %); and
    // the report names the triad as correlated, so a user sees why.
    let ln_err = |name: &str| -> f64 {
        let k = set::index(name).expect(name);
        assert_eq!(c.params[k].status, Status::Fitted, "{name} fitted");
        (c.params[k].value / th[k]).ln()
    };
    let (e_out, e_case, e_fric) = (ln_err("h_out_pump"), ln_err("film_case"), ln_err("pump_friction"));
    let common = (e_out + e_case + e_fric) / 3.0;
    eprintln!(
        "triad ln errors: h_out_pump {e_out:+.3}, film_case {e_case:+.3}, pump_friction {e_fric:+.3}; common {common:+.3}; ratios to pump_friction {:+.3} / {:+.3}",
        e_out - e_fric,
        e_case - e_fric
    );
    assert!((e_out - e_fric).abs() <= 0.10, "h_out_pump/pump_friction off by {:.3} in ln", e_out - e_fric);
    assert!((e_case - e_fric).abs() <= 0.10, "film_case/pump_friction off by {:.3} in ln", e_case - e_fric);
    assert!(common.abs() <= 0.25, "the triad's common factor off by {common:.3} in ln");
    for c2 in &c.ident.correlated {
        eprintln!("correlated: {} {} {:.2}", c2.0, c2.1, c2.2);
    }
    assert!(
        c.ident.correlated.iter().any(|(a, b, _)| [a.as_str(), b.as_str()].iter().all(|n| ["h_out_pump", "film_case", "pump_friction"].contains(n))),
        "the triad must be reported as correlated"
    );
    // Held out, a mission of another kind: every channel within 0.25 K RMS
    // (2.5σ of the sensor noise; measured 0.10–0.16 K) where the rig as
    // given misses by > 0.5 K on every channel.
    let hold = cal_log(&truth, Kind::SoakThenMixed, 13);
    let before = channel_errors(&hold, &hold.simulate(&base).expect("sim"));
    let after = channel_errors(&hold, &hold.simulate(&c.rig).expect("sim"));
    for (b, a) in before.iter().zip(&after) {
        eprintln!("{:14} held-out RMSE {:.3} -> {:.3} K, max {:.3} -> {:.3}", a.channel, b.rmse_k, a.rmse_k, b.max_abs_k, a.max_abs_k);
        // the rig file must be off for the test to mean anything (measured: the
        // motor 0.495 K, the other channels > 0.5 K)
        assert!(b.rmse_k > 0.45, "{}: the rig file must be off for the test to mean anything", b.channel);
        assert!(a.rmse_k <= 0.25, "{}: held-out RMSE {:.3} K", a.channel, a.rmse_k);
    }
}

/// One operating point (Case 1 at 500 rpm, 40 bar, 30 min): the warning
/// names the log and the held parameters include the loss coefficients
/// that only speed and pressure steps separate. Measured: see the printout.
#[test]
fn one_operating_point_warns_and_names_unidentifiable() {
    let base = Rig::default();
    let mut th = set::nominal();
    for (name, v) in TRUTH {
        th[set::index(name).expect(name)] = v;
    }
    let truth = apply(&base, &th);
    let logs = [cal_log(&truth, Kind::Constant { rpm: 500.0, bar: 40.0 }, 21)];
    let c = calibrate(&base, &logs, &CalOptions::default()).expect("calibration");
    for w in &c.warnings {
        eprintln!("{w}");
    }
    let held: Vec<&str> = c.params.iter().filter(|p| p.status != Status::Fitted).map(|p| p.name.as_str()).collect();
    eprintln!("held: {held:?}");
    assert!(c.warnings.iter().any(|w| w.contains("one operating point") && w.contains("Constant")), "warning names the log");
    let listed = c.warnings.iter().find(|w| w.contains("held at the rig file")).expect("held list in the warnings");
    for name in ["iron_loss", "leak_gap"] {
        assert!(held.contains(&name), "{name} held at one operating point");
        assert!(listed.contains(name), "{name} named in the warning");
    }
}

/// A calibration is reproducible: the same logs and options give the same
/// multipliers to the bit, also when the evaluation budget stops the fit
/// (here 60 evaluations, far short of convergence). The budget is now
/// counted in the minimiser's sequential calls; before, the parallel model
/// runs counted it, so a Jacobian cut by the budget had evaluated a
/// timing-dependent set of perturbed points, any of which could become the
/// best point: the emulator machine's commissioning (19 free parameters,
/// budget reached) gave `probe_oil` 1.089 and 1.122 on two runs of the same
/// code. This smaller case did not show that race on the old code (four
/// runs); it guards reproducibility, it does not reproduce the race.
#[test]
fn calibration_is_reproducible_when_the_budget_stops_it() {
    let base = Rig::default();
    let mut th = set::nominal();
    th[set::index("h_out_pump").expect("h_out_pump")] = 1.4;
    let truth = apply(&base, &th);
    let logs = [cal_log(&truth, Kind::PressureSteps, 31), cal_log(&truth, Kind::SpeedSteps, 32)];
    let o = CalOptions { max_evals: 60, ..CalOptions::default() };
    let a = calibrate(&base, &logs, &o).expect("calibration");
    let b = calibrate(&base, &logs, &o).expect("calibration");
    assert_eq!(a.model_runs, b.model_runs, "model runs");
    for (x, y) in a.theta.iter().zip(&b.theta) {
        assert_eq!(x.to_bits(), y.to_bits(), "multipliers differ: {:?} vs {:?}", a.theta, b.theta);
    }
}
