//! The final polish of a calibration: from Levenberg–Marquardt's end to
//! the regularised optimum, Gauss–Newton in ln θ with the prior rows, the
//! bounds as an active set; and the basin check of [`SCALE_PAIR`].
//!
//! The polish replays the logs at [`super::CalOptions::polish_rtol`]
//! ([`POLISH_RTOL`], 1e-6, by default; LM's replays run at 1e-5, where the
//! objective near the optimum is jagged by ~10 χ² units, the solver's own
//! error, the size of the stalls measured there: a damped step lowering
//! nothing).

use super::residuals::{data_residuals, jacobian_ln, on_lattice, Sigma};
use super::log::CalLog;
use super::set::PARAMS;
use crate::rig::Rig;
use nalgebra::{DMatrix, DVector};
use std::sync::atomic::AtomicUsize;

/// Gauss–Newton iterations at most in `polish` from LM's end; twice as
/// many from the reflected start of `polish_basins`, which starts farther
/// from an optimum (objective 37 509 against LM's 1 480 on leaky-heavy; 8
/// iterations left it 5 units short of where 16 took it, and the 1e-9 K
/// nudge then moved leaky-heavy's headline 0.057 K).
pub const POLISH_MAX_ITERS: usize = 8;

/// Relative tolerance of the replay solver in the polish by default, 1e-6
/// (LM's replays: [`crate::simulation::replay::REPLAY_RTOL`], 1e-5).
/// Measured on big-pump's training logs at the rig file
/// (`slow_replay_noise_at_the_last_digit`): the objective's second
/// differences along ln θ of `film_port` in steps of 1e-4 (smooth curvature
/// ≪ 1) are ±15…±490 χ² units at 1e-5 (χ² 1.5–2.2 million), ±1…±52 at
/// 1e-6, ±0.1…±13 at 1e-7; the noise scales with the residuals, so near an
/// optimum (χ² ≈ 1 500) 1e-5 leaves ~10 units, the size of the stalls
/// measured there. With [`CalOptions::polish_rtol`](super::CalOptions) 1e-7
/// the polish converges (decrement 0.05 and 0.017 at its end on big-pump's
/// original and nudged logs, against stalls at 3–90) but into two local
/// minima 11.3 units apart (1484.4 and 1473.1), and the nudge still moved
/// the headline 0.54 K (before the θ lattice, [`super::residuals::THETA_LATTICE_LN`],
/// which makes the last-digit nudge move nothing but leaves both minima);
/// a replay at 1e-7 takes ~5 times as long. The default is 1e-6, with
/// the priors tightened ([`super::fit::PRIOR_SCALE`]): the two together
/// end big-pump's original and nudged (1e-6 K) polishes at 1629.10 and
/// 1629.09 (decrements 2–8 at the end), and move the headline ≤ 0.045 K on
/// both emulator machines; the tightened priors at 1e-5 moved it 0.072 /
/// 0.162 K (docs/commissioning-foreign.md, "Reproducibility").
pub const POLISH_RTOL: f64 = 1e-6;

/// `polish` stops when the predicted decrease of the objective (the
/// Newton decrement gᵀH⁻¹g, in χ² units of the polish's σ, σ_d √s²; one
/// unit is one data point off by one σ) falls below this.
pub const POLISH_TOL: f64 = 0.01;

/// Outcome of the final Gauss–Newton polish of a calibration.
#[derive(Debug, Clone, Default, PartialEq, serde::Serialize)]
pub struct Polish {
    /// Objective (data χ² + prior rows) at each iterate, first = LM's end.
    pub objective: Vec<f64>,
    /// Predicted decrease (Newton decrement) at each iterate.
    pub decrement: Vec<f64>,
    /// Whether the last decrement is below [`POLISH_TOL`].
    pub converged: bool,
    /// Parameters held on a bound in the last step (active set).
    pub on_bound: Vec<String>,
    /// Reduced χ² at LM's end (≥ 1): the data rows' σ is σ_d √s² in the polish.
    pub s2: f64,
    /// Final objective of the polish from the other basin of [`SCALE_PAIR`]
    /// (the one not taken), when both of the pair are free.
    pub other_basin: Option<f64>,
}

/// A parameter within this of a bound (in ln θ) counts as on it in the polish.
const BOUND_LN: f64 = 1e-3;

