//! The candidate fits: their starts, the physical tier's admission, the
//! ranking by BIC with held-out improvement, the residuals' cross-
//! correlations with the regressors.

use super::*;

/// Starts per candidate fit in each tier (see [`diagnose`]'s body):
/// nominal nuisance values, the calibrated baseline with the candidate
/// nearly off, and the calibrated baseline with the candidate at its
/// [`typical_magnitude`].
pub const STARTS_PER_CANDIDATE: usize = 3;

/// Where a candidate fit starts.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Start {
    /// Nominal nuisance values, the candidate at its spec start.
    Nominal,
    /// The calibrated baseline, the candidate nearly off ([`fit_from`]).
    BaseOff,
    /// The calibrated baseline, the candidate at [`typical_magnitude`].
    BaseTypical,
}

/// The middle (geometric mean) of candidate `c`'s physically typical
/// magnitude range ([`crate::physics::candidates::magnitude_range`]: copper
/// α, a dead-end pocket's minutes, 2–4 % seal friction, 60–150 W churning at
/// 1500 rpm, a flange's W/K, a draught's m/s), clamped into `spec`'s bounds;
/// the spec's own start when the range is a placeholder. A prior value
/// from physics, the same for every log.
pub fn typical_magnitude(c: Candidate, spec: &crate::diagnosis::model::ParamSpec) -> f64 {
    let (lo, hi) = crate::physics::candidates::magnitude_range(c);
    if hi > lo { (lo * hi).sqrt().clamp(spec.lo, spec.hi) } else { spec.start }
}

/// Candidate `c` fitted jointly with the nuisance set from the baseline
/// `base`, with `c`'s first parameter at its [`typical_magnitude`] (any
/// further ones at their spec starts); its Jacobian at the best point owed.
pub fn fit_typical(sim: &dyn Simulator, run: &MeasuredRun, pts: &[Point], c: Candidate, base: &FitResult, o: &DiagnoseOptions) -> Option<FitResult> {
    let e: Vec<f64> = sim.extension_params(c).iter().enumerate().map(|(k, s)| if k == 0 { typical_magnitude(c, s) } else { s.start }).collect();
    fit_deferred(sim, run, pts, c, &base.nuisance, Some(&e), o.fit)
}

/// Candidate `c` fitted jointly with the nuisance set from the baseline
/// `base`, with `c`'s parameters nearly off (a tenth of their log range
/// above the lower bound); its Jacobian at the best point owed
/// ([`fit_deferred`], [`settle_jacobian`]).
pub fn fit_from(sim: &dyn Simulator, run: &MeasuredRun, pts: &[Point], c: Candidate, base: &FitResult, o: &DiagnoseOptions) -> Option<FitResult> {
    let off: Vec<f64> = sim.extension_params(c).iter().map(|s| s.lo * (s.hi / s.lo).powf(0.1)).collect();
    fit_deferred(sim, run, pts, c, &base.nuisance, Some(&off), o.fit)
}

/// Whether candidate `c` can be named on `run` (training window before
/// `split`) with `sim`'s nuisance set ([`identifiable`]; the per-housing
/// rules apply when the set calibrates a housing's outer transfer).
pub(crate) fn identifiable_here(c: Candidate, run: &MeasuredRun, split: f64, sim: &dyn Simulator) -> Result<(), &'static str> {
    let housing_outer_calibrated = sim.nuisance().iter().any(|p| p.name.starts_with(HOUSING_OUTER_PREFIX));
    identifiable(c, run, split, housing_outer_calibrated)
}

/// The diagnosis made again with `sim`'s physical calibration set, its model
/// runs counting the `spent` ones of the global tier; `None` when the model
/// has no physical set.
pub(super) fn in_physical_tier(
    run: &MeasuredRun,
    sim: &dyn Simulator,
    o: &DiagnoseOptions,
    spent: usize,
    phases: &[PhaseCost],
) -> Option<Result<Diagnosis, DiagnoseError>> {
    let p = sim.physical_set()?;
    Some(diagnose_tier(run, &*p, o, false).map(|mut d| {
        d.sims += spent;
        d.phases.splice(0..0, phases.iter().cloned());
        d
    }))
}

