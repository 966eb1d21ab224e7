//! The diagnosis procedure: baseline, calibration on the
//! training window, residual analysis, candidate fits ranked by BIC with
//! held-out improvement, and the winner's before/after errors.

use super::adequacy::{assess, Adequacy, MisfitRule};
use super::evidence::{posterior_of, Posterior, DISCREPANCY_TAU_S};
use super::fit::{fit_deferred, settle_jacobian, FitOptions, FitResult, Point};
use super::identify::{identifiable, HOUSING_OUTER_PREFIX};
use super::model::{Candidate, Phase, SimSeries, Simulator};
use super::regressors::regressors;
pub use super::stats::{ChannelMetrics, Metrics, XCorr};
use super::stats::{bias, bic, cross_correlation_every, ljung_box, max_abs, rmse};
use crate::measured::{Channel, MeasuredRun};
use rayon::prelude::*;

// The options, results and errors in `types`; the candidate fits' starts,
// checks and ranking in `candidates`; the procedure here.
mod candidates;
mod types;

pub use candidates::*;
pub use types::*;
use candidates::{cross_correlations, in_physical_tier, rank, Start};


/// Records phases of one tier: the runs and the time since the last mark.
struct PhaseLog {
    tier: &'static str,
    t: std::time::Instant,
    phases: Vec<PhaseCost>,
}

impl PhaseLog {
    fn new(tier: &'static str) -> Self {
        PhaseLog { tier, t: std::time::Instant::now(), phases: Vec::new() }
    }
    fn mark(&mut self, name: &str, runs: usize) {
        let secs = self.t.elapsed().as_secs_f64();
        self.t = std::time::Instant::now();
        self.phases.push(PhaseCost { name: format!("{} {name}", self.tier), runs, secs });
    }
}

/// Per-channel and pooled errors of `s` against `run`, training rows
/// before `split`, held out from it.
pub(crate) fn metrics(run: &MeasuredRun, s: &SimSeries, split: f64, lb_lags: usize) -> Metrics {
    let mut channels = Vec::new();
    let (mut tr, mut ho) = (Vec::new(), Vec::new());
    for ch in Channel::TEMPERATURES {
        let (Some(m), Some(y)) = (run.get(ch), s.channels.get(&ch)) else { continue };
        let r: Vec<Option<f64>> = m.iter().zip(y).map(|(m, y)| m.map(|m| y - m)).collect();
        let (rt, rh): (Vec<_>, Vec<_>) = r.iter().zip(&run.time_s).partition(|(_, t)| **t < split);
        let rt: Vec<Option<f64>> = rt.into_iter().map(|x| *x.0).collect();
        let rh: Vec<Option<f64>> = rh.into_iter().map(|x| *x.0).collect();
        if rmse(&r).is_none() {
            continue;
        }
        tr.extend(rt.iter().copied());
        ho.extend(rh.iter().copied());
        channels.push(ChannelMetrics {
            channel: ch.name().into(),
            train_rmse_k: rmse(&rt).unwrap_or(f64::NAN),
            heldout_rmse_k: rmse(&rh).unwrap_or(f64::NAN),
            bias_k: bias(&r).unwrap_or(f64::NAN),
            max_error_k: max_abs(&r).unwrap_or(f64::NAN),
            ljung_box: ljung_box(&r, lb_lags),
        });
    }
    Metrics { channels, train_rmse_k: rmse(&tr).unwrap_or(f64::NAN), heldout_rmse_k: rmse(&ho).unwrap_or(f64::NAN) }
}

/// The time that splits `run` into training and held-out windows, s: a
/// fraction `train_fraction` of its span (at most 0.7) from its start.
pub fn split_time_s(run: &MeasuredRun, train_fraction: f64) -> f64 {
    let (t0, t1) = (run.time_s[0], run.time_s[run.len() - 1]);
    t0 + train_fraction.min(0.7) * (t1 - t0)
}

