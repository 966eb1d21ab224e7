//! Where the physical tier's calibrated baseline comes from on one
//! emulator log: the baseline from the rig file, every candidate's three
//! starts (as `diagnose` fits them), and the two restarts of the baseline
//! from the two candidate fits of least training residual (with
//! `nominal-restarts` also from every candidate's nominal-start fit, as
//! `diagnose --nominal-restarts` adds); for each fit the training residual
//! (K²) and the prior rows' share of the fit's objective (K²), the
//! held-out RMSE pooled and per channel (K), and the calibration
//! parameters that moved by more than ×/÷1.35. The diagnosis keeps the
//! baseline of least training residual. Fits as the diagnosis makes them,
//! not its whole procedure (no refits after a restart). With `any-start`
//! also every candidate start judged by the admission's held-out checks
//! against the best baseline found (a measurement, not the product's rule).
//!
//! `cargo run --profile fast -p eha-sim --example basin_trace -- SEED [twin] [STRUCTURE] [nominal-restarts] [any-start]`
//! (STRUCTURE `off`/`full`/`no-case`/`no-case-held`, default the latter;
//! 36–60 s a log on two shared cores, 2026-11-28).

use clap::ValueEnum as _;
use eha_sim::diagnosis::analysis::{fit_from, fit_points, fit_typical, gain_where_it_acts, split_time_s, DiagnoseOptions, Structure};
use eha_sim::diagnosis::stats::bic;
use eha_sim::diagnosis::emu_sweep::case_of_seed;
use eha_sim::diagnosis::fit::{fit_deferred, FitResult};
use eha_sim::diagnosis::model::{SimSeries, Simulator};
use eha_sim::diagnosis::reference::ReferenceModel;
use eha_sim::diagnosis::stats::rmse;
use eha_sim::diagnosis::Candidate;
use eha_sim::emulator::{generate, generate_twin};
use eha_sim::measured::{Channel, MeasuredRun};
use eha_sim::rig::Rig;
use rayon::prelude::*;

/// Held-out RMSE of `channels`, K.
fn held(run: &MeasuredRun, s: &SimSeries, channels: &[Channel], split: f64) -> f64 {
    let mut ho = Vec::new();
    for &ch in channels {
        let (Some(m), Some(y)) = (run.get(ch), s.channels.get(&ch)) else { continue };
        for i in 0..run.len() {
            if let Some(m) = m[i] {
                if run.time_s[i] >= split {
                    ho.push(Some(y[i] - m));
                }
            }
        }
    }
    rmse(&ho).unwrap_or(f64::NAN)
}

/// The prior rows' share of the fit's objective, K² (what LM minimises
/// besides the data residual `rss`; `fit::PRIOR_DATA_SIGMA_K`).
fn prior_cost(sim: &dyn Simulator, f: &FitResult) -> f64 {
    let mut specs = sim.nuisance();
    specs.extend(sim.extension_params(f.candidate));
    specs
        .iter()
        .zip(f.nuisance.iter().chain(&f.ext))
        .filter_map(|(s, v)| s.prior_sigma_ln.map(|sig| (eha_sim::diagnosis::fit::PRIOR_DATA_SIGMA_K * (v / s.start).ln() / sig).powi(2)))
        .sum()
}

