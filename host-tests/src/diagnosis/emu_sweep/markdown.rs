//! The sweep's Markdown: one table row per result, the miss classes, the
//! oracle rows and the whole document (`emulator-sweep.md`, and what
//! `eha-sim docs` renders into docs/diagnosis-numbers.md and
//! docs/diagnosis-off.md). Separate because it is
//! output, not diagnosis.

use super::EmuResult;
use crate::diagnosis::model::Candidate;
use std::fmt::Write as _;

/// One Markdown table row of `r`.
pub fn table_row(r: &EmuResult) -> String {
    let ch: Vec<String> = r
        .channels
        .iter()
        .map(|(c, v, q, f, m)| {
            let b = if *m { "**" } else { "" };
            format!("{b}{} {v:.2} ({q:.0}σ, {:.0} %){b}", c.trim_start_matches("t_").trim_end_matches("_c"), 100.0 * f)
        })
        .collect();
    format!(
        "| {:?} ({}) | {} | {} | {} | {} | {} | {:.2} / {:.2} → {:.2} | {} | {} | {:.0} |",
        r.case.scenario,
        r.case.seed,
        r.case.hidden.name(),
        if r.case.hidden == Candidate::None { "–".to_string() } else { format!("{:.3e}", r.magnitude) },
        r.answer,
        r.affected.as_ref().map_or("–".into(), |(c, v)| format!("{c} ({v:.2} K)")),
        r.affected_heldout_k.map_or("–".into(), |(b, a)| format!("{b:.2} → {a:.2} ({:.0} %)", 100.0 * (1.0 - a / b))),
        r.pooled_heldout_k[0],
        r.pooled_heldout_k[1],
        r.pooled_heldout_k[2],
        ch.join(", "),
        if r.at_bounds.is_empty() { "–".into() } else { r.at_bounds.join(", ") },
        r.seconds
    )
}

/// What the hidden effect's own candidate achieved, in three classes:
/// `named`; `oracle < 50 %` (fitted, it does not reach the acceptance's
/// 50 % held-out gain on the affected channel, so no answer could meet it
/// on this log with this model and calibration set); `oracle ≥ 50 %`
/// (it would, and the rules did not name it). `None` for `none` cases.
pub fn miss_class(r: &EmuResult) -> Option<&'static str> {
    let h = r.hidden_fit.as_ref()?;
    Some(if r.hit() {
        "named"
    } else if h.affected_gain().is_some_and(|g| g >= 0.5) {
        "oracle ≥ 50 %"
    } else {
        "oracle < 50 %"
    })
}

/// One row of the oracle table: the hidden candidate as fitted.
pub fn oracle_row(r: &EmuResult) -> Option<String> {
    let h = r.hidden_fit.as_ref()?;
    Some(format!(
        "| {:?} ({}) | {} | {} | {:.1} | {} | {:.2} → {:.2} | {} | {} | {} |",
        r.case.scenario,
        r.case.seed,
        r.case.hidden.name(),
        r.answer,
        h.delta_bic,
        h.affected_heldout_k.zip(h.affected_gain()).map_or("–".into(), |((b, a), g)| format!("{b:.2} → {a:.2} ({:.0} %)", 100.0 * g)),
        h.pooled_heldout_k.0,
        h.pooled_heldout_k.1,
        if h.qualifies { "yes".to_string() } else if h.note.is_empty() { "no".into() } else { format!("no ({})", h.note) },
        r.hidden_detect.as_ref().map_or("–".into(), |x| format!("{:.2} of {:.2} K left ({:.0} %)", x.left_k, x.imprint_k.1, 100.0 * x.best_gain)),
        miss_class(r).unwrap_or("–"),
    ))
}

/// The sweep's Markdown (`emulator-sweep.md`): the answer table, its
/// summary line, the hidden effects' own fits and their classes. Also what
/// `eha-sim docs` renders into docs/diagnosis-numbers.md and
/// docs/diagnosis-off.md from the committed JSON.
pub fn document(ok: &[EmuResult]) -> String {
    let mut md = String::from(
        "| scenario (seed) | hidden | magnitude | answer | affected channel (imprint) | its held-out RMSE before → after (K) | pooled held-out RMSE nominal / calibrated → after (K) | calibrated held-out per channel, K (× noise σ, % of rise; **misfit**) | nuisance on a bound | s |\n|---|---|---|---|---|---|---|---|---|---:|\n",
    );
    for r in ok {
        md += &table_row(r);
        md.push('\n');
    }
    let with = ok.iter().filter(|r| r.case.hidden != Candidate::None).count();
    let hits = ok.iter().filter(|r| r.case.hidden != Candidate::None && r.hit()).count();
    let gain = ok.iter().filter(|r| r.case.hidden != Candidate::None && r.hit() && r.affected_gain().is_some_and(|g| g >= 0.5)).count();
    let count = |s: &str| ok.iter().filter(|r| r.answer == s).count();
    let nones: Vec<&EmuResult> = ok.iter().filter(|r| r.case.hidden == Candidate::None).collect();
    let false_disc = nones.iter().filter(|r| r.answer != "none" && r.answer != "unexplained").count();
    let _ = writeln!(
        md,
        "\nHidden effect named in {hits} of {with} (with ≥ 50 % held-out gain on the affected channel: {gain}); \
         `none` cases: {} none, {} unexplained, {false_disc} false discoveries of {}; answers overall: {} unexplained, {} none.",
        nones.iter().filter(|r| r.answer == "none").count(),
        nones.iter().filter(|r| r.answer == "unexplained").count(),
        nones.len(),
        count("unexplained"),
        count("none"),
    );
    md += "\n**The hidden effect's own candidate, as fitted in the diagnosis** (known to the sweep only):\n\n\
           | scenario (seed) | hidden | answer | ΔBIC | affected channel held-out, baseline → with it (gain) | pooled held-out (K) | qualifies | in the model's structure: imprint left after calibration (best gain) | class |\n\
           |---|---|---|---:|---|---|---|---|---|\n";
    for row in ok.iter().filter_map(oracle_row) {
        md += &row;
        md.push('\n');
    }
    let class = |c: &str| ok.iter().filter(|r| miss_class(r) == Some(c)).count();
    let absorbed = ok.iter().filter(|r| !r.hit() && r.hidden_detect.as_ref().is_some_and(|x| x.best_gain < 0.5)).count();
    let _ = writeln!(
        md,
        "\nOf {with} hidden effects: {} named, {} missed with the right candidate reaching ≥ 50 % on the affected channel, \
         {} where the right candidate, fitted, stays under 50 %; of the misses, {absorbed} where even the model's own \
         structure with the effect at its true magnitude leaves less than the 50 % bar after calibration.",
        class("named"),
        class("oracle ≥ 50 %"),
        class("oracle < 50 %"),
    );
    md += &crate::diagnosis::emu_tables::ratio_table(ok);
    md += &crate::diagnosis::emu_tables::reliability_table(ok);
    md += &crate::diagnosis::emu_tables::measured_rule_section(ok);
    md
}
