//! Commissioning machines built otherwise: two emulated machines far from
//! the paper rig (`eha_sim::emulator::bench`: big-pump, leaky-heavy),
//! trained on two one-at-a-time throttle missions, held out on a servo
//! mission and a throttle mix, every log with a drain-port thermocouple.
//! The user's rig file is the paper rig with the nameplate values.

use eha_sim::calibration::commission::{commission, commission_with, Commissioning};
use eha_sim::calibration::paths::PathKind;
use eha_sim::calibration::ident::{case_film_speed_range, drain_time_low_and_high_speed_s, duct_transition_range, duct_transition_time_s};
use eha_sim::calibration::{CalLog, CalOptions};
use eha_sim::emulator::bench::{bench_log, bench_set, commissioning_set, commissioning_set_hot, big_pump, leaky_heavy, machines, BenchLog, BenchSet, EmuMachine};
use eha_sim::emulator::missions::EmuScenario;
use eha_sim::measured::Channel;

/// A bench log as a calibration log (120 fit points per channel).
pub(super) fn cal(l: &BenchLog) -> CalLog {
    CalLog::new(&l.name, l.run.clone(), 120).expect("cal log")
}

/// The bench logs carry the drain thermocouple: within its lag and noise of
/// the true case oil (3 s / 5 s lag, σ 0.1 K, 12-bit; measured worst 0.40–0.89
/// K on big-pump, 2.47 K on leaky-heavy's soak log, whose drain rises ~0.5 K/s
/// after the load step against the 5 s probe), and the drain crosses the
/// 40 °C valve threshold on the throttle logs. The training logs never
/// hold the pump below 100 rpm, so the churned case film is held
/// (`case_film_speed_range`); the servo log (0–150 rpm) added frees it.
#[test]
fn bench_logs_carry_the_drain_thermocouple() {
    for m in machines() {
        let s = bench_set(&m, 3600).expect("bench");
        let mut train: Vec<CalLog> = s.train.iter().map(cal).collect();
        let (low, high) = drain_time_low_and_high_speed_s(&train);
        eprintln!("{}: training drain logs {low:.0} s below 100 rpm, {high:.0} s above 300 rpm", m.name);
        assert!(!case_film_speed_range(&train), "{}: the churned case film freed by throttle logs alone", m.name);
        train.push(cal(&s.holdout[0]));
        assert!(case_film_speed_range(&train), "{}: the servo log does not free the churned case film", m.name);
        for l in s.train.iter().chain(&s.holdout) {
            let d = l.run.get(Channel::TDrainC).expect("t_drain_c");
            let t = l.truth.get(Channel::TDrainC).expect("truth");
            let worst = d.iter().zip(t).filter_map(|(d, t)| Some((d.as_ref()? - t.as_ref()?).abs())).fold(0.0, f64::max);
            let top = t.iter().flatten().copied().fold(f64::MIN, f64::max);
            eprintln!("{}: {} rows, drain max {top:.1} °C, |thermocouple − true| max {worst:.2} K", l.name, l.run.len());
            assert!(worst < 3.0, "{}: thermocouple off the true drain by {worst:.2} K", l.name);
            if !l.name.contains("Servo") {
                assert!(top > 45.0, "{}: drain max {top:.1} °C", l.name);
            }
        }
    }
}

/// The commissioning procedure's training set (`commissioning_set`: the
/// soak log's idle replaced by low-speed holds) frees the churned case
/// film's speed law; its held-out logs are `bench_set`'s. With the hot-flow
/// run (`commissioning_set_hot`) the main-block passage's flow is above
/// Re 3000 for ≥ 300 s on big-pump (`duct_transition_range`; measured
/// 1500 s, Re up to 6200, drain up to 80.9 °C), not on leaky-heavy (×0.8
/// displacement: 0 s, Re up to 1960, drain up to 70.7 °C); without it on
/// neither (big-pump Re up to 2480, leaky-heavy 820).
#[test]
fn commissioning_set_frees_the_case_film_speed_law() {
    for (m, frees_duct) in machines().into_iter().zip([true, false]) {
        let s = commissioning_set_hot(&m, 3600).expect("bench");
        let train: Vec<CalLog> = s.train.iter().map(cal).collect();
        let (low, high) = drain_time_low_and_high_speed_s(&train[..2]);
        let rig = m.rig_file();
        let (re_s, re_top) = duct_transition_time_s(&train, &rig);
        let (re_s2, re_top2) = duct_transition_time_s(&train[..2], &rig);
        for l in &s.train[1..] {
            let t = l.truth.get(Channel::TDrainC).expect("truth");
            let top = t.iter().flatten().copied().fold(f64::MIN, f64::max);
            eprintln!("{}: {} drain max {top:.1} °C", m.name, l.name);
            assert!(top > 45.0 && top < 85.0, "{}: drain max {top:.1} °C", m.name);
        }
        eprintln!("{}: training drain logs {low:.0} s below 100 rpm, {high:.0} s above 300 rpm; passage Re > 3000 for {re_s:.0} s (top {re_top:.0}), without the hot-flow run {re_s2:.0} s (top {re_top2:.0})", m.name);
        assert!(case_film_speed_range(&train[..2]), "{}: the churned case film not freed", m.name);
        assert_eq!(duct_transition_range(&train, &rig), frees_duct, "{}: the ducts' turbulent level", m.name);
        assert!(!duct_transition_range(&train[..2], &rig), "{}: freed without the hot-flow run", m.name);
        let c = commissioning_set(&m, 3600).expect("bench");
        assert_eq!(c.train.len(), 2, "the procedure's default set");
    }
}


