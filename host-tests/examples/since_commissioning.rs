//! **Experiment** (not a product path): the diagnosis about a commissioned
//! machine. Each emulator case's machine is first calibrated on an
//! effect-free run of its own (an identification run, or the case's own
//! scenario; another mission and noise; the physical tier with the default
//! structure, on the whole run); the
//! case's log, its effect-free twin, or the effect-free case itself is then
//! diagnosed in the physical tier alone about that calibration, every freed
//! parameter held by a log-normal prior of σ `SIGMA` (ln) around its
//! commissioned value and `eta_m` the commissioning's. One JSON line per
//! diagnosed log, as `ranking_dump` writes them, plus the commissioning fit.
//!
//! `cargo run --profile fast -p eha-sim --example since_commissioning -- [--same-scenario] SIGMA OUT.jsonl SEED…`
//! (`--same-scenario`: the commissioning run flies the case's own scenario,
//! another seed, instead of an identification run).

use eha_sim::diagnosis::analysis::{diagnose_physical, fit_points};
use eha_sim::diagnosis::emu_sweep::{case_of_seed, effect_free_log};
use eha_sim::diagnosis::fit::{fit, FitOptions};
use eha_sim::diagnosis::reference::ReferenceModel;
use eha_sim::diagnosis::{Candidate, DiagnoseOptions, Simulator};
use eha_sim::emulator::missions::EmuScenario;
use eha_sim::emulator::{generate, generate_on_machine, EmuCase};
use eha_sim::measured::MeasuredRun;
use eha_sim::rig::Rig;
use std::io::Write as _;

/// Seed offset of a case's commissioning run (outside every case set).
const COMMISSIONING_SEED: u64 = 50_000;

/// A machine as commissioned: the rig, the freed parameters and what the
/// calibration found.
struct Commissioned {
    rig: Rig,
    free: Vec<usize>,
    names: Vec<String>,
    theta: Vec<f64>,
    eta_m: Option<f64>,
    rms_k: f64,
}

/// Calibrates the physical tier on `run`, all of it, from the rig file.
fn commission(run: &MeasuredRun, o: &DiagnoseOptions) -> Commissioned {
    let model = ReferenceModel::new(Rig::default(), run).expect("model").with_structure(run, o.structure);
    let phys = model.physical_set().expect("a physical tier");
    let specs = phys.nuisance();
    let pts = fit_points(run, f64::INFINITY, o.points_per_channel);
    let start: Vec<f64> = specs.iter().map(|s| s.start).collect();
    let f = fit(&*phys, run, &pts, Candidate::None, &start, None, FitOptions { max_sims: 300, ..o.fit }).expect("commissioning fit");
    Commissioned {
        rig: model.physical_rig(&f.nuisance),
        free: model.physical_free().to_vec(),
        names: specs.iter().map(|s| s.name.clone()).collect(),
        eta_m: model.eta_m_from_current().map(|e| e.0),
        rms_k: (f.rss / f.n as f64).sqrt(),
        theta: f.nuisance,
    }
}

#[derive(serde::Serialize)]
struct Line<'a> {
    seed: u64,
    kind: &'a str,
    hidden: &'static str,
    magnitude: f64,
    sigma_ln: f64,
    answer: &'static str,
    tier: String,
    commissioned: Vec<(String, f64)>,
    commissioned_eta_m: Option<f64>,
    commissioning_rms_k: f64,
    ranking: Vec<eha_sim::diagnosis::analysis::RankEntry>,
    posterior: Vec<(String, f64, f64, f64)>,
    seconds: f64,
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let same_scenario = args.first().is_some_and(|a| a == "--same-scenario");
    let [sigma, out, seeds @ ..] = &args[usize::from(same_scenario)..] else {
        eprintln!("usage: since_commissioning [--same-scenario] SIGMA OUT.jsonl SEED…");
        std::process::exit(2);
    };
    let sigma: f64 = sigma.parse().expect("SIGMA, a number");
    let o = DiagnoseOptions::default();
    let mut f = std::fs::OpenOptions::new().create(true).append(true).open(out).expect("output file");
    for seed in seeds.iter().map(|a| a.parse::<u64>().expect("seed")) {
        let Some(c) = case_of_seed(1200.0, seed) else {
            eprintln!("{seed}: not a case of the sets, skipped");
            continue;
        };
        let t = std::time::Instant::now();
        let (run, truth) = generate(&c).expect("log");
        let cc = EmuCase { hidden: Candidate::None, scenario: if same_scenario { c.scenario } else { EmuScenario::IdentRun }, seed: seed + COMMISSIONING_SEED, duration_s: c.duration_s };
        let (comm_run, _) = generate_on_machine(&cc, &truth).expect("commissioning log");
        let m = commission(&comm_run, &o);
        eprintln!("{seed} commissioned: rms {:.3} K, eta_m {:?} ({:.0} s)", m.rms_k, m.eta_m, t.elapsed().as_secs_f64());
        let logs = if c.hidden == Candidate::None {
            vec![("effect-free", run)]
        } else {
            vec![("case", run), ("twin", effect_free_log(&c).expect("twin"))]
        };
        for (kind, run) in logs {
            let t = std::time::Instant::now();
            let mut model = ReferenceModel::new(m.rig.clone(), &run).expect("model").with_nuisance_set(m.free.clone());
            for n in &m.names {
                model = model.with_prior_sigma(n, sigma);
            }
            let d = diagnose_physical(&run, &model, &o).expect("diagnosis");
            let v = Line {
                seed,
                kind,
                hidden: c.hidden.name(),
                magnitude: truth.magnitude,
                sigma_ln: sigma,
                answer: d.answer(),
                tier: d.nuisance_set.clone(),
                commissioned: m.names.iter().cloned().zip(m.theta.iter().copied()).collect(),
                commissioned_eta_m: m.eta_m,
                commissioning_rms_k: m.rms_k,
                posterior: d.posterior.causes.iter().map(|p| (p.cause.clone(), p.probability, p.log_bayes_factor, p.prior)).collect(),
                ranking: d.ranking,
                seconds: t.elapsed().as_secs_f64(),
            };
            eprintln!("{seed} {kind}: {} ({:.0} s)", v.answer, v.seconds);
            writeln!(f, "{}", serde_json::to_string(&v).expect("a line as JSON")).expect("write");
        }
    }
}
