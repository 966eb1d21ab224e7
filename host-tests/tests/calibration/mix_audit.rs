//! Heat-source audit of the throttle mix: the emulator machine's case-oil
//! heat balance (its own laws, `Plant::case_budget`) beside the commissioned
//! reference's on the same logged inputs, binned by operating point, on the
//! training logs and the held-out mix, and the reference's largest
//! under-predictions of the drain with where they sit. A measurement
//! printed, not a test of a number: run by hand (`-- --ignored --nocapture
//! slow_mix_heat_audit`; `MIXAUDIT_SERIES=1` prints the mix's time series,
//! the commissioned rig is cached in the temp dir, `MIXAUDIT_FRESH=1`
//! commissions again; the machine variants of [`slow_mix_experiment`] apply,
//! and its `EXP_TRAIN_MIX`).

use eha_sim::calibration::commission::commission_with;
use eha_sim::calibration::{CalLog, CalOptions};
use eha_sim::emulator::bench::{bench_log, bench_trace, machines, EmuMachine};
use eha_sim::emulator::missions::EmuScenario;
use eha_sim::emulator::plant::{Hidden, Plant};
use eha_sim::model::{Drive, Model, ReplayDrive};
use eha_sim::network::{self, Node};
use eha_sim::physics::candidates::Candidate;
use eha_sim::rig::Rig;
use eha_sim::scenario::Scenario;
use eha_sim::sim::{simulate_rtol, SimOptions};
pub(super) use super::like_ref::parse_switches;
use super::foreign::cal;
use super::like_ref::{like_ref, like_reference, rig_like_reference, variant};

/// Another throttle mix of `seed` (its own draw of speeds and loads,
/// 1800 s) on machine `m`, as a calibration log: a mix-like training log.
fn other_mix_log(m: &EmuMachine, seed: u64) -> CalLog {
    cal(&bench_log(m, EmuScenario::ThrottleMix, 1800.0, seed).expect("log"))
}

fn commissioned(m: &EmuMachine) -> Rig {
    let holds = std::env::var("EXP_HOLD").unwrap_or_default();
    let tag = std::env::var("MIXAUDIT_TAG").unwrap_or_default();
    let path = std::env::temp_dir().join(format!("mixaudit-{}{}{}{}.toml", m.name, holds, tag, if procedure() { "-procedure" } else { "" }));
    if std::env::var("MIXAUDIT_FRESH").is_err() {
        if let Ok(r) = Rig::from_toml_file(&path) {
            return r;
        }
    }
    let s = if procedure() { eha_sim::emulator::bench::commissioning_set(m, 3600) } else { eha_sim::emulator::bench::bench_set(m, 3600) }.expect("bench");
    let mut train: Vec<CalLog> = s.train.iter().map(cal).collect();
    if std::env::var("EXP_TRAIN_MIX").is_ok() {
        // the held-out mix trained too (tag the cache with MIXAUDIT_TAG)
        train.push(cal(&s.holdout[1]));
    }
    let mut o = CalOptions::default();
    for name in holds.split(',').filter(|n| !n.is_empty()) {
        let k = eha_sim::calibration::set::index(name).expect("parameter");
        o.hold.push((eha_sim::calibration::set::PARAMS[k].name, "experiment".into()));
    }
    let mut base = m.rig_file();
    rig_like_reference(&mut base, &like_ref());
    let c = commission_with(&base, &train, &[], &o, false).expect("commission");
    std::fs::write(&path, c.cal.rig.to_toml()).expect("write rig");
    c.cal.rig
}

/// `MIXAUDIT_TRAIN=procedure`: commission on the procedure's training set
/// (`commissioning_set`: speed-then-needle steps, soak then low-speed
/// holds, every structural freedom) instead of `bench_set`'s two throttle
/// logs, and audit its soak log.
fn procedure() -> bool {
    std::env::var("MIXAUDIT_TRAIN").is_ok_and(|v| v == "procedure")
}

#[derive(Default, Clone, Copy)]
struct Acc {
    n: f64,
    v: [f64; 14],
}

/// Columns of one bin.
const COLS: [&str; 14] = [
    "err", "emuΔT", "refΔT", "emuQ", "refQ", "emuG", "refG", "emuMech", "refFric", "emuLeak", "refLeak", "emuIn", "refIn", "refVisc",
];

