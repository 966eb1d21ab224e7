//! The drain margin's validation: folds of the training missions (one
//! fitted on every log's first [`SPLIT_FRACTION`] and scored after it, and
//! folds scored on the logs' starts, [`HeadFold`]), each fold's firmware
//! drain scored against the measured drain, and the margin from the worst
//! under-prediction (docs/commissioning.md, "The drain margin and
//! refusals"). The folds' calibrations are in [`super::commission`].

use super::check::{check_reduced_window, CommissionError, ReducedCheck};
pub use super::fit::{HeadFold, HEAD_FOLD_DEFAULT};
use super::log::CalLog;
use crate::rig::Rig;
use eha_guard::model::ReducedParams;

/// Allowance added to the validation's largest under-prediction, K: twice
/// the drain thermocouple's noise σ (0.1 K), by which a new log's noise
/// extremes can exceed the validation's.
pub const MARGIN_ALLOWANCE_K: f64 = 0.2;

/// The drain margin from validation on a split of the training missions
/// ([`super::commission::validate_margin`]).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct MarginValidation {
    /// One check per training log, scored after the split (margin 0).
    pub folds: Vec<ReducedCheck>,
    /// Allowance added, K ([`MARGIN_ALLOWANCE_K`]).
    pub allowance_k: f64,
    /// The margin: the folds' largest under-prediction of the measured
    /// drain plus the allowance, K (≥ 0).
    pub margin_k: f64,
}

impl MarginValidation {
    /// The fold with the largest under-prediction.
    pub fn worst(&self) -> Option<&ReducedCheck> {
        self.folds.iter().max_by(|a, b| a.vs_measured_under_k.unwrap_or(0.0).total_cmp(&b.vs_measured_under_k.unwrap_or(0.0)))
    }
}

/// Share of every training log the margin validation's fits see: the
/// first fold fits the first [`SPLIT_FRACTION`] of every training log and
/// scores the rest; the second ([`Part::Head`]) fits the last
/// [`SPLIT_FRACTION`] and scores the first 1 − [`SPLIT_FRACTION`], the
/// log's start from rest (a cold start) included.
pub const SPLIT_FRACTION: f64 = 0.6;

/// Which part of every training log a fold of the margin validation
/// scores (the fold's fits see only the other part's measurements).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub enum Part {
    /// After the split at [`SPLIT_FRACTION`] of the span (fitted on the heads).
    Tail,
    /// Before the split at 1 − [`SPLIT_FRACTION`] of the span: the log's
    /// start from rest (fitted on the tails; their replays run from the
    /// log's start, so the state at the split is the model's own).
    Head,
}

/// The time splitting `log` for a fold scoring `part`, s.
pub fn split_time_s(log: &CalLog, part: Part) -> f64 {
    let t = &log.run.time_s;
    let frac = match part {
        Part::Tail => SPLIT_FRACTION,
        Part::Head => 1.0 - SPLIT_FRACTION,
    };
    t[0] + frac * (t[t.len() - 1] - t[0])
}

/// One fold of the training missions that validates a margin: the logs
/// its fits see, the reference calibrated on them and its reduction.
#[derive(Debug, Clone)]
pub struct Split {
    /// The logs the fold's fits see: the heads of the training logs
    /// ([`Part::Tail`] scored), or the whole logs with fit points after
    /// their split only ([`Part::Head`] scored).
    pub heads: Vec<CalLog>,
    /// The reference calibrated on them.
    pub rig: Rig,
    /// Its reduction.
    pub reduction: ReducedParams,
    /// The part of every training log this fold scores.
    pub scored: Part,
    /// The one training log (index) the fold scores; `None`: every one.
    pub only: Option<usize>,
}

/// The firmware parameters `p` fitted on the split's heads, replayed over
/// each whole training log (from the start) and scored against its measured
/// drain after the split; the margin is the largest under-prediction there
/// plus [`MARGIN_ALLOWANCE_K`].
pub fn score_split(split: &Split, train: &[CalLog], p: &ReducedParams) -> Result<MarginValidation, CommissionError> {
    Ok(score_split_many(split, train, &[p])?.remove(0))
}

/// [`score_split`] for several firmware parameter sets on one replay of
/// `split.rig` per training log; one validation per set, in order. A
/// [`Part::Head`] fold scores before the split; its checks' log names
/// carry " (start, fitted on the rest)".
pub fn score_split_many(split: &Split, train: &[CalLog], ps: &[&ReducedParams]) -> Result<Vec<MarginValidation>, CommissionError> {
    let mut folds: Vec<Vec<ReducedCheck>> = vec![Vec::new(); ps.len()];
    let models: Vec<(&ReducedParams, &[f64])> = ps.iter().map(|&p| (p, &[0.0][..])).collect();
    for (i, (l, h)) in train.iter().zip(&split.heads).enumerate() {
        if split.only.is_some_and(|o| o != i) {
            continue;
        }
        // After the head's last row; before the time the tail's fit points start.
        let window = match split.scored {
            Part::Tail => (h.run.time_s[h.run.len() - 1], f64::INFINITY),
            Part::Head => (f64::NEG_INFINITY, h.fit_from_s),
        };
        let checks = check_reduced_window(&split.rig, l, &models, window).map_err(CommissionError::Run)?;
        for (f, mut c) in folds.iter_mut().zip(checks) {
            let mut c = c.remove(0);
            if split.scored == Part::Head {
                c.log = format!("{} {HEAD_FOLD_TAG}", c.log);
            }
            f.push(c);
        }
    }
    Ok(folds.into_iter().map(margin_of).collect())
}

/// Tag on the log name of a [`Part::Head`] fold's check.
pub const HEAD_FOLD_TAG: &str = "(start, fitted on the rest)";

/// The margin validated by `folds`: their largest under-prediction of the
/// measured drain plus [`MARGIN_ALLOWANCE_K`].
pub fn margin_of(folds: Vec<ReducedCheck>) -> MarginValidation {
    let worst = folds.iter().filter_map(|f| f.vs_measured_under_k).fold(0.0, f64::max);
    MarginValidation { folds, allowance_k: MARGIN_ALLOWANCE_K, margin_k: worst + MARGIN_ALLOWANCE_K }
}

/// The validation over every fold of `vs` (one path's folds, each
/// scored by [`score_split_many`]): their checks together, the margin from
/// the worst of them.
pub fn merge_folds(vs: Vec<MarginValidation>) -> MarginValidation {
    margin_of(vs.into_iter().flat_map(|v| v.folds).collect())
}
