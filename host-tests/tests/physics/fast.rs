//! The multirate fast path (`sim::simulate_fast`) against the BDF plant at
//! rtol 1e-9 (itself within 3e-4 K of rtol 1e-10 on these cases) on every
//! node temperature the output logs (12 channels, not only the five of the
//! measured format): the paper's Case 1 and Case 2, Fig. 15 with its LNG
//! thermostat and the five random missions of the firmware suite, with the
//! oil on its viscosity line (the reference's default: the
//! hydraulics see the temperatures). Spec: 0.01 K. Each test also has a
//! regression bound at 2-3x the deviation measured when it was written, so
//! that a change of the scheme that costs accuracy shows here first.

use eha_sim::missions::{random_mission, TEST_SEEDS};
use eha_sim::network::NODES;
use eha_sim::rig::Rig;
use eha_sim::scenario::Scenario;
use eha_sim::fast::{FastOptions, FastPlant};
use eha_sim::plant::Control;
use eha_sim::sim::{simulate_fast, simulate_rtol, SimOptions, SimOutput};

/// The bound on every logged temperature channel, K.
const SPEC_K: f64 = 0.01;

/// Largest |fast − BDF| over every node temperature and output time, K,
/// and its channel.
fn deviation(fast: &SimOutput, bdf: &SimOutput) -> (f64, &'static str) {
    assert_eq!(fast.time_s.len(), bdf.time_s.len(), "output times differ");
    let mut worst = (0.0, "");
    for n in NODES {
        let (a, b) = (fast.get(n.channel()).expect("channel"), bdf.get(n.channel()).expect("channel"));
        let d = a.iter().zip(b).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max);
        if d > worst.0 {
            worst = (d, n.channel());
        }
    }
    worst
}

/// Runs `sc` both ways and checks the spec and the regression bound.
fn check(rig: &Rig, sc: &Scenario, opt: &SimOptions, regression_k: f64) -> SimOutput {
    let bdf = simulate_rtol(rig, sc, opt, 1e-9).expect("BDF runs");
    let fast = simulate_fast(rig, sc, opt).expect("fast path runs");
    let (d, ch) = deviation(&fast, &bdf);
    println!("{}: {:.2e} K on {ch} ({} thermal steps, {} model evaluations; BDF {} steps)", fast.name, d, fast.stats.steps, fast.stats.rhs_evals, bdf.stats.steps);
    assert!(d <= SPEC_K, "{}: {d:.3e} K on {ch} exceeds the {SPEC_K} K spec", fast.name);
    assert!(d <= regression_k, "{}: {d:.3e} K on {ch} above the regression bound {regression_k:.0e} K", fast.name);
    assert_eq!(fast.valve_open_times_s.len(), bdf.valve_open_times_s.len(), "{}: valve openings", fast.name);
    fast
}

/// Case 1 at 60 bar, 600 s, with the benchmark's 10 s outputs and with the
/// default 1 s outputs (0.1 s callbacks, read from the interpolants).
/// Measured 6.1e-4 K and 1.14e-3 K at 2e-4 K per thermal step (the
/// drain; 4.9e-4 and 4.5e-4 K at 1e-4 K per step until 2026-11-28, whose
/// 10 s bound was 5e-4 K).
#[test]
fn case1_within_a_hundredth_of_a_kelvin() {
    let rig = Rig::default();
    let sc = Scenario::Case1 { needle_bar: 60.0, duration_s: 600.0 };
    check(&rig, &sc, &SimOptions { output_interval_s: 10.0, control_interval_s: 10.0 }, 1.5e-3);
    check(&rig, &sc, &SimOptions::default(), 3e-3);
}

/// Case 2 (servo, 0.2 Hz), 600 s, 1 s outputs. Measured 9.57e-3 K on the
/// winding, whose copper loss the steps integrate over 120 cycles (7.8e-3 K
/// at 2e-4 K per thermal step, 6.4e-3 K at 1e-4 K, before the servo ring
/// took the pump's delivery direction while the piston's flow is under the
/// leakage: one more switch of the ring near each reversal for the steps to
/// cross); the spec, 0.01 K, is the bound.
#[test]
fn case2_within_a_hundredth_of_a_kelvin() {
    check(&Rig::default(), &Scenario::Case2 { duration_s: 600.0 }, &SimOptions { output_interval_s: 1.0, control_interval_s: 1.0 }, SPEC_K);
}