fn line(sim: &dyn Simulator, tag: &str, run: &MeasuredRun, f: &FitResult, split: f64, names: &[String], starts: &[f64]) {
    let per: Vec<String> = Channel::TEMPERATURES
        .iter()
        .filter(|c| run.get(**c).is_some())
        .map(|&c| format!("{} {:.2}", &c.name()[2..c.name().len() - 2], held(run, &f.series, &[c], split)))
        .collect();
    let moved: Vec<String> = names
        .iter()
        .zip(f.nuisance.iter().zip(starts))
        .filter(|(_, (v, s))| (**v / **s).ln().abs() > 0.3)
        .map(|(n, (v, s))| format!("{n}×{:.2}", v / s))
        .collect();
    println!(
        "{tag:<34} rss {:>8.1} + prior {:.2} | held pooled {:.3} | {} | ext {:?} | moved: {}",
        f.rss,
        prior_cost(sim, f),
        held(run, &f.series, &Channel::TEMPERATURES, split),
        per.join(" "),
        f.ext.iter().map(|x| format!("{x:.3e}")).collect::<Vec<_>>(),
        moved.join(" ")
    );
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let seed: u64 = args[0].parse().expect("seed");
    let twin = args.iter().any(|a| a == "twin");
    let structure = args[1..]
        .iter()
        .find_map(|a| Structure::from_str(a, true).ok())
        .unwrap_or(Structure::NoCaseHeld);
    let case = case_of_seed(1200.0, seed).expect("seed in the case sets");
    let run = if twin { generate_twin(&case).expect("twin").0 } else { generate(&case).expect("case").0 };
    println!("{seed} {:?} hidden {} twin {twin} structure {structure:?}", case.scenario, case.hidden.name());
    let model = ReferenceModel::new(Rig::default(), &run).expect("model").with_structure(&run, structure);
    let sim = model.physical_set().expect("physical set");
    let specs = sim.nuisance();
    let names: Vec<String> = specs.iter().map(|p| p.name.clone()).collect();
    let nominal: Vec<f64> = specs.iter().map(|p| p.start).collect();
    let o = DiagnoseOptions::default();
    let split = split_time_s(&run, o.train_fraction);
    let pts = fit_points(&run, split, o.points_per_channel);
    let t = std::time::Instant::now();
    let base = fit_deferred(&*sim, &run, &pts, Candidate::None, &nominal, None, o.fit).expect("baseline");
    line(&*sim, "baseline from the rig file", &run, &base, split, &names, &nominal);
    let starts: Vec<(Candidate, usize)> = Candidate::EXTENSIONS.iter().flat_map(|&c| [(c, 0), (c, 1), (c, 2)]).collect();
    let fits: Vec<Option<FitResult>> = starts
        .par_iter()
        .map(|&(c, s)| match s {
            0 => fit_deferred(&*sim, &run, &pts, c, &nominal, None, o.fit),
            1 => fit_from(&*sim, &run, &pts, c, &base, &o),
            _ => fit_typical(&*sim, &run, &pts, c, &base, &o),
        })
        .collect();
    for ((c, s), f) in starts.iter().zip(&fits) {
        if let Some(f) = f {
            line(&*sim, &format!("{} {}", c.name(), ["nominal", "base-off", "base-typ"][*s]), &run, f, split, &names, &nominal);
        }
    }
    let mut best: Vec<&FitResult> =
        fits.chunks(3).filter_map(|g| g.iter().flatten().min_by(|a, b| a.rss.total_cmp(&b.rss))).collect();
    best.sort_by(|a, b| a.rss.total_cmp(&b.rss));
    for (k, f) in best.iter().take(2).enumerate() {
        if let Some(r) = fit_deferred(&*sim, &run, &pts, Candidate::None, &f.nuisance, None, o.fit) {
            line(&*sim, &format!("restart {k} from {}", f.candidate.name()), &run, &r, split, &names, &nominal);
        }
    }
    // `nominal-restarts`: the baseline restarted from every candidate's
    // nominal-start fit too (the other basins the candidate fits found).
    // `any-start`: then every candidate start judged by the admission's
    // held-out checks against the best baseline found (least training
    // residual), as if a candidate were admitted when any of its starts
    // passes (identifiability not applied; no refits): a measurement of
    // that rule's exposure, not the product's rule.
    if args.iter().any(|a| a == "nominal-restarts" || a == "any-start") {
        let from: Vec<&FitResult> = fits.chunks(3).filter_map(|g| g[0].as_ref()).collect();
        let rs: Vec<Option<FitResult>> =
            from.par_iter().map(|f| fit_deferred(&*sim, &run, &pts, Candidate::None, &f.nuisance, None, o.fit)).collect();
        let mut bases = vec![base.clone()];
        for (f, r) in from.iter().zip(rs) {
            if let Some(r) = r {
                line(&*sim, &format!("restart from {} nominal", f.candidate.name()), &run, &r, split, &names, &nominal);
                bases.push(r);
            }
        }
        for f in best.iter().take(2) {
            if let Some(r) = fit_deferred(&*sim, &run, &pts, Candidate::None, &f.nuisance, None, o.fit) {
                bases.push(r);
            }
        }
        if args.iter().any(|a| a == "any-start") {
            let b = bases.iter().min_by(|a, b| a.rss.total_cmp(&b.rss)).expect("a baseline");
            let chans: Vec<Channel> = Channel::TEMPERATURES.into_iter().filter(|c| run.get(*c).is_some()).collect();
            let per = |f: &FitResult| -> Vec<(String, f64)> { chans.iter().map(|&c| (c.name().to_string(), held(&run, &f.series, &[c], split))).collect() };
            let pooled = |f: &FitResult| held(&run, &f.series, &chans, split);
            let n = pts.len();
            let bic_none = bic(b.rss, n, specs.len());
            println!("best baseline rss {:.1}, held pooled {:.3}", b.rss, pooled(b));
            for ((c, s), f) in starts.iter().zip(&fits) {
                let Some(f) = f else { continue };
                let dbic = bic_none - bic(f.rss, n, specs.len() + f.ext.len());
                let (g, gk, ch) = gain_where_it_acts(*c, &per(b), &per(f), o.gain_floor_k);
                let pg = 1.0 - pooled(f) / pooled(b);
                let pass = dbic >= o.min_delta_bic && g >= o.min_heldout_gain && gk >= o.min_gain_k && pg >= o.min_pooled_gain;
                println!(
                    "  {} {}: dBIC {dbic:.1}, touched gain {:.0} % ({gk:.2} K, {ch}), pooled gain {:.0} % -> passes {pass}",
                    c.name(),
                    ["nominal", "base-off", "base-typ"][*s],
                    100.0 * g,
                    100.0 * pg
                );
            }
        }
    }
    println!("{:.0} s", t.elapsed().as_secs_f64());
}
