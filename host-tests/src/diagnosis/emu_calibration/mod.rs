//! The reliability of the stated probabilities on the stored emulator
//! sweeps under the default structure, and what an effective sample size
//! (a power on the likelihood) and a soft admission gate do to it,
//! re-computed from each log's stored ln Bayes factors and priors without
//! refitting (docs/diagnosis-numbers.md, "Reliability of the stated
//! probabilities"). Measured, not the product's rule.
//!
//! By topic: `fraction` the effective sample fractions (from a residual's
//! Ljung–Box p or the discrepancy's length scale), `restate` the
//! re-statements of a stored posterior ([`Variant`]), `gate` the table of
//! the gate's rejection as an observation; this file the logs
//! of the stored sweeps, the fitted power, the measurement of a variant
//! and the document.

mod fraction;
mod gate;
mod restate;

pub use fraction::{fraction_from_length_scale, fraction_from_ljung_box};
pub use gate::{calibrated, gate_document};
pub use restate::{power_grid, powered, restate_heldout, restate_no_gate, Variant};

use super::emu_result::EmuResult;
use super::emu_tables::{reliability_of, statements, Bin, Diagnosed};
use super::evidence::{names_a_cause, NAME_PROBABILITY};
use super::model::Candidate;
use super::report::ProbabilityJson;
use std::collections::BTreeMap;
use std::fmt::Write as _;

/// Training fit points per channel of the stored sweeps
/// (`DiagnoseOptions::points_per_channel`): the `n` of their Ljung–Box p.
pub const LB_POINTS: usize = 150;

/// Lags of the stored Ljung–Box p (`20.min(n / 4)` in the evidence).
pub const LB_LAGS: usize = 20;

/// Training share of a log of the stored sweeps (`DiagnoseOptions::train_fraction`).
pub const TRAIN_FRACTION: f64 = 0.7;

/// The stated probability of the truth in `probs`: of the hidden effect
/// `truth` when it stands clear of the floor (`ratio` ≥ 2), else of "no
/// cause" (`none` + `unexplained`).
fn p_truth(probs: &[ProbabilityJson], truth: &str, ratio: Option<f64>) -> f64 {
    let effect = names_a_cause(truth) && ratio.is_some_and(|r| r >= 2.0);
    probs.iter().filter(|p| if effect { p.cause == truth } else { !names_a_cause(&p.cause) }).map(|p| p.probability).sum()
}

/// The power η of [`Variant::HeldOutTempered`]: of [`power_grid`], the one
/// with the least mean log-loss −ln P(truth) ([`p_truth`], floored at
/// 1e-6) over `logs` under [`restate_heldout`] with every ln Bayes factor
/// times η; `None` when a record lacks the held-out parts.
fn fit_power(logs: &[Log]) -> Option<f64> {
    let rest: Vec<Vec<ProbabilityJson>> = logs.iter().map(|l| restate_heldout(&l.probs)).collect::<Option<_>>()?;
    let loss = |eta: f64| -> f64 {
        logs.iter().zip(&rest).map(|(l, p)| -p_truth(&powered(p, eta, 0.0), l.truth, l.ratio).max(1e-6).ln()).sum::<f64>() / logs.len().max(1) as f64
    };
    power_grid().into_iter().min_by(|a, b| loss(*a).total_cmp(&loss(*b)))
}

/// One diagnosed log, owned: seed, twin, truth, r, answer, probabilities,
/// the power's two fractions.
struct Log {
    seed: u64,
    twin: bool,
    truth: &'static str,
    ratio: Option<f64>,
    probs: Vec<ProbabilityJson>,
    w_lb: f64,
    w_len: f64,
    /// The log's recorded detectability (empty when the sweep did not
    /// record it).
    reach: Vec<super::gate_obs::Reach>,
}

