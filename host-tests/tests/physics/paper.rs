//! The paper's published numbers (Liu et al.), each with its tolerance and
//! the reason for it. One calibrated parameter set (`Rig::default()`) serves
//! every case; see docs/calibration.md for how it was calibrated.

use eha_sim::cooling::{size, Lng};
use eha_sim::heat::h_forced_plate;
use eha_sim::rig::Rig;
use eha_sim::scenario::Scenario;
use eha_sim::sim::{simulate, SimOptions, SimOutput};

fn case1(rig: &Rig, bar: f64) -> SimOutput {
    simulate(rig, &Scenario::Case1 { needle_bar: bar, duration_s: 600.0 }, &SimOptions::default()).expect("case 1 runs")
}

/// Table 4 (600 s, 60 bar): inlet 53.00, outlet 54.17, drain 59.67 °C, each
/// within ±1.5 K (the tolerance: the paper's own simulation-vs-test
/// agreement in Fig. 8 is of that order).
#[test]
fn table4_port_temperatures_at_600s_60bar() {
    let out = case1(&Rig::default(), 60.0);
    for (ch, paper) in [("t_inlet_c", 53.00), ("t_outlet_c", 54.17), ("t_drain_c", 59.67)] {
        let ours = out.last(ch).expect("channel");
        println!("{ch}: ours {ours:.2} °C, paper {paper:.2} °C");
        assert!((ours - paper).abs() <= 1.5, "{ch}: {ours:.2} vs {paper:.2}");
    }
    // The paper's ordering: drain hottest, outlet above inlet.
    let g = |c| out.last(c).unwrap_or(f64::NAN);
    assert!(g("t_drain_c") > g("t_outlet_c") && g("t_outlet_c") > g("t_inlet_c"));
}

/// Table 5: ram-air coefficients 66.13, 115.13, 173.25 W/(m²·K) at 15, 30,
/// 50 m/s within 1 % (issue tolerance). The run length is calibrated on the
/// 15 m/s entry only, so the 30 and 50 m/s entries test the correlation's
/// v^0.8 law.
#[test]
fn table5_ram_air_coefficients() {
    let rig = Rig::default();
    for (v, paper) in [(15.0, 66.13), (30.0, 115.13), (50.0, 173.25)] {
        let h = h_forced_plate(v, rig.outside.ram_run_length_m, rig.outside.ram_property_c);
        println!("{v} m/s: ours {h:.2}, paper {paper:.2} W/(m²·K)");
        assert!((h - paper).abs() / paper < 0.01, "{v} m/s: {h}");
    }
}

/// Table 5: the pump shell and the drain port cool as the air speed rises
/// (strictly monotonic; the paper reports 25.38 → 23.82 °C and 59.67 →
/// 58.57 °C from 0 to 50 m/s). Ours are printed beside the paper's.
#[test]
fn table5_pump_shell_and_drain_fall_with_air_speed() {
    let paper = [(0.0, 25.38, 59.67), (15.0, 24.78, 59.14), (30.0, 24.32, 58.84), (50.0, 23.82, 58.57)];
    let mut prev: Option<(f64, f64)> = None;
    for (v, shell_p, drain_p) in paper {
        let rig = Rig::default();
        let mut sc = Scenario::Case1 { needle_bar: 60.0, duration_s: 600.0 }.mission().expect("mission");
        sc.air_speed_mps = eha_sim::scenario::Schedule::constant(v);
        rig.validate().expect("rig");
        let out = simulate(&rig, &Scenario::Mission(sc), &SimOptions::default()).expect("runs");
        let (shell, drain) = (out.last("t_pump_c").unwrap_or(f64::NAN), out.last("t_drain_c").unwrap_or(f64::NAN));
        println!("{v:>4} m/s: pump shell ours {shell:.2} paper {shell_p:.2}; drain ours {drain:.2} paper {drain_p:.2}");
        if let Some((s0, d0)) = prev {
            assert!(shell < s0 && drain < d0, "not cooling at {v} m/s");
        }
        prev = Some((shell, drain));
    }
}

