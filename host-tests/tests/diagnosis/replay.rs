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
