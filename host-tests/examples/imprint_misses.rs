//! Why the diagnosis misses emulator cases whose imprint ratio r ≥ 2 (where
//! it must name the cause): for one case, the physical-tier baseline and the hidden
//! effect's own candidate fitted as the diagnosis fits it, from the true
//! magnitude, with a larger budget, and with variants of the nuisance set;
//! training and held-out RMSE on the affected channel and pooled.
//!
//! `cargo run --profile fast -p eha-sim --example imprint_misses -- SEED [twin] [structure|no-case|no-case-held] [sigma=NAME:S|cal…] [VARIANT…]`
//! (seeds 1700–1717, 2700–2717 and their repetitions 18xx, 19xx, 28xx,
//! 29xx; ~3–60 s a case on two cores).

use eha_sim::diagnosis::analysis::{fit_points, split_time_s};
use eha_sim::diagnosis::emu_sweep::case_of_seed;
use eha_sim::diagnosis::fit::{fit, FitOptions, FitResult};
use eha_sim::diagnosis::model::{SimSeries, Simulator};
use eha_sim::diagnosis::reference::{nuisance_set, ReferenceModel};
use eha_sim::diagnosis::stats::rmse;
use eha_sim::diagnosis::Candidate;
use eha_sim::emulator::{generate, generate_twin};
use eha_sim::measured::{Channel, MeasuredRun};
use eha_sim::rig::Rig;

/// Training and held-out RMSE of `channels`, K.
fn rm(run: &MeasuredRun, s: &SimSeries, channels: &[Channel], split: f64) -> (f64, f64) {
    let mut tr = Vec::new();
    let mut ho = Vec::new();
    for &ch in channels {
        let (Some(m), Some(y)) = (run.get(ch), s.channels.get(&ch)) else { continue };
        for i in 0..run.len() {
            if let Some(m) = m[i] {
                if run.time_s[i] < split { tr.push(Some(y[i] - m)) } else { ho.push(Some(y[i] - m)) }
            }
        }
    }
    (rmse(&tr).unwrap_or(f64::NAN), rmse(&ho).unwrap_or(f64::NAN))
}