/// Training fit points: present temperature samples before `split`, thinned
/// uniformly to at most `per_channel` per channel.
pub fn fit_points(run: &MeasuredRun, split: f64, per_channel: usize) -> Vec<Point> {
    points(run, split, per_channel, false)
}

/// The points the evidence is computed on: per channel, the training fit
/// points ([`fit_points`]) followed by the held-out samples thinned with the
/// same step; the held-out part enters as the predictive likelihood of the
/// fitted structure.
pub fn evidence_points(run: &MeasuredRun, split: f64, per_channel: usize) -> Vec<Point> {
    points(run, split, per_channel, true)
}

/// Per channel: the present samples before `split` thinned to at most
/// `per_channel`, then (with `held_out`) those from `split` on, thinned with
/// the same step.
fn points(run: &MeasuredRun, split: f64, per_channel: usize, held_out: bool) -> Vec<Point> {
    let mut pts = Vec::new();
    for ch in Channel::TEMPERATURES {
        let Some(m) = run.get(ch) else { continue };
        let rows: Vec<usize> = (0..run.len()).filter(|&i| run.time_s[i] < split && m[i].is_some()).collect();
        let step = rows.len().div_ceil(per_channel.max(1)).max(1);
        pts.extend(rows.iter().step_by(step).map(|&i| (ch, i)));
        if held_out {
            let held: Vec<usize> = (0..run.len()).filter(|&i| run.time_s[i] >= split && m[i].is_some()).collect();
            pts.extend(held.iter().step_by(step).map(|&i| (ch, i)));
        }
    }
    pts
}

fn named(specs: &[super::model::ParamSpec], v: &[f64]) -> Vec<(String, f64, String)> {
    specs.iter().zip(v).map(|(s, v)| (s.name.clone(), *v, s.unit.clone())).collect()
}

/// Diagnoses `run` against the model `sim` (see the module doc). The
/// nuisance set is first the model's global one; when its calibrated
/// baseline misfits ([`super::adequacy`]) and the model offers the physical
/// calibration set ([`Simulator::physical_set`]), the whole diagnosis is
/// made again with that set (per-housing films, outer transfer, capacities,
/// loss coefficients). Not the physical set from the start: on the
/// synthetic cases it absorbed churning, forced convection and motor–pump
/// conduction (fast tier: each answered `none`, calibrated held-out
/// 0.16–0.19 K), where the global set leaves them to be named.
///
/// Two escalations: early, when the global baseline misfits by
/// [`DiagnoseOptions::misfit`]; late, when no candidate qualifies and the
/// global baseline misfits by the strict [`DiagnoseOptions::physical_misfit`]
/// (so `none` always means "within the strict rule"). In each tier,
/// when a candidate qualifies, the baseline is refitted from the best candidate
/// fits' nuisance values and the better baseline is the one candidates are judged against.
pub fn diagnose(run: &MeasuredRun, sim: &dyn Simulator, o: &DiagnoseOptions) -> Result<Diagnosis, DiagnoseError> {
    diagnose_tier(run, sim, o, true)
}

/// The physical tier alone ([`Simulator::physical_set`], or `sim` itself
/// when it has none), without the global tier first: a diagnosis about a
/// machine whose parameters are already calibrated, where the priors of the
/// physical set, not four free multipliers, say how far it may have moved.
pub fn diagnose_physical(run: &MeasuredRun, sim: &dyn Simulator, o: &DiagnoseOptions) -> Result<Diagnosis, DiagnoseError> {
    match sim.physical_set() {
        Some(p) => diagnose_tier(run, &*p, o, false),
        None => diagnose_tier(run, sim, o, false),
    }
}