/// LNG sizing, eqs. (23)–(25) with Table 6: 1.5 kW over a 680 s mission needs
/// 2.30 L (the paper's "2.3 L"; the mission time is not printed, 680 s is the
/// one that gives it); the 5 L charge is 2.15 kg. Tolerances: half the last
/// printed digit.
#[test]
fn lng_sizing_reproduces_the_paper() {
    let lng = Lng::default();
    let s = size(&lng, 1500.0, 680.0, 2.0);
    assert!((s.volume_m3 * 1e3 - 2.3).abs() < 0.05, "{} L", s.volume_m3 * 1e3);
    assert!((lng.charge_kg() - 2.15).abs() < 0.005, "{} kg", lng.charge_kg());
    // And the inverse: the 5 L charge lasts 1478 s at 1.5 kW.
    let t = lng.mission_time_s(1500.0, 5e-3);
    assert!((t - 5e-3 * 430.0 * (509e3 + 2.9e3 * 180.0) / 1500.0).abs() < 1e-6);
}

/// Fig. 15: with the LNG exchanger the valve opens at about 110 s (±20 s,
/// the reading of the figure) and the drain port stays below 50 °C.
#[test]
fn fig15_lng_valve_opens_near_110s_and_drain_stays_below_50c() {
    let out = simulate(&Rig::default(), &Scenario::Lng { duration_s: 600.0 }, &SimOptions::default()).expect("runs");
    let open = *out.valve_open_times_s.first().expect("valve opened");
    let max_drain = out.max("t_drain_c").unwrap_or(f64::NAN);
    println!("valve opens at {open:.1} s (paper ≈ 110 s); drain max {max_drain:.2} °C (paper < 50 °C); {} openings", out.valve_open_times_s.len());
    assert!((open - 110.0).abs() <= 20.0);
    assert!(max_drain < 50.0);
}

/// Node temperatures at 600 s rise monotonically with the needle pressure
/// (0, 20, 40, 60 bar), as Fig. 8 shows for every measured point.
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

/// Case 2 reaches a periodic thermal balance (paper, Fig. 12b: "the heat
/// dissipation and power loss of the system are in balance after 200 s").
/// Balance at a port: the period-mean temperature drifts by less than 10 % of
/// its first-period drift (the transient has decayed to the slow warm-up of the
/// metal) and the swing repeats from period to period within 10 %. Every port
/// must reach it within the 600 s run; the times are printed beside the
/// paper's 200 s.
#[test]
fn case2_reaches_periodic_thermal_balance() {
    let out = simulate(&Rig::default(), &Scenario::Case2 { duration_s: 600.0 }, &SimOptions { output_interval_s: 0.1, control_interval_s: 0.1 }).expect("runs");
    let per = 50; // samples per 5 s period of the 0.2 Hz command
    for ch in ["t_inlet_c", "t_outlet_c", "t_drain_c"] {
        let periods: Vec<(f64, f64)> = out
            .get(ch)
            .expect("channel")
            .chunks_exact(per)
            .map(|c| {
                let mean = c.iter().sum::<f64>() / c.len() as f64;
                let hi = c.iter().copied().fold(f64::NEG_INFINITY, f64::max);
                let lo = c.iter().copied().fold(f64::INFINITY, f64::min);
                (mean, hi - lo)
            })
            .collect();
        let first = periods[1].0 - periods[0].0;
        assert!(first > 0.0, "{ch} does not warm up");
        let balanced = |k: usize| {
            periods[k..].windows(2).all(|w| (w[1].0 - w[0].0).abs() < 0.1 * first && (w[1].1 - w[0].1).abs() <= 0.1 * w[0].1)
        };
        let k = (1..periods.len() - 1).find(|&k| balanced(k)).expect("balance reached");
        println!("{ch}: periodic balance from {} s (paper: ≈ 200 s), swing {:.3} K", k * 5, periods[k].1);
        assert!(periods[k].1 > 0.0, "{ch}: no periodic swing");
    }
}
