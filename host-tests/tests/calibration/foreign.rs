//! Commissioning machines built otherwise: two emulated machines far from
//! the paper rig (`eha_sim::emulator::bench`), trained on two one-at-a-time
//! throttle missions, held out on a servo mission and a throttle mix, every
//! log with a drain-port thermocouple.

use eha_sim::calibration::commission::{check_reduced, commission};
use eha_sim::calibration::{CalLog, CalOptions};
use eha_sim::emulator::bench::{bench_set, machines, BenchLog};
use eha_sim::measured::Channel;

fn cal(l: &BenchLog) -> CalLog {
    CalLog::new(&l.name, l.run.clone(), 120).expect("cal log")
}

fn truth(l: &BenchLog) -> CalLog {
    CalLog::new(&l.name, l.truth.clone(), 120).expect("cal log")
}

/// The bench logs carry the drain thermocouple: within its lag and noise of
/// the true case oil (3 s / 5 s lag, σ 0.1 K, 12-bit), and the drain crosses
/// the 40 °C valve threshold on the throttle logs.
#[test]
fn bench_logs_carry_the_drain_thermocouple() {
    for m in machines() {
        let s = bench_set(&m, 3600).expect("bench");
        for l in s.train.iter().chain(&s.holdout) {
            let d = l.run.get(Channel::TDrainC).expect("t_drain_c");
            let t = l.truth.get(Channel::TDrainC).expect("truth");
            let worst = d.iter().zip(t).filter_map(|(d, t)| Some((d.as_ref()? - t.as_ref()?).abs())).fold(0.0, f64::max);
            let top = t.iter().flatten().copied().fold(f64::MIN, f64::max);
            eprintln!("{}: {} rows, drain max {top:.1} °C, |thermocouple − true| max {worst:.2} K", l.name, l.run.len());
            assert!(worst < 1.5, "{}: thermocouple off the true drain by {worst:.2} K", l.name);
            if !l.name.contains("Servo") {
                assert!(top > 45.0, "{}: drain max {top:.1} °C", l.name);
            }
        }
    }
}

/// The commissioning path as it stands, on both machines: the block written
/// or refused, the firmware's held-out drain error against the thermocouple
/// and against the true drain, the time.
#[test]
#[ignore = "slow tier: two commissionings on emulator bench logs"]
fn slow_commissioning_as_is_on_foreign_machines() {
    for m in machines() {
        let s = bench_set(&m, 3600).expect("bench");
        let train: Vec<CalLog> = s.train.iter().map(cal).collect();
        let hold: Vec<CalLog> = s.holdout.iter().map(cal).collect();
        let t0 = std::time::Instant::now();
        let c = commission(&m.rig_file(), &train, &hold, &CalOptions::default()).expect("commissioning");
        let secs = t0.elapsed().as_secs_f64();
        eprintln!("{}: {:.1} s, {} model runs, flashable {}, reduced_ok {}, excitation_ok {}", m.name, secs, c.cal.model_runs, c.flashable(), c.reduced_ok, c.excitation_ok);
        for w in &c.cal.warnings {
            eprintln!("  warning: {w}");
        }
        for p in &c.cal.params {
            eprintln!("  {:18} {:6.3} {:?}{}", p.name, p.value, p.status, if p.at_bound { " (bound)" } else { "" });
        }
        for r in &c.reduced {
            eprintln!("  reduced {:40} vs ref max {:.3} under {:.3} | vs measured max {:?} under {:?}", r.log, r.vs_reference_max_k, r.vs_reference_under_k, r.vs_measured_max_k, r.vs_measured_under_k);
        }
        for l in &s.holdout {
            let fw = check_reduced(&c.cal.rig, &c.params, &truth(l)).expect("check on truth");
            eprintln!("  true drain {:40} max {:.3} under {:.3}", l.name, fw.vs_measured_max_k.unwrap(), fw.vs_measured_under_k.unwrap());
        }
    }
}
