//! The direct fit: the logs prepared as fit points, the residuals of a
//! trial block, the Jacobian in ln θ, the posterior, the Levenberg–Marquardt
//! restarts ([`identify_direct`]) and the scores of the logs ([`score`]).
//! Separate because it is the numerical method, not the parameter space.

use super::{apply, range, DirectError, DirectFit, DirectOptions, DirectParamResult, LogScore, Target, DEFAULT_HOLD, DIRECT_PARAMS};
use crate::calibration::log::CalLog;
use crate::calibration::replay::{node_errors, node_of, TickInputs};
use crate::lsq::FdProblem;
use crate::measured::Channel;
use eha_guard::model::ReducedParams;
use levenberg_marquardt::LevenbergMarquardt;
use nalgebra::{DMatrix, DVector};
use rayon::prelude::*;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};

/// A training log prepared for the fit: its tick inputs and fit points
/// (tick, node, measured °C, σ K).
struct Prepared {
    inputs: TickInputs,
    ticks: Vec<usize>,
    points: Vec<(usize, usize, f64, f64)>,
}

fn prepare(log: &CalLog, o: &DirectOptions) -> Result<Prepared, String> {
    let inputs = TickInputs::of(log)?;
    let mut points = Vec::new();
    for &ch in &log.channels {
        let Some(node) = node_of(ch) else { continue };
        let sigma = if ch == Channel::TDrainC { o.sigma_drain_k } else { o.sigma_other_k };
        let col = log.run.get(ch).unwrap_or(&[]);
        // every row with a sample, after the first (the model's start)
        // (from the log's `fit_from_s` on: the margin's head fold), thinned
        // by the log's rule (the commissioning's, `CalLog::thinning`)
        let rows: Vec<usize> = (1..log.run.len()).filter(|&i| col[i].is_some() && log.run.time_s[i] >= log.fit_from_s).collect();
        for i in crate::calibration::thinning::thin_rows(&log.run, ch, &rows, o.points_per_channel, log.thinning) {
            if let Some(y) = col[i] {
                points.push((inputs.tick_of(log.run.time_s[i]), node, y, sigma));
            }
        }
    }
    let ticks = points.iter().map(|p| p.0).collect();
    Ok(Prepared { inputs, ticks, points })
}

/// Scaled residuals of every log with parameters `p`.
fn residuals(p: &ReducedParams, logs: &[Prepared], runs: &AtomicUsize) -> Option<Vec<f64>> {
    let parts: Option<Vec<Vec<f64>>> = logs
        .par_iter()
        .map(|l| {
            runs.fetch_add(1, Ordering::Relaxed);
            let t = l.inputs.temperatures_at(p, &l.ticks).ok()?;
            let r: Vec<f64> = l.points.iter().zip(&t).map(|(&(_, node, y, s), t)| (t[node] - y) / s).collect();
            r.iter().all(|x| x.is_finite()).then_some(r)
        })
        .collect();
    Some(parts?.concat())
}

fn to_ln(z: f64, lo: f64, hi: f64) -> f64 {
    lo.ln() + (hi / lo).ln() * 0.5 * (1.0 + z.sin())
}

fn to_z(ln: f64, lo: f64, hi: f64) -> f64 {
    let u = ((ln - lo.ln()) / (hi / lo).ln()).clamp(0.0, 1.0);
    (2.0 * u - 1.0).asin().clamp(-1.5, 1.5)
}

/// Step in ln θ of the Jacobian's forward differences.
const JAC_STEP_LN: f64 = 0.05;

/// Jacobian of the scaled data residuals in ln θ of the parameters `idx` at
/// `theta` (stepping inwards from an upper bound), with the residuals.
fn jacobian_ln(p0: &ReducedParams, logs: &[Prepared], theta: &[f64], idx: &[usize], runs: &AtomicUsize) -> Option<(DVector<f64>, DMatrix<f64>)> {
    let r0 = DVector::from_vec(residuals(&apply(p0, theta)?, logs, runs)?);
    let cols: Option<Vec<DVector<f64>>> = idx
        .par_iter()
        .map(|&k| {
            let h = if theta[k].ln() + JAC_STEP_LN > range(k, p0).1.ln() { -JAC_STEP_LN } else { JAC_STEP_LN };
            let mut th = theta.to_vec();
            th[k] = (theta[k].ln() + h).exp();
            let r = DVector::from_vec(residuals(&apply(p0, &th)?, logs, runs)?);
            Some((r - &r0) / h)
        })
        .collect();
    Some((r0.clone(), DMatrix::from_columns(&cols?)))
}

