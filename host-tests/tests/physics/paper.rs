//! The paper's published numbers (Liu et al.), each asserted with its
//! tolerance and the reason for it. One calibrated parameter set
//! (`Rig::default()`) serves every case (docs/calibration.md).
//!
//! Fitted vs predicted (docs/calibration.md): three parameters are fitted by
//! least squares to four numbers — Table 4's inlet / outlet / drain at 600 s
//! and the circulating oil passing 40 °C at 110 s (Fig. 15's valve opening);
//! one more, the pump housing's ram-air share, to Table 5's shell at 30 m/s.
//! Two numbers are set to the paper's outcome: the ram-air run length
//! (Table 5's 15 m/s coefficient) and the LNG flow (the smallest round flow
//! that keeps Fig. 15's drain below 50 °C). A test of a fitted number
//! reproduces the fit; it validates nothing. The predictions: the pump shell
//! in still air, the other Table 5 temperatures (`pump_energy.rs`), Table 5's
//! 30 and 50 m/s coefficients, the still-air coefficient, Case 2's balance
//! time.
//!
//! Known misses (the model disagrees with the paper) are asserted as measured,
//! with a tolerance around the measured value, and say so: they are to be
//! fixed by the physics, not by widening a tolerance. When the physics moves
//! one of them, the test fails and must be re-measured (towards the paper's
//! value, one hopes).

use eha_sim::calibrate::{evaluate, PAPER};
use eha_sim::cooling::{size, Lng};
use eha_sim::heat::h_forced_plate;
use eha_sim::network::{capacity_j_per_k, contents, h_outer, stored_j, Shape, NODES};
use eha_sim::rig::Rig;
use eha_sim::scenario::Scenario;
use eha_sim::sim::{simulate, SimOptions, SimOutput};

fn case1(rig: &Rig, bar: f64) -> SimOutput {
    simulate(rig, &Scenario::Case1 { needle_bar: bar, duration_s: 600.0 }, &SimOptions::default()).expect("case 1 runs")
}

/// Table 4 (600 s, 60 bar): inlet 53.00, outlet 54.17, drain 59.67 °C, each
/// within ±0.5 K (the specified bound: a tenth of the paper's own
/// simulation-vs-test scatter in Fig. 8, and twice the 0.25 K reading
/// uncertainty the fit assumes).
///
/// **Fitted, reproduces the fit**: these three temperatures are calibration
/// targets (four targets, three parameters, least squares), so passing
/// validates little; what it shows is that three physical parameters can
/// meet four numbers at once. Measured: 52.84 / 54.35 / 59.65 °C.
#[test]
fn table4_port_temperatures_at_600s_60bar_fitted() {
    let out = case1(&Rig::default(), 60.0);
    for (ch, paper) in [("t_inlet_c", 53.00), ("t_outlet_c", 54.17), ("t_drain_c", 59.67)] {
        let ours = out.last(ch).expect("channel");
        println!("{ch}: ours {ours:.3} °C, paper {paper:.2} °C (fitted)");
        assert!((ours - paper).abs() <= 0.5, "{ch}: {ours:.2} vs {paper:.2}");
    }
    // The paper's ordering: drain hottest, outlet above inlet.
    let g = |c| out.last(c).unwrap_or(f64::NAN);
    assert!(g("t_drain_c") > g("t_outlet_c") && g("t_outlet_c") > g("t_inlet_c"));
}

/// The committed rig still reproduces its calibration (`eha-sim calibrate`,
/// docs/calibration.md): the least-squares residuals as measured when the
/// fit was made (inlet −0.163, outlet +0.180, drain −0.023 K; 40 °C crossing
/// 109.97 s), each within 0.01 K (0.1 s): anything more means the physics
/// changed since the fit and `eha-sim calibrate` must be re-run, together
/// with every number downstream of the rig. A regression guard, not a
/// validation.
#[test]
fn calibration_targets_are_reproduced() {
    let m = evaluate(&Rig::default()).expect("case 1 runs");
    let temps = [
        ("inlet", m.inlet_c, PAPER.inlet_c, -0.163),
        ("outlet", m.outlet_c, PAPER.outlet_c, 0.180),
        ("drain", m.drain_c, PAPER.drain_c, -0.023),
    ];
    for (name, ours, target, residual) in temps {
        println!("{name}: ours {ours:.5} °C, target {target:.2} °C, residual {:+.4} K (at the fit {residual:+.3})", ours - target);
        assert!((ours - target - residual).abs() <= 0.01, "{name}: residual {:+.4} K: re-run `eha-sim calibrate`", ours - target);
    }
    println!("oil passes 40 °C at {:.3} s, target {:.1} s", m.t40_s, PAPER.t40_s);
    assert!((m.t40_s - 109.97).abs() <= 0.1, "40 °C crossing {:.2} s: re-run `eha-sim calibrate`", m.t40_s);
}

