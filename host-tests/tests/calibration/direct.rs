//! Direct identification of the firmware model's own parameters from
//! commissioning logs (`calibration::direct`): the replay it fits with
//! against `check_reduced`, the consistency of every block it tries, and
//! (slow tier) held-out drain errors on the synthetic other EHA and on the
//! rig emulator, and reproducibility at the last digit.

use eha_guard::model::{etd_matrix, Model};
use eha_guard::params::{DEFAULT, S_PER_STEP};
use eha_sim::calibration::commission::check_reduced;
use eha_sim::calibration::direct::{apply, identify_direct, score, range, DirectFit, DirectOptions, LogScore, DIRECT_PARAMS};
use eha_sim::calibration::replay::{node_errors, TickInputs};
use eha_sim::calibration::synthetic::{log, mission, other_rig_file, other_rig_truth, Kind};
use eha_sim::calibration::CalLog;
use eha_sim::diagnosis::Candidate;
use eha_sim::emulator::missions::{draw, EmuScenario};
use eha_sim::emulator::params::EmuParams;
use eha_sim::emulator::plant::{Hidden, Plant, N};
use eha_sim::measured::{Channel, MeasuredRun};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use std::time::Instant;

/// A 30 min log of the synthetic other EHA's true machine (2 s, noise,
/// quantisation, dropouts, drain thermocouple).
fn other_log(kind: Kind, seed: u64) -> CalLog {
    CalLog::new(&format!("{kind:?}-{seed}"), log(&other_rig_truth(), &mission(kind, 1800.0, seed), 2.0, seed, true).expect("log"), 120).expect("cal log")
}

/// The other EHA's training logs (those of tests/calibration/commission.rs)
/// and its held-out log.
fn other_logs() -> (Vec<CalLog>, Vec<CalLog>) {
    (vec![other_log(Kind::PressureSteps, 31), other_log(Kind::SpeedSteps, 32), other_log(Kind::CoolingSteps, 34)], vec![other_log(Kind::SoakThenMixed, 33)])
}

/// A 1200 s log of the nominal rig emulator in scenario `s` with a
/// `t_drain_c` column: the emulator's case-oil node (its logger does not
/// log a drain thermocouple) with the logger's temperature noise (σ 0.1 K,
/// 12-bit quantisation) from its own seed.
fn emu_log(s: EmuScenario, seed: u64) -> CalLog {
    let p = EmuParams::default();
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let m = draw(s, 1200.0, &mut rng);
    let trace = Plant { p: &p, m: &m, h: Hidden { effect: Candidate::None, magnitude: 0.0 } }.run(s.log_interval_s());
    let mut run = eha_sim::emulator::log_mission(&trace, &m, &mut rng);
    let mut noise = ChaCha8Rng::seed_from_u64(seed ^ 0xD7A1);
    let mut j = 0;
    let drain = run
        .time_s
        .iter()
        .map(|&t| {
            while trace[j].0 < t {
                j += 1;
            }
            let g = eha_sim::emulator::logger::gauss(&mut noise);
            Some(eha_sim::emulator::logger::quantise(trace[j].1[N::CaseOil as usize] + 0.1 * g))
        })
        .collect();
    run.set(Channel::TDrainC, drain);
    CalLog::new(&format!("{s:?}-{seed}"), run, 120).expect("cal log")
}

/// Every temperature of `run` moved by `dt` K (alternating in sign by row).
fn nudged(l: &CalLog, dt: f64) -> CalLog {
    let mut run: MeasuredRun = l.run.clone();
    for ch in Channel::TEMPERATURES.into_iter().chain([Channel::TDrainC]) {
        if let Some(v) = run.get(ch) {
            let v: Vec<Option<f64>> = v.iter().enumerate().map(|(i, x)| x.map(|x| x + if i % 2 == 0 { dt } else { -dt })).collect();
            run.set(ch, v);
        }
    }
    CalLog::new(&l.name, run, 120).expect("cal log")
}

