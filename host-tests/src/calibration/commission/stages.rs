//! The stages of [`super::commission_with`] that stand on their own: the
//! training set's warnings, the held-out scores of the reference, the
//! margin's folds scored for both paths, and every held-out log checked
//! against the firmware models.

use super::super::log::{channel_errors, CalLog};
use super::{cycles_valve, merge_folds, score_split_many, CommissionError, HoldoutScore, MarginValidation, ReducedCheck, Split, NO_COOLING};
use crate::rig::Rig;
use eha_guard::model::ReducedParams;

/// Warnings on what the training set cannot show: no LNG valve cycling
/// (the cooling credit unchecked), no log with speed and load varied
/// independently (one-at-a-time missions).
pub(super) fn training_warnings(train: &[CalLog], warnings: &mut Vec<String>) {
    if !train.iter().any(cycles_valve) {
        warnings.push(format!(
            "{NO_COOLING} (no `lng_valve` column that is both 0 and 1): the exchanger's cooling credit in the firmware is not checked against this machine; run a loaded mission with the valve cycling (docs/commissioning.md)"
        ));
    }
    if !train.iter().any(|l| crate::calibration::ident::independent_speed_and_load(&l.run)) {
        use crate::calibration::ident::{JOINT_MAX_CORRELATION, NO_JOINT_EXCITATION, ONE_POINT_SPREAD};
        warnings.push(format!(
            "{NO_JOINT_EXCITATION} (none has shaft speed and pressure drop each spreading by >= {:.0} % with |correlation| < {JOINT_MAX_CORRELATION}): one-at-a-time missions let the calibration absorb the machine's structure into values that hold only for them; add an identification run (docs/commissioning.md)",
            100.0 * ONE_POINT_SPREAD,
        ));
    }
}

/// Each held-out log's channel errors under the rig as given (`base`) and
/// as commissioned (`commissioned`).
pub(super) fn holdout_scores(base: &Rig, commissioned: &Rig, holdout: &[CalLog]) -> Result<Vec<HoldoutScore>, CommissionError> {
    let mut scores = Vec::new();
    for l in holdout {
        let a = l.simulate(base).map_err(CommissionError::Run)?;
        let b = l.simulate(commissioned).map_err(CommissionError::Run)?;
        scores.push(HoldoutScore { log: l.name.clone(), as_given: channel_errors(l, &a), commissioned: channel_errors(l, &b) });
    }
    Ok(scores)
}

/// The margin's folds scored for the reduction and, when the direct path
/// fitted one block per fold (`direct_folds`), for it too, on one replay of
/// each training log per fold: (the reduction's validation, the direct
/// path's when every fold has one). `(None, None)` without folds.
pub(super) fn score_folds(splits: &[Split], train: &[CalLog], direct_folds: Option<&[ReducedParams]>) -> Result<(Option<MarginValidation>, Option<MarginValidation>), CommissionError> {
    if splits.is_empty() {
        return Ok((None, None));
    }
    let (mut red, mut dir) = (Vec::new(), Vec::new());
    for (i, s) in splits.iter().enumerate() {
        let mut ps = vec![&s.reduction];
        if let Some(hs) = direct_folds {
            ps.extend(hs.get(i));
        }
        let mut v = score_split_many(s, train, &ps)?.into_iter();
        red.extend(v.next());
        dir.extend(v.next());
    }
    let dir_ok = dir.len() == splits.len();
    Ok((Some(merge_folds(red)), dir_ok.then(|| merge_folds(dir))))
}

/// Every held-out log checked against the firmware models of
/// [`holdout_checks`], per model and log.
#[derive(Default)]
pub(super) struct HoldoutChecks {
    /// The reduction without its margin.
    pub red_plain: Vec<ReducedCheck>,
    /// The reduction with its margin (without, when it has none).
    pub red_with: Vec<ReducedCheck>,
    /// The paper-default block.
    pub default: Vec<ReducedCheck>,
    /// The direct path without its margin (empty without a direct path).
    pub dir_plain: Vec<ReducedCheck>,
    /// The direct path with its margin.
    pub dir_with: Vec<ReducedCheck>,
}

/// Every held-out log on one replay of the commissioned reference `rig`:
/// `models` are the reduction with its margins, the paper default and,
/// when present, the direct path with its margins, in that order.
pub(super) fn holdout_checks(rig: &Rig, holdout: &[CalLog], models: &[(&ReducedParams, &[f64])]) -> Result<HoldoutChecks, CommissionError> {
    let mut h = HoldoutChecks::default();
    for l in holdout {
        let mut c = super::check_reduced_many(rig, l, models, f64::NEG_INFINITY).map_err(CommissionError::Run)?.into_iter();
        let (p, w) = super::super::paths::plain_and_with(c.next().expect("the reduction's checks"));
        h.red_plain.push(p);
        h.red_with.push(w);
        h.default.push(c.next().expect("the default's check").remove(0));
        if let Some(d) = c.next() {
            let (p, w) = super::super::paths::plain_and_with(d);
            h.dir_plain.push(p);
            h.dir_with.push(w);
        }
    }
    Ok(h)
}