/// Table 5's pump shell in still air at 600 s, 60 bar: paper 25.38 °C.
/// **Predicted** (no parameter is fitted to it). **Known miss**: measured
/// 29.43 °C, +4.05 K: with the sliding-pair rule (docs/calibration.md) the
/// housing receives the bearings' and about a quarter of the films' friction
/// heat, and with the oil on its viscosity line the hot case oil's film gives
/// the housing more (26.82 °C, +1.44 K, with the viscosity held at 40 °C;
/// with all film heat into the oil the shell came out 3.4 K too cold).
/// Asserted as measured (±0.05 K: a deterministic run).
#[test]
fn still_air_pump_shell_predicted_known_miss() {
    let m = evaluate(&Rig::default()).expect("case 1 runs");
    println!("pump shell {:.3} °C, paper 25.38 (predicted, {:+.2} K)", m.pump_shell_c, m.pump_shell_c - 25.38);
    assert!((m.pump_shell_c - 29.43).abs() <= 0.05, "shell {:.3}: re-measure", m.pump_shell_c);
}

/// Table 5: ram-air coefficients 66.13, 115.13, 173.25 W/(m²·K) at 15, 30,
/// 50 m/s within 1 % (issue tolerance).
///
/// **15 m/s: fitted, reproduces the fit** (the run length 0.352 m is set so
/// that this entry comes out). 30 and 50 m/s are predictions of the
/// correlation's v^0.8 law with the paper's property temperature; the
/// paper's entries grow exactly so. Measured: 66.13 / 115.14 / 173.26
/// (+0.00 / +0.01 / +0.01 %).
#[test]
fn table5_ram_air_coefficients() {
    let rig = Rig::default();
    for (v, paper, note) in [(15.0, 66.13, "fitted"), (30.0, 115.13, "predicted"), (50.0, 173.25, "predicted")] {
        let h = h_forced_plate(v, rig.outside.ram_run_length_m, 16.0, rig.outside.air_pressure_pa());
        println!("{v} m/s: ours {h:.3}, paper {paper:.2} W/(m²·K), {:+.3} % ({note})", 100.0 * (h - paper) / paper);
        assert!((h - paper).abs() / paper < 0.01, "{v} m/s: {h}");
    }
}

/// Table 5's still-air convective coefficient of the pump shell, 1.40
/// W/(m²·K). Ours is Churchill–Chu free convection (eq. 15) on the 0.12 m
/// housing at its 600 s, 60 bar wall temperature (predicted) over 16 °C
/// air. **Known miss**: measured 3.98 W/(m²·K) at the predicted 29.43 °C shell, 2.8 times the paper's; the
/// correlation's scatter is ±20 % or so, and no free-convection correlation
/// gives 1.40 at ΔT ≈ 9.4 K (docs/calibration.md). Asserted: the measured
/// value within ±2 % (the wall temperature is fitted to 0.01 K, h ∝ ΔT^¼
/// roughly; 2 % catches a change of the correlation or of the housing).
#[test]
fn table5_still_air_coefficient_known_miss() {
    let rig = Rig::default();
    let shell = case1(&rig, 60.0).last("t_pump_c").expect("channel");
    let h = h_outer(&rig, Shape::Cylinder(rig.pump.diameter_m), shell, 16.0, 0.0);
    let measured = 3.98;
    println!("still-air h of the pump shell: ours {h:.3} W/(m²·K) at {shell:.2} °C, paper 1.40 (known miss, measured {measured})");
    assert!((h - measured).abs() <= 0.02 * measured, "still-air h {h:.3}, measured {measured} (paper 1.40): re-measure");
}

