//! The calibrations commissioning runs: its own, with the pump's η_m from
//! the electrical balance when the logs carry current (`fit`,
//! [`with_eta_m_from_current`]), and the drain margin's folds on parts of
//! the training logs ([`split_fit`], [`head_fold_fit`], [`margin_folds`],
//! [`validate_margin`]).

use crate::calibration::check::CommissionError;
use crate::calibration::eta_m::{eta_m_balance, EtaMBalance};
use crate::calibration::fit::{calibrate, CalOptions, Calibration};
use crate::calibration::log::CalLog;
use crate::calibration::margin::{merge_folds, score_split, split_time_s, HeadFold, MarginValidation, Part, Split};
use crate::measured::Channel;
use crate::reduce::reduce;
use crate::rig::Rig;

/// What [`fit`] gives: the rig it started from, the calibration, η_m
/// identified from the current with the number of samples it rests on
/// (`None`: from the temperatures), and the electrical balance it came
/// from (which says why when it was not used).
type Fitted = (Rig, Calibration, Option<(f64, usize)>, EtaMBalance);

/// The calibration of `base` on `train` with `eta_m` from the current when
/// the logs carry it: the rig it started from, the calibration and that
/// `eta_m`.
pub(super) fn fit(base: &Rig, train: &[CalLog], o: &CalOptions) -> Result<Fitted, CommissionError> {
    let balance = eta_m_balance(base, train);
    let (base_e, o, eta_e) = with_eta_m(base, balance, o);
    let cal = calibrate(&base_e, train, &o)?;
    Ok((base_e, cal, eta_e, balance))
}

/// The rig and options the commissioning calibrates with: the pump's
/// friction coefficient η_m from the electrical balance when the logs
/// carry current under load ([`eta_m_from_current`](crate::calibration::eta_m::eta_m_from_current); identified directly,
/// and the firmware's sensor cross-check then agrees with this machine),
/// `pump_friction` held there; else the rig and options unchanged (η_m from
/// the temperatures with the rest of the set). Returns η_m and its sample
/// count when taken from the current.
pub fn with_eta_m_from_current(base: &Rig, train: &[CalLog], o: &CalOptions) -> (Rig, CalOptions, Option<(f64, usize)>) {
    with_eta_m(base, eta_m_balance(base, train), o)
}

/// [`with_eta_m_from_current`] from the logs' electrical `balance`.
fn with_eta_m(base: &Rig, balance: EtaMBalance, o: &CalOptions) -> (Rig, CalOptions, Option<(f64, usize)>) {
    let mut base_e = base.clone();
    let mut o = o.clone();
    // On the calibration's lattice (`residuals::THETA_LATTICE_LN`): η_m
    // weighs the current's rows by the viscosity at the logged drain
    // temperature, so a last-digit change of the logs changed the rig every
    // model run starts from in its last digits, and the adaptive replays
    // took other step sequences from the first run on.
    let eta_e = balance.plausible().map(|(eta, n)| (crate::calibration::residuals::on_lattice_value(eta, o.lattice_ln), n));
    if let Some((eta, n)) = eta_e {
        base_e.pump.eta_m = eta;
        o.hold.push(("pump_friction", format!("eta_m = {eta:.4} from the current of {n} loaded samples (electrical balance)")));
    }
    (base_e, o, eta_e)
}

/// Rows `rows` of `log` as a log of its own.
fn rows_of(log: &CalLog, rows: std::ops::Range<usize>, points_per_channel: usize) -> Result<CalLog, String> {
    let mut run = log.run.clone();
    run.time_s = run.time_s[rows.clone()].to_vec();
    run.channels.values_mut().for_each(|v| *v = v[rows.clone()].to_vec());
    CalLog::new_thinned(&log.name, run, points_per_channel, log.thinning)
}

/// The first [`SPLIT_FRACTION`](crate::calibration::margin::SPLIT_FRACTION) of `log`'s span as a log of its own.
fn head_of(log: &CalLog, points_per_channel: usize) -> Result<CalLog, String> {
    let t_split = split_time_s(log, Part::Tail);
    rows_of(log, 0..log.run.time_s.partition_point(|&t| t <= t_split), points_per_channel)
}

