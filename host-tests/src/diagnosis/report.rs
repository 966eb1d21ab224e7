//! Writing a diagnosis: `diagnosis.json` (the machine-readable verdict with
//! its documented keys) and `report.md` (the evidence, with PNGs).

use super::analysis::{Diagnosis, Metrics, RankEntry};
use std::fmt::Write as _;
use std::path::Path;

/// One ranking row of `diagnosis.json`.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize, PartialEq)]
pub struct RankingJson {
    /// Candidate name.
    pub cause: String,
    /// BIC on the training fit points (lower is better).
    pub bic: f64,
    /// Pooled held-out RMSE over the temperature channels, K.
    pub heldout_rmse_k: f64,
}

/// One structure's probability in `diagnosis.json`.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize, PartialEq)]
pub struct ProbabilityJson {
    /// `none`, `unexplained` or a candidate name.
    pub cause: String,
    /// Posterior probability.
    pub probability: f64,
    /// ln Bayes factor against `none`.
    pub log_bayes_factor: f64,
    /// Prior probability (0: the log cannot identify the candidate).
    pub prior: f64,
    /// Held-out predictive log density on the channels the structure
    /// touches against `none`'s, nats (part of the Bayes factor); `None`
    /// in records written before it was kept.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub heldout_touched: Option<f64>,
    /// The same on the channels it does not touch.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub heldout_untouched: Option<f64>,
    /// Whether the log can tell the structure apart (its identifiability
    /// rule); `None` in records written before it was kept.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub identifiable: Option<bool>,
}

impl From<&super::evidence::CauseProbability> for ProbabilityJson {
    fn from(c: &super::evidence::CauseProbability) -> Self {
        ProbabilityJson {
            cause: c.cause.clone(),
            probability: c.probability,
            log_bayes_factor: c.log_bayes_factor,
            prior: c.prior,
            heldout_touched: Some(c.heldout_touched),
            heldout_untouched: Some(c.heldout_untouched),
            identifiable: Some(c.identifiable),
        }
    }
}

/// `diagnosis.json`: exactly its documented top-level keys. RMSEs are pooled
/// over every measured temperature channel, K; "before" is the calibrated
/// baseline, "after" the model with `cause` switched on (equal to "before"
/// when `cause` is `none`).
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize, PartialEq)]
pub struct DiagnosisJson {
    /// Named cause: a candidate name, `none` (the calibrated model explains
    /// the data to the noise level) or `unexplained` (it does not, and no
    /// candidate does).
    pub cause: String,
    /// Fitted parameters of the cause, name → value (units in report.md).
    pub parameters: std::collections::BTreeMap<String, f64>,
    /// Training-window RMSE before, K.
    pub rmse_before_k: f64,
    /// Training-window RMSE after, K.
    pub rmse_after_k: f64,
    /// Held-out RMSE before, K.
    pub heldout_rmse_before_k: f64,
    /// Held-out RMSE after, K.
    pub heldout_rmse_after_k: f64,
    /// Every candidate and `none`, best BIC first.
    pub ranking: Vec<RankingJson>,
    /// Posterior probability of `none`, `unexplained` and every candidate,
    /// most probable first (a cause is named at ≥ 0.9; otherwise the first
    /// two are the answer's top two).
    pub probabilities: Vec<ProbabilityJson>,
    /// Per channel: the calibrated baseline's misfit on the training
    /// window, the structure floor estimated from the other channels, their
    /// ratio, the noise (K) and the Ljung–Box p before and after whitening.
    pub channels: Vec<super::evidence::ChannelEvidence>,
    /// Present only when `cause` is `unexplained`: what misfits and what
    /// to check.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub unexplained: Option<UnexplainedJson>,
    /// Present only when several logs of one machine were diagnosed
    /// together: each log's errors before and after, on its own training
    /// and held-out windows (the top-level RMSEs pool every log).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub logs: Vec<LogJson>,
}