fn print_fit(f: &DirectFit, secs: f64) {
    eprintln!("fit {secs:.1} s, {} model runs, chi2 {:.0} -> {:.0} over {} points", f.model_runs, f.chi2_before_after.0, f.chi2_before_after.1, f.n_points);
    for r in &f.results {
        match &r.held {
            None => eprintln!("  {:14} {:6.3} sd(ln) {:.3} 95% [{:.3}, {:.3}]{}", r.name, r.value, r.sd_ln, r.interval95.0, r.interval95.1, if r.at_bound { " AT BOUND" } else { "" }),
            Some(why) => eprintln!("  {:14} held: {why}", r.name),
        }
    }
    eprintln!("  max |rho| {:.3}; pairs >= 0.9: {:?}", f.max_abs_correlation, f.correlated);
}

fn print_scores(tag: &str, s: &[LogScore]) {
    for l in s {
        for (a, b) in l.before.iter().zip(&l.after) {
            eprintln!(
                "{tag} {:22} {:14} reduction rmse {:.3} max {:.3} under {:.3} | direct rmse {:.3} max {:.3} under {:.3}",
                l.log, a.channel, a.rmse_k, a.max_abs_k, a.max_under_k, b.rmse_k, b.max_abs_k, b.max_under_k
            );
        }
    }
}

/// The replay the fit uses drives the reduced model from the log's own
/// inputs; `check_reduced` drives it from the reference plant replaying
/// the same inputs. On the measured drain they must give the same numbers
/// (the same interpolation and tick rule): measured equal to the last
/// printed digit (max 4.887598282378718 K both, RMSE differing at 1e-15).
/// Tolerance 1e-9 K: summation order only.
#[test]
fn replay_gives_check_reduced_measured_drain_numbers() {
    let l = other_log(Kind::SoakThenMixed, 33);
    let p0 = eha_sim::reduce::reduce(&other_rig_file()).expect("reduction");
    let inputs = TickInputs::of(&l).expect("inputs");
    assert_eq!(inputs.ticks.len(), 180_001, "30 min at 10 ms, both ends");
    let e = node_errors(&p0, &l, &inputs).expect("replay");
    let d = e.iter().find(|c| c.channel == "t_drain_c").expect("drain");
    let c = check_reduced(&other_rig_truth(), &p0, &l).expect("check_reduced");
    eprintln!("replay {d:?}\ncheck_reduced {c:?}");
    let close = |a: f64, b: Option<f64>| (a - b.expect("measured drain")).abs() <= 1e-9;
    assert!(close(d.max_abs_k, c.vs_measured_max_k), "max {} vs {:?}", d.max_abs_k, c.vs_measured_max_k);
    assert!(close(d.max_under_k, c.vs_measured_under_k), "under {} vs {:?}", d.max_under_k, c.vs_measured_under_k);
    assert!(close(d.rmse_k, c.vs_measured_rmse_k), "rmse {} vs {:?}", d.rmse_k, c.vs_measured_rmse_k);
    // the rig-file reduction misses this machine by kelvins (the reason to identify)
    assert!(d.max_abs_k > 3.0, "{d:?}");
}

/// Every block the fit can try is one the firmware takes: each multiplier
/// at its lower and upper bound (the others at 1) on the paper reduction
/// and on the other EHA's gives parameters that `Model::new` accepts in f64
/// and f32 (plausibility, the bounds table, stability, the physics checks),
/// with the nominal Jacobian and `Phi` recomputed for the new values;
/// multipliers of 1 give back the reduction bit for bit; a multiplier that
/// takes a word out of the bounds table is refused.
#[test]
fn direct_multipliers_keep_the_block_consistent() {
    let other = eha_sim::reduce::reduce(&other_rig_file()).expect("reduction");
    for p0 in [DEFAULT, other] {
        let ones = vec![1.0; DIRECT_PARAMS.len()];
        assert_eq!(apply(&p0, &ones), Some(p0), "multipliers of 1 change the block");
        for (k, d) in DIRECT_PARAMS.iter().enumerate() {
            let (lo, hi) = range(k, &p0);
            eprintln!("{:14} range {lo:.3} .. {hi:.3}", d.name);
            for s in [lo, hi] {
                let mut th = ones.clone();
                th[k] = s;
                let q = apply(&p0, &th).unwrap_or_else(|| panic!("{} = {s} refused", d.name));
                let a = eha_sim::reduce::nominal_jacobian(&q).expect("jacobian");
                assert_eq!(q.nominal_jacobian_per_s, a, "{}: stale Jacobian", d.name);
                assert_eq!(q.phi_step_s, etd_matrix(&a, S_PER_STEP), "{}: stale Phi", d.name);
                assert!(Model::<f64>::new(&q).is_ok() && q.is_plausible());
                assert!(eha_sim::params_block::block_for(&q, "direct").is_ok(), "{}: no flashable block", d.name);
                if ["film_case", "loss_pressure", "cap_pump", "cap_loop_oil"].contains(&d.name) {
                    assert_ne!(q.phi_step_s, p0.phi_step_s, "{}: Phi not recomputed", d.name);
                }
            }
        }
        // the main block's outer conductance x100: 0.22 kW/K, above the
        // table's 0.1 kW/K
        let mut th = ones.clone();
        th[eha_sim::calibration::direct::index("outer_main").expect("outer_main")] = 100.0;
        assert_eq!(apply(&p0, &th), None);
    }
}

