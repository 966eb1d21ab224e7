//! Acceptance of the firmware's reduced model against
//! the full reference simulation: Case 1 at 0/20/40/60 bar, Case 2, the LNG case,
//! five random missions (`missions::TEST_SEEDS`), a long hot run (Case 1 at 60 bar
//! for an hour on a rig without LNG: the drain passes 60 °C, the oil thins to
//! ≈ 8 cSt) and a cold start (Case 1 at 60 bar in 0 °C air: ≈ 580 cSt at the
//! start); the reduced model is computed from the rig (`eha_sim::reduce`), fitted
//! to no run, so every run is unseen.
//!
//! Every run is **closed loop**, as on the actuator: the guard (`GuardOf<f64>`,
//! validation included, reduced `eha_guard::params::DEFAULT`) is fed the
//! reference's sensor signals as f32 wire samples every 10 ms and its valve
//! command drives the reference's LNG exchanger. The guard's model credits the
//! exchanger's cooling while its own valve is open, so an open-loop comparison
//! against a plant whose exchanger does not follow the guard would be meaningless.
//!
//! Every closed loop is made once per test binary (in parallel) and shared by the
//! tests of this file: [`runs`] holds the guard-driven run of every case (the
//! acceptance runs plus load-then-idle), [`thermostat_first_switch`] the
//! thermostat-driven loop of every case up to its first switch.
//!
//! Bounds: each assertion has the issue's **spec** bound and, where the spec sits
//! far above what is measured, a **regression** bound at 2–3× the measured value,
//! so that a change that makes the model several times worse fails even while it
//! still meets the spec.

use eha_guard::num::{Fx, Num};
use eha_guard::protection::Valve;
use eha_guard::{faults, GuardConfig, GuardOf, Restore};
use eha_sim::missions::{random_mission, stats, ErrorStats, TEST_SEEDS};
use eha_sim::plant::{Control, Plant, Sensors};
use eha_sim::rig::Rig;
use eha_sim::scenario::{Mission, Scenario, Schedule};
use rayon::prelude::*;
use std::sync::OnceLock;

// The tests by topic: the drain bounds of every run, the cross-check's
// margin and the number types' agreement, the valve's switching times.
mod drain;

mod precision;

mod switching;

/// Duration of every acceptance run, s (the paper's 600 s).
const DURATION_S: f64 = 600.0;
/// Specified bound on max |drain error|, K.
const MAX_ABS_K: f64 = 1.0;
/// Tighter bound on max |drain error| with the oil on its viscosity line,
/// K: the firmware stays within 0.1 K of the reference on every acceptance run,
/// the hour-long hot run and the 0 °C cold start included.
const MAX_ABS_TIGHT_K: f64 = 0.1;
/// Issue goal on max |drain error|, K (reported, not asserted).
const GOAL_K: f64 = 0.5;
/// Issue bound on drain under-prediction, K.
const MAX_UNDER_K: f64 = 0.5;
/// Issue bound on a valve switching time against switching on the true drain, s.
const MAX_SWITCH_S: f64 = 2.0;
/// Regression bound on max |drain error| over every run, K: measured worst
/// 0.098 K (the pump stopped with the valve open), 1.5×; 0.063 K on the
/// acceptance runs (random-2), 2.4×.
const REG_MAX_ABS_K: f64 = 0.15;
/// Regression bound on drain under-prediction over every run, K: measured worst
/// 0.060 K (random-5; 0.059 K before the high-pressure port's leakage in the
/// pump's delivery, 2026-11-28), 2.5×.
const REG_MAX_UNDER_K: f64 = 0.15;
/// Regression bound on |f32 − f64| drain, K: measured 3.81e-6 K (Case 1 60 bar
/// and LNG), 2.6×. (The fixed-point spec bound, 0.1 K, is itself 2.2× the
/// measured 4.47e-2 K, so it serves as that type's regression bound too.)
const REG_F32_K: f64 = 1e-5;
/// Regression bound on any switching-time difference, s. Measured worst 1.90 s
/// with the oil on its viscosity line (0.54 s with a constant viscosity): random-2
/// event 5, a closing at 575.7 s where the drain falls slowly (≈ 0.03 K/s), so the
/// estimate's +0.06 K there shows as 1.9 s; the next worst 0.71 s (random-1 event
/// 1). No margin is left for a regression bound above the 2 s: it is the
/// issue's bound ([`MAX_SWITCH_S`]).
const REG_SWITCH_S: f64 = MAX_SWITCH_S;
/// Regression bound on a first-opening difference, s: measured worst 0.08 s
/// (Case 1 40 bar), 3.75×.
const REG_FIRST_OPEN_S: f64 = 0.3;

