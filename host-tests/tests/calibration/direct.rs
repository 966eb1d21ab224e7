//! Direct identification of the firmware model's parameters from logs.

use eha_sim::calibration::commission::check_reduced;
use eha_sim::calibration::direct::{identify_direct, score, DirectOptions};
use eha_sim::calibration::replay::{node_errors, TickInputs};
use eha_sim::calibration::synthetic::{log, mission, other_rig_file, other_rig_truth, Kind};
use eha_sim::calibration::CalLog;
use std::time::Instant;

fn cal_log(kind: Kind, seed: u64) -> CalLog {
    CalLog::new(&format!("{kind:?}-{seed}"), log(&other_rig_truth(), &mission(kind, 1800.0, seed), 2.0, seed, true).expect("log"), 120).expect("cal log")
}

#[test]
fn explore_other_rig() {
    let t0 = Instant::now();
    let train = [cal_log(Kind::PressureSteps, 31), cal_log(Kind::SpeedSteps, 32), cal_log(Kind::CoolingSteps, 34)];
    let hold = [cal_log(Kind::SoakThenMixed, 33)];
    eprintln!("logs {:.2} s", t0.elapsed().as_secs_f64());
    let p0 = eha_sim::reduce::reduce(&other_rig_file()).expect("reduce");
    let t1 = Instant::now();
    let inp = TickInputs::of(&hold[0]).unwrap();
    eprintln!("inputs {:.3} s ({} ticks)", t1.elapsed().as_secs_f64(), inp.ticks.len());
    let t1 = Instant::now();
    let e = node_errors(&p0, &hold[0], &inp).unwrap();
    eprintln!("node_errors {:.3} s {:?}", t1.elapsed().as_secs_f64(), e);
    let t1 = Instant::now();
    let c = check_reduced(&other_rig_truth(), &p0, &hold[0]).unwrap();
    eprintln!("check_reduced {:.3} s {:?}", t1.elapsed().as_secs_f64(), c);
    let t1 = Instant::now();
    let f = identify_direct(&p0, &train, &DirectOptions::default()).expect("fit");
    eprintln!("fit {:.2} s, {} runs, chi2 {:?} n {}", t1.elapsed().as_secs_f64(), f.model_runs, f.chi2_before_after, f.n_points);
    for r in &f.results {
        eprintln!("{:14} {:6.3} sd {:.3} [{:.3},{:.3}] {} {:?}", r.name, r.value, r.sd_ln, r.interval95.0, r.interval95.1, r.at_bound, r.held);
    }
    eprintln!("max rho {:.3} {:?}", f.max_abs_correlation, f.correlated);
    for s in f.train.iter().chain(score(&p0, &f.params, &hold).unwrap().iter()) {
        for (a, b) in s.before.iter().zip(&s.after) {
            eprintln!("{:20} {:14} rmse {:.3}->{:.3} max {:.3}->{:.3} under {:.3}->{:.3}", s.log, a.channel, a.rmse_k, b.rmse_k, a.max_abs_k, b.max_abs_k, a.max_under_k, b.max_under_k);
        }
    }
    let truth = other_rig_truth();
    let a = check_reduced(&truth, &p0, &hold[0]).unwrap();
    let b = check_reduced(&truth, &f.params, &hold[0]).unwrap();
    eprintln!("vs true drain: reduction max {:.3} under {:.3}; direct max {:.3} under {:.3}", a.vs_reference_max_k, a.vs_reference_under_k, b.vs_reference_max_k, b.vs_reference_under_k);
}