/// One log of a joint diagnosis in `diagnosis.json`.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize, PartialEq)]
pub struct LogJson {
    /// The log's file as given.
    pub file: String,
    /// Rows in the log.
    pub rows: usize,
    /// Start of its held-out window, s (the log's own time).
    pub heldout_from_s: f64,
    /// Training-window RMSE before / after, pooled over its temperature channels, K.
    pub rmse_before_k: f64,
    /// Training-window RMSE after, K.
    pub rmse_after_k: f64,
    /// Held-out RMSE before, K.
    pub heldout_rmse_before_k: f64,
    /// Held-out RMSE after, K.
    pub heldout_rmse_after_k: f64,
    /// Per channel: held-out RMSE before and after, bias before, K.
    pub channels: Vec<LogChannelJson>,
}

/// One channel of one log of a joint diagnosis.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize, PartialEq)]
pub struct LogChannelJson {
    /// Channel name.
    pub channel: String,
    /// Held-out RMSE of the calibrated baseline, K.
    pub heldout_rmse_before_k: f64,
    /// Held-out RMSE with the cause, K.
    pub heldout_rmse_after_k: f64,
    /// Mean residual of the calibrated baseline (simulated − measured), K.
    pub bias_before_k: f64,
}

impl LogJson {
    /// The numbers of one log's part ([`super::multi::log_parts`]) of a joint diagnosis.
    pub fn of(file: &str, rows: usize, d: &Diagnosis) -> Self {
        LogJson {
            file: file.into(),
            rows,
            heldout_from_s: d.split_time_s,
            rmse_before_k: d.before.train_rmse_k,
            rmse_after_k: d.after.train_rmse_k,
            heldout_rmse_before_k: d.before.heldout_rmse_k,
            heldout_rmse_after_k: d.after.heldout_rmse_k,
            channels: d
                .before
                .channels
                .iter()
                .map(|b| LogChannelJson {
                    channel: b.channel.clone(),
                    heldout_rmse_before_k: b.heldout_rmse_k,
                    heldout_rmse_after_k: d.after.channel(&b.channel).map_or(f64::NAN, |a| a.heldout_rmse_k),
                    bias_before_k: b.bias_k,
                })
                .collect(),
        }
    }
}

/// One misfitting channel in `diagnosis.json`.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize, PartialEq)]
pub struct MisfitJson {
    /// Channel name.
    pub channel: String,
    /// Held-out RMSE of the calibrated baseline, K.
    pub heldout_rmse_k: f64,
    /// Mean residual (simulated − measured), K.
    pub bias_k: f64,
    /// Noise σ estimated from the samples, K.
    pub noise_k: f64,
    /// Regressors the residual correlates with most: name → peak ρ.
    pub correlates_with: std::collections::BTreeMap<String, f64>,
}

/// The evidence behind an `unexplained` answer.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize, PartialEq)]
pub struct UnexplainedJson {
    /// Channels whose held-out error is far above their noise.
    pub misfit_channels: Vec<MisfitJson>,
    /// Calibrated parameters on a bound: name → value.
    pub parameters_at_bounds: std::collections::BTreeMap<String, f64>,
    /// What to check or measure.
    pub check: Vec<String>,
}

impl DiagnosisJson {
    /// The JSON verdict of `d`.
    pub fn from_diagnosis(d: &Diagnosis) -> Self {
        DiagnosisJson {
            cause: d.answer().into(),
            parameters: d.params.iter().map(|(n, v, _)| (n.clone(), *v)).collect(),
            rmse_before_k: d.before.train_rmse_k,
            rmse_after_k: d.after.train_rmse_k,
            heldout_rmse_before_k: d.before.heldout_rmse_k,
            heldout_rmse_after_k: d.after.heldout_rmse_k,
            ranking: d
                .ranking
                .iter()
                .map(|r| RankingJson { cause: r.cause.clone(), bic: r.bic, heldout_rmse_k: r.heldout_rmse_k })
                .collect(),
            probabilities: d
                .posterior
                .causes
                .iter()
                .map(ProbabilityJson::from)
                .collect(),
            channels: d.posterior.channels.clone(),
            unexplained: d.unexplained.then(|| UnexplainedJson {
                misfit_channels: d
                    .adequacy
                    .channels
                    .iter()
                    .filter(|c| c.misfit)
                    .map(|c| MisfitJson {
                        channel: c.channel.clone(),
                        heldout_rmse_k: c.heldout_rmse_k,
                        bias_k: c.bias_k,
                        noise_k: c.noise_k,
                        correlates_with: c.regressors.iter().map(|(n, r, _)| (n.clone(), *r)).collect(),
                    })
                    .collect(),
                parameters_at_bounds: d.adequacy.at_bounds.iter().map(|b| (b.name.clone(), b.value)).collect(),
                check: d.adequacy.advice.clone(),
            }),
            logs: Vec::new(),
        }
    }
}

