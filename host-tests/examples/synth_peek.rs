//! Prints a synthetic run's inputs and temperatures every 10 s (scratch).
use eha_sim::diagnosis::synth::{generate, Mismatch, SynthCase, SynthScenario};
use eha_sim::diagnosis::Candidate;
use eha_sim::measured::Channel;
fn main() {
    let c = SynthCase { hidden: Candidate::CoulombFriction, scenario: SynthScenario::ServoHoldMove, mismatch: Mismatch::Nuisance, seed: 45, duration_s: 1200.0, sample_s: 2.0 };
    let (run, truth) = generate(&c).unwrap();
    println!("magnitude {} affected {:?} rows {}", truth.magnitude, truth.affected, run.len());
    let mut next = 0.0;
    for i in 0..run.len() {
        let t = run.time_s[i];
        if t + 1e-9 < next { continue; }
        next += 10.0;
        let g = |ch: Channel| run.get(ch).and_then(|v| v[i]).unwrap_or(f64::NAN);
        println!("{t:7.1} n {:7.0} I {:6.1} pa {:6.1} pb {:6.1} x {:6.1} oil {:6.2} blk {:6.2} pump {:6.2} mot {:6.2}", g(Channel::SpeedRpm), g(Channel::CurrentA), g(Channel::PABar), g(Channel::PBBar), g(Channel::PositionMm), g(Channel::TOilC), g(Channel::TBlockC), g(Channel::TPumpC), g(Channel::TMotorC));
    }
}
