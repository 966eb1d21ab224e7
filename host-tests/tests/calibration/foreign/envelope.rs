//! Training logs over the operating envelope: the procedure's
//! two one-at-a-time logs against variants that reach the envelope's
//! high-load, high-speed corner, scored on the held-out logs of the bench
//! set and on a second held-out draw (seed + 10) that no choice saw
//! (docs/commissioning-foreign.md, "Training logs over the operating envelope").

use super::{cal, headline, report};
use eha_sim::calibration::commission::{check_reduced_with, commission};
use eha_sim::calibration::ident::{case_film_speed_range, drain_time_low_and_high_speed_s, duct_transition_time_s};
use eha_sim::calibration::{CalLog, CalOptions};
use eha_sim::emulator::bench::{commissioning_set_of, holdout_logs, machines};
use eha_sim::emulator::missions::EmuScenario;
use eha_sim::measured::Channel;

/// The training variants, by name: the procedure's two logs and the three
/// decided before measuring (log 1, log 2).
pub(super) fn variant(name: &str) -> [EmuScenario; 2] {
    use EmuScenario::*;
    match name {
        "procedure" => [SpeedThenNeedleSteps, SoakThenLowSpeedHolds],
        "twoneedles" => [SpeedStepsAtTwoNeedles, SoakThenLowSpeedHolds],
        "highspeed" => [SpeedThenHighSpeedNeedleSteps, SoakThenLowSpeedHolds],
        "hotsoak" => [SpeedStepsAtTwoNeedles, HotSoakThenLowSpeedHolds],
        _ => panic!("EXP_VARIANT {name}: procedure, twoneedles, highspeed or hotsoak"),
    }
}

/// Measurement by hand (prints, asserts nothing): one commissioning with
/// both paths and their margins per machine (`EXP_MACHINE` for one), on
/// the training variant `EXP_VARIANT` (`procedure` by default), held out
/// on the bench set's servo and mix (seed 3600) and, for the same blocks,
/// on further draws (`EXP_DRAWS`, comma-separated seeds; default 3610, the
/// second draw).
#[test]
#[ignore = "measurement by hand: one commissioning per machine"]
fn slow_training_envelope_experiment() {
    let name = std::env::var("EXP_VARIANT").unwrap_or_else(|_| "procedure".into());
    let only = std::env::var("EXP_MACHINE").ok();
    for m in machines().into_iter().filter(|m| only.as_deref().is_none_or(|o| o == m.name)) {
        let s = commissioning_set_of(&m, 3600, variant(&name)).expect("bench");
        let train: Vec<CalLog> = s.train.iter().map(cal).collect();
        let (low, high) = drain_time_low_and_high_speed_s(&train);
        let (re_s, re_top) = duct_transition_time_s(&train, &m.rig_file());
        let tops: Vec<String> = s.train.iter().map(|l| format!("{:.1}", l.truth.get(Channel::TDrainC).expect("truth").iter().flatten().copied().fold(f64::MIN, f64::max))).collect();
        eprintln!("{} {name}: drain max {} °C; {low:.0} s below 100 rpm, {high:.0} s above 300 rpm, churned film freed {}; passage Re > 3000 for {re_s:.0} s (top {re_top:.0})", m.name, tops.join(" / "), case_film_speed_range(&train));
        let hold: Vec<CalLog> = s.holdout.iter().map(cal).collect();
        let t0 = std::time::Instant::now();
        let c = commission(&m.rig_file(), &train, &hold, &CalOptions::default()).expect("commissioning");
        let secs = t0.elapsed().as_secs_f64();
        report(&m, &c, secs);
        let h = headline(&m, &c, &s.holdout);
        let draws: Vec<u64> = std::env::var("EXP_DRAWS").unwrap_or_else(|_| "3610".into()).split(',').map(|d| d.parse().expect("EXP_DRAWS seed")).collect();
        let mut other = Vec::new();
        for &seed in &draws {
            let logs: Vec<CalLog> = holdout_logs(&m, seed).expect("another draw").iter().map(cal).collect();
            for p in std::iter::once(&c.reduction_path).chain(c.direct_path.as_ref().ok()) {
                let k = p.margin_k().unwrap_or(0.0);
                let r: Vec<(f64, f64)> = logs.iter().map(|l| check_reduced_with(&c.cal.rig, &p.params, l, k).expect("check")).map(|r| (r.vs_measured_max_k.expect("drain"), r.vs_measured_under_k.expect("drain"))).collect();
                eprintln!("  draw {seed}, path {:?} (margin {k:.3} K): {r:.3?}", p.kind);
                if p.kind == c.choice.chosen {
                    other.push((seed, r));
                }
            }
        }
        let cost: Vec<String> = c.holdout_without_margin().iter().zip(&c.holdout_with_margin).map(|(a, b)| format!("{:.0}->{:.0} s", a.valve_open_s, b.valve_open_s)).collect();
        eprintln!(
            "ENV {} {name}: {secs:.1} s, {} runs, path {:?}, flashable {}, margin {:.3} K; held out {:.3?}; other draws {:.3?}; valve {}",
            m.name,
            c.cal.model_runs,
            c.choice.chosen,
            c.flashable(),
            h.margin_k,
            h.measured,
            other,
            cost.join(", ")
        );
    }
}