/// The synthetic other EHA (its rig file reduced, the true machine with
/// films 30 % off and per-node deviations), three 30 min training logs,
/// one held-out mission of another kind. The direct fit from the rig file's
/// reduction (not from a commissioned rig: this tests the direct path
/// alone) against the true (noise-free) drain of the held-out mission.
///
/// Measured (one run, 2 cores under load ~9 from other builds: 24 s, 345
/// model runs of a 30 min log; held `split_case`, `cap_case_oil`,
/// `cap_ball`): held-out true drain max |e| 4.54 → 0.39 K, under-prediction
/// 0.002 → 0.35 K (the reduction of the rig file runs hot on this
/// machine); measured-drain RMSE 1.99 → 0.28 K. The multipliers recover the
/// truth's deviations where one maps to one parameter: loss_pressure 0.765
/// (η_m ×0.75), film_loop 0.711 (×0.7), film_port 1.345 (×1.3), film_case
/// 1.288 (×1.3), cap_pump 0.812 (×0.8), cap_main 1.20 (×1.25),
/// cap_loop_oil 1.198 (×1.2), leak 1.574 (gaps ×1.15: ×1.52).
/// Re-run with calib11's calibration defaults (which the direct fit does
/// not read): the same 4.544 → 0.386 K and 0.347 K, 8.9 s at load 3.2.
/// Tolerances: true drain max |e| ≤ 0.6 K and under ≤ 0.5 K (measured
/// 0.39/0.35 K plus the spread between fits with other held sets,
/// 0.39-0.64 K); each asserted multiplier within 10 % of the truth.
#[test]
#[ignore = "slow tier: direct fit on three 30 min logs (~10-25 s)"]
fn other_eha_direct_fit_on_held_out_drain() {
    let (train, hold) = other_logs();
    let p0 = eha_sim::reduce::reduce(&other_rig_file()).expect("reduction");
    let t0 = Instant::now();
    let f = identify_direct(&p0, &train, &DirectOptions::default()).expect("direct fit");
    print_fit(&f, t0.elapsed().as_secs_f64());
    print_scores("train", &f.train);
    let s = score(&p0, &f.params, &hold).expect("held-out scores");
    print_scores("held-out", &s);
    let truth = other_rig_truth();
    let a = check_reduced(&truth, &p0, &hold[0]).expect("reduction on the truth");
    let b = check_reduced(&truth, &f.params, &hold[0]).expect("direct on the truth");
    eprintln!(
        "held-out true drain: reduction max {:.3} under {:.3} K; direct max {:.3} under {:.3} K",
        a.vs_reference_max_k, a.vs_reference_under_k, b.vs_reference_max_k, b.vs_reference_under_k
    );
    assert!(b.vs_reference_max_k <= 0.6, "direct max |e| {:.3} K", b.vs_reference_max_k);
    assert!(b.vs_reference_under_k <= 0.5, "direct under {:.3} K", b.vs_reference_under_k);
    assert!(a.vs_reference_max_k > 3.0, "the reduction of the rig file {:.3} K", a.vs_reference_max_k);
    let v = |n: &str| f.results.iter().find(|r| r.name == n).expect(n).value;
    for (n, truth) in [("loss_pressure", 0.75), ("film_loop", 0.7), ("film_port", 1.3), ("film_case", 1.3), ("cap_pump", 0.8), ("cap_loop_oil", 1.2)] {
        assert!((v(n) / truth).ln().abs() <= 0.1, "{n} {:.3} against the truth's {truth}", v(n));
    }
}

