//! Commissioning an EHA that is not the paper's: a synthetic
//! other rig (1.5× displacement, other masses and areas in its rig file;
//! the true machine with films 30 % off and per-node deviations no global
//! multiplier represents), logs with noise, quantisation and dropouts and a
//! drain thermocouple; three training missions (one with the LNG valve on
//! the bench thermostat), one held-out mission of another kind.

use eha_sim::calibration::commission::{check_reduced, commission_with, NO_COOLING};
use eha_sim::calibration::synthetic::{log, mission, other_rig_file, other_rig_truth, Kind};
use eha_sim::calibration::{CalLog, CalOptions};

fn cal_log(kind: Kind, seed: u64) -> CalLog {
    CalLog::new(&format!("{kind:?}-{seed}"), log(&other_rig_truth(), &mission(kind, 1800.0, seed), 2.0, seed, true).expect("log"), 120).expect("cal log")
}

/// Without the margin validation (three more calibrations; the margin is
/// tested on the emulator machines, tests/calibration/foreign.rs).
fn commission(base: &eha_sim::rig::Rig, train: &[CalLog], hold: &[CalLog], o: &CalOptions) -> Result<eha_sim::calibration::commission::Commissioning, eha_sim::calibration::commission::CommissionError> {
    commission_with(base, train, hold, o, false)
}

/// Three training logs (pressure steps, speed steps, and needle steps with
/// the LNG valve on the bench thermostat), a soak-then-mixed held-out log.
/// Measured numbers: the eprintln and docs/commissioning.md (which also
/// records the earlier reduced-model misses this test caught).
#[test]
fn other_rig_commissioned_firmware_meets_drain_bounds_on_held_out_mission() {
    let t0 = std::time::Instant::now();
    let train = [cal_log(Kind::PressureSteps, 31), cal_log(Kind::SpeedSteps, 32), cal_log(Kind::CoolingSteps, 34)];
    let hold = [cal_log(Kind::SoakThenMixed, 33)];
    let c = commission(&other_rig_file(), &train, &hold, &CalOptions::default()).expect("commissioning");
    eprintln!("{:.1} s, {} model runs", t0.elapsed().as_secs_f64(), c.cal.model_runs);
    for p in &c.cal.params {
        eprintln!("{:18} {:6.3} [{:6.3}, {:6.3}] {:?}", p.name, p.value, p.interval95.0, p.interval95.1, p.status);
    }
    for s in &c.holdout {
        for (a, b) in s.as_given.iter().zip(&s.commissioned) {
            eprintln!("{} {:14} RMSE {:.3} -> {:.3}, max {:.3} -> {:.3}", s.log, a.channel, a.rmse_k, b.rmse_k, a.max_abs_k, b.max_abs_k);
        }
    }
    for r in &c.reduced {
        eprintln!("reduced {:22} vs ref max {:.3} | vs measured max {:?} under {:?} rmse {:?}", r.log, r.vs_reference_max_k, r.vs_measured_max_k, r.vs_measured_under_k, r.vs_measured_rmse_k);
    }
    for r in &c.default_on_holdout {
        eprintln!("paper default {:22} vs measured max {:?} under {:?}", r.log, r.vs_measured_max_k, r.vs_measured_under_k);
    }
    // The cooling run is in the training set: no warning about the exchanger.
    assert!(!c.cal.warnings.iter().any(|w| w.starts_with(NO_COOLING)), "{:?}", c.cal.warnings);
    // The reduced model within 0.2 K of the commissioned reference on every
    // log's inputs (measured worst 0.136 K).
    let worst = c.reduced.iter().map(|r| r.vs_reference_max_k).fold(0.0, f64::max);
    assert!(c.reduced_ok && worst <= eha_sim::calibration::commission::REDUCED_BOUND_K, "worst reduced-vs-reference {worst:.3} K");
    // Against the true (noise-free) drain of the machine: the reduced model
    // with the commissioned parameters vs the truth rig replaying the
    // held-out inputs (`vs_reference` of a check on the truth rig).
    let truth = other_rig_truth();
    let fw = check_reduced(&truth, &c.params, &hold[0]).expect("commissioned firmware on the truth");
    let paper = check_reduced(&truth, &eha_guard::params::DEFAULT, &hold[0]).expect("paper firmware on the truth");
    eprintln!(
        "held-out true drain: commissioned max |e| {:.3} K, under {:.3} K; paper default max |e| {:.3} K, under {:.3} K",
        fw.vs_reference_max_k, fw.vs_reference_under_k, paper.vs_reference_max_k, paper.vs_reference_under_k
    );
    eprintln!("held-out measured drain: commissioned under {:?}, paper default under {:?}", fw.vs_measured_under_k, paper.vs_measured_under_k);
    // Specified bounds on the held-out mission: max |e| ≤ 1.0 K against
    // the true drain.
    assert!(fw.vs_reference_max_k <= 1.0, "commissioned firmware max |e| {:.3} K", fw.vs_reference_max_k);
    assert!(fw.vs_reference_under_k <= 0.5, "commissioned firmware under-predicts by {:.3} K", fw.vs_reference_under_k);
    // The paper-default firmware is far off on this machine (the reason to
    // commission): > 5 K.
    assert!(paper.vs_reference_max_k > 5.0, "paper default {:.3} K", paper.vs_reference_max_k);
}