/// Fig. 15 (Case 1 at 60 bar with the LNG thermostat on the loop oil),
/// 1800 s, in two parts.
///
/// The temperatures: the fast path driven by the BDF's own valve schedule
/// (its openings and closings at the BDF's callbacks) against the BDF, on
/// every node, within the spec. Measured 1.6e-3 K (the ball-valve oil at
/// 192 s, just after a switch).
///
/// The switching: the free-running fast path with its own thermostat opens
/// and closes as often as the BDF, each switch within 1 s of the BDF's
/// (measured 0.70 s at most).
/// Not at the same callback: with the oil on its viscosity line
/// the BDF's loop oil crosses 40 °C at 613.4 s by 5e-6 K, the fast path's
/// (7.5e-5 K low, at any of its tolerances from 1e-5 to 1e-7 K per step)
/// one callback later; a thermostat limit cycle has no restoring force on
/// its phase, so the shift stays and grows (0.5 s by 1003 s, measured).
/// A 0.1 s shift of a 20 K step of the inlet oil is 10 K on that channel
/// for a second: the free-running comparison is not a temperature test.
#[test]
fn fig15_switches_with_the_bdf() {
    let rig = Rig::default();
    let sc = Scenario::Lng { duration_s: 1800.0 };
    let opt = SimOptions::default();
    let bdf = simulate_rtol(&rig, &sc, &opt, 1e-9).expect("BDF runs");
    assert!(bdf.valve_open_times_s.len() >= 50, "{} openings", bdf.valve_open_times_s.len());
    // The BDF's schedule: open from each opening to the next closing.
    let open_at = |t: f64| {
        let opened = bdf.valve_open_times_s.iter().filter(|&&o| o <= t + 1e-9).count();
        let closed = bdf.valve_close_times_s.iter().filter(|&&c| c <= t + 1e-9).count();
        opened > closed
    };
    let mut fast = FastPlant::with_options(&rig, &sc, FastOptions::for_scenario(&sc)).expect("fast plant");
    let mut worst = (0.0f64, "", 0.0);
    let mut k = 0usize;
    fast.run(0.1, 1800.0, |snap| {
        if k < bdf.time_s.len() && (snap.t - bdf.time_s[k]).abs() < 1e-6 {
            for n in NODES {
                let d = (snap.temp(n) - bdf.get(n.channel()).expect("channel")[k]).abs();
                if d > worst.0 {
                    worst = (d, n.channel(), snap.t);
                }
            }
            k += 1;
        }
        Ok(Control { lng_valve: Some(open_at(snap.t)), stop: false })
    })
    .expect("fast path runs");
    println!("lng-fig15 on the BDF's schedule: {:.2e} K on {} at {} s, {k} outputs", worst.0, worst.1, worst.2);
    assert_eq!(k, bdf.time_s.len(), "every output compared");
    assert!(worst.0 <= SPEC_K, "{:.3e} K on {} at {} s exceeds the {SPEC_K} K spec", worst.0, worst.1, worst.2);
    assert!(worst.0 <= 4e-3, "{:.3e} K above the regression bound 4e-3 K", worst.0);

    let free = simulate_fast(&rig, &sc, &opt).expect("fast path runs");
    assert_eq!(free.valve_open_times_s.len(), bdf.valve_open_times_s.len(), "openings");
    assert_eq!(free.valve_close_times_s.len(), bdf.valve_close_times_s.len(), "closings");
    let shift = free
        .valve_open_times_s
        .iter()
        .zip(&bdf.valve_open_times_s)
        .chain(free.valve_close_times_s.iter().zip(&bdf.valve_close_times_s))
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    println!("free-running switches: largest shift {shift:.2} s");
    assert!(shift <= 1.0, "a switch {shift:.2} s from the BDF's");
}