fn audit(m: &EmuMachine, rig: &Rig, scenario: EmuScenario, dur: f64, seed: u64) {
    let (mission, trace) = bench_trace(m, scenario, dur, seed);
    let log = bench_log(m, scenario, dur, seed).expect("log");
    let cal = cal(&log);
    let inputs = cal.replay_inputs().expect("replay").clone();
    let out = simulate_rtol(rig, &Scenario::Replay(inputs.clone()), &SimOptions { output_interval_s: 2.0, control_interval_s: 2.0 }, 1e-6).expect("sim");
    let model = Model::new(rig.clone(), Drive::Replay(ReplayDrive::new(inputs.clone())));
    let drive = ReplayDrive::new(inputs);
    let plant = Plant { p: &m.params, m: &mission, h: Hidden { effect: Candidate::None, magnitude: 0.0 } };
    let oil = &rig.oil;
    let mut bins = vec![Acc::default(); 16];
    let mut series = Vec::new();
    let sb = |rpm: f64| if rpm < 550.0 { 0 } else if rpm < 850.0 { 1 } else if rpm < 1050.0 { 2 } else { 3 };
    let pb = |bar: f64| if bar < 25.0 { 0 } else if bar < 40.0 { 1 } else if bar < 50.0 { 2 } else { 3 };
    for (t, y, _) in &trace {
        let e = plant.case_budget(*t, y);
        let at = |name: &str| out.at(name, *t).expect(name);
        let (tc, tp, tout) = (at("t_drain_c"), at("t_pump_c"), at("t_outlet_c"));
        let op = drive.op(rig, *t);
        let fh = model.friction_heat(&op, tc);
        let fr = model.pump_friction(&op, tc);
        let (_, fcase, _) = rig.pump.friction_pairs.shares();
        let ql = model.k_leak(tc) * (op.p_a - op.p_case);
        let rho = oil.rho(at("t_loop_oil_c"), 0.0);
        let leak = ql * rho * (oil.enthalpy_tp(tc, op.p_a) - oil.enthalpy_tp(tc, op.p_case));
        let inflow = ql * rho * (oil.enthalpy_tp(tout, op.p_a) - oil.enthalpy_tp(tc, op.p_a));
        let g = network::case_film_w_per_k(rig, op.omega, tc, model.nu(tc));
        let rpm = op.omega * 30.0 / std::f64::consts::PI;
        let bar = (op.p_a - op.p_b) * 1e-5;
        let k = sb(rpm) * 4 + pb(bar);
        let b = &mut bins[if *t < 300.0 { 15 } else { k }];
        b.n += 1.0;
        let row = [
            tc - e.case_c,
            e.case_c - e.wall_c,
            tc - tp,
            e.mech_w + e.leak_w + e.inflow_w,
            fh.case + leak + inflow,
            e.film_w_per_k,
            g,
            e.mech_w,
            fh.case,
            e.leak_w,
            leak,
            e.inflow_w,
            inflow,
            fcase * fr.viscous_w,
        ];
        for (a, x) in b.v.iter_mut().zip(row) {
            *a += x;
        }
        let _ = Node::Case;
        let series_of = if std::env::var("MIXAUDIT_SERIES").is_ok_and(|v| v == "soak") { EmuScenario::SoakThenLowSpeedHolds } else { EmuScenario::ThrottleMix };
        if scenario == series_of && (*t as i64) % if *t < 300.0 { 4 } else { 10 } == 0 {
            let cap = model.capacity(Node::Case, tc);
            series.push(format!(
                "{t:6.0} {rpm:6.0} {bar:5.1} emu case {:6.2} wall {:6.2} barrel {:6.2} end {:6.2} | ref case {tc:6.2} pump {tp:6.2} meas_pump {:6.2} | err {:6.2} | Q {:6.1}/{:6.1} G {:5.1}/{:5.1} tau_case {:5.1}/{:5.1} | mech→case {:5.1}/{:5.1} (ref viscous part {:5.1}, ref friction total {:5.1}) leak {:5.1}/{:5.1} inflow {:5.1}/{:5.1}",
                e.case_c, e.wall_c, y[2], y[3], log.run.value_at(eha_sim::measured::Channel::TPumpC, *t).unwrap_or(f64::NAN), tc - e.case_c,
                e.mech_w + e.leak_w + e.inflow_w, fh.case + leak + inflow, e.film_w_per_k, g, plant.capacities(y)[4] / e.film_w_per_k, cap / g,
                e.mech_w, fh.case, fcase * fr.viscous_w, fr.viscous_w + fr.pressure_w, e.leak_w, leak, e.inflow_w, inflow
            ));
        }
    }
    // The reference's drain against the thermocouple and the true drain at
    // every logged row: the largest under-predictions.
    let tc_log = log.run.get(eha_sim::measured::Channel::TDrainC).expect("drain");
    let tr_log = log.truth.get(eha_sim::measured::Channel::TDrainC).expect("truth");
    let mut rows: Vec<(f64, f64, f64, f64)> = Vec::new();
    for (k, &t) in log.run.time_s.iter().enumerate() {
        if let (Some(m), Some(tr)) = (tc_log[k], tr_log[k]) {
            rows.push((t, out.at("t_drain_c", t).expect("drain"), m, tr));
        }
    }
    rows.sort_by(|a, b| (a.1 - a.2).total_cmp(&(b.1 - b.2)));
    for r in rows.iter().take(4) {
        eprintln!("  worst under vs thermocouple: t {:.0} s ref {:.2} thermocouple {:.2} true {:.2}: {:.2} K (vs true {:.2} K)", r.0, r.1, r.2, r.3, r.1 - r.2, r.1 - r.3);
    }
    if std::env::var("MIXAUDIT_SERIES").is_ok() {
        for l in &series {
            eprintln!("{l}");
        }
    }
    eprintln!("== {} {:?} (t > 300 s; bins rpm <550/550-850/850-1050/>1050 × bar <25/25-40/40-50/>50)", m.name, scenario);
    eprintln!("{:>10} {:>5} {}", "bin", "n", COLS.iter().map(|c| format!("{c:>8}")).collect::<String>());
    for (k, b) in bins.iter().enumerate() {
        if b.n < 5.0 {
            continue;
        }
        let row: String = b.v.iter().map(|x| format!("{:>8.2}", x / b.n)).collect();
        eprintln!("{:>10} {:>5} {}", format!("s{} p{}", k / 4, k % 4), b.n, row);
    }
}