/// Every case log and twin of `rows`; r from the twin, else from `ratios`
/// (seed → r, for sweeps run without twins).
fn logs(rows: &[EmuResult], ratios: &BTreeMap<u64, f64>) -> Vec<Log> {
    let mut out = Vec::new();
    for r in rows {
        let dt = r.case.duration_s * TRAIN_FRACTION / LB_POINTS as f64;
        let w_lb = |ch: &[super::evidence::ChannelEvidence]| {
            ch.iter().map(|c| fraction_from_ljung_box(c.ljung_box_p_whitened, LB_POINTS, LB_LAGS)).fold(1.0, f64::min)
        };
        let ratio = r.twin.as_ref().map(|t| t.ratio()).or_else(|| ratios.get(&r.case.seed).copied());
        let truth = r.case.hidden.name();
        out.push(Log { seed: r.case.seed, twin: false, truth, ratio, probs: r.probabilities.clone(),
            w_lb: w_lb(r.evidence_channels.as_slice()),
            w_len: fraction_from_length_scale(dt),
            reach: r.reach.clone(),
        });
        if let Some(t) = r.twin.as_ref().filter(|t| !t.twin_probabilities.is_empty()) {
            let (probs, w) = (t.twin_probabilities.clone(), w_lb(t.twin_channels.as_slice()));
            let reach = t.twin_reach.clone();
            out.push(Log { seed: r.case.seed, twin: true, truth: Candidate::None.name(), ratio: None, probs, w_lb: w, w_len: fraction_from_length_scale(dt), reach });
        }
    }
    out
}

/// (reliability bins, decisions line) of `logs` under `v`; `None` when a
/// log's record lacks what `v` needs.
fn measure(logs: &[Log], v: Variant, eta: Option<f64>) -> Option<(Vec<Bin>, String)> {
    let restated: Vec<Vec<ProbabilityJson>> = logs
        .iter()
        .map(|l| match v {
            Variant::Stored => Some(l.probs.clone()),
            Variant::LjungBox => Some(powered(&l.probs, l.w_lb, 0.0)),
            Variant::LengthScale => Some(powered(&l.probs, l.w_len, 0.0)),
            Variant::LjungBoxLeak => Some(powered(&l.probs, l.w_lb, super::evidence::LEAK)),
            Variant::NoGate => Some(restate_no_gate(&l.probs)),
            Variant::HeldOut => restate_heldout(&l.probs),
            Variant::HeldOutTempered => Some(powered(&restate_heldout(&l.probs)?, eta?, 0.0)),
            Variant::GateObserved if l.reach.is_empty() => None,
            Variant::GateObserved => super::gate_obs::restate_gate_observed(&l.probs, &|c| super::gate_obs::p_fail_of(&l.reach, c)),
        })
        .collect::<Option<_>>()?;
    let named: Vec<Option<String>> = restated
        .iter()
        .map(|p| p.iter().find(|c| names_a_cause(&c.cause) && c.probability >= NAME_PROBABILITY).map(|c| c.cause.clone()))
        .collect();
    let answer = |i: usize| named[i].clone().unwrap_or_else(|| "none".into());
    let answers: Vec<String> = (0..logs.len()).map(answer).collect();
    let d: Vec<Diagnosed> = logs
        .iter()
        .zip(&restated)
        .zip(&answers)
        .map(|((l, p), a)| Diagnosed { seed: l.seed, twin: l.twin, truth: l.truth, ratio: l.ratio, answer: a.as_str(), probabilities: p.as_slice() })
        .collect();
    let must: Vec<usize> = (0..logs.len()).filter(|&i| logs[i].truth != "none" && logs[i].ratio.is_some_and(|r| r >= 2.0)).collect();
    let hit = must.iter().filter(|&&i| named[i].as_deref() == Some(logs[i].truth)).count();
    let list = |f: &dyn Fn(usize) -> bool| {
        let v: Vec<String> = (0..logs.len())
            .filter(|&i| f(i))
            .map(|i| format!("{}{} `{}`", logs[i].seed, if logs[i].twin { "'s twin" } else { "" }, named[i].as_deref().unwrap_or("")))
            .collect();
        if v.is_empty() { "0".to_string() } else { format!("{} ({})", v.len(), v.join(", ")) }
    };
    let wrong = list(&|i| logs[i].truth != "none" && named[i].as_deref().is_some_and(|n| n != logs[i].truth));
    let free = logs.iter().filter(|l| l.truth == "none").count();
    let fd = list(&|i| logs[i].truth == "none" && named[i].is_some());
    Some((reliability_of(&d), format!("{hit} of {} · {wrong} · {fd} of {free}", must.len())))
}

/// One bin as a cell: statements · mean stated → observed (at the floor).
fn cell(b: &Bin) -> String {
    if b.n == 0 {
        return "–".into();
    }
    format!("{} · {:.0} → {:.0} ({:.0})", b.n, 100.0 * b.stated, 100.0 * b.observed, 100.0 * b.observed_at_floor)
}