/// The ranking of `fits` against the baseline `base` (metrics `m_before`):
/// BIC, held-out gains and whether each candidate qualifies, unsorted;
/// and each fit's metrics, in the order of `fits`.
#[allow(clippy::too_many_arguments)]
pub(super) fn rank(
    run: &MeasuredRun,
    sim: &dyn Simulator,
    o: &DiagnoseOptions,
    split: f64,
    n: usize,
    base: &FitResult,
    m_before: &Metrics,
    fits: &[FitResult],
) -> (Vec<RankEntry>, Vec<Metrics>) {
    let nuis_len = sim.nuisance().len();
    let bic_none = bic(base.rss, n, nuis_len);
    let mut ranking = vec![RankEntry {
        cause: "none".into(),
        bic: bic_none,
        heldout_rmse_k: m_before.heldout_rmse_k,
        train_rmse_k: m_before.train_rmse_k,
        delta_bic: 0.0,
        heldout_gain: 0.0,
        gain_channel: String::new(),
        channel_heldout_k: m_before.channels.iter().map(|c| (c.channel.clone(), c.heldout_rmse_k)).collect(),
        params: vec![],
        qualifies: false,
        note: String::new(),
    }];
    let mut fit_metrics = Vec::with_capacity(fits.len());
    for f in fits {
        let m = metrics(run, &f.series, split, o.ljung_box_lags);
        let k = nuis_len + f.ext.len();
        let b = bic(f.rss, n, k);
        let (mut gain, mut gain_k, mut gch) = (f64::NEG_INFINITY, 0.0, String::new());
        for cb in &m_before.channels {
            let Some(ca) = m.channel(&cb.channel) else { continue };
            if cb.heldout_rmse_k >= o.gain_floor_k {
                let g = 1.0 - ca.heldout_rmse_k / cb.heldout_rmse_k;
                if g > gain {
                    (gain, gain_k, gch) = (g, cb.heldout_rmse_k - ca.heldout_rmse_k, cb.channel.clone());
                }
            }
        }
        let gain = if gain.is_finite() { gain } else { 0.0 };
        let ident = identifiable_here(f.candidate, run, split, sim);
        let pooled_ok = m.heldout_rmse_k <= (1.0 - o.min_pooled_gain) * m_before.heldout_rmse_k;
        ranking.push(RankEntry {
            cause: f.candidate.name().into(),
            bic: b,
            heldout_rmse_k: m.heldout_rmse_k,
            train_rmse_k: m.train_rmse_k,
            delta_bic: bic_none - b,
            heldout_gain: gain,
            gain_channel: gch,
            channel_heldout_k: m.channels.iter().map(|c| (c.channel.clone(), c.heldout_rmse_k)).collect(),
            params: named(&sim.extension_params(f.candidate), &f.ext),
            qualifies: ident.is_ok()
                && bic_none - b >= o.min_delta_bic
                && gain >= o.min_heldout_gain
                && gain_k >= o.min_gain_k
                && pooled_ok,
            note: ident.err().unwrap_or_default().into(),
        });
        fit_metrics.push(m);
    }
    (ranking, fit_metrics)
}

/// Cross-correlation of every channel's calibrated-baseline residual with
/// every regressor of [`regressors`], lags 0…`max_lag_s` every `step_s`
/// (rounded to whole samples, at least one).
pub(super) fn cross_correlations(run: &MeasuredRun, base: &SimSeries, max_lag_s: f64, step_s: f64) -> Vec<XCorr> {
    let regs = regressors(run, base);
    let dt = (run.time_s[run.len() - 1] - run.time_s[0]) / (run.len() - 1) as f64;
    let max_lag = ((max_lag_s / dt).round() as usize).min(run.len() / 3);
    let step = ((step_s / dt).round() as usize).max(1);
    type Residual = (Channel, Vec<Option<f64>>);
    let residuals: Vec<Residual> = Channel::TEMPERATURES
        .into_iter()
        .filter_map(|ch| {
            let (m, y) = (run.get(ch)?, base.channels.get(&ch)?);
            Some((ch, m.iter().zip(y).map(|(m, y)| m.map(|m| y - m)).collect()))
        })
        .collect();
    let pairs: Vec<(&Residual, &(String, Vec<f64>))> =
        residuals.iter().flat_map(|r| regs.iter().map(move |g| (r, g))).collect();
    pairs
        .par_iter()
        .map(|((ch, r), (name, u))| {
            let cc = cross_correlation_every(r, u, max_lag, step);
            let (k, peak) = cc.iter().enumerate().fold((0, 0.0f64), |b, (k, v)| if v.abs() > b.1.abs() { (k, *v) } else { b });
            XCorr { channel: ch.name().into(), regressor: name.clone(), rho0: cc[0], peak_rho: peak, peak_lag_s: (k * step) as f64 * dt }
        })
        .collect()
}