/// The rig emulator (its own 14-node structure, film correlations and
/// sensors: a truth not written with the reference), nominal machine, from
/// the paper reduction (`DEFAULT`). Trained on load cycles and speed
/// steps, held out on pressure-speed steps and a servo hold/move mission,
/// 1200 s each; the drain truth is the emulator's case-oil node (its logger
/// has no drain column yet) with the logger's noise.
///
/// Measured (one run, 15 s, 406 model runs of a 1200 s log; re-run with
/// calib11's calibration defaults, which the direct fit does not read:
/// the same 2.324 / 2.421 K, 7.3 s at load 3.1): the paper
/// reduction runs 33 K hot on this machine's drain (the emulator's case
/// film is another correlation on 5.3 times the wetted area); the fit takes
/// film_case to 14.3 and loss_speed to its 0.1 bound (the emulator, written
/// from the paper, has no no-load or viscous pump friction), largest
/// |ρ| 0.83. Held out, drain: pressure-speed steps max |e| 33.22 → 2.32 K,
/// RMSE 23.5 → 0.97 K, but under-prediction 0.08 → 2.32 K; servo hold/move
/// max 2.69 → 2.42 K, under-prediction 0.35 → 2.42 K. Trained on throttle
/// runs only, the direct model under-predicts the servo mission by more
/// than the paper reduction did: the reason `commission` must choose a path
/// by held-out error, under-prediction included, and count a margin.
/// Tolerances: max |e| ≤ 3.0 K on both (measured 2.32/2.42 K, ~25 % for the
/// fit's sensitivity to the emulator's structure), RMSE ≤ 1.3 K on the
/// throttle mix; the servo under-prediction asserted as the measured miss
/// (1.5-3.0 K) so that a change shows.
#[test]
#[ignore = "slow tier: direct fit on emulator logs (~7-15 s)"]
fn emulator_direct_fit_on_held_out_drain() {
    let train = [emu_log(EmuScenario::LoadCycles, 41), emu_log(EmuScenario::SpeedSteps, 42)];
    let hold = [emu_log(EmuScenario::PressureSpeedSteps, 43), emu_log(EmuScenario::ServoHoldMove, 44)];
    let t0 = Instant::now();
    let f = identify_direct(&DEFAULT, &train, &DirectOptions::default()).expect("direct fit");
    print_fit(&f, t0.elapsed().as_secs_f64());
    print_scores("train", &f.train);
    let s = score(&DEFAULT, &f.params, &hold).expect("held-out scores");
    print_scores("held-out", &s);
    for l in &s {
        let (a, b) = (l.drain_before().expect("drain"), l.drain_after().expect("drain"));
        eprintln!("{}: drain max {:.3} -> {:.3}, under {:.3} -> {:.3}", l.log, a.max_abs_k, b.max_abs_k, a.max_under_k, b.max_under_k);
        assert!(b.max_abs_k <= 3.0, "{}: direct drain max |e| {:.3} K", l.log, b.max_abs_k);
    }
    let (mix_before, mix) = (s[0].drain_before().expect("drain"), s[0].drain_after().expect("drain"));
    assert!(mix_before.max_abs_k > 20.0, "paper reduction on the emulator {:.3} K", mix_before.max_abs_k);
    assert!(mix.rmse_k <= 1.3, "throttle mix drain RMSE {:.3} K", mix.rmse_k);
    let servo = s[1].drain_after().expect("drain");
    assert!((1.5..=3.0).contains(&servo.max_under_k), "servo under-prediction {:.3} K (measured 2.42 K)", servo.max_under_k);
}