/// The reduction path without the margin (no validation, no direct
/// path), on both machines, trained as the commissioning procedure
/// prescribes (`commissioning_set`: the speed-then-needle steps and a soak
/// followed by low-speed holds), every structural freedom of the set fitted
/// (the churned case film, `friction_case` with `friction_speed`,
/// `probe_surface_*`). Measured (held-out servo, throttle mix; firmware
/// drain vs the thermocouple, max |e| / under-prediction), with the
/// default priors at half the set's widths and the polish at rtol 1e-6
/// (`fit::PRIOR_SCALE`): big-pump 0.700 / 0.700 K and 1.609 / 1.609 K,
/// leaky-heavy 1.059 / 1.059 K and 1.715 / 1.715 K (the set's own widths
/// and the polish at 1e-5: 1.902 / 1.902, 1.738 / 1.738, 1.046 / 1.046,
/// 1.706 / 1.706 K; the set before the freedoms, on the two throttle logs:
/// 2.25 / 2.25 and 3.87 / 2.29 K; 3.10 / 3.10 and 2.44 / 2.44 K). Both
/// were refused: the six-state model departed from the commissioned
/// reference by 0.444 K on big-pump's servo log and by 1.180 K on
/// leaky-heavy's, bound 0.2 K. Since the reference's replay books no
/// check-valve or lost ring heat (b36ffe3) and the firmware throttles
/// nothing in a servo hold (2026-11-28): big-pump 0.709 / 0.709 and
/// 1.604 / 1.604 K, its reduction **flashable** (0.178 K off the
/// reference; 0.177 K with the firmware's old bookkeeping, 0.7088 K the
/// same to 4 digits); leaky-heavy 1.058 / 1.058 and 1.567 / 1.567 K,
/// refused at 0.358 K (the old bookkeeping 1.057 K, 0.353 K). The misses
/// stay asserted as measured: the structure does not close them
/// (docs/commissioning-foreign.md, "Reproducibility").
#[test]
#[ignore = "slow tier: two commissionings on emulator bench logs (~40 s each)"]
fn slow_commissioning_without_margin_on_foreign_machines() {
    let measured = [(true, [(0.709, 0.709), (1.604, 1.604)]), (false, [(1.058, 1.058), (1.567, 1.567)])];
    for (m, (flash, want)) in machines().into_iter().zip(measured) {
        let s = commissioning_set(&m, 3600).expect("bench");
        let train: Vec<CalLog> = s.train.iter().map(cal).collect();
        let hold: Vec<CalLog> = s.holdout.iter().map(cal).collect();
        let t0 = std::time::Instant::now();
        let c = commission_with(&m.rig_file(), &train, &hold, &CalOptions::default(), false).expect("commissioning");
        report(&m, &c, t0.elapsed().as_secs_f64());
        let h = headline(&m, &c, &s.holdout);
        assert_eq!(c.flashable(), flash, "{}: flashable", m.name);
        for (got, want) in h.measured.iter().zip(want) {
            near(&format!("{} held-out max |e|", m.name), got.0, want.0);
            near(&format!("{} held-out under-prediction", m.name), got.1, want.1);
        }
    }
}