/// The calibration on the first [`SPLIT_FRACTION`](crate::calibration::margin::SPLIT_FRACTION) of every training log
/// and its reduction. `None` when a training log has no `t_drain_c`, or the
/// reduction gives parameters the firmware model rejects. `start`: the
/// multipliers the fit starts from (the commissioning's; its priors stay at
/// the rig file).
pub fn split_fit(base: &Rig, train: &[CalLog], o: &CalOptions, start: Option<&[f64]>) -> Result<Option<Split>, CommissionError> {
    if train.is_empty() || !train.iter().all(|l| l.has(Channel::TDrainC)) {
        return Ok(None);
    }
    let heads: Vec<CalLog> = train.iter().map(|l| head_of(l, o.points_per_channel)).collect::<Result<_, _>>().map_err(CommissionError::Run)?;
    let o = CalOptions { start: start.map(<[f64]>::to_vec), ..o.clone() };
    let (_, cal, _, _) = fit(base, &heads, &o)?;
    Ok(reduce(&cal.rig).map(|reduction| Split { heads, rig: cal.rig, reduction, scored: Part::Tail, only: None }))
}

/// A fold scored on training logs' starts (their first 1 − [`SPLIT_FRACTION`](crate::calibration::margin::SPLIT_FRACTION),
/// from rest: the cold start the first fold never scores): the calibration
/// on the training logs with the scored logs' fit points after their split
/// only, and its reduction. `only`: the one log scored (the others are fitted
/// whole, [`HeadFold::LeaveOneOut`]); `None`: every log scored
/// ([`HeadFold::Tails`]). The fit's replays run from each log's start (the
/// state at the split is the model's own, driven by the logged inputs); the
/// scored logs' fit points, and the current rows η_m is taken from, lie
/// after their split only, so no measured temperature of a scored part
/// enters the fit. (The excitation rules that decide which parameters are
/// free look at the whole logs' inputs.) `None` as [`split_fit`]. `start`:
/// as there.
pub fn head_fold_fit(base: &Rig, train: &[CalLog], o: &CalOptions, start: Option<&[f64]>, only: Option<usize>) -> Result<Option<Split>, CommissionError> {
    if train.is_empty() || !train.iter().all(|l| l.has(Channel::TDrainC)) {
        return Ok(None);
    }
    // The split of each scored log; `None`: fitted whole.
    let t_split: Vec<Option<f64>> = train.iter().enumerate().map(|(i, l)| only.is_none_or(|o| o == i).then(|| split_time_s(l, Part::Head))).collect();
    let fitted: Vec<CalLog> = train.iter().zip(&t_split).map(|(l, t)| t.map_or_else(|| l.clone(), |t| l.fitted_from(t, o.points_per_channel))).collect();
    let tails: Vec<CalLog> =
        train.iter().zip(&t_split).map(|(l, t)| t.map_or_else(|| Ok(l.clone()), |t| tail_of(l, t, o.points_per_channel))).collect::<Result<_, _>>().map_err(CommissionError::Run)?;
    let o = CalOptions { start: start.map(<[f64]>::to_vec), ..o.clone() };
    let (base_e, o, _) = with_eta_m(base, eta_m_balance(base, &tails), &o);
    let cal = calibrate(&base_e, &fitted, &o)?;
    Ok(reduce(&cal.rig).map(|reduction| Split { heads: fitted, rig: cal.rig, reduction, scored: Part::Head, only }))
}

/// The rows of `log` from `t0_s` on as a log of its own (for the
/// electrical balance of the head fold; never replayed).
fn tail_of(log: &CalLog, t0_s: f64, points_per_channel: usize) -> Result<CalLog, String> {
    let t = &log.run.time_s;
    rows_of(log, t.partition_point(|&t| t < t0_s)..t.len(), points_per_channel)
}

/// The margin's folds: [`split_fit`] and, with
/// [`CalOptions::margin_head_fold`], [`head_fold_fit`] (when it gives a
/// block the firmware accepts).
pub fn margin_folds(base: &Rig, train: &[CalLog], o: &CalOptions, start: Option<&[f64]>) -> Result<Vec<Split>, CommissionError> {
    let Some(first) = split_fit(base, train, o, start)? else { return Ok(Vec::new()) };
    let mut v = vec![first];
    match o.margin_head_fold {
        HeadFold::Off => {}
        HeadFold::Tails => v.extend(head_fold_fit(base, train, o, start, None)?),
        HeadFold::LeaveOneOut => {
            for i in 0..train.len() {
                v.extend(head_fold_fit(base, train, o, start, Some(i))?);
            }
        }
    }
    Ok(v)
}

/// Validation of the reduction path's firmware drain over the folds of
/// the training missions ([`margin_folds`], [`score_split`] of each fold's
/// reduction, merged).
pub fn validate_margin(base: &Rig, train: &[CalLog], o: &CalOptions, start: Option<&[f64]>) -> Result<Option<MarginValidation>, CommissionError> {
    let folds = margin_folds(base, train, o, start)?;
    if folds.is_empty() {
        return Ok(None);
    }
    let vs = folds.iter().map(|s| score_split(s, train, &s.reduction)).collect::<Result<Vec<_>, _>>()?;
    Ok(Some(merge_folds(vs)))
}