/// Posterior covariance of ln θ over `idx` (data Jacobian `j`, priors).
fn posterior(j: &DMatrix<f64>, idx: &[usize]) -> DMatrix<f64> {
    let mut h = j.transpose() * j;
    for (a, &k) in idx.iter().enumerate() {
        h[(a, a)] += 1.0 / DIRECT_PARAMS[k].prior_sigma_ln.powi(2);
    }
    h.try_inverse().unwrap_or_else(|| DMatrix::from_diagonal(&DVector::from_iterator(idx.len(), idx.iter().map(|&k| DIRECT_PARAMS[k].prior_sigma_ln.powi(2)))))
}

/// Levenberg–Marquardt starts at most (from the reduction, then from the
/// best point while a restart gains > 1 %).
const MAX_LM_STARTS: usize = 3;

/// Identifies the direct set on `train`, starting from (and regularised
/// towards) the reduction `p0`. Deterministic: the residuals do not depend
/// on thread timing and LM's budget is counted in its sequential calls.
pub fn identify_direct(p0: &ReducedParams, train: &[CalLog], o: &DirectOptions) -> Result<DirectFit, DirectError> {
    if train.is_empty() {
        return Err(DirectError::NoLogs);
    }
    let logs: Vec<Prepared> = train.iter().map(|l| prepare(l, o)).collect::<Result<_, _>>().map_err(DirectError::Model)?;
    if logs.iter().all(|l| l.points.is_empty()) {
        return Err(DirectError::NoData);
    }
    let runs = AtomicUsize::new(0);
    let n = DIRECT_PARAMS.len();
    let ones = vec![1.0; n];
    let ranges: Vec<(f64, f64)> = (0..n).map(|k| range(k, p0)).collect();
    apply(p0, &ones).ok_or_else(|| DirectError::Model("the firmware model rejects the starting parameters".into()))?;
    // 1. Which parameters act on a logged node and are held by the caller.
    let logged = |ch: Channel| train.iter().any(|l| l.has(ch));
    let mut held: Vec<Option<String>> = DIRECT_PARAMS
        .iter()
        .map(|d| {
            if o.hold.contains(&d.name) {
                return Some(if DEFAULT_HOLD.contains(&d.name) { "held by default (DEFAULT_HOLD: correlated with other parameters on one-at-a-time logs, or measured to generalise worse)".into() } else { "held by the caller".into() });
            }
            let needs = match d.target {
                Target::CapBall | Target::Outer(2) | Target::FilmBall => Some(Channel::TBallvalveC),
                Target::CapMain | Target::Outer(1) => Some(Channel::TBlockC),
                _ => None,
            };
            needs.filter(|c| !logged(*c)).map(|c| format!("no training log carries `{}`", c.name()))
        })
        .collect();
    // 2. Screening at the reduction: hold what the logs do not identify.
    let cand: Vec<usize> = (0..n).filter(|&k| held[k].is_none()).collect();
    let (r0, j0) = jacobian_ln(p0, &logs, &ones, &cand, &runs).ok_or_else(|| DirectError::Model("the reduced model failed in the screening Jacobian".into()))?;
    let chi2_before = r0.norm_squared();
    let c0 = posterior(&j0, &cand);
    for (a, &k) in cand.iter().enumerate() {
        let ratio = c0[(a, a)].max(0.0).sqrt() / DIRECT_PARAMS[k].prior_sigma_ln;
        if ratio > o.hold_ratio {
            held[k] = Some(format!("the logs reduce its prior sd only to {:.0} %", 100.0 * ratio));
        }
    }
    let free: Vec<usize> = (0..n).filter(|&k| held[k].is_none()).collect();
    // 3. LM on the free parameters (bounded z), data rows + prior rows.
    let best: Mutex<(f64, Vec<f64>)> = Mutex::new((f64::INFINITY, ones.clone()));
    let evals = Arc::new(AtomicUsize::new(0));
    let lm_run = |th0: &[f64]| -> bool {
        let before = best.lock().map(|b| b.0).unwrap_or(f64::INFINITY);
        let theta_of = |z: &[f64]| -> Vec<f64> {
            let mut th = th0.to_vec();
            for (j, &k) in free.iter().enumerate() {
                th[k] = to_ln(z[j], ranges[k].0, ranges[k].1).exp();
            }
            th
        };
        let residual = |z: &[f64]| -> Option<DVector<f64>> {
            let th = theta_of(z);
            let p = apply(p0, &th)?;
            let mut r = residuals(&p, &logs, &runs)?;
            r.extend(free.iter().map(|&k| th[k].ln() / DIRECT_PARAMS[k].prior_sigma_ln));
            let total: f64 = r.iter().map(|x| x * x).sum();
            let mut b = best.lock().ok()?;
            if total < b.0 {
                *b = (total, th);
            }
            Some(DVector::from_vec(r))
        };
        let z0 = DVector::from_vec(free.iter().map(|&k| to_z(th0[k].ln(), ranges[k].0, ranges[k].1)).collect());
        let patience = (o.max_evals / (free.len() + 1)).max(2);
        let _ = LevenbergMarquardt::new()
            .with_ftol(1e-8)
            .with_xtol(1e-6)
            .with_patience(patience)
            .minimize(FdProblem::new(&residual, z0, 0.01).with_budget(evals.clone(), o.max_evals));
        let after = best.lock().map(|b| b.0).unwrap_or(f64::INFINITY);
        after < 0.99 * before
    };
    if !free.is_empty() {
        for _ in 0..MAX_LM_STARTS {
            let Ok(th0) = best.lock().map(|b| b.1.clone()) else { break };
            if !lm_run(&th0) || evals.load(Ordering::Relaxed) >= o.max_evals {
                break;
            }
        }
    }
    let theta = best.into_inner().map(|b| b.1).unwrap_or(ones.clone());
    let params = apply(p0, &theta).ok_or_else(|| DirectError::Model("the firmware model rejects the fitted parameters".into()))?;
    // 4. Identifiability at the optimum.
    let (r1, j1) = jacobian_ln(p0, &logs, &theta, &free, &runs).ok_or_else(|| DirectError::Model("the reduced model failed in the final Jacobian".into()))?;
    let chi2_after = r1.norm_squared();
    let n_points = r1.len();
    let s2 = (chi2_after / n_points.saturating_sub(free.len()).max(1) as f64).max(1.0);
    let c1 = posterior(&j1, &free);
    let sd0: Vec<f64> = (0..free.len()).map(|a| c1[(a, a)].max(0.0).sqrt()).collect();
    let (mut correlated, mut max_rho) = (Vec::new(), 0.0f64);
    for a in 0..free.len() {
        for b in a + 1..free.len() {
            let rho = c1[(a, b)] / (sd0[a] * sd0[b]).max(1e-300);
            max_rho = max_rho.max(rho.abs());
            if rho.abs() >= o.corr_threshold {
                correlated.push((DIRECT_PARAMS[free[a]].name.to_string(), DIRECT_PARAMS[free[b]].name.to_string(), rho));
            }
        }
    }
    let results = (0..n)
        .map(|k| {
            let d = &DIRECT_PARAMS[k];
            match free.iter().position(|&f| f == k) {
                Some(a) => {
                    let (ln, sd) = (theta[k].ln(), sd0[a] * s2.sqrt());
                    DirectParamResult {
                        name: d.name.into(),
                        value: theta[k],
                        sd_ln: sd,
                        interval95: ((ln - 1.96 * sd).exp(), (ln + 1.96 * sd).exp()),
                        at_bound: (ln - ranges[k].0.ln()).abs() < 0.01 || (ranges[k].1.ln() - ln).abs() < 0.01,
                        held: None,
                    }
                }
                None => DirectParamResult { name: d.name.into(), value: 1.0, sd_ln: 0.0, interval95: (1.0, 1.0), at_bound: false, held: held[k].clone() },
            }
        })
        .collect();
    let train_scores = train
        .iter()
        .zip(&logs)
        .map(|(l, pl)| {
            Ok(LogScore { log: l.name.clone(), before: node_errors(p0, l, &pl.inputs)?, after: node_errors(&params, l, &pl.inputs)? })
        })
        .collect::<Result<Vec<_>, String>>()
        .map_err(DirectError::Model)?;
    Ok(DirectFit {
        params,
        theta,
        results,
        correlated,
        max_abs_correlation: max_rho,
        chi2_before_after: (chi2_before, chi2_after),
        n_points,
        model_runs: runs.load(Ordering::Relaxed),
        train: train_scores,
    })
}

/// Scores the reduction `p0` and the direct parameters `p` on `logs`
/// (held-out logs: per node channel, every tick, the rule of
/// `check_reduced`'s measured columns).
pub fn score(p0: &ReducedParams, p: &ReducedParams, logs: &[CalLog]) -> Result<Vec<LogScore>, String> {
    logs.iter()
        .map(|l| {
            let inputs = TickInputs::of(l)?;
            Ok(LogScore { log: l.name.clone(), before: node_errors(p0, l, &inputs)?, after: node_errors(p, l, &inputs)? })
        })
        .collect()
}
