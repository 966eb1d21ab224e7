//! The diagnosis rests on replay: driving the reference model with the
//! logged inputs of a run must reproduce that run. For each synthetic
//! scenario, the generator's own rig replayed from the logged inputs must
//! match the logged temperatures to within 0.3 K RMS per channel: the logged
//! data carry σ = 0.1 K noise plus 12-bit quantisation (0.049 K LSB), and the
//! inputs are logged every 2 s (servo runs 0.5 s, the hold/move and gust
//! missions 0.1 s) and interpolated linearly.
//! With servo runs logged at 2 s (below Nyquist for the 0.3 Hz piston
//! motion) this test failed at 0.314 K on the oil sensor; hence the 0.5 s.

use eha_sim::diagnosis::reference::ReferenceModel;
use eha_sim::diagnosis::synth::{generate, Mismatch, SynthCase, SynthScenario};
use eha_sim::diagnosis::{Candidate, Simulator};
use eha_sim::measured::Channel;
use rayon::prelude::*;

#[test]
fn replay_of_logged_inputs_reproduces_every_scenario() {
    let bad: Vec<String> = SynthScenario::ALL
        .par_iter()
        .flat_map(|&scenario| {
            let c = SynthCase { hidden: Candidate::None, scenario, mismatch: Mismatch::Structure, seed: 7, duration_s: 900.0, sample_s: 2.0 };
            let (run, truth) = generate(&c).expect("generate");
            let n = &truth.rig.nuisance;
            let m = ReferenceModel::new(truth.rig.clone(), &run).expect("replay model");
            let nuis = [n.outer_scale, n.inner_scale, n.metal_capacity_scale, n.oil_capacity_scale];
            let s = m.simulate(&nuis, Candidate::None, &[]).expect("replay");
            Channel::TEMPERATURES
                .into_iter()
                .filter_map(|ch| {
                    let r: Vec<f64> = run.get(ch)?.iter().zip(&s.channels[&ch]).filter_map(|(m, y)| Some(y - (*m)?)).collect();
                    let rms = (r.iter().map(|x| x * x).sum::<f64>() / r.len() as f64).sqrt();
                    eprintln!("{scenario:?} {ch}: {rms:.3} K");
                    (rms > 0.3).then(|| format!("{scenario:?} {ch}: replay RMS {rms:.3} K"))
                })
                .collect::<Vec<_>>()
        })
        .collect();
    assert!(bad.is_empty(), "{}", bad.join("\n"));
}

/// The diagnosis replays with loose error control on what no logged channel
/// reads (`Plant::set_replay_tolerances`: the energy integrals out of it,
/// the port oil at 0.01 K absolute) and `REPLAY_RTOL`. On a servo gust log
/// (flow reversing every second: the port oil swings) and a throttle log,
/// the five logged temperature channels must stay within 0.02 K of a
/// solution at rtol 1e-8 with every state under control: a fifth of the
/// σ = 0.1 K sensor noise, so the fits see the model, not the solver.
#[test]
fn replay_tolerances_keep_the_logged_channels_within_a_fifth_of_the_noise() {
    use eha_sim::diagnosis::reference::{replay_inputs, REPLAY_RTOL};
    use eha_sim::scenario::Scenario;
    use eha_sim::sim::{simulate_budget, simulate_rtol, SimOptions};
    let worst: Vec<(SynthScenario, f64)> = [SynthScenario::ServoGust, SynthScenario::ThrottleSteps]
        .par_iter()
        .map(|&scenario| {
            let c = SynthCase { hidden: Candidate::None, scenario, mismatch: Mismatch::Nuisance, seed: 7, duration_s: 900.0, sample_s: 0.1 };
            let (run, _) = generate(&c).expect("generate");
            let sc = Scenario::Replay(replay_inputs(&run, "replay").expect("inputs"));
            let opts = SimOptions { output_interval_s: 2.25, control_interval_s: 2.25 };
            let rig = eha_sim::rig::Rig::default();
            let fast = simulate_budget(&rig, &sc, &opts, REPLAY_RTOL, None).expect("replay");
            let tight = simulate_rtol(&rig, &sc, &opts, 1e-8).expect("tight replay");
            let worst = Channel::TEMPERATURES
                .iter()
                .flat_map(|ch| {
                    let (a, b) = (fast.get(ch.name()).expect("channel"), tight.get(ch.name()).expect("channel"));
                    a.iter().zip(b).map(|(x, y)| (x - y).abs()).collect::<Vec<_>>()
                })
                .fold(0.0, f64::max);
            eprintln!("{scenario:?}: largest difference {worst:.4} K");
            (scenario, worst)
        })
        .collect();
    for (scenario, w) in worst {
        assert!(w <= 0.02, "{scenario:?}: replay differs from the tight solution by {w:.4} K");
    }
}