/// Commissioning as the user runs it: both paths (the reduction, the
/// direct identification), each with its drain margin validated on a split
/// of the training missions, and the safer on the held-out logs flashed;
/// trained as the procedure prescribes (`commissioning_set`), the set's
/// structural freedoms fitted. The acceptance is 1.0 K max |e| and
/// ≤ 0.3 K under-prediction on the held-out logs with the margin counted.
/// Measured (max |e| / under vs the thermocouple, margin counted; servo,
/// throttle mix), with the default priors at half the set's widths and the
/// polish at rtol 1e-6 (`fit::PRIOR_SCALE`, `fit::POLISH_RTOL`), on the
/// reference with the replay's check valves limited to the make-up flow
/// and the servo ring's direction in holds from the pump's delivery
/// (2026-11-28, b36ffe3; the rows before it in CHANGELOG):
/// - big-pump: the reduction's block now holds (0.177 K off the reference
///   on the servo log, bound 0.2 K; was 0.444 K) and both paths are
///   validated; the held-out rule flashes the direct path, both beyond
///   0.3 K under and the direct path's under-prediction lower by more
///   than `paths::PATH_TIE_K` (0.54 against 0.70 K): margin 1.319 K,
///   1.859 / 0.000 and 2.782 / 0.541 K (the reduction, 0.906 K margin:
///   1.415 / 0.000 and 1.860 / 0.698 K).
/// - leaky-heavy: the reduction still refused (0.353 K off the reference
///   on the servo log; was 1.180 K), direct path, margin 1.191 K;
///   1.750 / 0.000 and 2.334 / 0.617 K (reduction, margin 0.847 K:
///   1.481 / 0.210 and 1.909 / 0.719 K); written.
/// - Not met: under-prediction 0.54–0.62 K, max |e| 2.3–2.8 K.
/// - Cost on the throttle mix (open loop, chosen path): valve open 1412 →
///   1520 s, LNG 2.87 → 3.05 kg (big-pump, direct; the reduction's 1403 →
///   1443 s, 2.80 → 2.87 kg); 1550 → 1560 s, 1.92 → 1.94 kg
///   (leaky-heavy); the servo logs stay below 40 °C.
/// - Since the reference's replay books no check-valve or lost ring heat
///   (b36ffe3) and the firmware throttles nothing in a servo hold
///   (2026-11-28, evening; asserted): big-pump direct, margin 1.319 K,
///   1.838 / 0.000 and 2.782 / 0.541 K (the firmware's old bookkeeping
///   1.859 / 0.000 K on the servo log, the mix the same), valve 1412 →
///   1519 s; leaky-heavy direct (its reduction refused at 0.358 K), margin
///   1.191 K, 1.471 / 0.000 and 2.334 / 0.617 K (old bookkeeping 1.750 K
///   on the servo log), valve 1550 → 1560 s. Not met: under-prediction
///   0.54–0.62 K, max |e| 2.3–2.8 K.
/// - **With the margin's head folds** (2026-11-28 night, the default
///   `margin::HEAD_FOLD_DEFAULT`: besides the fold fitted on the first
///   60 % of every training log and scored after it, one fold per
///   training log fitted on the other logs whole and on this log's last
///   60 %, scored on its first 40 %, the start from rest): big-pump's
///   soak start (t 13–71 s, 640 rpm, 48 bar, drain 27–34 °C) is 1.52 K
///   under, so the margin rises 0.906 → **1.722 K** (the reduction's) and
///   both paths come within 0.3 K under on the held-out logs; the
///   reduction (smaller max |e|) is flashed: **2.201 / 0.000 and
///   2.676 / 0.000 K** (the direct path, margin 1.712 K:
///   2.237 / 0.000, 3.176 / 0.152 K); the mix's valve 1405 → 1519 s, LNG
///   2.798 → 2.990 kg. Leaky-heavy's starts are 0.31–0.33 K under (the
///   direct path's), below its after-split 0.99 K: margin 1.191 K and its
///   numbers unchanged, 1.471 / 0.000 and 2.334 / 0.617 K (the mix's hot
///   corner; valve 1550 → 1560 s). Under-prediction met on big-pump, not on leaky-heavy; max
///   |e| met on neither.
/// - Time: see `slow_commissioning_is_reproducible_beyond_the_last_digit_big_pump`.
///   Not a timing test.
/// - With the hot-flow run as a third training log:
///   `slow_commissioning_with_the_hot_flow_run`.
/// - **Why no margin meets 1.0 K** (2026-11-29, asserted): the flashed
///   block on its own training logs (in-sample, no margin) spans
///   −1.275…+1.159 K on big-pump (the soak log) and −1.218…+1.284 K on
///   leaky-heavy, so no constant margin leaves less than **1.217 K** and
///   **1.251 K** max |e| even on the logs it was fitted to
///   (`TrainingSpread`, the report's in-sample section).
#[test]
#[ignore = "slow tier: two commissionings with margin validation on emulator bench logs (~1 min each)"]
fn slow_commissioning_with_margin_on_foreign_machines() {
    let measured = [
        (1.722, PathKind::Reduction, [(2.201, 0.000), (2.676, 0.000)], [1405.0, 1519.0]),
        (1.191, PathKind::Direct, [(1.471, 0.000), (2.334, 0.617)], [1550.0, 1560.0]),
    ];
    let floors_k = [1.217, 1.251];
    for ((m, row), floor_k) in machines().into_iter().zip(measured).zip(floors_k) {
        let s = commissioning_set(&m, 3600).expect("bench");
        let c = commission_as_measured(&m, &s, row);
        let t = eha_sim::calibration::commission::TrainingSpread::of(&c.train_chosen).expect("the in-sample error takes both signs");
        near(&format!("{} in-sample floor under any constant margin", m.name), t.floor_k(), floor_k);
        assert!(c.direct_path.is_ok(), "{}: the direct path did not run: {:?}", m.name, c.direct_path.as_ref().err());
        // The margin opens the valve earlier, never later (open loop).
        let (a, b) = (&c.holdout_without_margin()[1], &c.holdout_with_margin[1]);
        assert!(b.valve_open_s >= a.valve_open_s && b.lng_kg >= a.lng_kg, "{}: margin cost negative", m.name);
    }
}

