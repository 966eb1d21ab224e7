//! Calibration against a truth not written with the reference: the rig
//! emulator (`eha_sim::emulator`, 14 nodes, other correlations and
//! parameters), nominal machine, nothing hidden. Two training logs of
//! different kinds, one held-out log of a third kind; and (slow tier) which
//! kind of training log carries a calibration across regimes.

use eha_sim::calibration::{calibrate, channel_errors, CalLog, CalOptions};
use eha_sim::diagnosis::Candidate;
use eha_sim::emulator::missions::{draw, EmuScenario};
use eha_sim::emulator::params::EmuParams;
use eha_sim::emulator::plant::{Hidden, Plant};
use eha_sim::rig::Rig;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

/// A 1200 s log of the nominal emulator in scenario `s` (nothing hidden),
/// the ram air logged where the scenario has it.
fn emu_log(p: &EmuParams, s: EmuScenario, seed: u64) -> CalLog {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let m = draw(s, 1200.0, &mut rng);
    let trace = Plant { p, m: &m, h: Hidden { effect: Candidate::None, magnitude: 0.0 } }.run(s.log_interval_s());
    let run = eha_sim::emulator::log_mission(&trace, &m, &mut rng);
    CalLog::new(&format!("{s:?}-{seed}"), run, 120).expect("cal log")
}

fn pooled(e: &[eha_sim::calibration::ChannelError]) -> f64 {
    (e.iter().map(|c| c.rmse_k * c.rmse_k).sum::<f64>() / e.len() as f64).sqrt()
}

/// Measured with both oils on their viscosity lines (one run, ~11 s, 1150
/// model runs): pooled held-out RMSE 6.01 → 0.84 K (t_oil_c 12.6 → 1.54 K,
/// the other channels 1.1–4.1 → 0.24–0.75 K); 0.41 K while both oils had a
/// constant viscosity. Why it moved (measured with the emulator and the rig
/// file changed by hand, not in the suite):
/// - The miss is the held-out oil following the shaft speed at ~70 bar
///   (−2.5 K at 663 rpm, +2.4 K at 1164 rpm, the same run): no training log
///   moves the speed at a high pressure drop (load cycles at one speed, speed
///   steps at 5–25 bar), and with the viscosity falling 10× over the warm-up
///   the leakage, the films and the loss torque now depend on the oil
///   temperature jointly with speed and pressure.
/// - Both oils back at a constant 46 cSt, same code: 0.67 K (t_oil_c 0.66
///   K). Each of the emulator's viscosity paths held at 40 °C alone
///   (leakage, films, hoses): 0.88–1.23 K. No single path; the reference's
///   own temperature dependences against the emulator's other structure.
/// - `pump_friction` on its lower bound 0.1 (the emulator has no T0 or
///   C_v·μ term, and puts half its η_m heat into the delivered oil, the
///   reference into the case); it stays there with the rig's friction
///   scaled by 0.3 before the fit, so a wider bound would not help: the
///   emulator's structure, not a parameter missing from the set.
///   `leak_gap` left its ×2.5 bound (1.41): the hot oil's lower viscosity
///   supplies the leakage the wider gap gave before.
/// - Calibrated on two identification runs instead, the same held-out log
///   misses by 0.65 K (the slow test below asserts that case; with the
///   `block_wall` parameter those logs free, held here: no training log
///   moves speed and load independently).
///
/// `film_case` 8.7 where the emulator's case-oil wetted area is ×5.3
/// (another film correlation); `cap_case_oil` held (no drain sensor).
#[test]
fn emulator_machine_held_out_error_falls() {
    let p = EmuParams::default();
    let train = [emu_log(&p, EmuScenario::LoadCycles, 41), emu_log(&p, EmuScenario::SpeedSteps, 42)];
    let hold = emu_log(&p, EmuScenario::PressureSpeedSteps, 43);
    let base = Rig::default();
    // The emulator's oil probe lags (a 6 s thermowell against the rig
    // file's 2 s): its response time is fitted too (`--fit-oil-probe`),
    // which exercises the staged fit (thermal network first).
    let o = CalOptions { hold: Vec::new(), ..CalOptions::default() };
    let c = calibrate(&base, &train, &o).expect("calibration");
    for q in &c.params {
        eprintln!("{:18} {:6.3} {:?}{}", q.name, q.value, q.status, if q.at_bound { " (bound)" } else { "" });
    }
    let before = channel_errors(&hold, &hold.simulate(&base).expect("sim"));
    let after = channel_errors(&hold, &hold.simulate(&c.rig).expect("sim"));
    for (b, a) in before.iter().zip(&after) {
        eprintln!("{:14} held-out RMSE {:.3} -> {:.3} K", a.channel, b.rmse_k, a.rmse_k);
    }
    eprintln!("pooled {:.3} -> {:.3} K, {} runs", pooled(&before), pooled(&after), c.model_runs);
    // Held out, every channel better; pooled ≤ 1.0 K (measured 0.84 K; the
    // fit is ill-conditioned here: a change of the emulator's hose viscosity
    // that moves the rig-as-given error by 0.004 K gave 0.98 K), the oil
    // channel that carries the miss ≤ 1.8 K (measured 1.54 K), the others
    // ≤ 0.8 K (measured 0.24–0.75 K).
    assert!(pooled(&after) <= 1.0, "pooled held-out {:.3} K", pooled(&after));
    for a in &after {
        let bound = if a.channel == "t_oil_c" { 1.8 } else { 0.8 };
        assert!(a.rmse_k <= bound, "{} held-out {:.3} K (bound {bound} K)", a.channel, a.rmse_k);
    }
    for (b, a) in before.iter().zip(&after) {
        assert!(a.rmse_k < b.rmse_k, "{} got worse", a.channel);
    }
    let v = |n: &str| c.params.iter().find(|q| q.name == n).expect(n).value;
    // The deviation that maps one to one, within the range the emulator's own
    // structure allows: case film ×5.3 (another correlation: > 2; measured 8.70).
    assert!(v("film_case") > 2.0, "film_case {:.3}", v("film_case"));
    // Not one to one with the emulator's η_m ×0.72: the reference's pump has
    // no-load and viscous friction and a housing share, the emulator
    // (written from the paper) none of them (both have the compression
    // heat), and the fit trades
    // the friction against the leakage (leak_gap 1.41; on its ×2.5 bound
    // while the oils had a constant viscosity).
    // Asserted as measured (0.105 before the emulator's compression heat,
    // 0.101 with it, 0.100 on its lower bound with both oils on their
    // viscosity lines; ±30 %) so that a change shows.
    let k = eha_sim::calibration::set::index("leak_gap").expect("leak_gap");
    eprintln!("pump_friction {:.3}, leak_gap {:.3} at bound {}", v("pump_friction"), v("leak_gap"), c.params[k].at_bound);
    assert!((v("pump_friction") / 0.105).ln().abs() <= 0.3, "pump_friction {:.3}", v("pump_friction"));
    // The probe is fitted, not held; its value is not asserted: measured
    // 1.09–1.15 (2.2–2.3 s, nondeterministic in the last digits) where the
    // emulator's is 6 s — the 2 s-sampled logs see the lag only on steps.
    let p = c.params.iter().find(|q| q.name == "probe_oil").expect("probe_oil");
    assert_eq!(p.status, eha_sim::calibration::Status::Fitted, "probe_oil fitted");
}