/// Commissioning in closed loop, through the flash block: the commissioned
/// parameters written as `firmware-params.bin`, read back in place as the
/// firmware reads its PARAMS region, run the f32 guard against the true
/// machine on the held-out mission (30 min; the guard's valve acts on the
/// plant). Issue bounds: drain max |e| ≤ 1.0 K, under-prediction ≤ 0.5 K
/// against the true drain; the paper-default image on the same loop is
/// reported beside it.
#[test]
fn commissioned_block_in_closed_loop_on_the_held_out_mission() {
    use eha_guard::GuardConfig;
    use eha_sim::pil::sil::SilTarget;
    use eha_sim::pil::{run_closed_loop, Build, LoopOptions};
    use eha_sim::plant::Plant;
    use eha_sim::scenario::Scenario;

    let train = [cal_log(Kind::PressureSteps, 31), cal_log(Kind::SpeedSteps, 32), cal_log(Kind::CoolingSteps, 34)];
    let hold = [cal_log(Kind::SoakThenMixed, 33)];
    let c = commission(&other_rig_file(), &train, &hold, &CalOptions::default()).expect("commissioning");
    let block = eha_sim::params_block::block_for(&c.params, "other-eha").expect("a block the firmware accepts");
    #[repr(C, align(4))]
    struct Flash([u8; eha_guard::params_block::BLOCK_LEN]);
    let flash = Flash(block);
    let consts = eha_guard::params_block::view(&flash.0).expect("valid block").expect("present block");
    // Per run: max |e| and under-prediction over the whole mission and while
    // the guard's LNG budget lasts (after that the guard takes no cooling
    // credit by design, while this plant's tank never runs dry: the estimate
    // then reads high, on the safe side), ticks with the valve open, and the
    // first fault.
    struct Loop {
        max: f64,
        under: f64,
        max_lng: f64,
        under_lng: f64,
        before_open: f64,
        open: usize,
        n: usize,
        fault: Option<(f64, eha_guard::Faults)>,
    }
    let run = |cfg: &GuardConfig| {
        assert!(eha_guard::GuardOf::<f32>::new(cfg, eha_guard::Restore::Cold).faults().is_empty(), "configuration accepted");
        let mut sil = SilTarget::with_config(Build::F32, cfg);
        let m = mission(Kind::SoakThenMixed, 1800.0, 33);
        let mut plant = Plant::new(&other_rig_truth(), &Scenario::Mission(m)).expect("plant");
        let opts = LoopOptions { tick_s: eha_guard::params::S_PER_TICK, duration_s: 1800.0 };
        let rec = run_closed_loop(&mut plant, &mut sil, &opts).unwrap_or_else(|f| panic!("{:#}", f.error));
        let e = |r: &eha_sim::pil::TickRecord| f64::from(r.reply.out.drain_c) - r.sensors.t_drain_c;
        let lng = |r: &&eha_sim::pil::TickRecord| r.reply.out.lng_remaining_kg > 0.0;
        Loop {
            max: rec.iter().map(|r| e(r).abs()).fold(0.0, f64::max),
            under: rec.iter().map(|r| -e(r)).fold(0.0, f64::max),
            max_lng: rec.iter().filter(lng).map(|r| e(r).abs()).fold(0.0, f64::max),
            under_lng: rec.iter().filter(lng).map(|r| -e(r)).fold(0.0, f64::max),
            before_open: rec.iter().take_while(|r| !r.reply.out.valve_open).map(|r| e(r).abs()).fold(0.0, f64::max),
            open: rec.iter().filter(|r| r.reply.out.valve_open).count(),
            n: rec.len(),
            fault: rec.iter().find(|r| !r.reply.out.faults.is_empty()).map(|r| (r.t_s, r.reply.out.faults)),
        }
    };
    let fw = run(&GuardConfig { model: consts, ..GuardConfig::DEFAULT });
    let paper = run(&GuardConfig::DEFAULT);
    for (name, l) in [("commissioned block", &fw), ("paper default", &paper)] {
        eprintln!(
            "{name}: max |e| {:.3} K, under {:.3} K; before the valve opens {:.3} K; while LNG lasts max |e| {:.3} K, under {:.3} K; valve open {} of {} ticks; first fault {:?}",
            l.max, l.under, l.before_open, l.max_lng, l.under_lng, l.open, l.n, l.fault
        );
    }
    eprintln!("eta_m from the current: {:?}", c.eta_m_from_current);
    // Specified bounds with the block as flashed (cross-check on): max |e|
    // ≤ 1.0 K while the guard's cooling model holds, under-prediction ≤ 0.5 K
    // over the whole mission (measured 0.173 / 0.086 K; eta_m from the
    // current takes the viscous friction at the log's oil temperature:
    // 0.3325 against the truth's 0.3327). The third training
    // log (valve on the bench thermostat) is what holds the bound: trained
    // without it, the commissioned reference matched the true machine open
    // loop but the exchanger's cycling exposed ball-block and port-film values
    // the throttle logs could not tell apart, and the loop under-predicted by
    // 0.667 K. After the guard's LNG budget is spent it takes no cooling credit
    // (this plant's tank never runs dry): the estimate then reads high, the
    // safe side.
    assert!(fw.max_lng <= 1.0, "commissioned block: max |e| {:.3} K > 1.0 K", fw.max_lng);
    assert!(fw.under <= 0.5, "commissioned block: under-prediction {:.3} K > 0.5 K", fw.under);
    // The electrical balance is commissioned (eta_m from the current), so the
    // sensor cross-check agrees with this machine: the only fault is LNG_LOW.
    assert!(
        fw.fault.is_none_or(|(_, bits)| !bits.intersects(eha_guard::faults::SENSOR_DISAGREE)),
        "cross-check fault with the commissioned block: {:?}",
        fw.fault
    );
    // The paper-default image on this machine: its cross-check sees the wrong
    // machine within a second (SENSOR_DISAGREE, fail-safe), so it never
    // under-predicts here, but its estimate is useless: the reason to commission.
    let (t_fault, bits) = paper.fault.expect("measured: the paper default's cross-check latches");
    assert!(t_fault <= 1.5 && bits.intersects(eha_guard::faults::SENSOR_DISAGREE), "first fault {:?}", paper.fault);
    assert!(paper.max_lng > 5.0, "paper default: max |e| {:.3} K", paper.max_lng);
}

