//! Benchmark: one diagnosis of a 30-minute log sampled at 0.1 s (issue
//! "Diagnosis on rigs that are not our model", speed: ≤ 60 s wall on 2
//! cores). Two logs from the hidden-effect generator: a throttle mission with
//! speed and pressure steps and a gust-rejection servo mission (the slowest
//! replay: the fast oil nodes follow the 1 Hz manoeuvres). Prints the wall
//! time, the model runs and the verdict of each; run with
//! `cargo bench --profile fast -p eha-sim --bench diagnose_30min`.
//! (One run per log: a diagnosis is a minute-scale job, so the statistics of
//! criterion's repeated sampling would cost ten times that.)

use eha_sim::diagnosis::reference::ReferenceModel;
use eha_sim::diagnosis::synth::{generate, Mismatch, SynthCase, SynthScenario};
use eha_sim::diagnosis::{diagnose, Candidate, DiagnoseOptions};
use eha_sim::rig::Rig;
use std::time::Instant;

fn main() {
    let cases = [
        ("throttle steps, 30 min at 0.1 s", SynthScenario::ThrottleSteps, Candidate::SensorLag),
        ("servo gusts, 30 min at 0.1 s", SynthScenario::ServoGust, Candidate::CoulombFriction),
    ];
    for (name, scenario, hidden) in cases {
        let case = SynthCase { hidden, scenario, mismatch: Mismatch::Nuisance, seed: 7, duration_s: 1800.0, sample_s: 0.1 };
        let (run, _) = generate(&case).expect("generate");
        let t = Instant::now();
        let model = ReferenceModel::new(Rig::default(), &run).expect("model");
        let d = diagnose(&run, &model, &DiagnoseOptions::default()).expect("diagnose");
        println!(
            "{name}: {} rows, {:.1} s wall, {} model runs, cause {} (hidden {}), held-out {:.3} -> {:.3} K",
            run.len(),
            t.elapsed().as_secs_f64(),
            d.sims,
            d.cause.name(),
            hidden.name(),
            d.before.heldout_rmse_k,
            d.after.heldout_rmse_k
        );
    }
}
