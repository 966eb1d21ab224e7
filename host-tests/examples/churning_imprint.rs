//! **Experiment**: does the reference's `churning-loss` candidate move the
//! logged temperatures as the emulator's churning does? For an emulator
//! case hiding churning: the physical tier calibrated on the case's
//! effect-free twin (the same machine, mission and noise; the whole run,
//! 300 model runs), then, on the case's inputs, the reference with the
//! candidate at the emulator's true magnitude against without it. The
//! emulator's imprint is the case log less its twin (the same noise: the
//! effect alone). Per channel, training (first 70 %) and held-out windows:
//! RMS of the emulator's imprint and of the reference's, their mean, and
//! the least-squares scale of the reference's onto the emulator's with
//! the share of the emulator's imprint it leaves.
//!
//! `cargo run --profile fast -p eha-sim --example churning_imprint -- SEED…`

use eha_sim::diagnosis::analysis::{fit_points, split_time_s};
use eha_sim::diagnosis::emu_sweep::{case_of_seed, effect_free_log};
use eha_sim::diagnosis::fit::{fit, FitOptions};
use eha_sim::diagnosis::reference::ReferenceModel;
use eha_sim::diagnosis::{Candidate, DiagnoseOptions, Simulator};
use eha_sim::emulator::generate;
use eha_sim::measured::Channel;
use eha_sim::rig::Rig;

/// One side of an (emulator, reference) imprint pair.
type Of = fn(&(f64, f64)) -> f64;

fn main() {
    let o = DiagnoseOptions::default();
    for seed in std::env::args().skip(1).map(|a| a.parse::<u64>().expect("seed")) {
        let Some(c) = case_of_seed(1200.0, seed).filter(|c| c.hidden == Candidate::ChurningLoss) else {
            eprintln!("{seed}: not a churning case of the sets, skipped");
            continue;
        };
        let (run, truth) = generate(&c).expect("log");
        let twin = effect_free_log(&c).expect("twin");
        // the machine as it is without the effect: calibrated on the twin
        let model = ReferenceModel::new(Rig::default(), &twin).expect("model").with_structure(&twin, o.structure);
        let phys = model.physical_set().expect("a physical tier");
        let start: Vec<f64> = phys.nuisance().iter().map(|s| s.start).collect();
        let pts = fit_points(&twin, f64::INFINITY, o.points_per_channel);
        let f = fit(&*phys, &twin, &pts, Candidate::None, &start, None, FitOptions { max_sims: 300, ..o.fit }).expect("calibration");
        let held = ReferenceModel::new(model.physical_rig(&f.nuisance), &run).expect("model").with_nuisance_set(model.physical_free().to_vec());
        let p = held.physical_set().expect("a physical tier");
        let nominal: Vec<f64> = p.nuisance().iter().map(|s| s.start).collect();
        let off = p.simulate(&nominal, Candidate::None, &[]).expect("without");
        let on = p.simulate(&nominal, Candidate::ChurningLoss, &[truth.magnitude]).expect("with");
        let split = split_time_s(&run, o.train_fraction);
        let cal: Vec<String> = phys.nuisance().iter().zip(&f.nuisance).map(|(s, v)| format!("{} {v:.2}", s.name)).collect();
        println!("{seed} calibrated on the twin: {}", cal.join(", "));
        println!(
            "{seed} {:?}: churning {:.2e} W/(rad/s)^2.5, calibration rms {:.3} K; per channel and window: emulator RMS / mean, reference RMS / mean, scale, share left",
            c.scenario,
            truth.magnitude,
            (f.rss / f.n.max(1) as f64).sqrt()
        );
        for ch in Channel::TEMPERATURES {
            let (Some(a), Some(b), Some(y0), Some(y1)) = (run.get(ch), twin.get(ch), off.channels.get(&ch), on.channels.get(&ch)) else { continue };
            for (name, train) in [("train", true), ("held out", false)] {
                let pairs: Vec<(f64, f64)> = (0..run.len())
                    .filter(|&i| (run.time_s[i] < split) == train)
                    .filter_map(|i| Some((a[i]? - b[i]?, y1[i] - y0[i])))
                    .collect();
                let n = pairs.len().max(1) as f64;
                let rms = |f: Of| (pairs.iter().map(|p| f(p).powi(2)).sum::<f64>() / n).sqrt();
                let mean = |f: Of| pairs.iter().map(f).sum::<f64>() / n;
                let e: Of = |p| p.0;
                let m: Of = |p| p.1;
                let mm: f64 = pairs.iter().map(|p| p.1 * p.1).sum();
                let scale = if mm > 0.0 { pairs.iter().map(|p| p.0 * p.1).sum::<f64>() / mm } else { 0.0 };
                let left = (pairs.iter().map(|p| (p.0 - scale * p.1).powi(2)).sum::<f64>() / n).sqrt() / rms(e).max(1e-12);
                println!(
                    "  {:<14} {:<8} {:.3} / {:+.3}  {:.3} / {:+.3}  {:+.2}  {:.0} %",
                    ch.name(),
                    name,
                    rms(e),
                    mean(e),
                    rms(m),
                    mean(m),
                    scale,
                    100.0 * left
                );
            }
        }
    }
}
