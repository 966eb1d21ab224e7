//! The Laplace evidence's parts: the Occam factor of a structure (prior
//! density and posterior volume from the whitened JᵀJ), and the
//! discrepancy amplitude's grid read at a point or marginalised.

use super::super::fit::{FitResult, Point};
use super::super::model::ParamSpec;
use super::{Whitener, LN_AMPLITUDE_GRID, MAX_DISCREPANCY_K};
use crate::measured::{Channel, MeasuredRun};
use nalgebra::DMatrix;

/// Channel runs of `pts` (grouped by channel, rows increasing, as
/// [`super::analysis::fit_points`] makes them): (channel, index range).
pub(super) fn channel_runs(pts: &[Point]) -> Vec<(Channel, std::ops::Range<usize>)> {
    let mut out: Vec<(Channel, std::ops::Range<usize>)> = Vec::new();
    for (i, (ch, _)) in pts.iter().enumerate() {
        match out.last_mut() {
            Some((c, r)) if c == ch => r.end = i + 1,
            _ => out.push((*ch, i..i + 1)),
        }
    }
    out
}

/// Log prior density and prior precision of each parameter in ln-value
/// space: Gaussian where the spec has a prior; otherwise uniform between
/// the bounds, with the uniform's precision (12/range²) standing in for
/// its curvature so that a parameter the data do not inform costs nothing.
pub(super) fn prior_terms(specs: &[ParamSpec], values: &[f64]) -> (f64, Vec<f64>) {
    let mut lp = 0.0;
    let mut prec = Vec::with_capacity(specs.len());
    for (s, v) in specs.iter().zip(values) {
        match s.prior_sigma_ln {
            Some(sig) => {
                let z = (v / s.start).ln() / sig;
                lp += -0.5 * z * z - (sig * (2.0 * std::f64::consts::PI).sqrt()).ln();
                prec.push(1.0 / (sig * sig));
            }
            None => {
                let range = (s.hi / s.lo).ln().max(1e-9);
                lp -= range.ln();
                prec.push(12.0 / (range * range));
            }
        }
    }
    (lp, prec)
}

/// The Occam factor of the Laplace evidence of the structure `fit`
/// (parameters `specs`, nuisance then extension), nats: ln prior density +
/// ln posterior volume, with the discrepancy amplitude `amp(channel)` of
/// every channel and time constant `tau_s`; `noise(channel)` the channel's
/// σ. (The likelihood part is [`super::ChannelTerms::log_lik`].) `None` when the
/// fit has no Jacobian or no residual at `all_pts`.
#[allow(clippy::too_many_arguments)]
pub fn log_occam(
    run: &MeasuredRun,
    pts: &[Point],
    all_pts: &[Point],
    fit: &FitResult,
    specs: &[ParamSpec],
    amp: &dyn Fn(Channel) -> f64,
    noise: &dyn Fn(Channel) -> f64,
    tau_s: f64,
) -> Option<f64> {
    super::super::fit::residuals_at(run, &fit.series, all_pts)?;
    let j = fit.jac_ln.as_ref()?;
    let p = j.ncols();
    let mut h = DMatrix::<f64>::zeros(p, p);
    for (ch, range) in channel_runs(pts) {
        let times: Vec<f64> = pts[range.clone()].iter().map(|(_, i)| run.time_s[*i]).collect();
        let w = Whitener::new(&times, amp(ch), noise(ch), tau_s);
        let cols: Vec<Vec<f64>> = (0..p).map(|k| w.whiten(&j.column(k).rows(range.start, range.len()).iter().copied().collect::<Vec<_>>())).collect();
        for a in 0..p {
            for b in a..p {
                let v: f64 = cols[a].iter().zip(&cols[b]).map(|(x, y)| x * y).sum();
                h[(a, b)] += v;
                if a != b {
                    h[(b, a)] += v;
                }
            }
        }
    }
    let values: Vec<f64> = fit.nuisance.iter().chain(&fit.ext).copied().collect();
    let (log_prior, prec) = prior_terms(specs, &values);
    for (k, q) in prec.iter().enumerate() {
        h[(k, k)] += q;
    }
    let ln_det = h.clone().cholesky().map(|c| 2.0 * c.l().diagonal().iter().map(|d| d.ln()).sum::<f64>()).unwrap_or_else(|| {
        h.symmetric_eigenvalues().iter().map(|e| e.max(1e-12).ln()).sum()
    });
    let log_volume = 0.5 * p as f64 * (2.0 * std::f64::consts::PI).ln() - 0.5 * ln_det;
    Some(log_prior + log_volume)
}

/// The log-likelihood on the amplitude grid at amplitude `a_k`: quadratic
/// through the three nearest grid points in ln a (linear left 0.16 nats
/// on a 700-point residual); clamped to the grid's ends.
pub(super) fn grid_at(l: &[f64], a_k: f64) -> f64 {
    let g: &[f64] = &LN_AMPLITUDE_GRID;
    let x = a_k.ln().clamp(g[0], g[g.len() - 1]);
    let i = g.iter().rposition(|v| *v <= x).unwrap_or(0).clamp(1, g.len() - 2);
    let (x0, x1, x2) = (g[i - 1], g[i], g[i + 1]);
    l[i - 1] * (x - x1) * (x - x2) / ((x0 - x1) * (x0 - x2))
        + l[i] * (x - x0) * (x - x2) / ((x1 - x0) * (x1 - x2))
        + l[i + 1] * (x - x0) * (x - x1) / ((x2 - x0) * (x2 - x1))
}

/// Log marginal likelihood of one channel with its discrepancy amplitude
/// free: log-uniform prior on [`lo_k`, [`MAX_DISCREPANCY_K`]], integrated
/// on 48 points in ln a of the amplitude grid's interpolant ([`grid_at`]).
pub(super) fn grid_free(l: &[f64], lo_k: f64) -> f64 {
    let (a, b) = (lo_k.ln(), MAX_DISCREPANCY_K.ln().max(lo_k.ln() + 1e-6));
    let n = 48;
    let d = (b - a) / n as f64;
    let ls: Vec<f64> = (0..n).map(|i| grid_at(l, (a + (i as f64 + 0.5) * d).exp())).collect();
    let m = ls.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    m + (ls.iter().map(|v| (v - m).exp()).sum::<f64>() * d / (b - a)).ln()
}

/// ln(eᵃ + eᵇ).
pub(super) fn log_sum_exp(a: f64, b: f64) -> f64 {
    let m = a.max(b);
    if m == f64::NEG_INFINITY {
        return m;
    }
    m + ((a - m).exp() + (b - m).exp()).ln()
}