#[test]
#[ignore = "measurement by hand: a commissioning (cached in the temp dir) and replays"]
fn slow_mix_heat_audit() {
    for mut m in machines() {
        if std::env::var("EXP_MACHINE").is_ok_and(|n| n != m.name) {
            continue;
        }
        variant(&mut m);
        let rig = commissioned(&m);
        audit(&m, &rig, EmuScenario::SpeedThenNeedleSteps, 1800.0, 3600);
        let soak = if procedure() { EmuScenario::SoakThenLowSpeedHolds } else { EmuScenario::SoakThenIdle };
        audit(&m, &rig, soak, 1800.0, 3601);
        audit(&m, &rig, EmuScenario::ThrottleMix, 1800.0, 3603);
    }
}

/// Emulator-side and calibration-side experiments on the mix's miss, by
/// environment (docs/commissioning-foreign.md, "The held-out drain misses:
/// structural bisection"): on the emulator machines
/// `EXP_MECH_RULE=1` places the mechanical loss by the reference's
/// sliding-pair rule (delivered 0.6, case 0.15, metal 0.25);
/// `EXP_G_BARREL_END=W/K`, `EXP_PROBE_AMBIENT=frac`, `EXP_PROBE_BARREL=w`
/// set those fields; `EXP_A_CASE=k`, `EXP_GAP=k` scale the case wetted area
/// and the leakage gap; on the user's rig file `EXP_RIG_CV=k`,
/// `EXP_RIG_T0=k` scale the viscous and no-load friction torques,
/// `EXP_RIG_CASE_OIL=k` the case-oil volume (a volume the user measured),
/// `EXP_RIG_GAP=k` the three pump gaps (with `EXP_HOLD=leak_gap`: the
/// machine's leakage conductance, ×1.414 big-pump, ×1.658 leaky-heavy);
/// `EXP_HOLD=a,b` holds calibration parameters at the rig file;
/// `EXP_DRAIN_WEIGHT=w` weights the drain residuals; `EXP_LIKE_REF=a,b`
/// (or `all`) the structural switches of [`like_reference`];
/// `EXP_TRAIN_MIX=1` / `EXP_TRAIN_SERVO=1` add the held-out mix / servo log
/// to the training set (still scored: can the reference follow it at all?);
/// `EXP_TRAIN_OTHER_MIX=seed` adds another throttle mix of that seed;
/// `EXP_MACHINE` picks one machine. Prints the held-out numbers without the
/// margin (firmware drain vs thermocouple).
#[test]
#[ignore = "measurement by hand: one commissioning per machine"]
fn slow_mix_experiment() {
    for mut m in machines() {
        if std::env::var("EXP_MACHINE").is_ok_and(|n| n != m.name) {
            continue;
        }
        variant(&mut m);
        let s = eha_sim::emulator::bench::bench_set(&m, 3600).expect("bench");
        let train: Vec<CalLog> = s.train.iter().map(cal).collect();
        let hold: Vec<CalLog> = s.holdout.iter().map(cal).collect();
        let mut o = CalOptions::default();
        for name in std::env::var("EXP_HOLD").unwrap_or_default().split(',').filter(|n| !n.is_empty()) {
            let k = eha_sim::calibration::set::index(name).expect("parameter");
            o.hold.push((eha_sim::calibration::set::PARAMS[k].name, "experiment".into()));
        }
        let env = |k: &str| std::env::var(k).ok().and_then(|v| v.parse::<f64>().ok());
        if let Some(w) = env("EXP_DRAIN_WEIGHT") {
            o.drain_weight = w;
        }
        let mut base = m.rig_file();
        if let Some(k) = env("EXP_RIG_CV") {
            base.pump.viscous_torque_coeff *= k;
        }
        if let Some(k) = env("EXP_RIG_T0") {
            base.pump.no_load_torque_nm *= k;
        }
        if let Some(k) = env("EXP_RIG_CASE_OIL") {
            base.pump.case_oil_m3 *= k;
        }
        if let Some(k) = env("EXP_RIG_GAP") {
            let g = &mut base.pump.gaps;
            g.piston_gap_m *= k;
            g.slipper_gap_m *= k;
            g.port_gap_m *= k;
        }
        rig_like_reference(&mut base, &like_ref());
        let mut train = train;
        if std::env::var("EXP_TRAIN_MIX").is_ok() {
            // the held-out mix in the training set too: can the reference follow it at all?
            train.push(hold[1].clone());
        }
        if let Some(seed) = env("EXP_TRAIN_OTHER_MIX") {
            // another throttle mix (its own draw, this seed) in the training set:
            // does a mix-like training log carry the held-out mix?
            train.push(other_mix_log(&m, seed as u64));
        }
        if std::env::var("EXP_TRAIN_SERVO").is_ok() {
            // the held-out servo log in the training set too (frees the churned case film)
            train.push(hold[0].clone());
        }
        let t0 = std::time::Instant::now();
        let c = commission_with(&base, &train, &hold, &o, false).expect("commission");
        let fitted: Vec<String> = c.cal.params.iter().filter(|p| p.status == eha_sim::calibration::Status::Fitted).map(|p| format!("{} {:.3}{}", p.name, p.value, if p.at_bound { "*" } else { "" })).collect();
        eprintln!("{} ({:.0} s): fitted {}", m.name, t0.elapsed().as_secs_f64(), fitted.join(", "));
        for r in c.reduced.iter() {
            eprintln!("  {:45} reduced vs ref {:.3} | vs measured max {:.3?} under {:.3?}", r.log, r.vs_reference_max_k, r.vs_measured_max_k, r.vs_measured_under_k);
        }
        for r in &c.holdout_with_margin {
            eprintln!("  held out {:36} max {:.3?} under {:.3?} over {:.3?} at {}", r.log, r.vs_measured_max_k, r.vs_measured_under_k, r.vs_measured_over_k, r.vs_measured_region.as_ref().map(|g| g.to_string()).unwrap_or_default());
        }
    }
}

