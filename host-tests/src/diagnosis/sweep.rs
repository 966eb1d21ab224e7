//! Hidden-effect cases end to end: generate a synthetic run
//! ([`super::synth`]), diagnose it blind with the baseline rig, and score
//! the verdict. Used by the tests and by `eha-sim diagnose-sweep` (the large
//! sweep, too slow for the default test run).

use super::analysis::{diagnose, DiagnoseOptions};
use super::model::Candidate;
use super::reference::ReferenceModel;
use super::synth::{generate, Mismatch, SynthCase, SynthScenario};
use crate::rig::Rig;
use rayon::prelude::*;
use std::process::ExitCode;

/// Score of one hidden-effect case.
#[derive(Debug, Clone)]
pub struct CaseResult {
    /// The case.
    pub case: SynthCase,
    /// The cause the diagnosis named.
    pub named: Candidate,
    /// The answer: the named cause, `none` or `unexplained`.
    pub answer: &'static str,
    /// Hidden magnitude.
    pub magnitude: f64,
    /// Channel the hidden effect changes most (truth side), its imprint, K.
    pub affected: Option<(String, f64)>,
    /// Held-out RMSE on the affected channel before → after, K.
    pub affected_heldout_k: Option<(f64, f64)>,
    /// Pooled held-out RMSE before → after, K.
    pub pooled_heldout_k: (f64, f64),
    /// Fitted extension parameters.
    pub params: Vec<(String, f64, String)>,
    /// Wall time of the diagnosis, s.
    pub seconds: f64,
    /// Model runs.
    pub sims: usize,
    /// The diagnosis ranking (every candidate's evidence), best BIC first.
    pub ranking: Vec<super::analysis::RankEntry>,
    /// The calibrated baseline against the noise floor, per channel.
    pub adequacy: Vec<super::adequacy::ChannelFit>,
}

impl CaseResult {
    /// Relative held-out RMSE reduction on the affected channel.
    pub fn affected_gain(&self) -> Option<f64> {
        self.affected_heldout_k.map(|(b, a)| 1.0 - a / b)
    }

    /// The ranking, one line per candidate: ΔBIC, best-channel held-out
    /// gain, pooled held-out gain, the held-out RMSE of every channel (K)
    /// and whether it qualified.
    pub fn detail(&self) -> String {
        let none = self.ranking.iter().find(|r| r.cause == "none");
        let pooled0 = none.map_or(f64::NAN, |r| r.heldout_rmse_k);
        let mut s = String::new();
        for r in &self.ranking {
            let ch: Vec<String> = r
                .channel_heldout_k
                .iter()
                .map(|(c, v)| format!("{}={v:.3}", c.trim_start_matches("t_").trim_end_matches("_c")))
                .collect();
            let p: Vec<String> = r.params.iter().map(|(n, v, _)| format!("{n}={v:.4}")).collect();
            s += &format!(
                "    {:<31} dBIC {:>8.1} best {:>4.0} % {:<13} pooled {:>4.0} % ({:.3} K) [{}] {}{} {}\n",
                r.cause,
                r.delta_bic,
                100.0 * r.heldout_gain,
                r.gain_channel,
                100.0 * (1.0 - r.heldout_rmse_k / pooled0),
                r.heldout_rmse_k,
                ch.join(" "),
                if r.qualifies { "QUALIFIES" } else { "-" },
                if r.note.is_empty() { String::new() } else { format!(" ({})", r.note) },
                p.join(" ")
            );
        }
        let a: Vec<String> = self
            .adequacy
            .iter()
            .map(|c| {
                format!(
                    "{}={:.3} K ({:.1}σ, {:.0} % of rise {:.1} K){}",
                    c.channel.trim_start_matches("t_").trim_end_matches("_c"),
                    c.heldout_rmse_k,
                    c.heldout_rmse_k / c.noise_k,
                    100.0 * c.heldout_rmse_k / c.rise_k.max(1e-9),
                    c.rise_k,
                    if c.misfit { " MISFIT" } else { "" }
                )
            })
            .collect();
        s += &format!("    calibrated baseline: {}\n", a.join(", "));
        s
    }

    /// One-line summary.
    pub fn line(&self) -> String {
        format!(
            "hidden {:<31} {:?}/{:?} seed {:>3}: answer {:<31} affected {:<14} gain {:>6} held-out {:.3}->{:.3} K  {:.0} s, {} runs",
            self.case.hidden.name(),
            self.case.scenario,
            self.case.mismatch,
            self.case.seed,
            self.answer,
            self.affected.as_ref().map_or("-".into(), |a| format!("{} ({:.2} K)", a.0, a.1)),
            self.affected_gain().map_or("-".into(), |g| format!("{:.0} %", 100.0 * g)),
            self.pooled_heldout_k.0,
            self.pooled_heldout_k.1,
            self.seconds,
            self.sims
        )
    }
}