/// Reproducible at the last digit: every logged temperature moved by
/// ±1e-9 K (alternating by row) moves the headline numbers (held-out
/// measured drain max |e|, under-prediction, RMSE; the multipliers) by at
/// most 0.05 K (the bound). Measured: identical to 6 decimals
/// (held-out max 0.686196 K both), max |Δ ln θ| 2.5e-10.
#[test]
#[ignore = "slow tier: two direct fits on three 30 min logs (~60 s)"]
fn direct_fit_is_reproducible_at_the_last_digit() {
    let (train, hold) = other_logs();
    let p0 = eha_sim::reduce::reduce(&other_rig_file()).expect("reduction");
    let o = DirectOptions::default();
    let f1 = identify_direct(&p0, &train, &o).expect("fit");
    let train2: Vec<CalLog> = train.iter().map(|l| nudged(l, 1e-9)).collect();
    let hold2: Vec<CalLog> = hold.iter().map(|l| nudged(l, 1e-9)).collect();
    let f2 = identify_direct(&p0, &train2, &o).expect("fit");
    let s1 = score(&p0, &f1.params, &hold).expect("scores");
    let s2 = score(&p0, &f2.params, &hold2).expect("scores");
    let (a, b) = (s1[0].drain_after().expect("drain"), s2[0].drain_after().expect("drain"));
    let moved = [(a.max_abs_k - b.max_abs_k).abs(), (a.max_under_k - b.max_under_k).abs(), (a.rmse_k - b.rmse_k).abs()];
    let dtheta = f1.theta.iter().zip(&f2.theta).map(|(x, y)| (x / y).ln().abs()).fold(0.0, f64::max);
    eprintln!("held-out drain max {:.6} / {:.6}, under {:.6} / {:.6}, rmse {:.6} / {:.6}; max |d ln theta| {dtheta:.2e}", a.max_abs_k, b.max_abs_k, a.max_under_k, b.max_under_k, a.rmse_k, b.rmse_k);
    assert!(moved.iter().all(|m| *m <= 0.05), "headline moved by {moved:?} K");
}

/// The path `commission` would take on the other EHA: the reference
/// calibrated to the training logs, reduced (`c.params`, the reduction
/// path), then the direct fit from that reduction. Both against the true
/// drain of the held-out mission. Measured with the calibration's defaults
/// of calib11 (priors ×0.5, polish at rtol 1e-6; one run, load 3.2-3.7 on
/// 2 shared cores, 59 s in all: commissioning 49.9 s, 2889 reference runs;
/// the direct fit 8.6 s, 384 model runs): commissioned reduction max |e|
/// 0.218 K, under-prediction 0.063 K (was 0.229 / 0.154 K with the set's
/// prior widths and polish at 1e-5); direct from it 0.301 K and 0.061 K
/// (was 0.325 / 0.061 K); measured drain RMSE 0.189 → 0.184 K (was
/// 0.218 → 0.171 K); multipliers within 3.1 % of 1 except `outer_pump`
/// 0.945 and the main block's (`outer_main` 0.576, `cap_main` 1.053,
/// |ρ| 0.92). On a machine built like
/// our model the reduction already holds and the two paths are within
/// 0.1 K. Tolerances: both ≤ 0.5 K max |e| (the other-EHA bound),
/// under-prediction ≤ 0.3 K.
#[test]
#[ignore = "slow tier: commissioning (~50 s) and a direct fit from its reduction (~10 s)"]
fn other_eha_direct_fit_from_the_commissioned_reduction() {
    let (train, hold) = other_logs();
    let t0 = Instant::now();
    let c = eha_sim::calibration::commission::commission(&other_rig_file(), &train, &hold, &eha_sim::calibration::CalOptions::default()).expect("commissioning");
    eprintln!("commissioning {:.1} s, {} reference runs", t0.elapsed().as_secs_f64(), c.cal.model_runs);
    let t0 = Instant::now();
    let f = identify_direct(&c.params, &train, &DirectOptions::default()).expect("direct fit");
    print_fit(&f, t0.elapsed().as_secs_f64());
    print_scores("train", &f.train);
    let s = score(&c.params, &f.params, &hold).expect("held-out scores");
    print_scores("held-out", &s);
    let truth = other_rig_truth();
    let a = check_reduced(&truth, &c.params, &hold[0]).expect("reduction on the truth");
    let b = check_reduced(&truth, &f.params, &hold[0]).expect("direct on the truth");
    eprintln!(
        "held-out true drain: commissioned reduction max {:.3} under {:.3} K; direct from it max {:.3} under {:.3} K",
        a.vs_reference_max_k, a.vs_reference_under_k, b.vs_reference_max_k, b.vs_reference_under_k
    );
    for (path, r) in [("commissioned reduction", &a), ("direct", &b)] {
        assert!(r.vs_reference_max_k <= 0.5 && r.vs_reference_under_k <= 0.3, "{path}: max {:.3} under {:.3} K", r.vs_reference_max_k, r.vs_reference_under_k);
    }
}