/// Held-out numbers of one bisection step: the machine with `switches`,
/// commissioned on its two training logs without the margin: (servo
/// under-prediction, mix max |e|, mix under-prediction), K, firmware drain
/// against the thermocouple.
fn bisection_step(machine: &EmuMachine, switches: &[String]) -> (f64, f64, f64) {
    bisection_run(machine, switches, false, None)
}

/// [`bisection_step`], with the held-out mix added to the training set
/// when `train_mix` (still scored: can the reference follow it at all?),
/// and another throttle mix of seed `other_mix` (1800 s) when given.
pub(super) fn bisection_run(machine: &EmuMachine, switches: &[String], train_mix: bool, other_mix: Option<u64>) -> (f64, f64, f64) {
    let mut m = machine.clone();
    like_reference(&mut m.params, switches);
    let s = eha_sim::emulator::bench::bench_set(&m, 3600).expect("bench");
    let train: Vec<CalLog> = s.train.iter().map(cal).collect();
    let hold: Vec<CalLog> = s.holdout.iter().map(cal).collect();
    let mut base = m.rig_file();
    rig_like_reference(&mut base, switches);
    let mut train = train;
    if train_mix {
        train.push(hold[1].clone());
    }
    if let Some(seed) = other_mix {
        train.push(other_mix_log(&m, seed));
    }
    // The set as the bisection measured it: the structural freedoms it led
    // to held (they are measured in foreign.rs).
    let mut o = CalOptions::default();
    o.hold.extend(eha_sim::calibration::set::STRUCTURAL.map(|n| (n, "the bisection's set".to_string())));
    let c = commission_with(&base, &train, &hold, &o, false).expect("commission");
    let h = &c.holdout_with_margin;
    let v = |x: Option<f64>| x.expect("drain logged");
    (v(h[0].vs_measured_under_k), v(h[1].vs_measured_max_k), v(h[1].vs_measured_under_k))
}