/// The damped Gauss–Newton step (H + λ diag H) δ = −g over the parameters
/// not `active`; a parameter whose step would leave its bounds joins the
/// active set (held for this step) and the step is solved again.
fn constrained_step(h: &DMatrix<f64>, g: &DVector<f64>, u: &DVector<f64>, free: &[usize], active: &mut [bool], lambda: f64, lnb: &dyn Fn(usize) -> (f64, f64)) -> Option<DVector<f64>> {
    let n = free.len();
    loop {
        let idx: Vec<usize> = (0..n).filter(|&a| !active[a]).collect();
        let m = idx.len();
        let mut hr = DMatrix::from_fn(m, m, |x, y| h[(idx[x], idx[y])]);
        for x in 0..m {
            hr[(x, x)] *= 1.0 + lambda;
        }
        let gr = DVector::from_iterator(m, idx.iter().map(|&a| g[a]));
        let sr = -hr.cholesky()?.solve(&gr);
        let mut step = DVector::zeros(n);
        let mut crossed = false;
        for (x, &a) in idx.iter().enumerate() {
            let (lo, hi) = lnb(free[a]);
            let v = u[a] + sr[x];
            if v < lo - BOUND_LN || v > hi + BOUND_LN {
                active[a] = true;
                crossed = true;
            }
            step[a] = sr[x];
        }
        if !crossed {
            return Some(step);
        }
    }
}

/// Objective of the calibration at `theta`: data χ² plus the prior rows of
/// the parameters `free`.
fn objective(base: &Rig, logs: &[CalLog], theta: &[f64], free: &[usize], sigma: Sigma, runs: &AtomicUsize) -> Option<f64> {
    let r = data_residuals(base, logs, theta, sigma, runs)?;
    let prior: f64 = free.iter().map(|&k| (theta[k].ln() / sigma.prior_ln[k]).powi(2)).sum();
    Some(r.iter().map(|x| x * x).sum::<f64>() + prior)
}

/// Converges the regularised least squares from `theta` (LM's end) to its
/// optimum: Gauss–Newton in ln θ on the parameters `free` with the prior
/// rows (H = JᵀJ + Σ⁻¹, so a direction the logs do not inform is pulled to
/// the rig file by its prior instead of left where the path put it), the
/// bounds as an active set (a parameter on a bound whose gradient pushes it
/// out is held there), a backtracking line search; until the predicted
/// decrease is below [`POLISH_TOL`]. The LM fit before it
/// stops where its evaluation budget or step tolerance stops it: measured
/// on big-pump, a 1e-9 K nudge of the logs moved that point enough to move
/// the held-out headline by 0.09 K.
pub(super) fn polish(base: &Rig, logs: &[CalLog], theta: Vec<f64>, free: &[usize], sigma: Sigma, runs: &AtomicUsize) -> (Vec<f64>, Polish) {
    let mut out = Polish::default();
    if free.is_empty() {
        out.converged = true;
        return (theta, out);
    }
    // The data rows in units of the misfit the model structure leaves: σ_d
    // times √s², s² the reduced χ² at LM's end (at least 1). A model that
    // cannot follow the machine (χ² per point ≫ 1) then leaves the
    // directions its logs barely inform to the priors, instead of to the
    // path LM took; a model that fits (s² = 1) keeps σ_d.
    let Some(r0) = data_residuals(base, logs, &theta, sigma, runs) else { return (theta, out) };
    out.s2 = sigma.polish_s2.unwrap_or_else(|| (r0.iter().map(|x| x * x).sum::<f64>() / r0.len().saturating_sub(free.len()).max(1) as f64).max(1.0));
    polish_at(base, logs, theta, free, sigma, runs, out, false)
}

/// The ball-valve block's oil film and heat capacity: their ratio (the
/// block's time constant behind its oil) is what the logs determine; their
/// common scale is not, and the objective has two basins along it (measured
/// on leaky-heavy: film ×3.28 with capacity ×2.46, or ×0.58 with ×0.46, the
/// ratio 0.75–0.79 in both; a 1e-9 K nudge of the logs sent LM to either).
pub const SCALE_PAIR: (&str, &str) = ("film_ball", "cap_ball_block");