/// Commissioning, second case: logs that lack excitation. The other EHA
/// commissioned from one operating point only (500 rpm, 40 bar, 30 min): the
/// warning names the log and the parameters held for lack of excitation, and
/// the result is refused by `commission` (reduced model off the commissioned
/// reference by more than 0.2 K) or conservative on the held-out mission of
/// another kind (the reduced model under-predicts the true drain by ≤ 0.5 K).
/// Measured: every reduced check passes (worst 0.096 K) but `commission`
/// refuses the block for the excitation (`Commissioning::flashable`); the
/// refused parameters would under-predict the held-out true drain by 1.81 K
/// (eta_m comes exactly from the current, 0.2074; the leak gaps, ×1.15 on
/// this machine, are held at the rig file and one operating point cannot
/// tell leakage from the films). Without the pump's energy balance the same
/// parameters under-predicted by 0.28 K and were accepted.
#[test]
fn low_excitation_commissioning_warns_and_is_refused_or_conservative() {
    let train = [cal_log(Kind::Constant { rpm: 500.0, bar: 40.0 }, 41)];
    let hold = [cal_log(Kind::SoakThenMixed, 33)];
    let c = commission(&other_rig_file(), &train, &hold, &CalOptions::default()).expect("commissioning");
    for w in &c.cal.warnings {
        eprintln!("{w}");
    }
    assert!(c.cal.warnings.iter().any(|w| w.contains("one operating point")), "no low-excitation warning: {:?}", c.cal.warnings);
    assert!(c.cal.warnings.iter().any(|w| w.starts_with(NO_COOLING)), "no warning that the LNG valve never opens: {:?}", c.cal.warnings);
    let joint = eha_sim::calibration::ident::NO_JOINT_EXCITATION;
    assert!(c.cal.warnings.iter().any(|w| w.starts_with(joint)), "no warning that speed and load never move independently: {:?}", c.cal.warnings);
    let listed = c.cal.warnings.iter().find(|w| w.contains("held at the rig file")).expect("held list in the warnings");
    for name in ["iron_loss", "leak_gap"] {
        assert!(listed.contains(name), "{name} not named in the warning: {listed}");
    }
    let fw = check_reduced(&other_rig_truth(), &c.params, &hold[0]).expect("reduced model on the truth");
    let worst = c.reduced.iter().map(|r| r.vs_reference_max_k).fold(0.0, f64::max);
    eprintln!(
        "one operating point: commission {} (worst reduced vs reference {worst:.3} K); held-out true drain max |e| {:.3} K, under {:.3} K; eta_m from current {:?}",
        if c.flashable() { "accepts" } else { "refuses" },
        fw.vs_reference_max_k,
        fw.vs_reference_under_k,
        c.eta_m_from_current
    );
    assert!(!c.flashable() || fw.vs_reference_under_k <= 0.5, "accepted and under-predicts by {:.3} K", fw.vs_reference_under_k);
    // Measured: the reduced checks pass (0.137 K) but the block is refused
    // for the excitation; flashed anyway it would under-predict by 1.4 K.
    assert!(!c.flashable() && c.reduced_ok, "measured: refused for the excitation alone");
}

