//! `report.md`: the evidence of a diagnosis in Markdown, section by
//! section (cause and fitted parameters, logs of a joint diagnosis,
//! probabilities, the baseline against the noise floor, ranking, errors
//! per channel, nuisance parameters, residual cross-correlations, plots).

use super::json::LogJson;
use crate::diagnosis::analysis::{Diagnosis, Metrics, RankEntry};
use std::fmt::Write as _;

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
            crate::diagnosis::evidence::NAME_PROBABILITY, c[0].cause, c[0].probability, c[1].cause, c[1].probability
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