/// The probabilities of the structures and the per-channel floor numbers.
fn probability_section(s: &mut String, d: &Diagnosis) {
    let p = &d.posterior;
    let c = &p.causes;
    if c.is_empty() {
        return;
    }
    if p.named().is_none() && c.len() > 1 {
        let _ = writeln!(
            s,
            "\nNo cause reaches P ≥ {:.1}. Most probable: `{}` (P = {:.2}), then `{}` (P = {:.2}).",
            super::evidence::NAME_PROBABILITY, c[0].cause, c[0].probability, c[1].cause, c[1].probability
        );
    }
    let _ = writeln!(s, "\n## Probabilities (discrepancy of floor size, time constant {:.0} s)\n", p.tau_s);
    let _ = writeln!(s, "| structure | prior | ln Bayes factor vs `none` | probability |\n|---|---:|---:|---:|");
    for x in c {
        let _ = writeln!(s, "| `{}` | {:.3} | {:.1} | {:.3} |", x.cause, x.prior, x.log_bayes_factor, x.probability);
    }
    let _ = writeln!(s, "\n| channel | misfit, training (K) | floor from the other channels (K) | ratio | noise σ (K) | Ljung–Box p raw | whitened |\n|---|---:|---:|---:|---:|---:|---:|");
    for x in &p.channels {
        let _ = writeln!(
            s,
            "| `{}` | {:.3} | {:.3} | {:.1} | {:.3} | {:.1e} | {:.1e} |",
            x.channel, x.misfit_k, x.floor_k, x.imprint_ratio, x.noise_k, x.ljung_box_p_raw, x.ljung_box_p_whitened
        );
    }
}

/// A parameter value with 4 significant digits (scientific when small).
fn num(v: f64) -> String {
    if v != 0.0 && (v.abs() < 0.01 || v.abs() >= 1e5) { format!("{v:.3e}") } else { format!("{v:.4}") }
}

fn metrics_table(s: &mut String, title: &str, m: &Metrics) {
    let _ = writeln!(s, "\n**{title}** (pooled: training {:.3} K, held-out {:.3} K)\n", m.train_rmse_k, m.heldout_rmse_k);
    let _ = writeln!(s, "| channel | RMSE train (K) | RMSE held-out (K) | bias (K) | max error (K) | Ljung–Box Q | p |");
    let _ = writeln!(s, "|---|---:|---:|---:|---:|---:|---:|");
    for c in &m.channels {
        let _ = writeln!(
            s,
            "| `{}` | {:.3} | {:.3} | {:+.3} | {:.3} | {:.0} | {:.2e} |",
            c.channel, c.train_rmse_k, c.heldout_rmse_k, c.bias_k, c.max_error_k, c.ljung_box.q, c.ljung_box.p_value
        );
    }
}

/// The calibrated baseline's fit per channel against its noise floor and
/// rise, and (for `unexplained`) what to check.
fn adequacy_section(s: &mut String, d: &Diagnosis) {
    let a = &d.adequacy;
    if d.unexplained {
        let _ = writeln!(
            s,
            "\nNo candidate qualifies, and the calibrated baseline does not explain the data to the noise level: \
             the model is missing something that is not among the candidates, or the rig file is wrong by more than the calibration can take up."
        );
    }
    let _ = writeln!(s, "\n## Calibrated baseline against the noise floor\n");
    let _ = writeln!(s, "| channel | held-out RMSE (K) | noise σ (K) | ratio | RMS rise (K) | bias (K) | misfit | correlates with (peak ρ) |");
    let _ = writeln!(s, "|---|---:|---:|---:|---:|---:|---|---|");
    for c in &a.channels {
        let r: Vec<String> = c.regressors.iter().map(|(n, rho, lag)| format!("{n} {rho:+.2} @{lag:.0}s")).collect();
        let _ = writeln!(
            s,
            "| `{}` | {:.3} | {:.3} | {:.1} | {:.2} | {:+.3} | {} | {} |",
            c.channel, c.heldout_rmse_k, c.noise_k, c.heldout_rmse_k / c.noise_k, c.rise_k, c.bias_k,
            if c.misfit { "yes" } else { "no" }, r.join(", ")
        );
    }
    for b in &a.at_bounds {
        let _ = writeln!(s, "\n- calibrated `{}` = {:.4} is on its {} bound", b.name, b.value, b.bound);
    }
    if d.unexplained && !a.advice.is_empty() {
        let _ = writeln!(s, "\n**What to check or measure**\n");
        for x in &a.advice {
            let _ = writeln!(s, "- {x}");
        }
    }
}

