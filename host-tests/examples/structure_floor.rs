//! The structure floor of the diagnosis's physical tier with and without
//! the commissioning's structure (`ReferenceModel::with_structure`: the
//! pump's `eta_m` from the motor current, `pump_friction` held, the
//! friction heat's placement and speed law and the housing probes'
//! reading towards the air freed): on effect-free emulator logs, the
//! physical-tier baseline fitted once from the rig file on the training
//! window as the diagnosis fits it (first 70 %, 150 points a channel),
//! then the held-out RMSE per channel and pooled, K.
//!
//! `cargo run --profile fast -p eha-sim --example structure_floor -- [sims=N] SEED…`
//! (seeds 1700–1717, 2700–2717: a case with a hidden effect gives its
//! effect-free twin, an effect-free case itself; ~10–60 s a log on two cores).

use eha_sim::diagnosis::analysis::{fit_points, split_time_s};
use eha_sim::diagnosis::emu_sweep::case_of_seed;
use eha_sim::diagnosis::fit::{fit, FitOptions, FitResult};
use eha_sim::diagnosis::reference::ReferenceModel;
use eha_sim::diagnosis::stats::rmse;
use eha_sim::diagnosis::{Candidate, Simulator};
use eha_sim::emulator::generate_twin;
use eha_sim::measured::{Channel, MeasuredRun};
use eha_sim::rig::Rig;

/// Held-out RMSE of `channels` from `split` on, K.
fn held(run: &MeasuredRun, f: &FitResult, channels: &[Channel], split: f64) -> f64 {
    let mut ho = Vec::new();
    for &ch in channels {
        let (Some(m), Some(y)) = (run.get(ch), f.series.channels.get(&ch)) else { continue };
        for i in 0..run.len() {
            if let (Some(m), true) = (m[i], run.time_s[i] >= split) {
                ho.push(Some(y[i] - m));
            }
        }
    }
    rmse(&ho).unwrap_or(f64::NAN)
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    // `sims=N`: the fit's model-run budget (default: the diagnosis's, at
    // least six Jacobians of the set).
    let max_sims = args.iter().find_map(|a| a.strip_prefix("sims=")).map_or(FitOptions::default().max_sims, |n| n.parse().expect("sims=N"));
    let seeds: Vec<u64> = args.iter().filter(|a| !a.contains('=')).map(|a| a.parse().expect("seed")).collect();
    for seed in seeds {
        let case = case_of_seed(1200.0, seed).expect("seed in the case sets");
        let run = generate_twin(&case).expect("log").0;
        let split = split_time_s(&run, 0.7);
        let pts = fit_points(&run, split, 150);
        let t = std::time::Instant::now();
        let one = |on: bool| {
            let model = ReferenceModel::new(Rig::default(), &run).expect("model").with_structure(&run, on);
            let eta = model.eta_m_from_current();
            let sim = model.physical_set().expect("physical set");
            let specs = sim.nuisance();
            let nom: Vec<f64> = specs.iter().map(|p| p.start).collect();
            let f = fit(&*sim, &run, &pts, Candidate::None, &nom, None, FitOptions { max_sims, ..FitOptions::default() }).expect("baseline");
            let moved: Vec<String> = specs
                .iter()
                .zip(&f.nuisance)
                .filter(|(s, v)| (**v).ln().abs() > 0.3 || (s.name.starts_with("probe_surface") && (**v).ln().abs() > 0.01))
                .map(|(s, v)| format!("{}={v:.2}", s.name))
                .collect();
            (eta, f, moved)
        };
        let (a, b) = rayon::join(|| one(false), || one(true));
        println!("{seed} {:?} {} (twin) eta_m from current {:?}  [{:.0} s]", case.scenario, case.hidden.name(), b.0, t.elapsed().as_secs_f64());
        for (tag, (_, f, moved)) in [("rig-file set", &a), ("with structure", &b)] {
            let per: Vec<String> = Channel::TEMPERATURES
                .iter()
                .map(|&c| format!("{} {:.2}", &c.name()[2..c.name().len() - 2], held(&run, f, &[c], split)))
                .collect();
            println!(
                "  {tag:<15} pooled held-out {:.3} K | {} | train rss {:.1} K² sims {} | moved: {}",
                held(&run, f, &Channel::TEMPERATURES, split),
                per.join(", "),
                f.rss,
                f.sims,
                moved.join(" ")
            );
        }
    }
}