/// LNG sizing, eqs. (23)–(25) with Table 6. Tolerances: half the last printed
/// digit.
///
/// **2.3 L is fitted, reproduces the choice**: the paper does not print the
/// mission time; t_m = 680 s is the one that gives 2.3 L at 1.5 kW (measured
/// 2.30 L). **2.15 kg is arithmetic of the paper's own numbers** (5 L × Table
/// 6's 430 kg/m³; measured 2.150 kg): it checks our Table 6 density, not a
/// model.
#[test]
fn lng_sizing_reproduces_the_paper_fitted() {
    let lng = Lng::default();
    let s = size(&lng, 1500.0, 680.0, 2.0);
    println!("1.5 kW, 680 s: {:.3} L (paper 2.3 L, t_m chosen); 5 L: {:.4} kg (paper 2.15 kg)", s.volume_m3 * 1e3, lng.charge_kg());
    assert!((s.volume_m3 * 1e3 - 2.3).abs() < 0.05, "{} L", s.volume_m3 * 1e3);
    assert!((lng.charge_kg() - 2.15).abs() < 0.005, "{} kg", lng.charge_kg());
    // And the inverse: the 5 L charge lasts 1478 s at 1.5 kW.
    let t = lng.mission_time_s(1500.0, 5e-3);
    assert!((t - 5e-3 * 430.0 * (509e3 + 2.9e3 * 180.0) / 1500.0).abs() < 1e-6);
}

/// Fig. 15: with the LNG exchanger the valve opens at about 110 s (±20 s,
/// the reading of the figure) and the drain port stays below 50 °C.
///
/// **The opening is fitted, reproduces the fit**: the valve follows the
/// circulating oil at 40 °C, whose 110 s crossing is a calibration target
/// (measured: opens at 110.0 s, the thermostat sampled every 0.1 s). The
/// drain below 50 °C is a prediction: the LNG flow (3 g/s) was chosen on an
/// earlier fit, before the pump's energy balance, as the smallest round value
/// that kept the drain below 50 °C (then 49.97 °C max); measured now
/// 46.83 °C max.
#[test]
fn fig15_lng_valve_opens_near_110s_and_drain_stays_below_50c_fitted() {
    let out = simulate(&Rig::default(), &Scenario::Lng { duration_s: 600.0 }, &SimOptions::default()).expect("runs");
    let open = *out.valve_open_times_s.first().expect("valve opened");
    let max_drain = out.max("t_drain_c").unwrap_or(f64::NAN);
    println!(
        "valve opens at {open:.1} s (paper ≈ 110 s, fitted); drain max {max_drain:.3} °C (paper < 50 °C, LNG flow chosen); {} openings",
        out.valve_open_times_s.len()
    );
    assert!((open - 110.0).abs() <= 20.0);
    assert!(max_drain < 50.0);
}

/// Node temperatures at 600 s rise monotonically with the needle pressure
/// (0, 20, 40, 60 bar), as Fig. 8 shows for every measured point. (Only 60 bar
/// is calibrated; 0–40 bar are predictions.)
#[test]
fn temperatures_rise_monotonically_with_needle_pressure() {
    let rig = Rig::default();
    let runs: Vec<SimOutput> = [0.0, 20.0, 40.0, 60.0].iter().map(|&b| case1(&rig, b)).collect();
    for ch in ["t_motor_c", "t_pump_c", "t_block_c", "t_ballvalve_c", "t_oil_c", "t_inlet_c", "t_outlet_c", "t_drain_c", "t_winding_c"] {
        let v: Vec<f64> = runs.iter().map(|o| o.last(ch).unwrap_or(f64::NAN)).collect();
        println!("{ch}: {v:.2?}");
        assert!(v.windows(2).all(|w| w[1] > w[0]), "{ch} not monotonic: {v:?}");
    }
}

/// Period of the Case 2 command (0.2 Hz sine), s.
const CASE2_PERIOD_S: f64 = 5.0;
/// Output samples per period (0.1 s output interval).
const CASE2_PER: usize = 50;
/// Periods over which a drift is measured (30 s): from one period to the
/// next a port's period-mean drift scatters by ≈ ±0.2 mK, ±5 % of the 3.4 mK
/// per period that the 10 % threshold allows, and the threshold ratio falls
/// so slowly (≈ 0.0003 per period) that one-period drifts move the crossing
/// by up to 80 s; over six periods the scatter is a sixth.
const CASE2_WINDOW: usize = 6;
/// Balance threshold: the oil stores less than 10 % of the power lost into
/// it, i.e. 90 % of it leaves (the 90 % settling of a first-order lag).
const CASE2_EPS: f64 = 0.10;
/// Loss channels that heat oil nodes (model.rs `thermal`: leakage, the
/// pump's friction that the sliding-pair rule puts into the case and
/// high-pressure port oil, churning, line and valve losses into the loop oil,
/// needle throttling into the ball-valve oil) and those that heat metal
/// (winding, motor, actuator, the pump friction's metal part: bearings,
/// shaft seal and the films' share on the metal faces).
const OIL_LOSSES: [&str; 6] = ["p_leak_w", "p_mech_oil_w", "p_churn_w", "p_line_w", "p_throttle_w", "p_valves_w"];
const METAL_LOSSES: [&str; 6] = ["p_cu_w", "p_fe_w", "p_bearing_w", "p_act_leak_w", "p_act_friction_w", "p_mech_metal_w"];