/// The Markdown report of `d` for the measured file `source`; `pngs` are
/// the plot file names (relative to the report) to embed.
pub fn report_markdown(d: &Diagnosis, source: &str, pngs: &[String]) -> String {
    report_markdown_logs(d, source, pngs, &[])
}

/// Each log's errors of a joint diagnosis.
fn logs_section(s: &mut String, logs: &[LogJson]) {
    let _ = writeln!(s, "\n## Logs (one machine, one calibration)\n");
    let _ = writeln!(s, "| log | rows | held out from (s) | RMSE train before → after (K) | held-out before → after (K) | held-out per channel, before → after (K) |");
    let _ = writeln!(s, "|---|---:|---:|---|---|---|");
    for l in logs {
        let ch: Vec<String> =
            l.channels.iter().map(|c| format!("{} {:.2} → {:.2}", c.channel, c.heldout_rmse_before_k, c.heldout_rmse_after_k)).collect();
        let _ = writeln!(
            s,
            "| `{}` | {} | {:.0} | {:.3} → {:.3} | {:.3} → {:.3} | {} |",
            l.file, l.rows, l.heldout_from_s, l.rmse_before_k, l.rmse_after_k, l.heldout_rmse_before_k, l.heldout_rmse_after_k, ch.join(", ")
        );
    }
}

