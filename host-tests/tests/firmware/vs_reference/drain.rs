//! The drain estimate within its bounds on every acceptance run: Case 1 at
//! four pressures, Case 2, the hot run and the cold start, the random
//! missions, the LNG case, the pump stopped with the valve open.

use super::*;

/// Case 1 at the paper's four needle-valve pressures.
#[test]
fn case1_all_pressures_drain_within_bounds() {
    assert_bounds(&report(&["case1-"]));
}

/// Case 2 (servo, spring load): piston work leaves as work, not heat.
#[test]
fn case2_drain_within_bounds() {
    assert_bounds(&report(&["case2"]));
}

/// The long hot run: Case 1 at 60 bar for an hour on a rig without LNG (the drain
/// passes 60 °C after ≈ 10 minutes and reaches ≈ 92 °C, the oil ≈ 8 cSt: leakage
/// ≈ 6 times, viscous friction a sixth of their 40 °C values), and the cold start:
/// Case 1 at 60 bar in 0 °C air (the oil starts at ≈ 580 cSt: viscous friction 12
/// times its 40 °C value).
#[test]
fn hot_run_and_cold_start_drain_within_bounds() {
    let rows = report(&["hot-1h", "cold-start"]);
    assert_eq!(rows.len(), 2);
    let hot = runs().iter().find(|r| r.name.starts_with("hot-1h")).expect("hot run");
    let peak = hot.sensors.iter().map(|s| s.t_drain_c).fold(f64::NEG_INFINITY, f64::max);
    println!("hot run: reference drain peaks at {peak:.2} °C");
    assert!(peak > 60.0, "the hot run must take the drain past 60 °C: {peak:.2}");
    let cold = runs().iter().find(|r| r.name.starts_with("cold-start")).expect("cold run");
    assert!(cold.sensors[0].t_drain_c.abs() < 1e-9, "the cold start starts at 0 °C");
    assert_bounds(&rows);
}

/// Five random missions (the model is reduced from the rig, fitted to no run).
#[test]
fn random_missions_drain_within_bounds() {
    let rows = report(&["random-"]);
    assert_eq!(rows.len(), TEST_SEEDS.len());
    assert_bounds(&rows);
}

/// The LNG case (Fig. 15: 60 bar, 600 s), the exchanger commanded by the guard.
#[test]
fn lng_case_drain_within_bounds() {
    let rows = report(&["lng"]);
    assert_eq!(rows.len(), 1);
    assert_bounds(&rows);
}

/// Pump stopped with the valve open ([`stop_with_valve_open`]): before the exchanger
/// credit was cut below the LNG table's second point (1.98e-3 L/s), the model credited
/// 0.3 kW to the ports' leakage and under-predicted the drain by 0.7 K within 3 s of
/// the stop.
#[test]
fn pump_stopped_with_valve_open_drain_within_bounds() {
    let r = closed_loop(&Case::new("lng-stop-valve-open", stop_with_valve_open()));
    let open_at_stop = r.events.iter().take_while(|(t, _)| *t <= STOP_S).last().is_some_and(|e| e.1);
    assert!(open_at_stop, "the scenario needs the valve open when the pump stops: {:?}", r.events);
    let e = drain_stats(&r);
    println!(
        "lng-stop-valve-open: max |e| {:.3} K  rms {:.3} K  max under {:.3} K  max over {:.3} K  faults {:#06x}",
        e.max_abs, e.rms, e.max_under, e.max_over, r.faults
    );
    assert_bounds(&[(r.name.clone(), e, r.faults)]);
}