/// One run of the suite: its name, its scenario, and whether the rig has an LNG
/// cooler (the hot run has none: the reference's exchanger takes nothing and the
/// guard's tank is empty, so it credits nothing).
#[derive(Clone)]
struct Case {
    name: String,
    scenario: Scenario,
    lng: bool,
}

impl Case {
    fn new(name: &str, scenario: Scenario) -> Self {
        Case { name: name.into(), scenario, lng: true }
    }

    /// The reference rig of this run.
    fn rig(&self) -> Rig {
        let mut rig = Rig::default();
        if !self.lng {
            rig.lng.flow_kg_per_s = 0.0;
        }
        rig
    }

    /// The guard's configuration of this run.
    fn config(&self) -> GuardConfig<'static> {
        let mut cfg = GuardConfig::DEFAULT;
        if !self.lng {
            cfg.lng.charge_l = 0.0;
        }
        cfg
    }
}

/// The acceptance runs (drain-error bounds) followed by load-then-idle (valve
/// switching only).
fn cases() -> &'static [Case] {
    static C: OnceLock<Vec<Case>> = OnceLock::new();
    C.get_or_init(|| {
        let mut v = scenarios();
        v.push(Case::new("load-then-idle", load_then_idle()));
        v
    })
}

/// Pump speed below which the pump counts as stopped, rpm: the LNG table's second
/// point (1.98e-3 L/s of geometric flow); below it the model takes no exchanger credit.
const STOPPED_RPM: f64 = 6.2;
/// Latest a closing with the pump stopped may come after the true-drain thermostat's, s:
/// the hot-side error after a stop (≤ 0.13 K measured) over the drift (0.019 K/s) is
/// 7 s; 10 s bound.
const STOPPED_LATE_S: f64 = 10.0;

/// Duration of the long hot run, s.
const HOT_S: f64 = 3600.0;
/// Air temperature of the cold start, °C.
const COLD_AIR_C: f64 = 0.0;
/// Duration of the cold start, s (long enough for the valve to open).
const COLD_S: f64 = 900.0;

fn scenarios() -> Vec<Case> {
    let mut v: Vec<Case> = [0.0, 20.0, 40.0, 60.0]
        .iter()
        .map(|&b| Case::new(&format!("case1-{b}bar"), Scenario::Case1 { needle_bar: b, duration_s: DURATION_S }))
        .collect();
    v.push(Case::new("case2", Scenario::Case2 { duration_s: DURATION_S }));
    v.push(Case::new("lng", Scenario::Lng { duration_s: DURATION_S }));
    for s in TEST_SEEDS {
        v.push(Case::new(&format!("random-{s}"), Scenario::Mission(random_mission(s, DURATION_S))));
    }
    v.push(Case { lng: false, ..Case::new("hot-1h-no-lng", Scenario::Case1 { needle_bar: 60.0, duration_s: HOT_S }) });
    let mut cold: Mission = Scenario::Case1 { needle_bar: 60.0, duration_s: COLD_S }.mission().expect("mission");
    cold.name = "cold-start".into();
    cold.ambient_c = Schedule::constant(COLD_AIR_C);
    v.push(Case::new("cold-start-0c", Scenario::Mission(cold)));
    v
}

/// One closed-loop run: the reference plant with its exchanger commanded by the
/// guard.
struct Run {
    name: String,
    /// Sensor snapshots at `t = k·10 ms`, `k = 0..=n` (valve state included).
    sensors: Vec<Sensors>,
    /// Guard drain prediction after sample `k` (compared with the truth at `k+1`), °C.
    pred: Vec<f64>,
    /// OR of the guard's fault words over the run.
    faults: eha_guard::Faults,
    /// Valve events (time s, open) of the guard.
    events: Vec<(f64, bool)>,
    /// The guard's two estimates of the shaft's loss at every model step (from the
    /// pressures, from the current), W: the sensor cross-check's inputs.
    mech_pairs: Vec<(f64, f64)>,
}