/// Which logs to commission with. The same emulated machine
/// calibrated on two logs of the operating families (load cycles, speed
/// steps) or on two identification runs (speed, load and ram air stepped
/// independently, `EmuScenario::IdentRun`), each checked on a held-out log
/// of either kind. Measured (one run each, ~1200 model runs, ~8 s):
/// families → pressure-speed steps 0.41 K pooled but → identification run
/// 1.47 K (t_ballvalve_c 2.18 K, t_block_c 1.71 K); identification runs →
/// 0.54 K and 0.53 K. The families' calibration absorbs structure into
/// values that hold only for their own excitation; the identification runs
/// pin the same set across regimes. Tolerances: the identification-run
/// calibration within 0.75 K pooled on both held-out logs (the
/// emulator's structure floor, ~0.5 K, plus margin), the families'
/// calibration at least 1.1 K off on the identification run (a miss more
/// than twice the floor: the finding itself).
///
/// With both oils on their viscosity lines the identification runs held
/// out 1.87 / 1.56 K, 1.07 / 1.17 K with the forced-convection coefficient
/// `h_forced` in the set (this test failed). The rest was the oil channel
/// (1.5–2.1 K on every log, training included). Measured with the example
/// `ident_structure` (docs/calibration.md, "Rig-level structure in the
/// commissioning and diagnosis calibration set"): the calibrated oil
/// residual regresses on speed and drop (+2…+7 K per 1000 rpm, +4…+6 K per
/// 100 bar, R² 0.55–0.85: too warm at high flow and high heat input); each
/// emulator path switched off alone (pump → manifold joint, the plate's
/// film, the port-plate friction heat, the ball-block joint, probe lags,
/// hoses) left the oil at 1.3–2.4 K; the cause is the reference's block
/// wall in series with the loop film, which caps the oil's coupling to the
/// block at 68 W/K at 2000 rpm and 70 °C where the emulator's films (no
/// wall) reach 216 W/K. With that wall a calibration parameter
/// (`block_wall`, fitted at ×54.3) the identification runs hold out
/// **0.650 / 0.695 K** (oil 1.12 / 1.14 K, training 0.64 / 0.64 K; 1236
/// model runs, ~50 s for both calibrations on 2 cores); the families are
/// unchanged at 0.839 / 2.441 K (`block_wall` needs a log that moves speed
/// and load independently: freed on the families it went to ×25 against
/// three parameters on bounds and worsened their held-out pump channel).
/// Those numbers with the set's prior widths and the polish at rtol 1e-5;
/// re-run with calib11's defaults (priors ×0.5, polish at rtol 1e-6; one
/// run, 29.3 s at load 3.0-3.7 on 2 shared cores): identification runs
/// **0.599 / 0.614 K** (was 0.650 / 0.695), families 0.869 / 2.707 K (was
/// 0.839 / 2.441: the identification-run miss 0.27 K larger, within the
/// 0.3-0.9 K path spread docs/commissioning-foreign.md measures); the test prints
/// only the pooled held-out numbers, the training, oil and `block_wall`
/// figures above were not measured again. On the fixed reference (b36ffe3;
/// 88.0 s wall, 56.6 s user at load 5–6): identification runs
/// **0.498 / 0.502 K**, families 0.827 / 2.624 K.
#[test]
#[ignore = "slow tier: two calibrations on emulator logs (~30 s)"]
fn slow_identification_runs_commission_across_regimes() {
    let p = EmuParams::default();
    let base = Rig::default();
    let o = CalOptions { hold: Vec::new(), ..CalOptions::default() };
    let holds = [emu_log(&p, EmuScenario::PressureSpeedSteps, 43), emu_log(&p, EmuScenario::IdentRun, 46)];
    let held = |c: &eha_sim::calibration::Calibration| -> Vec<f64> {
        holds.iter().map(|l| pooled(&channel_errors(l, &l.simulate(&c.rig).expect("sim")))).collect()
    };
    let fam = calibrate(&base, &[emu_log(&p, EmuScenario::LoadCycles, 41), emu_log(&p, EmuScenario::SpeedSteps, 42)], &o)
        .expect("calibration on families");
    let ident = calibrate(&base, &[emu_log(&p, EmuScenario::IdentRun, 44), emu_log(&p, EmuScenario::IdentRun, 45)], &o)
        .expect("calibration on identification runs");
    let (f, i) = (held(&fam), held(&ident));
    eprintln!("held out (pressure-speed steps, identification run): families {f:.3?} K, identification runs {i:.3?} K");
    assert!(i.iter().all(|&e| e <= 0.75), "identification-run calibration held out {i:.3?} K (measured 0.498, 0.502 on the fixed reference; 0.599, 0.614 before it; 0.650, 0.695 before calib11's defaults)");
    assert!(f[1] >= 1.1, "families' calibration on the identification run {:.3} K (measured 2.624 on the fixed reference; 2.707 before it; 2.441 before calib11's defaults)", f[1]);
}

/// The identification run is recognised as moving speed and load
/// independently, the operating families are not (spreads and correlation
/// printed; `commission` warns with `NO_JOINT_EXCITATION` when no training
/// log does).
#[test]
fn identification_runs_are_recognised_as_joint_excitation() {
    use eha_sim::calibration::ident::{independent_speed_and_load, speed_load_excitation};
    let p = EmuParams::default();
    for (s, seed, want) in [
        (EmuScenario::IdentRun, 44, true),
        (EmuScenario::IdentRun, 45, true),
        (EmuScenario::LoadCycles, 41, false),
        (EmuScenario::SpeedSteps, 42, false),
        (EmuScenario::PressureSpeedSteps, 43, false),
        (EmuScenario::ConstantThrottle, 47, false),
    ] {
        let l = emu_log(&p, s, seed);
        let (a, b, rho) = speed_load_excitation(&l.run);
        eprintln!("{s:?}: speed spread {a:.2}, Δp spread {b:.2}, ρ {rho:.2}");
        assert_eq!(independent_speed_and_load(&l.run), want, "{s:?}");
    }
}
