//! The candidate fits: their starts, the physical tier's admission, the
//! ranking by BIC with held-out improvement, the residuals' cross-
//! correlations with the regressors.

use super::*;
use crate::diagnosis::evidence::touched_channels;

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
        let held = |x: &Metrics| -> Vec<(String, f64)> { x.channels.iter().map(|c| (c.channel.clone(), c.heldout_rmse_k)).collect() };
        let (gain, gain_k, gch) = gain_where_it_acts(f.candidate, &held(m_before), &held(&m), o.gain_floor_k);
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

/// The held-out gain of a candidate's fit **where its physics acts**: the
/// best relative reduction of the held-out RMSE, 1 − after/before, over the
/// channels `c` touches ([`touched_channels`]: the probe for a lag, the
/// housings for a draught or a motor–pump path, …) whose calibrated
/// baseline is at least `floor_k` (K; below it a channel is at the noise);
/// returns (gain, reduction in K, channel), (0, 0, "") when no touched
/// channel counts. `before` and `after` are (channel, held-out RMSE in K).
///
/// Why only the touched channels: a candidate is fitted jointly with the
/// ~20-parameter nuisance set, and the refit can move a channel the
/// candidate's physics does not reach. Measured on the emulator's
/// identification run 2813 (a hidden draught): `sensor-lag` fitted τ 1.7 s
/// (the lag nearly off) and passed the per-channel check with 47 % on
/// t_ballvalve_c (0.87 → 0.46 K), a gain of the nuisance refit; on the
/// probe it acts on, t_oil_c, 25 % (0.92 → 0.69 K), below the 30 % bar. It
/// was named at P 1.00, a wrong cause.
pub fn gain_where_it_acts(c: Candidate, before: &[(String, f64)], after: &[(String, f64)], floor_k: f64) -> (f64, f64, String) {
    let touched = touched_channels(c);
    let mut best = (f64::NEG_INFINITY, 0.0, String::new());
    for (ch, b) in before {
        if *b < floor_k || !touched.iter().any(|t| t.name() == ch) {
            continue;
        }
        let Some((_, a)) = after.iter().find(|(n, _)| n == ch) else { continue };
        let g = 1.0 - a / b;
        if g > best.0 {
            best = (g, b - a, ch.clone());
        }
    }
    if best.0.is_finite() { best } else { (0.0, 0.0, String::new()) }
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

#[cfg(test)]
mod tests {
    use super::*;

    fn ch(v: &[(&str, f64)]) -> Vec<(String, f64)> {
        v.iter().map(|(n, k)| (n.to_string(), *k)).collect()
    }

    /// The held-out RMSEs of emulator identification run 2813 (a hidden
    /// draught), calibrated baseline and `sensor-lag`'s joint fit, K, as
    /// `eha-sim diagnose` measured them: the lag's best channel overall is
    /// t_ballvalve_c (47 %), which its physics does not reach; on the probe
    /// it acts on, 25 %, below the 30 % bar. The draught's own channels.
    #[test]
    fn a_gain_counts_only_where_the_candidate_acts() {
        let before = ch(&[("t_motor_c", 0.460), ("t_pump_c", 0.793), ("t_block_c", 1.795), ("t_ballvalve_c", 0.872), ("t_oil_c", 0.915)]);
        let lag = ch(&[("t_motor_c", 0.308), ("t_pump_c", 0.595), ("t_block_c", 1.466), ("t_ballvalve_c", 0.461), ("t_oil_c", 0.685)]);
        let (g, k, c) = gain_where_it_acts(Candidate::SensorLag, &before, &lag, 0.15);
        assert_eq!(c, "t_oil_c");
        assert!((g - (1.0 - 0.685 / 0.915)).abs() < 1e-12 && g < 0.3, "gain {g}");
        assert!((k - 0.230).abs() < 1e-9);
        // The same numbers judged as a draught: its best touched channel is
        // t_motor_c (33 %), not t_ballvalve_c.
        let (g, _, c) = gain_where_it_acts(Candidate::ForcedConvection, &before, &lag, 0.15);
        assert_eq!(c, "t_motor_c");
        assert!((g - (1.0 - 0.308 / 0.460)).abs() < 1e-12);
        // A touched channel at the noise floor does not count: no gain.
        let quiet = ch(&[("t_oil_c", 0.12), ("t_pump_c", 0.9)]);
        let fitted = ch(&[("t_oil_c", 0.02), ("t_pump_c", 0.1)]);
        assert_eq!(gain_where_it_acts(Candidate::SensorLag, &quiet, &fitted, 0.15), (0.0, 0.0, String::new()));
    }
}
