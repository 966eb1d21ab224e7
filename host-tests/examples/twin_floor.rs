//! The effect-free emulator logs alone, diagnosed as `emulator-sweep`
//! diagnoses them (the case's effect-free twin, or the effect-free case
//! itself), under one `--structure` variant: answer, the most probable
//! structure and candidate with their probabilities, the calibrated
//! baseline's held-out misfit (pooled and per channel, K). A named cause
//! on any of these logs is a false discovery. Half the time of a sweep
//! with twins (the case's own log is not diagnosed).
//!
//! `cargo run --profile fast -p eha-sim --example twin_floor -- STRUCTURE [nominal-restarts] SEED…`
//! (STRUCTURE `off`/`full`/`no-case`/`no-case-held`; `nominal-restarts`:
//! `DiagnoseOptions::nominal_restarts`; seeds 1700–1717 and 2700–2717;
//! 3–50 s a log on two shared cores, 2026-11-28).

use clap::ValueEnum as _;
use eha_sim::diagnosis::analysis::Structure;
use eha_sim::diagnosis::emu_sweep::{case_of_seed, effect_free_log};
use eha_sim::diagnosis::reference::ReferenceModel;
use eha_sim::diagnosis::{diagnose, Candidate, DiagnoseOptions};
use eha_sim::rig::Rig;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let Some((s, seeds)) = args.split_first() else {
        eprintln!("usage: twin_floor STRUCTURE [nominal-restarts] SEED…");
        std::process::exit(2);
    };
    let structure = Structure::from_str(s, true).expect("structure: off, full, no-case or no-case-held");
    let nominal_restarts = seeds.first().is_some_and(|a| a == "nominal-restarts");
    let seeds = &seeds[usize::from(nominal_restarts)..];
    let o = DiagnoseOptions { structure, nominal_restarts, ..DiagnoseOptions::default() };
    for seed in seeds.iter().map(|a| a.parse::<u64>().expect("seed")) {
        let c = case_of_seed(1200.0, seed).expect("seed 1700–1717 or 2700–2717");
        let t = std::time::Instant::now();
        let run = effect_free_log(&c).expect("log");
        let tag = if c.hidden == Candidate::None { "effect-free case".to_string() } else { format!("twin of {}", c.hidden.name()) };
        let model = ReferenceModel::new(Rig::default(), &run).expect("model").with_structure(&run, structure);
        let d = diagnose(&run, &model, &o).expect("diagnosis");
        let top = &d.posterior.causes[0];
        let cand = d.posterior.causes.iter().find(|p| p.cause != "none" && p.cause != "unexplained");
        let none_ho = d.ranking.iter().find(|e| e.cause == "none").map_or(f64::NAN, |e| e.heldout_rmse_k);
        let lag = d
            .ranking
            .iter()
            .find(|e| e.cause == "sensor-lag")
            .map(|e| {
                format!(
                    "sensor-lag: dBIC {:.0}, pooled held out {:.3} -> {:.3} K ({:+.0} %), qualifies {}{}",
                    e.delta_bic,
                    none_ho,
                    e.heldout_rmse_k,
                    100.0 * (e.heldout_rmse_k / none_ho - 1.0),
                    e.qualifies,
                    if e.note.is_empty() { String::new() } else { format!(" ({})", e.note) }
                )
            })
            .unwrap_or_default();
        let per: Vec<String> =
            d.before.channels.iter().map(|m| format!("{} {:.2}", m.channel, m.heldout_rmse_k)).collect();
        println!(
            "{seed} {:?} {tag} | tier {} | answer {} | top {} {:.3} | best candidate {} | pooled held out {:.3} K | {} | {lag} | false discovery: {} | {:.0} s",
            c.scenario,
            d.nuisance_set,
            d.answer(),
            top.cause,
            top.probability,
            cand.map(|p| format!("{} {:.3} (prior {:.3}, ln B {:.1})", p.cause, p.probability, p.prior, p.log_bayes_factor))
                .unwrap_or_default(),
            d.before.heldout_rmse_k,
            per.join(", "),
            d.answer() != "none" && d.answer() != "unexplained",
            t.elapsed().as_secs_f64()
        );
    }
}
