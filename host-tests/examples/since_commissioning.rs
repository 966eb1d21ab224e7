//! **Experiment** (not a product path): the diagnosis about a commissioned
//! machine. Each emulator case's machine is first calibrated on an
//! effect-free run of its own (an identification run, the case's own
//! scenario drawn again, or its very mission repeated on another day; the
//! physical tier with the default structure, on the whole run); the
//! case's log, its effect-free twin, or the effect-free case itself is then
//! diagnosed in the physical tier alone about that calibration, every freed
//! parameter held by a log-normal prior of σ `SIGMA` (ln) around its
//! commissioned value and `eta_m` the commissioning's. One JSON line per
//! diagnosed log, as `ranking_dump` writes them, plus the commissioning fit.
//!
//! `cargo run --profile fast -p eha-sim --example since_commissioning -- [--same-scenario | --repeat] SIGMA OUT.jsonl SEED…`
//! (`--same-scenario`: the commissioning run flies the case's own scenario,
//! another draw, instead of an identification run; `--repeat`: the case's
//! own mission, repeated on another day, `emulator::generate_repeat`).

use eha_sim::diagnosis::analysis::{diagnose_physical, fit_points};
use eha_sim::diagnosis::emu_sweep::{case_of_seed, effect_free_log};
use eha_sim::diagnosis::fit::{fit, FitOptions};
use eha_sim::diagnosis::reference::ReferenceModel;
use eha_sim::diagnosis::{Candidate, DiagnoseOptions, Diagnosis, Simulator};
use eha_sim::measured::MeasuredRun;
use eha_sim::emulator::missions::EmuScenario;
use eha_sim::emulator::{generate, generate_on_machine, generate_repeat, EmuCase};
use eha_sim::rig::Rig;
use std::io::Write as _;

/// Seed offset of a case's commissioning run (outside every case set).
const COMMISSIONING_SEED: u64 = 50_000;

/// The machine as calibrated on its healthy log.
struct Healthy {
    /// The rig with the calibrated parameters (and `eta_m`) applied.
    rig: Rig,
    /// Indices of the freed calibration parameters.
    free: Vec<usize>,
    /// Their names and calibrated multipliers.
    params: Vec<(String, f64)>,
    /// The pump's `eta_m` from the healthy log's current, when it had
    /// loaded current.
    eta_m: Option<f64>,
    /// RMS misfit of the calibration over every temperature point, K.
    rms_k: f64,
}

/// Calibrates the physical tier on the whole healthy log `run` from `rig`
/// (300 model runs).
fn calibrate(rig: Rig, run: &MeasuredRun, o: &DiagnoseOptions) -> Result<Healthy, String> {
    let model = ReferenceModel::new(rig, run).map_err(|e| e.to_string())?.with_structure(run, o.structure);
    let phys = model.physical_set().ok_or("the rig has no physical calibration tier")?;
    let specs = phys.nuisance();
    let pts = fit_points(run, f64::INFINITY, o.points_per_channel);
    let start: Vec<f64> = specs.iter().map(|s| s.start).collect();
    let f = fit(&*phys, run, &pts, Candidate::None, &start, None, FitOptions { max_sims: 300, ..o.fit })
        .ok_or("the healthy log's calibration found no valid residuals")?;
    Ok(Healthy {
        rig: model.physical_rig(&f.nuisance),
        free: model.physical_free().to_vec(),
        params: specs.iter().map(|s| s.name.clone()).zip(f.nuisance.iter().copied()).collect(),
        eta_m: model.eta_m_from_current().map(|e| e.0),
        rms_k: (f.rss / f.n.max(1) as f64).sqrt(),
    })
}

/// Diagnoses `run` in the physical tier alone (rules unchanged) about the
/// healthy calibration `h`: every calibration parameter held by a
/// log-normal prior of σ `sigma_ln` around it.
fn diagnose_since(h: &Healthy, run: &MeasuredRun, o: &DiagnoseOptions, sigma_ln: f64) -> Result<Diagnosis, String> {
    let mut model = ReferenceModel::new(h.rig.clone(), run).map_err(|e| e.to_string())?.with_nuisance_set(h.free.clone());
    for (n, _) in &h.params {
        model = model.with_prior_sigma(n, sigma_ln);
    }
    diagnose_physical(run, &model, o).map_err(|e| e.to_string())
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
    let design = match args.first().map(String::as_str) {
        Some("--same-scenario") => "same",
        Some("--repeat") => "repeat",
        _ => "ident",
    };
    let [sigma, out, seeds @ ..] = &args[usize::from(design != "ident")..] else {
        eprintln!("usage: since_commissioning [--same-scenario | --repeat] SIGMA OUT.jsonl SEED…");
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
        let comm_run = match design {
            "repeat" => generate_repeat(&c, seed + COMMISSIONING_SEED).expect("repeated log").0,
            _ => {
                let scenario = if design == "same" { c.scenario } else { EmuScenario::IdentRun };
                let cc = EmuCase { hidden: Candidate::None, scenario, seed: seed + COMMISSIONING_SEED, duration_s: c.duration_s };
                generate_on_machine(&cc, &truth).expect("commissioning log").0
            }
        };
        let m = calibrate(Rig::default(), &comm_run, &o).expect("commissioning");
        eprintln!("{seed} commissioned: rms {:.3} K, eta_m {:?} ({:.0} s)", m.rms_k, m.eta_m, t.elapsed().as_secs_f64());
        let logs = if c.hidden == Candidate::None {
            vec![("effect-free", run)]
        } else {
            vec![("case", run), ("twin", effect_free_log(&c).expect("twin"))]
        };
        for (kind, run) in logs {
            let t = std::time::Instant::now();
            let d = diagnose_since(&m, &run, &o, sigma).expect("diagnosis");
            let v = Line {
                seed,
                kind,
                hidden: c.hidden.name(),
                magnitude: truth.magnitude,
                sigma_ln: sigma,
                answer: d.answer(),
                tier: d.nuisance_set.clone(),
                commissioned: m.params.clone(),
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
