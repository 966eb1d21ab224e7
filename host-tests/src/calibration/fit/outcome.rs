//! What a calibration gives: each parameter's outcome ([`ParamResult`],
//! [`Status`]), the whole [`Calibration`], and its errors ([`CalError`]).

use crate::calibration::ident::Identifiability;
use crate::calibration::polish::Polish;
use crate::calibration::set::PARAMS;
use crate::rig::Rig;

/// Status of one parameter after calibration.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub enum Status {
    /// Fitted.
    Fitted,
    /// Held at the rig value: the reason.
    Held(String),
}

/// One parameter's outcome.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct ParamResult {
    /// Parameter name ([`crate::calibration::set::PARAMS`]).
    pub name: String,
    /// Multiplier on the rig file.
    pub value: f64,
    /// Approximate 95 % interval of the multiplier (linearised, prior
    /// included, inflated by the reduced χ² when above 1); the value itself
    /// for held parameters.
    pub interval95: (f64, f64),
    /// Whether it ended within 1 % (in ln) of a bound.
    pub at_bound: bool,
    /// Fitted or held (with the reason and the excitation that would identify it).
    pub status: Status,
}

/// Outcome of a calibration.
#[derive(Debug, Clone)]
pub struct Calibration {
    /// Multipliers for every [`PARAMS`](crate::calibration::set::PARAMS) entry (1 = held at the rig file).
    pub theta: Vec<f64>,
    /// Per parameter.
    pub params: Vec<ParamResult>,
    /// The calibrated rig.
    pub rig: Rig,
    /// Data part of the objective (Σ (r/σ_d)²) at the rig file and at the end.
    pub chi2_before_after: (f64, f64),
    /// Number of data points.
    pub n_points: usize,
    /// Model runs spent (one per log per evaluation).
    pub model_runs: usize,
    /// Identifiability at the optimum (fitted parameters).
    pub ident: Identifiability,
    /// Warnings: logs with one operating point, parameters nothing identifies.
    pub warnings: Vec<String>,
    /// The final Gauss–Newton polish from LM's end to the optimum.
    pub polish: Polish,
}

/// Errors of a calibration.
#[derive(Debug, thiserror::Error)]
pub enum CalError {
    /// No log given.
    #[error("no training log")]
    NoLogs,
    /// The model does not run on a log with the rig as given.
    #[error("reference model fails on {0}: {1}")]
    Model(String, String),
}

/// Every parameter's result: a held one at 1 with its reason, a fitted one
/// at `theta` with its 95 % interval from `sd_ln` (the free parameters'
/// posterior sd in ln, in the order of `free`) and whether it sits within
/// 1 % of a bound.
pub(super) fn param_results(theta: &[f64], held: &[Option<String>], free: &[usize], sd_ln: &[f64]) -> Vec<ParamResult> {
    PARAMS
        .iter()
        .enumerate()
        .map(|(k, d)| {
            let ln = theta[k].ln();
            let at_bound = (ln - d.lo.ln()).abs() < 0.01 || (d.hi.ln() - ln).abs() < 0.01;
            match &held[k] {
                Some(why) => ParamResult { name: d.name.into(), value: 1.0, interval95: (1.0, 1.0), at_bound: false, status: Status::Held(why.clone()) },
                None => {
                    let j = free.iter().position(|&f| f == k).unwrap_or(0);
                    let sd = sd_ln[j];
                    ParamResult {
                        name: d.name.into(),
                        value: theta[k],
                        interval95: ((ln - 1.96 * sd).exp(), (ln + 1.96 * sd).exp()),
                        at_bound,
                        status: Status::Fitted,
                    }
                }
            }
        })
        .collect()
}