/// One machine's measured headline in a slow commissioning test: the
/// margin (K), the path chosen, (max |e|, under-prediction) with the margin
/// on each held-out log (K), the throttle mix's valve opening without and
/// with the margin (s).
type Measured = (f64, PathKind, [(f64, f64); 2], [f64; 2]);

/// Commissions `m` on the bench set `s` with the calibration's defaults and
/// asserts the measured headline: margin and held-out errors within
/// [`near`]'s tolerance, the path, a flashable block, the mix's valve
/// opening within 20 s of the measured. The commissioning, for a test's
/// own checks.
fn commission_as_measured(m: &EmuMachine, s: &BenchSet, (margin, path, want, open_s): Measured) -> Commissioning {
    let train: Vec<CalLog> = s.train.iter().map(cal).collect();
    let hold: Vec<CalLog> = s.holdout.iter().map(cal).collect();
    let t0 = std::time::Instant::now();
    let c = commission(&m.rig_file(), &train, &hold, &CalOptions::default()).expect("commissioning");
    report(m, &c, t0.elapsed().as_secs_f64());
    let h = headline(m, &c, &s.holdout);
    near(&format!("{} margin", m.name), h.margin_k, margin);
    assert_eq!(c.choice.chosen, path, "{}: {}", m.name, c.choice.why);
    assert!(c.flashable(), "{}: {:?}", m.name, c.refusal().map(|r| r.to_string()));
    for (got, want) in h.measured.iter().zip(want) {
        near(&format!("{} held-out max |e| with margin", m.name), got.0, want.0);
        near(&format!("{} held-out under-prediction with margin", m.name), got.1, want.1);
    }
    let (a, b) = (&c.holdout_without_margin()[1], &c.holdout_with_margin[1]);
    assert!((a.valve_open_s - open_s[0]).abs() <= 20.0 && (b.valve_open_s - open_s[1]).abs() <= 20.0, "{}: valve open {:.0} -> {:.0} s", m.name, a.valve_open_s, b.valve_open_s);
    c
}

/// A training set that cannot identify the machine: one operating point
/// (500 rpm, one needle setting, 20 min) on big-pump. Refused, and the
/// refusal names the log, its operating region, the channel and the bench
/// run that would fix it.
#[test]
fn one_operating_point_is_refused_with_log_region_channel_and_bench_run() {
    let m = big_pump();
    let l = bench_log(&m, EmuScenario::ConstantThrottle, 1200.0, 3700).expect("bench log");
    let c = commission(&m.rig_file(), &[cal(&l)], &[], &CalOptions::default()).expect("commissioning");
    let r = c.refusal().expect("refused");
    eprintln!("{r}");
    assert!(!c.flashable());
    assert!(r.reason.contains("one operating point"), "{}", r.reason);
    assert_eq!(r.log, l.name);
    assert!(r.region.contains("one operating point") && r.region.contains("rpm") && r.region.contains("bar") && r.region.contains("°C"), "{}", r.region);
    assert!(r.channel.contains("temperature"), "{}", r.channel);
    assert!(r.bench_run.contains("speed steps") && r.bench_run.contains("needle steps") && r.bench_run.contains("t_drain_c"), "{}", r.bench_run);
}



