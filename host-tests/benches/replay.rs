//! Benchmark: one diagnosis replay of a 30-minute log at 0.1 s (the unit of
//! work a diagnosis repeats ~1000 times), a throttle-step log and a servo
//! gust log from the hidden-effect generator, with the diagnosis's error
//! control (`sim::simulate_budget`: replay tolerances, `REPLAY_RTOL`) and,
//! for comparison, every state under control (`sim::simulate_rtol`). Prints
//! the solver steps and model evaluations of each; run with
//! `cargo bench --profile speed -p eha-sim --bench replay`.

use criterion::{criterion_group, criterion_main, Criterion};
use eha_sim::diagnosis::reference::{replay_inputs, REPLAY_RTOL};
use eha_sim::diagnosis::synth::{generate, Mismatch, SynthCase, SynthScenario};
use eha_sim::diagnosis::Candidate;
use eha_sim::rig::Rig;
use eha_sim::scenario::Scenario;
use eha_sim::sim::{simulate_budget, simulate_rtol, SimOptions};
use std::hint::black_box;

fn replay_30min(c: &mut Criterion) {
    let rig = Rig::default();
    // The diagnosis's output interval for a 30-minute log (span / 400).
    let opt = SimOptions { output_interval_s: 4.5, control_interval_s: 4.5 };
    let mut g = c.benchmark_group("replay_30min");
    g.sample_size(10);
    for (name, scenario) in [("throttle_steps", SynthScenario::ThrottleSteps), ("servo_gusts", SynthScenario::ServoGust)] {
        let case = SynthCase { hidden: Candidate::None, scenario, mismatch: Mismatch::Nuisance, seed: 7, duration_s: 1800.0, sample_s: 0.1 };
        let (run, _) = generate(&case).expect("generate");
        let sc = Scenario::Replay(replay_inputs(&run, name).expect("inputs"));
        let fast = simulate_budget(&rig, &sc, &opt, REPLAY_RTOL, None).expect("replay");
        let full = simulate_rtol(&rig, &sc, &opt, REPLAY_RTOL).expect("replay");
        eprintln!(
            "{name}: diagnosis replay {} steps, {} evaluations; every state controlled {} steps, {} evaluations",
            fast.stats.steps, fast.stats.rhs_evals, full.stats.steps, full.stats.rhs_evals
        );
        // The multirate fast path on the same replay, timed against the
        // diagnosis's replay, alternating (5 each; a quick look, not criterion).
        let (mut t_bdf, mut t_fast) = (0.0, 0.0);
        for _ in 0..5 {
            let t = std::time::Instant::now();
            black_box(simulate_budget(&rig, &sc, &opt, REPLAY_RTOL, None).expect("replay"));
            t_bdf += t.elapsed().as_secs_f64() / 5.0;
            let t = std::time::Instant::now();
            black_box(eha_sim::sim::simulate_fast(&rig, &sc, &opt).expect("fast replay"));
            t_fast += t.elapsed().as_secs_f64() / 5.0;
        }
        eprintln!("{name}: diagnosis replay {:.1} ms, fast path {:.1} ms (mean of 5, alternating)", 1e3 * t_bdf, 1e3 * t_fast);
        g.bench_function(format!("{name}_diagnosis"), |b| {
            b.iter(|| simulate_budget(black_box(&rig), black_box(&sc), &opt, REPLAY_RTOL, None).expect("replay"))
        });
        g.bench_function(format!("{name}_every_state"), |b| {
            b.iter(|| simulate_rtol(black_box(&rig), black_box(&sc), &opt, REPLAY_RTOL).expect("replay"))
        });
    }
    g.finish();
}

criterion_group!(benches, replay_30min);
criterion_main!(benches);