/// One replay of the reference carrying several firmware models and
/// margins (`check_reduced_many`, how commissioning scores the held-out
/// logs) gives each model and margin exactly what its own replay gives:
/// the margin is added to the estimate only and the models do not share
/// state. Exact equality: the same operations in the same order.
#[test]
fn one_replay_scores_several_models_and_margins_as_separate_replays() {
    use eha_sim::calibration::commission::{check_reduced_many, check_reduced_with};
    let l = CalLog::new("soak-33", log(&other_rig_truth(), &mission(Kind::SoakThenMixed, 600.0, 33), 2.0, 33, true).expect("log"), 120).expect("cal log");
    let rig = other_rig_file();
    let p = eha_sim::reduce::reduce(&rig).expect("reduction");
    let d = eha_guard::params::DEFAULT;
    let many = check_reduced_many(&rig, &l, &[(&p, &[0.0, 1.5]), (&d, &[0.0])], f64::NEG_INFINITY).expect("one replay");
    assert_eq!(many[0][0], check_reduced_with(&rig, &p, &l, 0.0).expect("replay"));
    assert_eq!(many[0][1], check_reduced_with(&rig, &p, &l, 1.5).expect("replay"));
    assert_eq!(many[1][0], check_reduced(&rig, &d, &l).expect("replay"));
    assert!(many[0][1].valve_open_s >= many[0][0].valve_open_s, "the margin opens the valve earlier");
}