/// The document: for every set of `sets` (label, its results) and all
/// together, each [`Variant`]'s decisions and reliability, and what makes
/// the stated probabilities extreme (the gate, the merged "no cause").
/// `ratios`: r of the cases whose sweep ran without twins.
pub fn document(sets: &[(&str, Vec<EmuResult>)], ratios: &BTreeMap<u64, f64>) -> String {
    let per: Vec<(&str, Vec<Log>)> = sets.iter().map(|(l, r)| (*l, logs(r, ratios))).collect();
    let all: Vec<Log> = sets.iter().flat_map(|(_, r)| logs(r, ratios)).collect();
    let mut md = String::from(
        "\n| statements on | logs | stated as | named at r ≥ 2 · wrong causes · false discoveries | 0.00–0.10 | 0.10–0.30 | 0.30–0.50 | 0.50–0.70 | 0.70–0.90 | 0.90–0.99 | 0.99–1.00 |\n|---|---:|---|---|---|---|---|---|---|---|---|\n",
    );
    let eta = per.first().and_then(|(_, l)| fit_power(l));
    let mut rows: Vec<(&str, &[Log])> = per.iter().map(|(l, v)| (*l, v.as_slice())).collect();
    rows.push(("all", all.as_slice()));
    for (label, set) in &rows {
        for v in Variant::ALL {
            match measure(set, v, eta) {
                Some((bins, dec)) => {
                    let cells: Vec<String> = bins.iter().map(cell).collect();
                    let _ = writeln!(md, "| {label} | {} | {} | {dec} | {} |", set.len(), v.label(), cells.join(" | "));
                }
                None => {
                    let _ = writeln!(md, "| {label} | {} | {} | not stored (re-run the sweep) |{}", set.len(), v.label(), " – |".repeat(7));
                }
            }
        }
    }
    let gated = |l: &Log| !l.probs.iter().any(|p| names_a_cause(&p.cause) && p.prior > 0.0);
    let true_low: Vec<&Log> = all
        .iter()
        .filter(|l| {
            let t = if l.truth == "none" { "no cause" } else { l.truth };
            statements(&l.probs).iter().any(|(s, p)| *p < 0.1 && s == t)
        })
        .collect();
    let of_gate = true_low.iter().filter(|l| l.probs.iter().any(|p| p.cause == l.truth && p.prior == 0.0)).count();
    let range = |f: &dyn Fn(&Log) -> f64| all.iter().map(f).fold((f64::INFINITY, 0f64), |(a, b), x| (a.min(x), b.max(x)));
    let (lb_lo, lb_hi) = range(&|l| l.w_lb);
    let (len_lo, len_hi) = range(&|l| l.w_len);
    let _ = write!(
        md,
        "\nCells: statements · mean stated → observed (observed with the answers' truth: the effect at r ≥ 2, else no cause), per cent. \
         Powers: Ljung–Box {lb_lo:.2}–{lb_hi:.2}, length scale {len_lo:.3}–{len_hi:.3}. \
         Logs with no admitted candidate (only `none` and `unexplained`, so \"no cause\" at P = 1 whatever the power): \
         {} of {}. True statements at P < 0.10: {}, of which the hidden effect's candidate failed the held-out checks \
         (prior 0): {of_gate}. Tempering power η of the held-out likelihood (fitted on the first set, least log-loss \
         of the truth over 0.05–1): {}.\n",
        all.iter().filter(|l| gated(l)).count(),
        all.len(),
        true_low.len(),
        eta.map_or("not fitted (its records lack the held-out parts)".to_string(), |e| format!("{e:.2}")),
    );
    md
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The stored sweeps, (label, records) per set.
    type Sets = Vec<(&'static str, Vec<EmuResult>)>;

    /// The stored sweeps (docs/data/) as `eha-sim docs` reads them:
    /// (label, records) per set, and the imprint ratios of the cases run
    /// without twins.
    fn stored() -> (Sets, BTreeMap<u64, f64>) {
        let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs/data");
        let read = |f: &str| std::fs::read_to_string(dir.join(f)).unwrap();
        let sets = [
            ("1700s/2700s", "emulator-sweep-hidden-no-case-held.json"),
            ("1800–1817", "emulator-sweep-1800.json"),
            ("2800–2817", "emulator-sweep-2800.json"),
        ]
        .into_iter()
        .map(|(l, f)| (l, serde_json::from_str::<Vec<EmuResult>>(&read(f)).unwrap()))
        .collect();
        let ratios: BTreeMap<String, f64> = serde_json::from_str(&read("imprint-ratios-no-case-held.json")).unwrap();
        (sets, ratios.into_iter().map(|(k, v)| (k.parse().unwrap(), v)).collect())
    }

    /// The reliability table regenerated from the stored sweeps, as
    /// measured (all three on the fixed reference, b36ffe3); the one
    /// constant, the held-out likelihood's power η, is fitted on the first
    /// set (1700s/2700s) and judged on the second seed sets, which did not
    /// choose it.
    /// - The product's gate: every statement at P ≤ 0.10 or ≥ 0.99; the
    ///   top bin 73 statements, 51 % observed with the hidden effect as the
    ///   truth at any r: not calibrated so; with the truth the answers are
    ///   judged by (the effect at r ≥ 2, else no cause) 92 % in the top bin
    ///   and 4 % in the bottom one: within 10 points, on all three sets
    ///   together and on each second seed set alone.
    /// - No gate (stored ln BF): 3 wrong causes, 7 false discoveries.
    /// - The held-out likelihood instead of the gate (nothing fitted): 2
    ///   wrong causes and 5 false discoveries over the 73 logs; top bin 32
    ///   statements, 53 % observed.
    /// - Tempered, η = 0.40 fitted (0.30 on the sweeps before the fix): on
    ///   the check sets 4 of 6 named at r ≥ 2 (the product's 4), 0 wrong,
    ///   3 false discoveries (1800's and 1808's twins on 1800–1817, 2809's
    ///   twin on 2800–2817; the gate rejects them); the top bin of
    ///   1800–1817 5 statements, 100 % observed; of 2800–2817 14, 64 %:
    ///   not calibrated, and false discoveries: not adopted.
    #[test]
    fn the_reliability_table_from_the_stored_sweeps_is_as_measured() {
        let (sets, ratios) = stored();
        let per: Vec<Vec<Log>> = sets.iter().map(|(_, r)| logs(r, &ratios)).collect();
        let all: Vec<Log> = sets.iter().flat_map(|(_, r)| logs(r, &ratios)).collect();
        assert_eq!(all.len(), 73);
        let eta = fit_power(&per[0]);
        assert_eq!(eta.map(|e| (e * 100.0).round() as i64), Some(40), "η fitted on 1700s/2700s");
        let ends = |l: &[Log], v: Variant| {
            let (bins, dec) = measure(l, v, eta).unwrap();
            let pct = |b: &Bin| (b.n, (100.0 * b.observed).round() as i64);
            (pct(&bins[0]), pct(&bins[6]), dec)
        };
        let counts = |dec: &str| -> Vec<String> { dec.split(" · ").map(|x| x.split(" (").next().unwrap_or("").to_string()).collect() };
        let (lo, hi, dec) = ends(&all, Variant::Stored);
        assert_eq!((lo, hi, counts(&dec)), ((68, 16), (73, 51), vec!["4 of 9".into(), "0".into(), "0 of 32".into()]));
        // With the truth the answers are judged by (the effect at r ≥ 2,
        // else no cause) the product's two bins are within 10 points: 68
        // statements at 0 % stated, 4 % true; 73 at 100 %, 92 % true.
        let (bins, _) = measure(&all, Variant::Stored, eta).unwrap();
        let floor = |b: &Bin| (b.n, (100.0 * b.observed_at_floor).round() as i64);
        assert_eq!((floor(&bins[0]), floor(&bins[6])), ((68, 4), (73, 92)));
        assert_eq!(calibrated(&bins), (false, true));
        for set in &per[1..] {
            let (bins, _) = measure(set, Variant::Stored, eta).unwrap();
            assert_eq!(calibrated(&bins), (false, true), "each second seed set alone");
        }
        let (_, _, dec) = ends(&all, Variant::NoGate);
        assert_eq!(counts(&dec), vec!["5 of 9", "3", "7"]);
        let (_, hi, dec) = ends(&all, Variant::HeldOut);
        assert_eq!((hi, counts(&dec)), ((32, 53), vec!["4 of 9".to_string(), "2".into(), "5".into()]));
        let (_, hi, dec) = ends(&per[1], Variant::HeldOutTempered);
        assert_eq!((hi, counts(&dec)), ((5, 100), vec!["3 of 4".to_string(), "0".into(), "2".into()]));
        assert!(dec.contains("1808's twin `churning-loss`"), "{dec}");
        let (_, hi, dec) = ends(&per[2], Variant::HeldOutTempered);
        assert_eq!((hi, counts(&dec)), ((14, 64), vec!["1 of 2".to_string(), "0".into(), "1".into()]));
    }
}
