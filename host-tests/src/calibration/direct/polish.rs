//! The direct fit's polish: Gauss–Newton in ln θ from LM's end to the
//! regularised optimum itself. LM stops where its evaluation budget or its
//! step tolerance stops it, a point that depends on the path it took (on
//! big-pump a 1e-6 K nudge of the logs moved the direct path's held-out
//! mix under-prediction 0.541 → 0.694 K and flipped the path choice). The
//! firmware model's replay is a fixed 10 ms tick (no adaptive solver), so
//! the objective is smooth in θ and a Newton-type iteration can converge
//! to a point that is a function of the data.

use nalgebra::{DMatrix, DVector};
use rayon::prelude::*;

/// Step in ln θ of the polish's forward differences: small against the
/// curvature (the replay has no solver noise to rise above).
pub const POLISH_STEP_LN: f64 = 1e-4;

/// Gauss–Newton iterations at most.
pub const POLISH_MAX_ITERS: usize = 10;

/// The polish stops when the predicted decrease of the objective
/// (Σ (r/σ)² + prior rows) is below this.
pub const POLISH_TOL: f64 = 1e-3;

/// Outcome of the polish.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct DirectPolish {
    /// Objective at LM's end and at the polish's end.
    pub objective: (f64, f64),
    /// Iterations taken.
    pub iters: usize,
    /// Predicted decrease of the last step taken (or of the step refused).
    pub last_decrement: f64,
    /// Whether the predicted decrease fell below [`POLISH_TOL`].
    pub converged: bool,
}

/// Polishes `theta` (LM's end) over the `free` parameters within `ranges`;
/// `rows(θ)`: every scaled residual, data rows then the prior rows
/// (`None` where the firmware model rejects θ).
pub fn polish<F>(rows: F, mut theta: Vec<f64>, free: &[usize], ranges: &[(f64, f64)]) -> (Vec<f64>, DirectPolish)
where
    F: Fn(&[f64]) -> Option<DVector<f64>> + Sync,
{
    let Some(mut r) = rows(&theta) else {
        return (theta, DirectPolish { objective: (f64::INFINITY, f64::INFINITY), iters: 0, last_decrement: f64::INFINITY, converged: false });
    };
    let f0 = r.norm_squared();
    let mut out = DirectPolish { objective: (f0, f0), iters: 0, last_decrement: f64::INFINITY, converged: false };
    for it in 0..POLISH_MAX_ITERS {
        // Jacobian of every row in ln θ (forward differences, inward at an upper bound).
        let cols: Option<Vec<DVector<f64>>> = free
            .par_iter()
            .map(|&k| {
                let h = if theta[k].ln() + POLISH_STEP_LN > ranges[k].1.ln() { -POLISH_STEP_LN } else { POLISH_STEP_LN };
                let mut th = theta.clone();
                th[k] = (theta[k].ln() + h).exp();
                Some((rows(&th)? - &r) / h)
            })
            .collect();
        let Some(cols) = cols else { break };
        let j = DMatrix::from_columns(&cols);
        let g = j.transpose() * &r;
        let h = j.transpose() * &j;
        // Active set: a parameter on a bound whose step points outwards is held.
        let mut act: Vec<usize> = (0..free.len()).collect();
        let mut step = DVector::zeros(free.len());
        for _ in 0..free.len() {
            let ha = DMatrix::from_fn(act.len(), act.len(), |a, b| h[(act[a], act[b])]);
            let ga = DVector::from_iterator(act.len(), act.iter().map(|&a| g[a]));
            let Some(d) = ha.cholesky().map(|c| c.solve(&(-ga))) else { break };
            step = DVector::zeros(free.len());
            for (a, &i) in act.iter().enumerate() {
                step[i] = d[a];
            }
            let out_of = |i: usize| {
                let k = free[i];
                let ln = theta[k].ln();
                (ln <= ranges[k].0.ln() + 1e-9 && step[i] < 0.0) || (ln >= ranges[k].1.ln() - 1e-9 && step[i] > 0.0)
            };
            let before = act.len();
            act.retain(|&i| !out_of(i));
            if act.len() == before {
                break;
            }
        }
        let pred = -(g.dot(&step) + 0.5 * step.dot(&(&h * &step))) * 2.0;
        out.last_decrement = pred;
        if pred < POLISH_TOL {
            out.converged = true;
            break;
        }
        // Damped: the full step, else halved until the objective falls.
        let mut taken = false;
        let mut alpha = 1.0;
        for _ in 0..6 {
            let mut th = theta.clone();
            for (i, &k) in free.iter().enumerate() {
                th[k] = (theta[k].ln() + alpha * step[i]).clamp(ranges[k].0.ln(), ranges[k].1.ln()).exp();
            }
            if let Some(rn) = rows(&th) {
                if rn.norm_squared() < r.norm_squared() {
                    theta = th;
                    r = rn;
                    taken = true;
                    break;
                }
            }
            alpha *= 0.5;
        }
        out.iters = it + 1;
        if !taken {
            break;
        }
    }
    out.objective.1 = r.norm_squared();
    (theta, out)
}
