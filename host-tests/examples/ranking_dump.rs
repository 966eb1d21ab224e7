//! Every candidate's fit on emulator logs, as the diagnosis ranks it, for
//! measuring an admission rule offline: for each seed the case's log (its
//! hidden effect in) and its effect-free log (the twin, or the case itself
//! when nothing is hidden), diagnosed under the default options; one JSON
//! line per log with the answer, the whole ranking (ΔBIC, the gain where
//! the candidate acts, the pooled and per-channel held-out RMSE, whether it
//! qualifies and why not), the evidence's per-channel floors and the
//! posterior.
//!
//! `cargo run --profile fast -p eha-sim --example ranking_dump -- [--affected] OUT.jsonl SEED…`
//! (seeds of the case sets, 1700–1717 … 2000–2017, 2700–2717 …
//! 3000–3017; a case that hides nothing is its own effect-free
//! log, one line; lines are appended, so a stopped run is resumed by
//! passing the seeds left). `--affected`: only print each case's affected
//! channel, the one its imprint ratio is taken on, without diagnosing.

use eha_sim::diagnosis::emu_sweep::{case_of_seed, effect_free_log};
use eha_sim::diagnosis::reference::ReferenceModel;
use eha_sim::diagnosis::{diagnose, Candidate, DiagnoseOptions};
use eha_sim::emulator::{generate, EmuCase};
use eha_sim::measured::MeasuredRun;
use eha_sim::rig::Rig;
use std::io::Write as _;

/// One log's line: what the diagnosis answered and every fit it ranked.
/// A derived `Serialize`, not `serde_json::json!`: the macro over this
/// object took 76 s of a clean build (1.5 s now), which CI pays.
#[derive(serde::Serialize)]
struct Line<'a> {
    seed: u64,
    kind: &'a str,
    scenario: String,
    hidden: &'static str,
    answer: &'static str,
    tier: String,
    ranking: Vec<eha_sim::diagnosis::analysis::RankEntry>,
    floors: Vec<Floor>,
    /// Per structure: (cause, probability, ln Bayes factor, prior).
    posterior: Vec<(String, f64, f64, f64)>,
    seconds: f64,
}

/// One channel's evidence numbers, K.
#[derive(serde::Serialize)]
struct Floor {
    channel: String,
    misfit_k: f64,
    floor_k: f64,
    noise_k: f64,
}

fn line<'a>(seed: u64, kind: &'a str, c: &EmuCase, run: &MeasuredRun, o: &DiagnoseOptions) -> Line<'a> {
    let model = ReferenceModel::new(Rig::default(), run).expect("model").with_structure(run, o.structure);
    let t = std::time::Instant::now();
    let d = diagnose(run, &model, o).expect("diagnosis");
    Line {
        seed,
        kind,
        scenario: format!("{:?}", c.scenario),
        hidden: c.hidden.name(),
        answer: d.answer(),
        tier: d.nuisance_set.clone(),
        floors: d.posterior.channels.iter().map(|e| Floor { channel: e.channel.clone(), misfit_k: e.misfit_k, floor_k: e.floor_k, noise_k: e.noise_k }).collect(),
        posterior: d.posterior.causes.iter().map(|p| (p.cause.clone(), p.probability, p.log_bayes_factor, p.prior)).collect(),
        ranking: d.ranking,
        seconds: t.elapsed().as_secs_f64(),
    }
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let affected_only = args.first().is_some_and(|a| a == "--affected");
    let args = &args[usize::from(affected_only)..];
    let Some((out, seeds)) = args.split_first() else {
        eprintln!("usage: ranking_dump [--affected] OUT.jsonl SEED…");
        std::process::exit(2);
    };
    let o = DiagnoseOptions::default();
    let mut f = std::fs::OpenOptions::new().create(true).append(true).open(out).expect("output file");
    for seed in seeds.iter().map(|a| a.parse::<u64>().expect("seed")) {
        let Some(c) = case_of_seed(1200.0, seed) else {
            eprintln!("{seed}: not a case of the sets (a retired slot?), skipped");
            continue;
        };
        let mut logs = vec![];
        if c.hidden != Candidate::None {
            let (run, truth) = generate(&c).expect("log");
            // The channel the effect changes most (the imprint ratio's).
            eprintln!("{seed} affected {:?}", truth.affected.map(|a| a.0.name()));
            if affected_only {
                continue;
            }
            logs.push(("case", run));
            logs.push(("twin", effect_free_log(&c).expect("twin")));
        } else if !affected_only {
            logs.push(("effect-free", effect_free_log(&c).expect("log")));
        }
        for (kind, run) in logs {
            let v = line(seed, kind, &c, &run, &o);
            eprintln!("{seed} {kind}: {} ({:.0} s)", v.answer, v.seconds);
            writeln!(f, "{}", serde_json::to_string(&v).expect("a line as JSON")).expect("write");
        }
    }
}