/// The firmware suite's five random missions (throttle and servo), 600 s.
/// Measured 5.7e-4, 2.3e-3, 4.9e-4, 4.6e-4, 3.6e-3 K at 2e-4 K per thermal
/// step (4.0e-4, 2.3e-3, 2.4e-4, 3.4e-4, 1.8e-3 K at 1e-4 K).
#[test]
fn random_missions_within_a_hundredth_of_a_kelvin() {
    let rig = Rig::default();
    for (s, reg) in TEST_SEEDS.iter().zip([3e-3, 6e-3, 1.5e-3, 4e-3, 6e-3]) {
        check(&rig, &Scenario::Mission(random_mission(*s, 600.0)), &SimOptions::default(), reg);
    }
}

/// Slow tier: twenty random missions of 30 minutes (seeds 6–25, throttle
/// and servo; the oil on its viscosity line): 20 runs within the
/// spec of the BDF at rtol 1e-9, but for the measured [`DEGENERATE`] ones.
///
/// Those stop a throttle from high pressure (or rest a servo) with the
/// needle open: the port pressures decay to equal values, and the heat
/// balances send the pump leakage through the outlet or the inlet port by
/// the sign of p_A − p_B (the model's `hp`), a sign switch at a difference
/// that vanishes. The BDF holds it at exactly 0 (outlet); any other
/// integrator's rounding of a vanishing difference flips it (the fast path:
/// ±1 Pa with its Jacobian kept, ±1e-2 Pa with a fresh one every step,
/// the same 1.7e-2 K), and on four of the missions the shipped BDF (rtol
/// 1e-6) is itself more than 0.01 K from its rtol 1e-9 solution. The
/// reference does not define these runs to 0.01 K; the fast path is
/// asserted there within 0.1 K (the sensors' noise; measured at most
/// 3.6e-2 K), and the list of them as measured, so that a change of the
/// model (a smooth routing of the leakage) or of either solver shows here.
#[test]
#[ignore]
fn slow_twenty_long_random_missions_within_a_hundredth_of_a_kelvin() {
    let opt = SimOptions::default();
    let (mut degenerate, mut misses) = (vec![], vec![]);
    {
        let rig = Rig::default();
        for s in 6..26 {
            let sc = Scenario::Mission(random_mission(s, 1800.0));
            let tight = simulate_rtol(&rig, &sc, &opt, 1e-9).expect("BDF runs");
            let shipped = simulate_rtol(&rig, &sc, &opt, 1e-6).expect("BDF runs");
            let fast = simulate_fast(&rig, &sc, &opt).expect("fast path runs");
            let ((d, ch), (b, bch)) = (deviation(&fast, &tight), deviation(&shipped, &tight));
            println!("seed {s}: fast {d:.2e} K on {ch}, shipped BDF {b:.2e} K on {bch}");
            if d > SPEC_K || b > SPEC_K {
                degenerate.push(s);
            }
            if d > 0.1 || (d > SPEC_K && !DEGENERATE.contains(&s)) {
                misses.push(format!("seed {s}: {d:.3e} K on {ch} (shipped BDF {b:.2e} K)"));
            }
        }
    }
    println!("beyond 0.01 K (fast or shipped BDF): {degenerate:?}");
    assert!(misses.is_empty(), "{misses:#?}");
    assert_eq!(degenerate, DEGENERATE, "missions beyond 0.01 K by the fast path or the shipped BDF");
}

/// The missions of the slow test where the fast path or the shipped BDF is
/// more than 0.01 K from the BDF at rtol 1e-9, both at a stop or rest with
/// the needle open. Measured with the oil on its viscosity line,
/// fast / shipped BDF: seed 13 1.28e-2 / 1.06e-2 K, seed 21 5.2e-3 /
/// 1.49e-2 K; the other 18 within 8.5e-3 K (fast, seed 9) and 9.9e-3 K
/// (shipped). At 1e-4 K per thermal step (until 2026-11-28) seed 13's fast
/// deviation was 8.0e-3 K and the others' within 5.5e-3 K.
const DEGENERATE: [u64; 2] = [13, 21];