/// [`polish`] from LM's end and, when both parameters of [`SCALE_PAIR`] are
/// free, again from the same point with the pair's common scale reflected
/// through the rig file (ln θ_a, ln θ_b each minus twice their mean: the
/// ratio kept, the scale s → 1/s), with the same s². The lower objective
/// (data χ² in the first polish's units plus the priors) is taken: the
/// maximum a posteriori among the two basins, whichever of them LM
/// reached first. Records the other basin's objective in
/// [`Polish::other_basin`].
pub(super) fn polish_basins(base: &Rig, logs: &[CalLog], lm_theta: Vec<f64>, free: &[usize], sigma: Sigma, runs: &AtomicUsize) -> (Vec<f64>, Polish) {
    let start = lm_theta.clone();
    let (theta, p) = polish(base, logs, lm_theta, free, sigma, runs);
    let pair = (super::set::index(SCALE_PAIR.0), super::set::index(SCALE_PAIR.1));
    let (Some(a), Some(b)) = pair else { return (theta, p) };
    if !(free.contains(&a) && free.contains(&b)) {
        return (theta, p);
    }
    let mut mirror = start;
    let mean = 0.5 * (mirror[a].ln() + mirror[b].ln());
    for k in [a, b] {
        let (lo, hi) = (PARAMS[k].lo.ln(), PARAMS[k].hi.ln());
        mirror[k] = (mirror[k].ln() - 2.0 * mean).clamp(lo, hi).exp();
    }
    let mirror = on_lattice(&mirror, sigma.lattice_ln);
    let (theta2, p2) = polish_at(base, logs, mirror, free, sigma, runs, Polish { s2: p.s2, ..Polish::default() }, true);
    let (f1, f2) = (p.objective.last().copied().unwrap_or(f64::INFINITY), p2.objective.last().copied().unwrap_or(f64::INFINITY));
    if f2 < f1 {
        (theta2, Polish { other_basin: Some(f1), ..p2 })
    } else {
        (theta, Polish { other_basin: Some(f2), ..p })
    }
}

/// The Gauss–Newton iterations of [`polish`] with `out.s2` set; `far`: the
/// start is far from an optimum (the reflected start of [`polish_basins`]),
/// twice [`POLISH_MAX_ITERS`].
#[allow(clippy::too_many_arguments)]
pub(super) fn polish_at(base: &Rig, logs: &[CalLog], mut theta: Vec<f64>, free: &[usize], sigma: Sigma, runs: &AtomicUsize, mut out: Polish, far: bool) -> (Vec<f64>, Polish) {
    let s2 = out.s2;
    let lnb = |k: usize| (PARAMS[k].lo.ln(), PARAMS[k].hi.ln());
    let sigma = Sigma { data_k: sigma.data_k * s2.sqrt(), ..sigma };
    let Some(mut f) = objective(base, logs, &theta, free, sigma, runs) else { return (theta, out) };
    let iters = if far { 2 * sigma.polish_iters } else { sigma.polish_iters };
    for _ in 0..iters {
        out.objective.push(f);
        let Some((r, j)) = jacobian_ln(base, logs, &theta, free, sigma, runs) else { break };
        let n = free.len();
        let inv_var = DVector::from_iterator(n, free.iter().map(|&k| sigma.prior_ln[k].powi(-2)));
        let u = DVector::from_iterator(n, free.iter().map(|&k| theta[k].ln()));
        let g = j.transpose() * &r + u.component_mul(&inv_var);
        let mut h = j.transpose() * &j;
        for a in 0..n {
            h[(a, a)] += inv_var[a];
        }
        // Active set: on a bound (within BOUND_LN) with the descent pointing
        // out, then every parameter whose step would cross a bound, until
        // the step stays inside (each is held where it is for this step).
        let near = |a: usize, k: usize| {
            let (lo, hi) = lnb(k);
            (u[a] <= lo + BOUND_LN && g[a] > 0.0) || (u[a] >= hi - BOUND_LN && g[a] < 0.0)
        };
        let mut active: Vec<bool> = free.iter().enumerate().map(|(a, &k)| near(a, k)).collect();
        out.on_bound = (0..n).filter(|&a| active[a]).map(|a| PARAMS[free[a]].name.to_string()).collect();
        // Damped Gauss–Newton: H + λ diag(H), λ from 0 up while the step
        // does not lower the objective.
        let mut moved = false;
        let mut dec0 = None;
        for lambda in [0.0, 0.03, 0.3, 3.0, 30.0] {
            let Some(step) = constrained_step(&h, &g, &u, free, &mut active, lambda, &lnb) else { break };
            let dec = -g.dot(&step);
            if dec0.is_none() {
                out.decrement.push(dec);
                dec0 = Some(dec);
                if dec < POLISH_TOL {
                    out.converged = true;
                    break;
                }
            }
            let mut th = theta.clone();
            for (a, &k) in free.iter().enumerate() {
                let (lo, hi) = lnb(k);
                th[k] = (u[a] + step[a]).clamp(lo, hi).exp();
            }
            let th = on_lattice(&th, sigma.lattice_ln);
            if let Some(f1) = objective(base, logs, &th, free, sigma, runs) {
                if f1 < f {
                    (theta, f, moved) = (th, f1, true);
                    break;
                }
            }
        }
        if out.converged || !moved {
            break;
        }
    }
    out.objective.push(f);
    (theta, out)
}