/// The structural bisection's headline steps (docs/commissioning-foreign.md, "The
/// held-out drain misses: structural bisection"), measured at this commit
/// on this build: servo under-prediction, mix max |e| and under-prediction
/// per machine, K, without the margin. Asserted within 0.25 K of the
/// measured: the fit's basin moves with the optimiser's path, which a build
/// with other float rounding in the model changes (big-pump as built moved
/// 0.59 K between the fits before and on the θ lattice, the other rows
/// ≤ 0.19 K); the conclusions drawn rest on differences of ≥ 0.6 K between
/// rows. The rows are measured with calib11's calibration defaults (priors
/// ×0.5, polish at rtol 1e-6; one run, 150 s at load 1.8-3.0); those
/// defaults moved big-pump `gapfilm`'s mix 1.488 → 1.991 K (max |e| and
/// under-prediction; within the 0.3-0.9 K path spread, over this test's
/// 0.25 K), big-pump as built's mix under-prediction 2.893 → 2.651 K and
/// `split,nofric`'s 1.722 → 1.488 K, the rest ≤ 0.1 K. Re-measured on the
/// fixed reference (b36ffe3; 459.9 s wall, 307.4 s user at load 5–6): the
/// rows moved ≤ 0.21 K except leaky-heavy's control, whose mix went
/// 0.799 → 0.519 K (outside 0.25 K), re-asserted as measured.
#[test]
#[ignore = "slow: ten commissionings, 150–277 s on 2 shared cores"]
fn slow_structural_bisection_of_the_drain_misses() {
    // switches, big-pump (servo under, mix max, mix under), leaky-heavy (same)
    let rows: [(&str, [f64; 3], [f64; 3]); 5] = [
        // Measured with calib11's defaults (priors ×0.5, polish 1e-6). Before
        // them (set's widths, polish 1e-5; old → new): big-pump as built
        // [2.327, 3.694, 2.893], leaky-heavy [3.063, 2.443, 2.443]; gapfilm
        // [0.632, 1.488, 1.488], [1.762, 1.751, 1.751]; split,nofric
        // [2.339, 4.034, 1.722], [3.151, 1.840, 1.840]; the nine
        // [2.291, 3.969, 0.469], [3.055, 1.700, 1.516]; all [0.614, 1.638,
        // 1.345], [0.778, 0.793, 0.793]. Big-pump as built: mix under
        // 2.306 K before the θ lattice, 2.893 K on it, 2.651 K with the
        // defaults (other optimiser paths).
        // Measured on the fixed reference (b36ffe3); before it (calib11's
        // defaults): as built [2.331, 3.680, 2.651], [3.079, 2.473, 2.473];
        // gapfilm [0.630, 1.991, 1.991], [1.772, 1.715, 1.715];
        // split,nofric [2.321, 4.039, 1.488], [3.150, 1.936, 1.936]; the
        // nine [2.317, 4.014, 0.488], [3.055, 1.684, 1.510]; all [0.610,
        // 1.641, 1.321], [0.770, 0.799, 0.799].
        ("", [2.334, 3.728, 2.571], [3.075, 2.448, 2.448]),
        ("gapfilm", [0.626, 2.099, 2.099], [1.747, 1.504, 1.504]),
        ("split,nofric", [2.320, 4.053, 1.357], [3.156, 1.751, 1.751]),
        ("split,nofric,onepump,surface,oilprobe,drain,flange,blocks,emiss", [2.324, 4.053, 0.511], [3.068, 1.712, 1.488]),
        ("all", [0.612, 1.794, 1.220], [0.760, 0.519, 0.519]),
    ];
    let mut bad = Vec::new();
    for (switches, bp, lh) in rows {
        for (m, want) in machines().iter().zip([bp, lh]) {
            let got = bisection_step(m, &parse_switches(switches));
            let got = [got.0, got.1, got.2];
            eprintln!("{} [{switches}]: servo under {:.3}, mix max {:.3} under {:.3} K (measured {want:?})", m.name, got[0], got[1], got[2]);
            if got.iter().zip(want).any(|(g, w)| (g - w).abs() > 0.25) {
                bad.push(format!("{} [{switches}]: {got:.3?} against {want:?}", m.name));
            }
        }
    }
    assert!(bad.is_empty(), "bisection steps off their measured numbers: {bad:#?}");
}
