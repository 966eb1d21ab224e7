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
    /// Spacing in ln θ of the lattice the model is evaluated on
    /// ([`on_lattice`]; 0: off).
    pub(crate) lattice_ln: f64,
    /// Prior width σ in ln θ of every [`PARAMS`] entry
    /// ([`CalOptions::prior_sigma`](super::CalOptions::prior_sigma) over
    /// the set's own).
    pub(crate) prior_ln: [f64; PARAMS.len()],
    /// The polish's reduced χ² s² when fixed by the caller
    /// ([`CalOptions::polish_s2`](super::CalOptions::polish_s2)).
    pub(crate) polish_s2: Option<f64>,
}

/// Spacing, in ln θ, of the lattice on which every multiplier vector of a
/// calibration is evaluated ([`on_lattice`]): 1e-4, a 0.01 % change of a
/// multiplier, far below any parameter's interval (tens of %) and 1/500 of
/// the Jacobian's 0.05 difference step (which therefore lands on the
/// lattice too). Why: the replays' adaptive solver makes the model output a
/// discontinuous function of θ at the level of its error (a vector that
/// differs in its last digits takes another step sequence; near an optimum
/// ~10 χ² units at rtol 1e-5), so the last-digit differences that any
/// change of the data puts into the optimiser's steps grew, through its
/// accept/reject decisions, into another end point (measured on big-pump: a
/// 1e-9 K nudge of the logs moved the held-out headline 0.795 K). On the
/// lattice two vectors that differ by less than its spacing give the
/// bit-identical model run.
pub const THETA_LATTICE_LN: f64 = 1e-4;

/// `x` (> 0) with its logarithm rounded to the lattice of spacing
/// `step_ln` ([`on_lattice`] for one number without bounds); unchanged
/// when `step_ln` is 0.
pub fn on_lattice_value(x: f64, step_ln: f64) -> f64 {
    if step_ln <= 0.0 || x <= 0.0 {
        return x;
    }
    lattice_point(x, step_ln, f64::NEG_INFINITY, f64::INFINITY)
}

/// The lattice point of spacing `step_ln` nearest to ln `x`, its index
/// clamped to `[lo, hi]` (lattice indices).
fn lattice_point(x: f64, step_ln: f64, lo: f64, hi: f64) -> f64 {
    ((x.ln() / step_ln).round().clamp(lo, hi) * step_ln).exp()
}

/// `theta` with every ln θ rounded to the lattice of spacing `step_ln`, to
/// its nearest point within the parameter's bounds (a bound that is not on
/// the lattice is replaced by the lattice point next inside it, < 1e-4 in
/// ln away); unchanged when `step_ln` is 0. Idempotent: a vector on the
/// lattice maps to itself, so the multipliers a calibration keeps are the
/// ones its model runs used.
pub fn on_lattice(theta: &[f64], step_ln: f64) -> Vec<f64> {
    if step_ln <= 0.0 {
        return theta.to_vec();
    }
    theta
        .iter()
        .zip(PARAMS.iter())
        .map(|(&t, d)| {
            lattice_point(t, step_ln, (d.lo.ln() / step_ln).ceil(), (d.hi.ln() / step_ln).floor())
        })
        .collect()
}

/// Scaled data residuals of every log at full multiplier vector `theta`.
pub(crate) fn data_residuals(base: &Rig, logs: &[CalLog], theta: &[f64], sigma: Sigma, runs: &AtomicUsize) -> Option<Vec<f64>> {
    let rig = apply(base, &on_lattice(theta, sigma.lattice_ln));
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

#[cfg(test)]
mod tests {
    use super::*;

    /// Two vectors that differ in their last digits map to the same
    /// lattice point; the lattice point maps to itself; it stays within a
    /// cell of the vector (half a cell away from a bound) and within the
    /// bounds, also for a vector on or beyond them.
    #[test]
    fn lattice_absorbs_last_digits() {
        let mut a: Vec<f64> = PARAMS.iter().enumerate().map(|(k, d)| (d.lo * d.hi).sqrt() * (1.0 + 0.013 * k as f64)).collect();
        a[0] = PARAMS[0].lo;
        a[1] = PARAMS[1].hi;
        let b: Vec<f64> = a.iter().map(|x| x * (1.0 + 3e-15)).collect();
        let (la, lb) = (on_lattice(&a, THETA_LATTICE_LN), on_lattice(&b, THETA_LATTICE_LN));
        assert_eq!(la, lb);
        assert_eq!(on_lattice(&la, THETA_LATTICE_LN), la);
        for ((x, y), d) in a.iter().zip(&la).zip(PARAMS.iter()) {
            let (lo, hi) = (d.lo.ln(), d.hi.ln());
            assert!(y.ln() >= lo && y.ln() <= hi, "{}: {y} outside its bounds", d.name);
            if x.ln() >= lo && x.ln() <= hi {
                assert!((x.ln() - y.ln()).abs() <= THETA_LATTICE_LN, "{}: {x} -> {y}", d.name);
            }
        }
        let ones = vec![1.0; PARAMS.len()];
        assert_eq!(on_lattice(&ones, THETA_LATTICE_LN), ones);
        assert_eq!(on_lattice(&a, 0.0), a);
        assert_eq!(on_lattice_value(0.2468190011, THETA_LATTICE_LN), on_lattice_value(0.2468190011 * (1.0 + 2e-15), THETA_LATTICE_LN));
    }
}
