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

/// Measured (one run, ~7 s, 1212 model runs; session 15, the emulator with
/// compression heat; session 16 with the probe fitted and the staged fit:
/// 1282 runs, 0.41 K): pooled held-out RMSE 8.08 → 0.41 K (t_oil_c 16.1 →
/// 0.44 K, the other channels 1.1–7.0 → 0.24–0.54 K); `film_case` 9.82
/// where the emulator's case-oil wetted area is ×5.3 (with another film
/// correlation); `pump_friction` 0.101 with `leak_gap`
/// on its bound (see below); `cap_case_oil` held (no drain sensor). Not every multiplier maps
/// one to one (the main-block mass is ×0.78 in the emulator, fitted 1.15,
/// its manifold plate and pump→block path are missing in the reference).
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
    // Held out, every channel better and pooled ≤ 0.6 K (measured 0.42 K;
    // the rest is the emulator's structure the reference lacks).
    assert!(pooled(&after) <= 0.6, "pooled held-out {:.3} K", pooled(&after));
    for (b, a) in before.iter().zip(&after) {
        assert!(a.rmse_k < b.rmse_k, "{} got worse", a.channel);
    }
    let v = |n: &str| c.params.iter().find(|q| q.name == n).expect(n).value;
    // The deviation that maps one to one, within the range the emulator's own
    // structure allows: case film ×5.3 (another correlation: > 2; measured 9.85).
    assert!(v("film_case") > 2.0, "film_case {:.3}", v("film_case"));
    // No longer one to one since issue 16 (was 0.695 for the emulator's η_m
    // ×0.72): the reference's pump now has no-load and viscous friction, a
    // housing share, the emulator (written from the paper) none of them
    // (compression heat both have since session 15), and the fit trades
    // the friction against the leakage (leak_gap on its ×2.5 bound).
    // Asserted as measured (0.105 before the emulator's compression heat,
    // 0.101 with it; ±30 %) so that a change shows.
    let k = eha_sim::calibration::set::index("leak_gap").expect("leak_gap");
    eprintln!("pump_friction {:.3}, leak_gap {:.3} at bound {}", v("pump_friction"), v("leak_gap"), c.params[k].at_bound);
    assert!((v("pump_friction") / 0.105).ln().abs() <= 0.3, "pump_friction {:.3}", v("pump_friction"));
    // The probe is fitted, not held; its value is not asserted: measured
    // 1.09–1.15 (2.2–2.3 s, nondeterministic in the last digits) where the
    // emulator's is 6 s — the 2 s-sampled logs see the lag only on steps.
    let p = c.params.iter().find(|q| q.name == "probe_oil").expect("probe_oil");
    assert_eq!(p.status, eha_sim::calibration::Status::Fitted, "probe_oil fitted");
}

/// Which logs to commission with (session 19). The same emulated machine
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
#[test]
#[ignore = "slow tier: two calibrations on emulator logs"]
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
    assert!(i.iter().all(|&e| e <= 0.75), "identification-run calibration held out {i:.3?} K (measured 0.54, 0.53)");
    assert!(f[1] >= 1.1, "families' calibration on the identification run {:.3} K (measured 1.47)", f[1]);
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