/// Runs `case` in closed loop, the valve following the guard.
fn closed_loop(case: &Case) -> Run {
    let scenario = &case.scenario;
    let rig = case.rig();
    let mut plant = Plant::new(&rig, scenario).expect("plant");
    let cfg = case.config();
    let mut guard = GuardOf::<f64>::new(&cfg, Restore::Cold);
    let mut run = Run { name: case.name.clone(), sensors: vec![], pred: vec![], faults: eha_guard::Faults::NONE, events: vec![], mech_pairs: vec![] };
    let mut open = false;
    plant
        .run(0.01, scenario.duration_s(), |snap| {
            let s = Sensors::from(snap);
            // the valve's position switch: the valve the plant ran last tick
            guard.valve_feedback(snap.lng_open);
            let o = guard.tick(&s.sample());
            run.faults |= o.faults;
            run.pred.push(o.drain_c as f64);
            if let Some(m) = guard.model().filter(|m| m.pending_ticks() == 0) {
                let (p, i) = m.last_mech_pair_kw();
                run.mech_pairs.push((p * 1e3, i * 1e3));
            }
            let want = o.valve_open;
            if want != open {
                run.events.push((s.t, want));
                open = want;
            }
            run.sensors.push(s);
            Ok(Control { lng_valve: Some(want), stop: false })
        })
        .expect("run");
    run
}

/// The guard-driven run of every case of [`cases`], in its order.
fn runs() -> &'static [Run] {
    static R: OnceLock<Vec<Run>> = OnceLock::new();
    R.get_or_init(|| cases().par_iter().map(closed_loop).collect())
}

/// For every case of [`cases`], in its order: when a thermostat with the guard's
/// hysteresis and dwell on the **true** drain, commanding the exchanger from
/// t = 0, first switches (an opening; None: not in the run). This is event 0 of
/// [`thermostat_from_branch`], shared by both valve tests.
fn thermostat_first_switch() -> &'static [Option<f64>] {
    static T: OnceLock<Vec<Option<f64>>> = OnceLock::new();
    T.get_or_init(|| cases().par_iter().map(|c| thermostat_from_branch(c, &[], 0).map(|(t, _)| t)).collect())
}

/// The guard of number type `N` on a run's sensor signals: drain estimate
/// (element k: after sample k), its own valve command (which sets its
/// exchanger credit) per tick, faults at the end.
fn guard_drain_valve<N: Num>(run: &Run) -> (Vec<f64>, Vec<bool>, eha_guard::Faults) {
    let cfg = cases().iter().find(|c| c.name == run.name).map_or(GuardConfig::DEFAULT, Case::config);
    let mut g = GuardOf::<N>::new(&cfg, Restore::Cold);
    let n = run.sensors.len() - 1;
    let (mut out, mut valve) = (Vec::with_capacity(n), Vec::with_capacity(n));
    let mut faults = eha_guard::Faults::NONE;
    for s in &run.sensors[..n] {
        // a valve that follows the command (its position switch reports it)
        g.valve_feedback(g.output().valve_open);
        let o = g.tick(&s.sample());
        faults |= o.faults;
        out.push(o.drain_c as f64);
        valve.push(o.valve_open);
    }
    (out, valve, faults)
}

fn drain_stats(run: &Run) -> ErrorStats {
    stats(run.pred.iter().zip(run.sensors.iter().skip(1)).map(|(p, s)| p - s.t_drain_c))
}

fn report(names: &[&str]) -> Vec<(String, ErrorStats, eha_guard::Faults)> {
    let rows: Vec<_> = runs()
        .iter()
        .filter(|r| names.iter().any(|n| r.name.starts_with(n)))
        .map(|r| (r.name.clone(), drain_stats(r), r.faults))
        .collect();
    for (n, e, f) in &rows {
        println!(
            "{n:>14}: max |e| {:.3} K  rms {:.3} K  max under {:.3} K  max over {:.3} K  faults {f:#06x}{}",
            e.max_abs,
            e.rms,
            e.max_under,
            e.max_over,
            if e.max_abs <= GOAL_K { "  (goal met)" } else { "" }
        );
    }
    rows
}