fn diagnose_tier(run: &MeasuredRun, sim: &dyn Simulator, o: &DiagnoseOptions, escalate: bool) -> Result<Diagnosis, DiagnoseError> {
    if !Channel::TEMPERATURES.iter().any(|c| run.get(*c).is_some_and(|v| v.iter().any(Option::is_some))) {
        return Err(DiagnoseError::NoTemperature);
    }
    if run.len() < 20 {
        return Err(DiagnoseError::TooShort(run.len()));
    }
    let split = split_time_s(run, o.train_fraction);
    let pts = fit_points(run, split, o.points_per_channel);
    let nuis_specs = sim.nuisance();
    let mut log = PhaseLog::new(sim.nuisance_set_name());
    sim.phase(Phase::Baseline { params: nuis_specs.len() });
    let nominal_v: Vec<f64> = nuis_specs.iter().map(|s| s.start).collect();
    let nominal = sim.simulate(&nominal_v, Candidate::None, &[]).map_err(DiagnoseError::Baseline)?;
    // Fits are made without their Jacobian at the best point (owed, see
    // `fit_deferred`): only the kept ones pay it, before the evidence.
    let base = fit_deferred(sim, run, &pts, Candidate::None, &nominal_v, None, o.fit)
        .ok_or_else(|| DiagnoseError::Baseline("no valid residuals at the nominal parameters".into()))?;
    log.mark("baseline", 1 + base.sims);
    let m_before = metrics(run, &base.series, split, o.ljung_box_lags);
    let xcorr = cross_correlations(run, &base.series, o.max_lag_s, o.xcorr_lag_step_s);
    log.mark("residual analysis", 0);
    // `escalate` is false only in the physical tier (called from below).
    let rule = if escalate { o.misfit } else { o.physical_misfit };
    if escalate && assess(run, split, &m_before, &xcorr, (&nuis_specs, &base.nuisance), rule).misfits {
        if let Some(d) = in_physical_tier(run, sim, o, 1 + base.sims, &log.phases) {
            return d;
        }
    }
    let may_escalate = escalate && assess(run, split, &m_before, &xcorr, (&nuis_specs, &base.nuisance), o.physical_misfit).misfits;
    // Every candidate is fitted jointly with the nuisance set from
    // [`STARTS_PER_CANDIDATE`] starts, keeping the best: (a) the nominal
    // nuisance values with the candidate's spec start — starting from the
    // calibrated baseline alone would inherit the distortions the nuisance
    // set took on to mimic the missing effect; (b) the calibrated baseline
    // with the candidate nearly off, so that a candidate (which contains the
    // baseline as its limit) never ends up with a worse fit than the
    // baseline; (c) the calibrated baseline with the candidate at the middle
    // of its physical range ([`typical_magnitude`]): from (b) the fit often
    // stays in the baseline's basin with the candidate off, from (a) the
    // ~20-parameter physical set ends its budget far from the baseline's
    // values (measured on emulator logs whose effect stands well above the
    // structure floor: docs/diagnosis-limits.md, "Why effects above the floor
    // are missed").
    let starts: Vec<(Candidate, Start)> =
        Candidate::EXTENSIONS.iter().flat_map(|&c| [(c, Start::Nominal), (c, Start::BaseOff), (c, Start::BaseTypical)]).collect();
    sim.phase(Phase::Candidates { fits: starts.len(), may_escalate: may_escalate && sim.physical_set().is_some() });
    let all: Vec<Option<FitResult>> = starts
        .par_iter()
        .map(|&(c, start)| match start {
            Start::Nominal => fit_deferred(sim, run, &pts, c, &nominal_v, None, o.fit),
            Start::BaseOff => fit_from(sim, run, &pts, c, &base, o),
            Start::BaseTypical => fit_typical(sim, run, &pts, c, &base, o),
        })
        .collect();
    let mut extra_sims = 0;
    let fits: Vec<Option<FitResult>> = all
        .chunks(STARTS_PER_CANDIDATE)
        .map(|group| {
            extra_sims += group.iter().flatten().map(|f| f.sims).sum::<usize>();
            group.iter().flatten().min_by(|a, b| a.rss.total_cmp(&b.rss)).cloned()
        })
        .collect();
    log.mark("candidates", extra_sims);
    let n = pts.len();
    let mut fits: Vec<FitResult> = fits.into_iter().flatten().collect();
    let base_sims = base.sims;
    let (mut base, mut m_before, mut xcorr) = (base, m_before, xcorr);
    let (mut ranking, mut fit_metrics) = rank(run, sim, o, split, n, &base, &m_before, &fits);
    // A candidate qualifies: refit the baseline from the nuisance values of
    // the two candidate fits with the least residual. A candidate fitted
    // from other starts may have found a better basin of the nuisance set,
    // and its gain would then be the basin's, not the effect's; the better
    // baseline (training residual) is the one candidates are judged
    // against. In the global tier only then (restarting every global
    // baseline turned the servo `none` log 1717 `unexplained`);
    // in the physical tier always: whether a candidate first qualifies there
    // is itself path-dependent (a semantically neutral refactor moved
    // emulator log 1708 across it, and its baseline from 0.38 to 0.41 K held
    // out), and the baseline should not depend on it.
    if ranking.iter().any(|r| r.qualifies) || !escalate {
        let mut by_rss: Vec<&FitResult> = fits.iter().collect();
        by_rss.sort_by(|a, b| a.rss.total_cmp(&b.rss));
        let mut starts: Vec<Vec<f64>> = by_rss.iter().take(2).map(|f| f.nuisance.clone()).collect();
        // In the physical tier also from every candidate's nominal-start
        // fit (`DiagnoseOptions::nominal_restarts`): the two fits of least residual mostly
        // sit in the calibrated baseline's own basin (they start from it),
        // while a nominal-start fit, whatever its own residual, may have
        // carried the ~20-parameter set into a basin where the baseline
        // fits far better. Measured on the effect-free twin of emulator
        // log 2712: the two restarts ended at 144 K² (held out 2.49 K
        // pooled); restarted from `motor-pump-conduction`'s nominal-start
        // fit (538 K² with the path on) the baseline reached 91 K² (held
        // out 0.85 K) (docs/diagnosis-limits.md, "The calibration's basins").
        if o.nominal_restarts && !escalate {
            for g in all.chunks(STARTS_PER_CANDIDATE) {
                if let Some(f) = g[0].as_ref().filter(|f| !starts.contains(&f.nuisance)) {
                    starts.push(f.nuisance.clone());
                }
            }
        }
        sim.phase(Phase::Restarts { fits: starts.len() });
        let restarts: Vec<FitResult> =
            starts.par_iter().filter_map(|v| fit_deferred(sim, run, &pts, Candidate::None, v, None, o.fit)).collect();
        let r_sims = restarts.iter().map(|f| f.sims).sum::<usize>();
        extra_sims += r_sims;
        log.mark("restarts", r_sims);
        if let Some(better) = restarts.into_iter().filter(|r| r.rss < base.rss).min_by(|a, b| a.rss.total_cmp(&b.rss)) {
            base = better;
            // The candidates get the same chance: each is fitted again from
            // the new baseline (nearly off), the better fit kept. Without
            // it a candidate, which contains the baseline as its limit,
            // could rank far below it (measured: emulator seed 1701, every
            // candidate ΔBIC −290 to −420).
            sim.phase(Phase::Refits { fits: fits.len() });
            let refits: Vec<Option<FitResult>> = fits.par_iter().map(|f| fit_from(sim, run, &pts, f.candidate, &base, o)).collect();
            let r_sims = refits.iter().flatten().map(|f| f.sims).sum::<usize>();
            extra_sims += r_sims;
            log.mark("refits", r_sims);
            for (f, r) in fits.iter_mut().zip(refits) {
                if let Some(r) = r.filter(|r| r.rss < f.rss) {
                    *f = r;
                }
            }
            m_before = metrics(run, &base.series, split, o.ljung_box_lags);
            xcorr = cross_correlations(run, &base.series, o.max_lag_s, o.xcorr_lag_step_s);
            (ranking, fit_metrics) = rank(run, sim, o, split, n, &base, &m_before, &fits);
            log.mark("residual analysis", 0);
        }
    }
    let sims = 1 + base_sims + extra_sims;
    ranking.sort_by(|a, b| a.bic.total_cmp(&b.bic));
    let adequacy = assess(run, split, &m_before, &xcorr, (&nuis_specs, &base.nuisance), rule);
    // The kept fits' owed Jacobians, for the evidence (each fit's own runs,
    // in parallel; the results do not depend on the order).
    let settle_sims = {
        let mut kept: Vec<&mut FitResult> = std::iter::once(&mut base).chain(fits.iter_mut()).collect();
        let owed = kept.iter().filter_map(|f| f.jac_owed.as_ref().map(|(x, _)| x.len())).sum();
        sim.phase(Phase::Jacobians { runs: owed });
        let before: usize = kept.iter().map(|f| f.sims).sum();
        kept.par_iter_mut().for_each(|f| settle_jacobian(sim, run, &pts, f));
        kept.iter().map(|f| f.sims).sum::<usize>() - before
    };
    let sims = sims + settle_sims;
    log.mark("jacobians", settle_sims);
    let chan: Vec<(Channel, f64, f64)> =
        adequacy.channels.iter().filter_map(|c| Some((Channel::from_name(&c.channel)?, c.noise_k, c.rise_k))).collect();
    let posterior = posterior_of(
        run,
        &pts,
        &evidence_points(run, split, o.points_per_channel),
        &base,
        &fits,
        &nuis_specs,
        &|c| sim.extension_params(c),
        &chan,
        &|c| ranking.iter().any(|r| r.qualifies && r.cause == c.name()),
        &|c| ranking.iter().any(|r| r.note.is_empty() && r.cause == c.name()),
        split,
        DISCREPANCY_TAU_S,
    );
    log.mark("evidence", 0);
    let winner = posterior.named().and_then(|r| Candidate::from_name(&r.cause));
    let (cause, after_fit, m_after) = match winner.and_then(|w| fits.iter().zip(&fit_metrics).find(|(f, _)| f.candidate == w)) {
        Some((f, m)) => (f.candidate, f.clone(), m.clone()),
        None => (Candidate::None, base.clone(), m_before.clone()),
    };
    // Late escalation: nothing qualifies with the global set and its
    // baseline passes the loose rule, but not the strict one (a channel off
    // by 5σ and 10 % of its rise or 1 K). `none` would then claim more than
    // the global set shows, so the diagnosis is made again with the
    // physical set, whose answer (named, `none` to the strict rule, or
    // `unexplained`) stands. Only after the candidates: escalating before
    // them lets the physical set absorb effects the global set leaves to be
    // named (see [`diagnose`]).
    //
    // Confirmation, the same rule on a named cause: the answer's fit (the
    // baseline, or the baseline with the named cause) must explain the
    // log to the strict rule. Where the global set plus a cause still
    // misfits, the cause stood in for a structure the four multipliers
    // lack (measured: motor–pump conduction named at P 1.00 on an
    // effect-free 2400 s emulator log, t_oil_c 1.18 K after it), and the
    // physical set decides. On a machine built like the model the named
    // cause leaves the noise (the synthetic suite), and nothing changes.
    if escalate && assess(run, split, &m_after, &xcorr, (&nuis_specs, &after_fit.nuisance), o.physical_misfit).misfits {
        if let Some(d) = in_physical_tier(run, sim, o, sims, &log.phases) {
            return d;
        }
    }
    sim.phase(Phase::Done);
    let m_nominal = metrics(run, &nominal, split, o.ljung_box_lags);
    Ok(Diagnosis {
        nuisance_set: sim.nuisance_set_name().into(),
        cause,
        unexplained: winner.is_none() && adequacy.misfits,
        adequacy,
        params: named(&sim.extension_params(cause), &after_fit.ext),
        nuisance_before: named(&nuis_specs, &base.nuisance),
        nuisance_after: named(&nuis_specs, &after_fit.nuisance),
        nominal: m_nominal,
        before: m_before,
        after: m_after,
        ranking,
        xcorr,
        split_time_s: split,
        series: [nominal, base.series.clone(), after_fit.series],
        sims,
        phases: log.phases,
        posterior,
    })
}