/// [`report_markdown`] of a joint diagnosis of several logs (`logs`, one
/// entry per log; empty for one log): the windows are each log's own and
/// the per-log errors get their own section.
pub fn report_markdown_logs(d: &Diagnosis, source: &str, pngs: &[String], logs: &[LogJson]) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "# Diagnosis of `{source}`\n");
    let _ = writeln!(s, "**Cause: `{}`**", d.answer());
    for (n, v, u) in &d.params {
        let _ = writeln!(s, "- fitted `{n}` = {} {u}", num(*v));
    }
    if !logs.is_empty() {
        logs_section(&mut s, logs);
    }
    probability_section(&mut s, d);
    adequacy_section(&mut s, d);
    let window = if logs.is_empty() {
        format!("Training window: before {:.2} s; held-out window: from {:.2} s (last ≥ 30 % of the run).", d.split_time_s, d.split_time_s)
    } else {
        "Training window: the first part of each log, held-out window: the rest (last ≥ 30 % of each log; times under \"Logs\").".to_string()
    };
    let _ = writeln!(
        s,
        "\n{window} \
         RMSE pooled over temperature channels: training {:.3} → {:.3} K, held-out {:.3} → {:.3} K ({} model runs).",
        d.before.train_rmse_k, d.after.train_rmse_k, d.before.heldout_rmse_k,
        d.after.heldout_rmse_k, d.sims
    );
    if !d.phases.is_empty() {
        let p: Vec<String> = d.phases.iter().map(|p| format!("{} {} ({:.1} s)", p.name, p.runs, p.secs)).collect();
        let _ = writeln!(s, "\nModel runs by phase: {}.", p.join(", "));
    }
    let _ = writeln!(s, "\n## Ranking (BIC on the training window, held-out check)\n");
    let _ = writeln!(s, "| cause | BIC | ΔBIC vs none | RMSE train (K) | RMSE held-out (K) | gain where it acts (best touched channel) | qualifies | fitted |");
    let _ = writeln!(s, "|---|---:|---:|---:|---:|---|---|---|");
    for r in &d.ranking {
        let p: Vec<String> = r.params.iter().map(|(n, v, u)| format!("{n}={} {u}", num(*v))).collect();
        let _ = writeln!(
            s,
            "| `{}` | {:.1} | {:.1} | {:.3} | {:.3} | {:.0} % {} | {} | {} |",
            r.cause, r.bic, r.delta_bic, r.train_rmse_k, r.heldout_rmse_k, 100.0 * r.heldout_gain, r.gain_channel,
            if r.qualifies { "yes".to_string() } else if r.note.is_empty() { "no".to_string() } else { format!("no ({})", r.note) },
            p.join(", ")
        );
    }
    let qualifying: Vec<&RankEntry> = d.ranking.iter().filter(|r| r.qualifies).collect();
    if qualifying.len() > 1 {
        let others: Vec<String> = qualifying
            .iter()
            .filter(|r| r.cause != d.cause.name())
            .map(|r| format!("`{}` (held-out {:.3} K, ΔBIC {:.1})", r.cause, r.heldout_rmse_k, r.delta_bic))
            .collect();
        let _ = writeln!(
            s,
            "\n**More than one candidate qualifies.** Named: the one with the lowest held-out error; also qualifying: {}. \
             This log does not separate them well: a run that excites where they differ (air-speed steps for \
             forced convection, motor-only heating for conduction, speed steps for churning) would.",
            others.join(", ")
        );
    }
    let _ = writeln!(s, "\n## Errors per channel\n");
    metrics_table(&mut s, "Baseline at nominal parameters", &d.nominal);
    metrics_table(&mut s, "Calibrated baseline (before)", &d.before);
    metrics_table(&mut s, &format!("With `{}` (after)", d.cause.name()), &d.after);
    let _ = writeln!(s, "\n## Calibrated nuisance parameters (set: {})\n\n| parameter | before | after | unit |\n|---|---:|---:|---|", d.nuisance_set);
    for ((n, b, u), (_, a, _)) in d.nuisance_before.iter().zip(&d.nuisance_after) {
        let _ = writeln!(s, "| `{n}` | {b:.4} | {a:.4} | {u} |");
    }
    let _ = writeln!(s, "\n## Residual cross-correlation with physical regressors (calibrated baseline)\n");
    let _ = writeln!(s, "Peak |ρ| over lags 0…lag_max (regressor leading the residual); ρ at lag 0 in brackets.\n");
    let regs: Vec<String> = {
        let mut v: Vec<String> = d.xcorr.iter().map(|x| x.regressor.clone()).collect();
        v.dedup();
        v.sort();
        v.dedup();
        v
    };
    let _ = writeln!(s, "| channel | {} |", regs.join(" | "));
    let _ = writeln!(s, "|---|{}", "---|".repeat(regs.len()));
    let mut chans: Vec<String> = d.xcorr.iter().map(|x| x.channel.clone()).collect();
    chans.dedup();
    for ch in chans {
        let cells: Vec<String> = regs
            .iter()
            .map(|r| {
                d.xcorr
                    .iter()
                    .find(|x| x.channel == ch && &x.regressor == r)
                    .map(|x| format!("{:+.2} @{:.0}s ({:+.2})", x.peak_rho, x.peak_lag_s, x.rho0))
                    .unwrap_or_default()
            })
            .collect();
        let _ = writeln!(s, "| `{ch}` | {} |", cells.join(" | "));
    }
    let _ = writeln!(s, "\n## Plots\n");
    for p in pngs {
        let _ = writeln!(s, "![{p}]({p})\n");
    }
    s
}

/// Writes `report.md`, `diagnosis.json` and the PNGs of `d` into `out`.
pub fn write_outputs(d: &Diagnosis, run: &crate::measured::MeasuredRun, source: &str, out: &Path) -> std::io::Result<()> {
    std::fs::create_dir_all(out)?;
    let pngs = super::plot::write_plots(d, run, out).map_err(|e| std::io::Error::other(e.to_string()))?;
    std::fs::write(out.join("report.md"), report_markdown(d, source, &pngs))?;
    let j = serde_json::to_string_pretty(&DiagnosisJson::from_diagnosis(d)).map_err(std::io::Error::other)?;
    std::fs::write(out.join("diagnosis.json"), j + "\n")
}