/// Balance time: the centre of the first window from which on every window's
/// ratio (stored / lost power, `(centre s, ratio)`) is below `eps` in
/// magnitude, s; None if that never holds to the end of the run.
fn balance_from(ratios: &[(f64, f64)], eps: f64) -> Option<f64> {
    (0..ratios.len()).find(|&k| ratios[k..].iter().all(|r| r.1.abs() < eps)).map(|k| ratios[k].0)
}

/// Case 2 periodic balance against the paper (Fig. 12b: "the heat
/// dissipation and power loss of the system are in balance after 200 s").
///
/// Balance, defined physically: the circulating oil (every oil node) receives
/// the losses in `OIL_LOSSES` and hands heat on to the metal; it is in balance
/// when, over 30 s windows (whole periods, so the swing cancels), the energy
/// it stores is below 10 % of the power lost into it (90 % leaves) — for this
/// and every later window. A port or the drain is in balance when its
/// period-mean temperature rises no faster than that: C_oil·dT̄/dt < 10 % of
/// the oil's loss power (the lumped view of the paper's model, where one
/// temperature stands for the oil; for the oil as a whole the two definitions
/// coincide). The time is the window's centre. The whole rig is far from
/// balance in 600 s (≈ 4 % of the losses reach ambient at 600 s, the metal
/// stores the rest; printed), so the paper's statement can only mean the oil.
///
/// Paper: ≈ 200 s, read as ±50 s (half a 100 s division of a 600 s axis).
/// **Known miss**: measured oil 585.0 s, inlet 547.5 s, outlet 537.5 s, drain
/// not within 600 s (515 / 502.5 / 502.5 s with the viscosity held at 40 °C). The denominator is the friction heat that really enters
/// the oil: the sliding-pair rule puts the no-load term and a quarter of the
/// films' heat into the pump's metal (`p_mech_metal_w`), which the oil never
/// receives. Counting all of eq. (8) as oil heat (the earlier accounting)
/// overstated the oil's input by that much and gave 305.0 / 212.5 / 212.5 s,
/// an upper bound, not a balance time (without the pump's energy balance:
/// 390 / 382.5 / 382.5 / 517.5 s). Printed beside: the 20 % and 5 % crossings.
/// Asserted: each time within ±15 s of the measured (three periods: near the
/// crossing the ratio falls ≈ 0.001 per 15 s and scatters ≈ ±0.0005 between
/// windows; 30 s windows of 3–10 periods and a 0.05 s output grid give times
/// within 5 s of these). The port and drain swing must repeat period to
/// period within 10 % over the last 100 s (a periodic state, not a drift).
/// Previous definition (drift below 10 % of the first period's drift) gave
/// ports 25–30 s, drain 245 s: the first period's drift of a port is its own
/// fast fill-up, not the oil's heat balance.
#[test]
fn case2_periodic_balance_time_known_miss() {
    let rig = Rig::default();
    let out = simulate(&rig, &Scenario::Case2 { duration_s: 600.0 }, &SimOptions { output_interval_s: 0.1, control_interval_s: 0.1 })
        .expect("runs");
    let get = |c: &str| out.get(c).unwrap_or_else(|| panic!("channel {c}"));
    let n_per = (out.time_s.len() - 1) / CASE2_PER;
    assert!((out.time_s[CASE2_PER] - CASE2_PERIOD_S).abs() < 1e-9, "output grid is not 0.1 s");
    // Every loss channel is either an oil or a metal one (a new loss channel
    // must be placed before this test can be trusted).
    let total = get("p_total_w");
    let all: Vec<&[f64]> = OIL_LOSSES.iter().chain(&METAL_LOSSES).map(|c| get(c)).collect();
    for (i, &p) in total.iter().enumerate() {
        let s: f64 = all.iter().map(|v| v[i]).sum();
        assert!((s - p).abs() <= 1e-9 * p.abs().max(1.0), "loss channels do not add up to p_total_w at sample {i}");
    }
    let p_oil: Vec<f64> = (0..total.len()).map(|i| OIL_LOSSES.iter().map(|c| get(c)[i]).sum()).collect();
    // Oil energy (enthalpy) and capacity from the oil nodes.
    let m = contents(&rig);
    let oil_nodes: Vec<(usize, &[f64])> =
        NODES.iter().enumerate().filter(|(_, n)| n.is_oil()).map(|(i, n)| (i, get(n.channel()))).collect();
    let e_oil = |s: usize| oil_nodes.iter().map(|&(i, t)| stored_j(&rig, NODES[i], m[i], t[s])).sum::<f64>();
    let c_oil = |s: usize| oil_nodes.iter().map(|&(i, t)| capacity_j_per_k(&rig, NODES[i], m[i], t[s])).sum::<f64>();
    let period_mean = |v: &[f64], k: usize| v[k * CASE2_PER..(k + 1) * CASE2_PER].iter().sum::<f64>() / CASE2_PER as f64;
    let w = CASE2_WINDOW;
    let span = w as f64 * CASE2_PERIOD_S;
    // Window k: periods k..k+w (oil energy at their bounds, centre (k + w/2)·T);
    // node means of periods k and k+w (centre (k + w/2 + 1/2)·T).
    let p_in = |k: usize| (k..k + w).map(|j| period_mean(&p_oil, j)).sum::<f64>() / w as f64;
    let oil: Vec<(f64, f64)> = (0..=n_per - w)
        .map(|k| ((k as f64 + w as f64 / 2.0) * CASE2_PERIOD_S, (e_oil((k + w) * CASE2_PER) - e_oil(k * CASE2_PER)) / span / p_in(k)))
        .collect();
    let node = |ch: &str| -> Vec<(f64, f64)> {
        let v = get(ch);
        (0..n_per - w)
            .map(|k| {
                let rate = (period_mean(v, k + w) - period_mean(v, k)) / span;
                ((k as f64 + w as f64 / 2.0 + 0.5) * CASE2_PERIOD_S, c_oil(k * CASE2_PER) * rate / p_in(k))
            })
            .collect()
    };
    let (amb, loss) = (out.last("e_ambient_j").unwrap_or(0.0), out.last("e_loss_j").unwrap_or(1.0));
    let (pa, pl) = (
        (amb - out.at("e_ambient_j", 570.0).unwrap_or(0.0)) / 30.0,
        (loss - out.at("e_loss_j", 570.0).unwrap_or(0.0)) / 30.0,
    );
    println!(
        "whole rig, 570-600 s: {pl:.1} W lost, {pa:.2} W to ambient ({:.1} %); oil: {:.2} W of it, C_oil {:.0} J/K",
        100.0 * pa / pl,
        p_in(n_per - w),
        c_oil(0)
    );
    // (name, measured balance time at CASE2_EPS, s)
    type Series = Vec<(f64, f64)>;
    let cases: [(&str, Series, Option<f64>); 4] = [
        ("oil (energy)", oil, Some(585.0)),
        ("t_inlet_c", node("t_inlet_c"), Some(547.5)),
        ("t_outlet_c", node("t_outlet_c"), Some(537.5)),
        ("t_drain_c", node("t_drain_c"), None),
    ];
    let mut failures = vec![];
    for (name, ratios, measured) in &cases {
        let at = |eps| balance_from(ratios, eps).map_or("not in 600 s".to_string(), |t| format!("{t:.1} s"));
        let t = balance_from(ratios, CASE2_EPS);
        println!(
            "{name}: balance (< {:.0} %) from {} (paper ≈ 200 s; measured {measured:?} s); at 20 %: {}, at 5 %: {}; ratio at 300 s {:.3}, at 550 s {:.3}",
            100.0 * CASE2_EPS,
            at(CASE2_EPS),
            at(0.2),
            at(0.05),
            ratios.iter().find(|r| r.0 >= 300.0).map_or(f64::NAN, |r| r.1),
            ratios.iter().find(|r| r.0 >= 550.0).map_or(f64::NAN, |r| r.1),
        );
        match (t, measured) {
            (Some(t), Some(m)) if (t - m).abs() <= 15.0 => {}
            (None, None) => {}
            _ => failures.push(format!("{name}: balance at {t:?} s, measured {measured:?} s (paper ≈ 200 s): re-measure")),
        }
    }
    // Periodic: the swing repeats within 10 % over the last 100 s.
    for ch in ["t_inlet_c", "t_outlet_c", "t_drain_c"] {
        let v = get(ch);
        let swing = |k: usize| {
            let c = &v[k * CASE2_PER..(k + 1) * CASE2_PER];
            c.iter().copied().fold(f64::NEG_INFINITY, f64::max) - c.iter().copied().fold(f64::INFINITY, f64::min)
        };
        let s: Vec<f64> = (n_per - 20..n_per).map(swing).collect();
        println!("{ch}: swing over the last 100 s {:.3}–{:.3} K", s.iter().copied().fold(f64::INFINITY, f64::min), s.iter().copied().fold(0.0, f64::max));
        if !(s[0] > 0.0 && s.windows(2).all(|p| (p[1] - p[0]).abs() <= 0.1 * p[0])) {
            failures.push(format!("{ch}: swing not periodic in the last 100 s: {s:.4?}"));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// Losses of the energy transfer at `t`: every loss but the needle's
/// throttling (the load the paper's Case 1 sets), W.
fn transfer_loss_w(out: &SimOutput, t: f64) -> f64 {
    out.at("p_total_w", t).unwrap_or(f64::NAN) - out.at("p_throttle_w", t).unwrap_or(f64::NAN)
}

/// The paper (Section IV.B): "In Case 1 the power loss at 60 bar pressure is
/// 0.7 kW and the combined system thermal power is about 1.5 kW", the
/// latter used to size the LNG (eqs. 23–25, 2.3 L).
///
/// Ours, Case 1 at 60 bar, mean over 0–600 s: the losses of the energy
/// transfer (motor copper and iron, pump leakage and friction, lines: every
/// loss but the needle's throttling, which is the load Case 1 sets) and the
/// combined thermal power (all of them). The paper prints one significant
/// figure, so its 0.7 kW stands for [0.65, 0.75) kW and its 1.5 kW for
/// [1.45, 1.55) kW. **Measured**: transfer 0.766 kW, combined 1.657 kW:
/// both **known misses**, above the intervals by 0.016 and 0.107 kW (with
/// the viscosity held at 40 °C they were 0.571 and 1.485 kW: the fit now
/// needs η_m 0.44 for Table 4, see `pump_energy.rs`). Asserted as measured,
/// ±0.005 kW (deterministic runs; catches any change of a loss law).
///
/// LNG sizing from the model's own dissipation beside the paper's input:
/// eqs. (23)–(25) with the same mission time (680 s, the one that gives the
/// paper's 2.3 L at 1.5 kW): measured 2.54 L from our 1.657 kW, against the
/// paper's 2.30 L (asserted as measured, ±0.01 L).
#[test]
fn power_loss_at_60bar_against_the_paper_and_lng_sized_from_the_model() {
    let out = case1(&Rig::default(), 60.0);
    let ts: Vec<f64> = out.time_s.clone();
    let mean = |f: &dyn Fn(f64) -> f64| ts.windows(2).map(|w| 0.5 * (f(w[0]) + f(w[1])) * (w[1] - w[0])).sum::<f64>() / 600.0;
    let transfer = mean(&|t| transfer_loss_w(&out, t)) * 1e-3;
    let combined = mean(&|t| out.at("p_total_w", t).unwrap_or(f64::NAN)) * 1e-3;
    let at600 = (transfer_loss_w(&out, 600.0) * 1e-3, out.last("p_total_w").unwrap_or(f64::NAN) * 1e-3);
    let lng = Lng::default();
    let ours = size(&lng, combined * 1e3, 680.0, 2.0);
    let paper = size(&lng, 1500.0, 680.0, 2.0);
    println!(
        "60 bar, mean 0-600 s: transfer losses {transfer:.3} kW (paper 0.7), combined {combined:.3} kW (paper 1.5); at 600 s {:.3} / {:.3} kW",
        at600.0, at600.1
    );
    println!(
        "LNG for 680 s: {:.3} L from the model's {combined:.3} kW ({:.2} L with 2x), paper's 1.5 kW {:.3} L",
        ours.volume_m3 * 1e3,
        ours.volume_with_redundancy_m3 * 1e3,
        paper.volume_m3 * 1e3
    );
    assert!((transfer - 0.766).abs() <= 0.005, "transfer losses {transfer:.4} kW: re-measure");
    assert!((combined - 1.657).abs() <= 0.005, "combined {combined:.4} kW: re-measure");
    assert!((ours.volume_m3 * 1e3 - 2.54).abs() <= 0.01, "LNG {:.3} L: re-measure", ours.volume_m3 * 1e3);
}