fn line(tag: &str, run: &MeasuredRun, f: &FitResult, ch: Channel, split: f64, names: &[String]) {
    let (at, ah) = rm(run, &f.series, &[ch], split);
    let (pt, ph) = rm(run, &f.series, &Channel::TEMPERATURES, split);
    let per: Vec<String> = Channel::TEMPERATURES
        .iter()
        .map(|&c| {
            let (t, h) = rm(run, &f.series, &[c], split);
            format!("{} {:.2}/{:.2}", &c.name()[2..c.name().len() - 2], t, h)
        })
        .collect();
    let bounds: Vec<String> = names
        .iter()
        .zip(&f.nuisance)
        .filter(|(_, v)| (**v).ln().abs() > 0.3)
        .map(|(n, v)| format!("{n}={v:.2}"))
        .collect();
    println!(
        "{tag:<22} ext {:?} rss {:.1} sims {} | {} train/held {:.2}/{:.2} | pooled {:.2}/{:.2} | {} | moved: {}",
        f.ext.iter().map(|x| format!("{x:.3e}")).collect::<Vec<_>>(),
        f.rss,
        f.sims,
        ch.name(),
        at,
        ah,
        pt,
        ph,
        per.join(", "),
        bounds.join(" ")
    );
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let seed: u64 = args[0].parse().expect("seed");
    let twin = args.iter().any(|a| a == "twin");
    let has = |v: &str| args.iter().any(|a| a == v);
    let case = case_of_seed(1200.0, seed).expect("seed in the case sets");
    let (run, truth) = generate(&case).expect("case");
    let ch = truth.affected.map(|a| a.0).unwrap_or(Channel::TOilC);
    let run = if twin { generate_twin(&case).expect("twin").0 } else { run };
    let hid = case.hidden;
    println!("case {seed} {:?} {} magnitude {:.3e} affected {:?} twin {twin}", case.scenario, hid.name(), truth.magnitude, truth.affected);
    let mut free = nuisance_set(&run);
    // Variants of the physical set: drop a parameter by name (`-NAME`).
    for a in &args {
        if let Some(n) = a.strip_prefix('-') {
            if let Some(k) = eha_sim::calibration::set::index(n) {
                free.retain(|&j| j != k);
            }
        }
    }
    // Variant of the candidate's pocket: its conductance to the block metal (`g=W/K`).
    let mut rig = Rig::default();
    for a in &args {
        if let Some(g) = a.strip_prefix("g=") {
            rig.blocks.sensor_to_block_w_per_k = g.parse().expect("g=W/K");
        }
    }
    // `structure`: the physical tier with the commissioning's structure
    // (`ReferenceModel::with_structure`; its own set, the `-PARAM` variants
    // then do not apply).
    // `no-case`, `no-case-held`: the structure option's variants of those
    // names instead of `full`.
    // `sigma=NAME:S` replaces the physical tier's prior on NAME by σ S on
    // ln θ (`sigma=NAME:cal` back to the calibration set's), after the
    // structure option's own diagnosis-only priors.
    use eha_sim::diagnosis::analysis::Structure;
    let variant = if has("no-case-held") {
        Structure::NoCaseHeld
    } else if has("no-case") {
        Structure::NoCase
    } else if has("structure") {
        Structure::Full
    } else {
        Structure::Off
    };
    let mut model = ReferenceModel::new(rig, &run).expect("model").with_nuisance_set(free).with_structure(&run, variant);
    for a in &args {
        if let Some((n, v)) = a.strip_prefix("sigma=").and_then(|x| x.split_once(':')) {
            model = model.with_prior_sigma(n, if v == "cal" { None } else { Some(v.parse::<f64>().expect("sigma=NAME:S")) });
        }
    }
    let sim = model.physical_set().expect("physical set");
    let names: Vec<String> = sim.nuisance().iter().map(|p| p.name.clone()).collect();
    println!("set: {}", names.join(" "));
    let split = split_time_s(&run, 0.7);
    let pts = fit_points(&run, split, 150);
    let opts = FitOptions::default();
    let nom: Vec<f64> = sim.nuisance().iter().map(|p| p.start).collect();
    let t = std::time::Instant::now();
    let base = fit(&*sim, &run, &pts, Candidate::None, &nom, None, opts).expect("baseline");
    line("baseline", &run, &base, ch, split, &names);
    let c = if hid == Candidate::None { Candidate::SensorLag } else { hid };
    let ex = sim.extension_params(c);
    let off: Vec<f64> = ex.iter().map(|s| s.lo * (s.hi / s.lo).powf(0.1)).collect();
    let (a, b) = rayon::join(
        || fit(&*sim, &run, &pts, c, &nom, None, opts),
        || fit(&*sim, &run, &pts, c, &base.nuisance, Some(&off), opts),
    );
    let (a, b) = (a.expect("fit"), b.expect("fit"));
    line("cand from nominal", &run, &a, ch, split, &names);
    line("cand from base", &run, &b, ch, split, &names);
    let best = if a.rss <= b.rss { a } else { b };
    let tm: Vec<f64> = ex.iter().enumerate().map(|(k, s)| if k == 0 { truth.magnitude } else { s.start }).collect();
    let (tru, long) = rayon::join(
        || (hid != Candidate::None).then(|| fit(&*sim, &run, &pts, c, &base.nuisance, Some(&tm), opts)).flatten(),
        || has("long").then(|| fit(&*sim, &run, &pts, c, &best.nuisance, Some(&best.ext), FitOptions { max_sims: 400, ..opts })).flatten(),
    );
    // the calibrated baseline with the candidate at the middle of its
    // physical range (`magnitude_range`, geometric mean)
    let (lo, hi) = eha_sim::physics::candidates::magnitude_range(c);
    let mid: Vec<f64> = ex.iter().enumerate().map(|(k, s)| if k == 0 { (lo * hi).sqrt() } else { s.start }).collect();
    if let Some(f) = fit(&*sim, &run, &pts, c, &base.nuisance, Some(&mid), opts) {
        line("cand base+mid", &run, &f, ch, split, &names);
    }
    if let Some(f) = tru {
        line("cand from truth", &run, &f, ch, split, &names);
    }
    if let Some(f) = long {
        line("cand best, 400 runs", &run, &f, ch, split, &names);
    }
    if has("fixed") && hid != Candidate::None {
        // the baseline refitted with the candidate held at the truth: a
        // wrapper whose candidate has no free parameter
        struct Fixed<'a>(&'a dyn Simulator, Candidate, f64);
        impl Simulator for Fixed<'_> {
            fn nuisance(&self) -> Vec<eha_sim::diagnosis::ParamSpec> {
                self.0.nuisance()
            }
            fn extension_params(&self, _: Candidate) -> Vec<eha_sim::diagnosis::ParamSpec> {
                vec![]
            }
            fn simulate(&self, n: &[f64], _: Candidate, _: &[f64]) -> Result<SimSeries, String> {
                self.0.simulate(n, self.1, &[self.2])
            }
        }
        let fx = Fixed(&*sim, c, truth.magnitude);
        if let Some(f) = fit(&fx, &run, &pts, Candidate::None, &base.nuisance, None, opts) {
            line("held at truth", &run, &f, ch, split, &names);
        }
    }
    println!("{:.1} s", t.elapsed().as_secs_f64());
}
