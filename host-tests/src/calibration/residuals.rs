//! The calibration's objective: the logs' scaled data residuals at a
//! multiplier vector and their Jacobian in ln θ, shared by the
//! Levenberg–Marquardt fit (`fit`) and the final polish (`polish`).

use super::log::CalLog;
use super::set::{apply, PARAMS};
use crate::rig::Rig;
use nalgebra::{DMatrix, DVector};
use rayon::prelude::*;
use std::sync::atomic::{AtomicUsize, Ordering};

/// Data σ: the common one, and the drain channel's weight on it.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Sigma {
    /// σ of every channel, K.
    pub(crate) data_k: f64,
    /// `t_drain_c` residuals are multiplied by this as well.
    pub(crate) drain_weight: f64,
    /// Gauss–Newton iterations of the polish from LM's end
    /// ([`CalOptions::polish_iters`](super::CalOptions::polish_iters)).
    pub(crate) polish_iters: usize,
}

/// Scaled data residuals of every log at full multiplier vector `theta`.
pub(crate) fn data_residuals(base: &Rig, logs: &[CalLog], theta: &[f64], sigma: Sigma, runs: &AtomicUsize) -> Option<Vec<f64>> {
    let rig = apply(base, theta);
    let parts: Option<Vec<Vec<f64>>> = logs
        .par_iter()
        .map(|l| {
            runs.fetch_add(1, Ordering::Relaxed);
            let s = l.simulate(&rig).ok()?;
            let r = l.residuals(&s);
            let w = |ch: crate::measured::Channel| if ch == crate::measured::Channel::TDrainC { sigma.drain_weight } else { 1.0 };
            r.iter().all(|x| x.is_finite()).then(|| r.into_iter().zip(&l.points).map(|(x, p)| x * w(p.0) / sigma.data_k).collect())
        })
        .collect();
    Some(parts?.concat())
}

/// Jacobian of the scaled data residuals with respect to ln θ of the
/// parameters `idx`, at `theta` (forward differences of 0.05 in ln θ,
/// stepping inwards from an upper bound).
pub(crate) fn jacobian_ln(base: &Rig, logs: &[CalLog], theta: &[f64], idx: &[usize], sigma: Sigma, runs: &AtomicUsize) -> Option<(DVector<f64>, DMatrix<f64>)> {
    let r0 = DVector::from_vec(data_residuals(base, logs, theta, sigma, runs)?);
    let cols: Option<Vec<DVector<f64>>> = idx
        .par_iter()
        .map(|&k| {
            let d = &PARAMS[k];
            let h = if (theta[k].ln() + 0.05) > d.hi.ln() { -0.05 } else { 0.05 };
            let mut th = theta.to_vec();
            th[k] = (theta[k].ln() + h).exp();
            let r = DVector::from_vec(data_residuals(base, logs, &th, sigma, runs)?);
            Some((r - &r0) / h)
        })
        .collect();
    Some((r0.clone(), DMatrix::from_columns(&cols?)))
}