/// The circuit of a replay comes from the log's `# circuit:` line or the
/// piston's travel, never from whether a `position_mm` column exists: a
/// throttle log that also logs its stationary piston (12.3 mm ± 0.05 mm of
/// encoder noise) replays exactly as the same log without the column. Before
/// the rule, that log was replayed as a servo circuit and the temperatures
/// moved by kelvins.
#[test]
fn a_logged_stationary_piston_does_not_change_the_circuit() {
    use eha_sim::diagnosis::reference::replay_inputs;
    use eha_sim::scenario::{Circuit, Scenario};
    use eha_sim::sim::{simulate_budget, SimOptions};
    let c = SynthCase { hidden: Candidate::None, scenario: SynthScenario::ThrottleSteps, mismatch: Mismatch::Nuisance, seed: 7, duration_s: 600.0, sample_s: 2.0 };
    let (plain, _) = generate(&c).expect("generate");
    assert!(plain.get(Channel::PositionMm).is_none(), "the synthetic throttle log has no position column");
    let mut with_piston = plain.clone();
    let noise = |i: usize| 0.05 * ((i as f64) * 0.7).sin();
    with_piston.set(Channel::PositionMm, (0..plain.len()).map(|i| Some(12.3 + noise(i))).collect());
    let a = replay_inputs(&plain, "plain").expect("inputs");
    let b = replay_inputs(&with_piston, "piston").expect("inputs");
    assert_eq!((a.circuit, b.circuit), (Circuit::Throttle, Circuit::Throttle));
    // The diagnosis's calibration set by the same rule: the needle split
    // (throttling only) stays free on the throttle log with its piston.
    let set = eha_sim::diagnosis::reference::nuisance_set;
    let needle = eha_sim::calibration::PARAMS.iter().position(|d| d.name == "needle_split").expect("needle_split");
    assert!(set(&plain).contains(&needle), "the throttle steps calibrate the needle split");
    assert_eq!(set(&plain), set(&with_piston), "the position column changed the calibration set");
    let opts = SimOptions { output_interval_s: 10.0, control_interval_s: 10.0 };
    let rig = eha_sim::rig::Rig::default();
    let ya = simulate_budget(&rig, &Scenario::Replay(a), &opts, 1e-6, None).expect("replay");
    let yb = simulate_budget(&rig, &Scenario::Replay(b), &opts, 1e-6, None).expect("replay");
    for ch in Channel::TEMPERATURES {
        let (x, y) = (ya.get(ch.name()).expect("channel"), yb.get(ch.name()).expect("channel"));
        let d = x.iter().zip(y).map(|(p, q)| (p - q).abs()).fold(0.0, f64::max);
        assert_eq!(d, 0.0, "{ch}: the position column moved the replay by {d} K");
    }
}

/// Every other case of the rule: a stated circuit (and a contradiction of
/// it, with its line), a moving piston, and the ambiguous travel between
/// 0.5 and 2 mm, refused with the line to add.
#[test]
fn the_circuit_is_stated_or_inferred_and_an_ambiguous_log_is_refused() {
    use eha_sim::diagnosis::reference::circuit_of;
    use eha_sim::measured::MeasuredRun;
    use eha_sim::scenario::Circuit;
    let run = |travel: Option<f64>, meta: Option<&str>| {
        let mut r = MeasuredRun::new((0..50).map(|i| i as f64).collect());
        r.push_meta("rig", "bench 3");
        if let Some(m) = meta {
            r.push_meta("circuit", m);
        }
        if let Some(t) = travel {
            r.set(Channel::PositionMm, (0..50).map(|i| Some(t * (i as f64 / 49.0))).collect());
        }
        r
    };
    assert_eq!(circuit_of(&run(None, None)).expect("no column"), Circuit::Throttle);
    assert_eq!(circuit_of(&run(Some(0.4), None)).expect("stationary"), Circuit::Throttle);
    assert_eq!(circuit_of(&run(Some(20.0), None)).expect("moving"), Circuit::Servo);
    assert_eq!(circuit_of(&run(Some(0.1), Some("servo"))).expect("stated"), Circuit::Servo);
    assert_eq!(circuit_of(&run(Some(0.1), Some(" throttle "))).expect("stated"), Circuit::Throttle);
    let e = circuit_of(&run(Some(1.0), None)).expect_err("ambiguous").to_string();
    assert!(e.contains("1.00 mm") && e.contains("# circuit: throttle"), "{e}");
    let e = circuit_of(&run(Some(20.0), Some("throttle"))).expect_err("contradiction").to_string();
    assert!(e.starts_with("line 2:") && e.contains("20.00 mm"), "{e}");
    let e = circuit_of(&run(None, Some("servo"))).expect_err("servo without position").to_string();
    assert!(e.contains("no position_mm column"), "{e}");
    let e = circuit_of(&run(None, Some("hydrostatic"))).expect_err("unknown").to_string();
    assert!(e.contains("expected `throttle` or `servo`"), "{e}");
}
