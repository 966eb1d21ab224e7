//! What a candidate at a given magnitude would leave on a log after a
//! nonlinear recalibration (the emulator sweep's oracle column; the
//! `--detectability` report is the linearised, floor-based
//! [`super::projection`]): the imprint it would leave on the logged
//! channels and how much of that imprint the calibration set takes up. The calibrated model plus the candidate is simulated over the log's
//! own inputs (noise-free), the baseline is refitted to that output on the
//! training window, and what it cannot follow on the held-out window is the
//! imprint "left". With sensor noise σ on that channel, the best held-out
//! gain any diagnosis could show there is 1 − σ/√(σ² + left²) (the baseline
//! misses by √(σ² + left²), the right candidate by σ): 50 % needs
//! left ≥ √3·σ. This assumes the model's own structure; a rig that differs
//! in structure adds its own misfit on top (docs/diagnosis-limits.md, "Why
//! effects above the floor are missed"). The recalibration is a local fit from the
//! calibrated point: a fit that absorbs more would leave less, so "left" and
//! the best gain are upper bounds (a low value is certain, a high one
//! optimistic), and they need not grow with the magnitude.

use super::adequacy::noise_sigma;
use super::analysis::{fit_points, identifiable_here, DiagnoseOptions, Diagnosis};
use super::fit::{fit, residuals_at, Point};
use super::model::{Candidate, SimSeries, Simulator};
use crate::measured::{Channel, MeasuredRun};

/// One candidate's detectability on one log.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub struct Detectability {
    /// Candidate name.
    pub candidate: String,
    /// Magnitude injected: (parameter, value, unit); empty for structural
    /// candidates (temperature-dependent viscosity).
    pub magnitude: Vec<(String, f64, String)>,
    /// Channel with the largest held-out imprint and that imprint (RMS of
    /// the candidate's change), K.
    pub imprint_k: (String, f64),
    /// On the same channel: the imprint left once the baseline is
    /// recalibrated to the output with the candidate (held-out RMS), K.
    pub left_k: f64,
    /// That channel's sensor noise σ, K (from the log's second differences).
    pub noise_k: f64,
    /// Best held-out gain a diagnosis could show on that channel,
    /// 1 − σ/√(σ² + left²).
    pub best_gain: f64,
    /// Why the candidate cannot be named on this log whatever its fit
    /// (empty when it can; `diagnosis::identify`).
    pub note: String,
}

/// Multiples of a candidate's typical magnitude that are injected.
pub const MULTIPLES: [f64; 3] = [1.0, 4.0, 16.0];

/// RMS over the rows at or after `split` where `run` has `ch`, of a − b.
fn heldout_rms(run: &MeasuredRun, ch: Channel, a: &SimSeries, b: &SimSeries, split: f64) -> Option<f64> {
    let (m, ya, yb) = (run.get(ch)?, a.channels.get(&ch)?, b.channels.get(&ch)?);
    let d: Vec<f64> = (0..run.len()).filter(|&i| run.time_s[i] >= split && m[i].is_some()).map(|i| (ya[i] - yb[i]).powi(2)).collect();
    (!d.is_empty()).then(|| (d.iter().sum::<f64>() / d.len() as f64).sqrt())
}

/// The calibrated point the injections start from: the simulator of a tier,
/// its calibrated nuisance values, the baseline series there and the
/// training/held-out split.
pub struct Around<'a> {
    /// Simulator of the tier (the reference model or its physical set).
    pub sim: &'a dyn Simulator,
    /// Calibrated nuisance values, in `sim.nuisance()` order.
    pub nuisance: &'a [f64],
    /// The baseline's series at those values.
    pub base: &'a SimSeries,
    /// Start of the held-out window, s.
    pub split: f64,
}

/// Runs `f` around the calibrated point of the tier whose answer stands in
/// `d` (`model` or its physical set; the baseline series is the
/// diagnosis's own, not simulated again).
pub fn with_answer_tier<R>(model: &dyn Simulator, d: &Diagnosis, f: impl FnOnce(&Around) -> R) -> R {
    let physical = model.physical_set();
    let sim: &dyn Simulator = match (&physical, d.nuisance_set.as_str()) {
        (Some(p), "physical") => &**p,
        _ => model,
    };
    let values: Vec<f64> = d.nuisance_before.iter().map(|(_, v, _)| *v).collect();
    f(&Around { sim, nuisance: &values, base: &d.series[1], split: d.split_time_s })
}

/// The detectability of candidate `c` at parameters `ext` around `a` (one
/// fit); `None` when a run fails.
pub fn detect_one(run: &MeasuredRun, a: &Around, o: &DiagnoseOptions, c: Candidate, ext: &[f64]) -> Option<Detectability> {
    inject(run, a, &fit_points(run, a.split, o.points_per_channel), o, c, ext)
}

/// [`detect_one`] with the training points `pts` given.
fn inject(run: &MeasuredRun, a: &Around, pts: &[Point], o: &DiagnoseOptions, c: Candidate, ext: &[f64]) -> Option<Detectability> {
    let (sim, base, split) = (a.sim, a.base, a.split);
    let train_rss = |s: &SimSeries, m: &MeasuredRun| -> Option<f64> { residuals_at(m, s, pts).map(|r| r.iter().map(|e| e * e).sum()) };
    let with = sim.simulate(a.nuisance, c, ext).ok()?;
    // The log as the model with the candidate would have written it,
    // noise-free, with the log's own missing samples.
    let mut syn = run.clone();
    for ch in Channel::TEMPERATURES {
        let (Some(m), Some(y)) = (run.get(ch), with.channels.get(&ch)) else { continue };
        let v = m.iter().zip(y).map(|(m, y)| m.map(|_| *y)).collect();
        syn.set(ch, v);
    }
    let (ch, imprint) = Channel::TEMPERATURES
        .into_iter()
        .filter_map(|ch| Some((ch, heldout_rms(run, ch, &with, base, split)?)))
        .max_by(|x, y| x.1.total_cmp(&y.1))?;
    // The fit starts a hair off any bound (`diagnosis::fit`), so the
    // calibrated point itself stays a contender: the better of the two on
    // the training window.
    let refit = fit(sim, &syn, pts, Candidate::None, a.nuisance, None, o.fit)?;
    let best = if train_rss(&refit.series, &syn)? < train_rss(base, &syn)? { &refit.series } else { base };
    let left = heldout_rms(run, ch, best, &with, split)?;
    let noise = run.get(ch).and_then(noise_sigma).unwrap_or(0.1).max(0.02);
    Some(Detectability {
        candidate: c.name().into(),
        magnitude: sim.extension_params(c).iter().zip(ext).map(|(s, v)| (s.name.clone(), *v, s.unit.clone())).collect(),
        imprint_k: (ch.name().into(), imprint),
        left_k: left,
        noise_k: noise,
        best_gain: 1.0 - noise / (noise * noise + left * left).sqrt(),
        note: identifiable_here(c, run, split, sim).err().unwrap_or_default().into(),
    })
}