/// Generates and diagnoses one case with the default rig as baseline.
pub fn run_case(case: SynthCase, o: &DiagnoseOptions) -> Result<CaseResult, String> {
    let (run, truth) = generate(&case)?;
    let t = std::time::Instant::now();
    let model = ReferenceModel::new(Rig::default(), &run).map_err(|e| e.to_string())?;
    let d = diagnose(&run, &model, o).map_err(|e| e.to_string())?;
    let affected = truth.affected.map(|(c, v)| (c.name().to_string(), v));
    let affected_heldout_k = affected.as_ref().and_then(|(c, _)| {
        Some((d.before.channel(c)?.heldout_rmse_k, d.after.channel(c)?.heldout_rmse_k))
    });
    Ok(CaseResult {
        case,
        named: d.cause,
        answer: d.answer(),
        magnitude: truth.magnitude,
        affected,
        affected_heldout_k,
        pooled_heldout_k: (d.before.heldout_rmse_k, d.after.heldout_rmse_k),
        params: d.params,
        seconds: t.elapsed().as_secs_f64(),
        sims: d.sims,
        ranking: d.ranking,
        adequacy: d.adequacy.channels,
    })
}

/// Arguments of `diagnose-sweep`.
#[derive(Debug, Clone, clap::Args)]
pub struct SweepArgs {
    /// Seeds per (effect, scenario, mismatch) combination.
    #[arg(long, default_value_t = 2)]
    pub seeds: u64,
    /// Run duration, s.
    #[arg(long, default_value_t = 1800.0)]
    pub duration: f64,
    /// Logger sample interval, s.
    #[arg(long, default_value_t = 2.0)]
    pub sample: f64,
    /// Leave out the servo scenarios (10–20× slower to replay) and with
    /// them `coulomb-friction`.
    #[arg(long)]
    pub no_servo: bool,
}

/// Every (effect incl. none, scenario, mismatch, seed) combination.
pub fn sweep_cases(a: &SweepArgs) -> Vec<SynthCase> {
    let mut v = Vec::new();
    for hidden in Candidate::EXTENSIONS.into_iter().chain([Candidate::None]) {
        for scenario in SynthScenario::ALL.into_iter().filter(|s| s.can_show(hidden) && !(a.no_servo && s.is_servo())) {
            for mismatch in [Mismatch::Nuisance, Mismatch::Structure] {
                for seed in 0..a.seeds {
                    v.push(SynthCase { hidden, scenario, mismatch, seed: 1000 + seed, duration_s: a.duration, sample_s: a.sample });
                }
            }
        }
    }
    v
}

/// Runs the sweep, prints one line per case and the totals; exit 0 always
/// (it is a measurement, not a test).
pub fn run(a: &SweepArgs) -> ExitCode {
    let cases = sweep_cases(a);
    let bar = indicatif::ProgressBar::new(cases.len() as u64);
    let res: Vec<Result<CaseResult, String>> = cases
        .par_iter()
        .map(|c| {
            let r = run_case(*c, &DiagnoseOptions::default());
            bar.inc(1);
            r
        })
        .collect();
    bar.finish_and_clear();
    let (mut ok, mut n) = (0, 0);
    for r in &res {
        match r {
            Ok(r) => {
                n += 1;
                let hit = r.answer == r.case.hidden.name();
                ok += hit as usize;
                println!("{} {}", if hit { "OK  " } else { "MISS" }, r.line());
            }
            Err(e) => println!("ERR  {e}"),
        }
    }
    println!("identified {ok} of {n} cases");
    for hidden in Candidate::EXTENSIONS.into_iter().chain([Candidate::None]) {
        let mine: Vec<&CaseResult> = res.iter().flatten().filter(|r| r.case.hidden == hidden).collect();
        if mine.is_empty() {
            continue;
        }
        let hits = mine.iter().filter(|r| r.answer == hidden.name()).count();
        let gain_ok = mine
            .iter()
            
            .filter(|r| r.answer == hidden.name() && (hidden == Candidate::None || r.affected_gain().is_some_and(|g| g >= 0.5)))
            .count();
        println!("  {:<31} named {hits}/{}  (named with >= 50 % held-out gain: {gain_ok})", hidden.name(), mine.len());
    }
    ExitCode::SUCCESS
}