fn assert_bounds(rows: &[(String, ErrorStats, eha_guard::Faults)]) {
    for (n, e, f) in rows {
        // No fault on clean reference signals (validation, SENSOR_DISAGREE, ...):
        // otherwise the estimate is the fail-safe one, not the model's.
        assert!(!f.intersects(faults::LATCHED), "{n}: guard faulted on reference signals");
        // Issue: max |drain error| <= 1.0 K.
        assert!(e.max_abs <= MAX_ABS_K, "{n}: max |error| {:.3} K > {MAX_ABS_K} K", e.max_abs);
        // Within 0.1 K of the reference on every acceptance run.
        assert!(e.max_abs <= MAX_ABS_TIGHT_K, "{n}: max |error| {:.3} K > {MAX_ABS_TIGHT_K} K", e.max_abs);
        // Issue: under-prediction is the unsafe side, never more than 0.5 K.
        assert!(e.max_under <= MAX_UNDER_K, "{n}: under-prediction {:.3} K > {MAX_UNDER_K} K", e.max_under);
        // Regression bounds (2-3x the measured worst; the spec bounds above are what the issue demands).
        assert!(e.max_abs <= REG_MAX_ABS_K, "{n}: max |error| {:.3} K > regression bound {REG_MAX_ABS_K} K", e.max_abs);
        assert!(e.max_under <= REG_MAX_UNDER_K, "{n}: under-prediction {:.3} K > regression bound {REG_MAX_UNDER_K} K", e.max_under);
    }
}

/// A 60 bar load with the exchanger available, then idle at 0 rpm: both an
/// opening and a closing with the pump stopped.
fn load_then_idle() -> Scenario {
    let mut m: Mission = Scenario::Lng { duration_s: 900.0 }.mission().expect("mission");
    m.name = "lng-load-then-idle".into();
    m.speed_rpm = Schedule(vec![(0.0, 500.0), (300.0, 500.0), (300.0, 0.0)]);
    Scenario::Mission(m)
}

/// The LNG case's 60 bar load with the pump stopped at 310 s, while the guard's valve
/// is open (it opens at 297.8 s and would close at 323.8 s; 285 s with a constant
/// viscosity, before the oil on its viscosity line moved the openings): the drain bounds of the
/// acceptance runs over the 290 s after the stop (the exchanger stays commanded open
/// with no oil through it).
fn stop_with_valve_open() -> Scenario {
    let mut m: Mission = Scenario::Lng { duration_s: 600.0 }.mission().expect("mission");
    m.name = "lng-stop-valve-open".into();
    m.speed_rpm = Schedule(vec![(0.0, 500.0), (STOP_S, 500.0), (STOP_S, 0.0)]);
    Scenario::Mission(m)
}

/// When [`stop_with_valve_open`] stops the pump, s.
const STOP_S: f64 = 310.0;

/// Counterfactual switching time of guard event `i` of a guard-driven run: the plant
/// is driven by the guard's own commands up to its previous event (or t = 0), from
/// where a thermostat with the guard's hysteresis and dwell on the **true** drain
/// takes over in the same valve state; returns when that thermostat first switches
/// (None: not before the end of the run). Same plant, same state, same valve
/// history up to the branch point: the difference to the guard's event is the
/// switching delay due to the estimate alone.
fn thermostat_from_branch(case: &Case, events: &[(f64, bool)], i: usize) -> Option<(f64, f64)> {
    let scenario = &case.scenario;
    let (branch_t, open_at_branch) = if i == 0 { (f64::NEG_INFINITY, false) } else { events[i - 1] };
    let rig = case.rig();
    let mut plant = Plant::new(&rig, scenario).expect("plant");
    let cfg = case.config();
    let mut valve = Valve::new();
    let mut branched = false;
    let mut switched = None;
    plant
        .run(0.01, scenario.duration_s(), |snap| {
            let s = Sensors::from(snap);
            // Commands up to the branch: the guard's (state after its last event ≤ t).
            if !branched && s.t < branch_t - 1e-9 {
                let open = events.iter().take_while(|(t, _)| *t <= s.t + 1e-9).last().is_some_and(|e| e.1);
                return Ok(Control { lng_valve: Some(open), stop: false });
            }
            if !branched {
                branched = true;
                if open_at_branch {
                    valve.update(f32::NAN, true, &cfg.valve); // forced open: dwell counts from here
                }
            }
            let before = valve.is_open();
            valve.update(s.t_drain_c as f32, false, &cfg.valve);
            if valve.is_open() != before {
                switched = Some((s.t, s.speed_rpm));
                return Ok(Control { lng_valve: Some(valve.is_open()), stop: true });
            }
            Ok(Control { lng_valve: Some(valve.is_open()), stop: false })
        })
        .expect("run");
    switched
}