/// The churned case film where the training set frees it: big-pump trained
/// on its two throttle logs and the servo log (0–150 rpm holds), held out
/// on the throttle mix; the same commissioning with the churned film held
/// (the gap law) beside it. Measured on the fixed reference (b36ffe3; the
/// calibration's defaults, priors ×0.5 and polish at rtol 1e-6; 180.9 s
/// wall for both with other helpers' jobs on the 2 cores; firmware drain
/// vs the thermocouple, max |e| / under-prediction, without the margin):
/// churned film fitted (film ×0.77, churn ×33.8, speed law 0.90,
/// `cap_case_oil` on its ×3 bound), mix 2.463 / 2.463 K, the servo log
/// (training) 0.865 K under; gap law (`film_case` on its ×10 bound)
/// 3.803 / 2.471 K, servo 2.324 K under. Before the fix 2.697 / 2.697,
/// 0.877 and 3.868 / 2.264, 2.266 K (the gap law's mix under-prediction
/// moved 0.207 K, outside `AS_MEASURED_K`: re-asserted as measured);
/// earlier rows in CHANGELOG. Max |e| falls 1.34 K with the churned film,
/// the under-prediction does not (2.471 → 2.463 K).
#[test]
#[ignore = "slow tier: two commissionings on emulator bench logs (~1 min each)"]
fn slow_churned_case_film_with_a_low_speed_training_log() {
    let m = big_pump();
    let s = bench_set(&m, 3600).expect("bench");
    let mut train: Vec<CalLog> = s.train.iter().map(cal).collect();
    train.push(cal(&s.holdout[0]));
    let hold = [cal(&s.holdout[1])];
    let churn = eha_sim::calibration::set::CASE_CHURN;
    let mut got = Vec::new();
    for held in [false, true] {
        let mut o = CalOptions::default();
        // The churned film alone, as measured: the other structural
        // freedoms held (measured together in the commissioning tests).
        o.hold.extend(eha_sim::calibration::set::STRUCTURAL.map(|n| (n, "the churned film alone".to_string())));
        if held {
            o.hold.push((churn, "the gap law, for comparison".into()));
            o.hold.push((eha_sim::calibration::set::CASE_CHURN_SPEED, "the gap law, for comparison".into()));
        }
        let t0 = std::time::Instant::now();
        let c = commission_with(&m.rig_file(), &train, &hold, &o, false).expect("commissioning");
        report(&m, &c, t0.elapsed().as_secs_f64());
        let fitted = c.cal.params.iter().any(|p| p.name == churn && p.status == eha_sim::calibration::Status::Fitted);
        assert_eq!(fitted, !held, "case_churn fitted");
        let mix = &c.holdout_with_margin[0];
        let servo = c.reduced.iter().find(|r| r.log.contains("Servo")).expect("servo log");
        got.push((mix.vs_measured_max_k.expect("drain"), mix.vs_measured_under_k.expect("drain"), servo.vs_measured_under_k.expect("drain")));
    }
    eprintln!("churned film / gap law: mix (max, under), servo under: {got:.3?}");
    // The churned fit's path spread (0.24 K under a 1e-9 K nudge before the
    // θ lattice; 0.14 K between the fits before and on it): its numbers
    // within 0.3 K; the gap law's within AS_MEASURED_K. Measured on the
    // fixed reference (b36ffe3) with calib11's defaults.
    let want = [(2.463, 2.463, 0.865, 0.3), (3.803, 2.471, 2.324, AS_MEASURED_K)];
    for (g, w) in got.iter().zip(want) {
        for (what, x, y) in [("mix max |e|", g.0, w.0), ("mix under-prediction", g.1, w.1), ("servo (training) under-prediction", g.2, w.2)] {
            assert!((x - y).abs() <= w.3, "{what}: {x:.3} K, measured {y:.3} K (±{})", w.3);
        }
    }
    // The churned film's gain on the held-out mix's max |e|: ≥ 1 K.
    assert!(got[1].0 - got[0].0 >= 1.0, "mix max |e| {:.3} K churned, {:.3} K gap law", got[0].0, got[1].0);
}

mod printout;
use printout::{headline, near, report, AS_MEASURED_K};
mod experiment;

use experiment::{exp_head_fold, exp_priors};

mod basins;
mod coverage;
mod envelope;
mod hot_flow;
mod reproducible;