/// The reduced parameters are the rig's: `DEFAULT` in `src/params.rs` equals what
/// `eha_sim::reduce` computes from `Rig::default()` now (so a rig change cannot
/// leave the firmware's constants stale), and the LNG table reproduces the
/// reference exchanger of eqs. (20)-(22) at its points (to the 1e-12 of the
/// literals) and between them within 1 % over 100-3000 rpm (linear interpolation
/// in sqrt(q) of a smooth saturating curve).
#[test]
fn params_are_the_reduction_of_the_rig() {
    let rig = Rig::default();
    let p = eha_sim::reduce::reduce(&rig).expect("reduce");
    let d = eha_guard::params::DEFAULT;
    let rel = |a: f64, b: f64| (a - b).abs() <= 1e-12 * a.abs().max(b.abs()).max(1e-30);
    let flat = |q: &eha_guard::params::ReducedParams| {
        let mut v: Vec<(String, f64)> = eha_sim::reduce::scalar_fields(q).iter().map(|(n, x)| (n.to_string(), *x)).collect();
        for (n, t) in eha_sim::reduce::array_fields(q) {
            v.extend(t.iter().enumerate().map(|(i, x)| (format!("{n}[{i}]"), *x)));
        }
        for (i, r) in q.nominal_jacobian_per_s.iter().enumerate() {
            v.extend(r.iter().enumerate().map(|(j, x)| (format!("nominal_jacobian_per_s[{i}][{j}]"), *x)));
        }
        for (i, r) in q.phi_step_s.iter().enumerate() {
            v.extend(r.iter().enumerate().map(|(j, x)| (format!("phi_step_s[{i}][{j}]"), *x)));
        }
        v
    };
    let (a, b) = (flat(&p), flat(&d));
    let stale: Vec<&str> = a.iter().zip(&b).filter(|((_, x), (_, y))| !rel(*x, *y)).map(|((n, _), _)| n.as_str()).collect();
    assert!(stale.is_empty(), "src/params.rs DEFAULT differs from reduce(Rig::default()) at fields {stale:?}: run `cargo run --release -p eha-sim --example reduce`");
    // The LNG table between its points, against eqs. (20)-(22) with the oil stream D|w|.
    let rho_cp = rig.oil.rho(40.0, 0.0) * rig.oil.cp(40.0);
    let n1 = (eha_guard::params::N_TABLE - 1) as f64;
    for rpm in (100..=3000).step_by(25) {
        let q = rpm as f64 * std::f64::consts::PI / 30.0 * d.displacement_m3_per_rad;
        let u = (q / d.flow_table_max_m3_per_s).sqrt() * n1;
        let j = u.floor() as usize;
        let f = u - j as f64;
        let g = d.g_lng_w_per_k[j] * (1.0 - f) + d.g_lng_w_per_k[j + 1] * f;
        let t_oil = 45.0;
        let q_ref = rig.lng.exchanger_w(rho_cp * q, t_oil);
        let r = (g * (t_oil - d.lng_inlet_c) - q_ref) / q_ref;
        assert!(r.abs() < 0.01, "{rpm} rpm: LNG table {:+.3} % off eqs. (20)-(22)", 100.0 * r);
    }
}
