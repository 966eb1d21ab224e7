//! What a log can show, against the structure floor: each candidate's
//! imprint projected off the span of the calibration parameters'
//! sensitivities, compared per channel with the floor
//! ([`super::evidence::floor_for`]), and the angles between the projected
//! imprints (confusability).
//!
//! Linearised calibration: around the calibrated point the calibration
//! moves the model along the columns J of its sensitivities (K per unit of
//! ln value, forward differences), fitted by least squares on the training
//! points with the parameters' priors as ridge rows (as
//! [`super::fit`] weighs them). A candidate's imprint s (the model with the
//! candidate on minus without, at every point) is what the calibration
//! could take up along J on the training window; what it cannot, s − Jβ,
//! on the held-out window is the imprint **left**. With the log's floor f
//! on a channel (the misfit an effect-free log of this machine leaves
//! there), the baseline would misfit that channel by about √(f² + left²),
//! so the expected imprint ratio is r̂ = √(f² + left²)/f: r̂ ≥ 2 (left ≥
//! √3·f) is where a diagnosis must name the cause. Bounds are ignored and
//! the calibration is taken as linear, so r̂ is an estimate, not a bound.

mod report;

use super::adequacy::{channel_noise_k, rms_rise_k};
use super::evidence::{floor_for, touched_channels, ChannelFloor};
use super::fit::{residuals_at, Point, PRIOR_DATA_SIGMA_K};
use super::model::{Candidate, ParamSpec, SimSeries, Simulator};
use crate::measured::{Channel, MeasuredRun};
use nalgebra::{DMatrix, DVector};
use rayon::prelude::*;

/// Step of the sensitivities in ln value (the fit's own step,
/// [`super::fit::FitOptions::fd_step`]).
pub const LN_STEP: f64 = 0.02;

/// Expected imprint ratio at which an effect stands clear of the floor.
pub const SHOWABLE_RATIO: f64 = 2.0;

/// Angle below which two projected imprints are called confusable, degrees.
pub const CONFUSABLE_DEG: f64 = 20.0;

/// The calibration's sensitivities at one point of one log.
pub struct Sensitivities {
    /// Points (channel, row): training points then held-out points.
    pub pts: Vec<Point>,
    /// Whether each point is held out (at or after the split).
    pub held_out: Vec<bool>,
    /// The model at the calibrated point.
    pub base: SimSeries,
    /// Sensitivities of the model at `pts` to the ln of each calibration
    /// parameter, K.
    pub jac: DMatrix<f64>,
    /// Ridge weight of each parameter (its prior row's weight squared; 0
    /// without a prior).
    pub ridge: Vec<f64>,
}

/// The model at `pts` (K).
fn at(s: &SimSeries, pts: &[Point]) -> Option<DVector<f64>> {
    let v: Option<Vec<f64>> = pts.iter().map(|(ch, i)| s.channels.get(ch)?.get(*i).copied()).collect();
    v.map(DVector::from_vec)
}

impl Sensitivities {
    /// The sensitivities of `sim` at nuisance values `nuisance` on the points
    /// `pts` of `run` (`split` separates training and held-out), by forward
    /// differences of [`LN_STEP`] (inwards at an upper bound): p + 1 model
    /// runs, in parallel.
    pub fn new(sim: &dyn Simulator, run: &MeasuredRun, nuisance: &[f64], pts: Vec<Point>, split: f64) -> Result<Self, String> {
        let specs = sim.nuisance();
        let base = sim.simulate(nuisance, Candidate::None, &[])?;
        let y0 = at(&base, &pts).ok_or("the model lacks a logged channel")?;
        let cols: Vec<Result<DVector<f64>, String>> = (0..specs.len())
            .into_par_iter()
            .map(|k| {
                let mut v = nuisance.to_vec();
                let h = if v[k] * LN_STEP.exp() > specs[k].hi { -LN_STEP } else { LN_STEP };
                v[k] *= h.exp();
                let y = at(&sim.simulate(&v, Candidate::None, &[])?, &pts).ok_or("the model lacks a logged channel")?;
                Ok((y - &y0) / h)
            })
            .collect();
        let cols = cols.into_iter().collect::<Result<Vec<_>, _>>()?;
        let jac = if cols.is_empty() { DMatrix::zeros(pts.len(), 0) } else { DMatrix::from_columns(&cols) };
        let held_out = pts.iter().map(|(_, i)| run.time_s[*i] >= split).collect();
        Ok(Sensitivities { pts, held_out, base, jac, ridge: ridge(&specs) })
    }

    /// The imprint of candidate `c` at parameters `ext`: the model with it
    /// minus without, at the points (one model run).
    pub fn imprint(&self, sim: &dyn Simulator, nuisance: &[f64], c: Candidate, ext: &[f64]) -> Result<DVector<f64>, String> {
        let y = at(&sim.simulate(nuisance, c, ext)?, &self.pts).ok_or("the model lacks a logged channel")?;
        Ok(y - at(&self.base, &self.pts).ok_or("the model lacks a logged channel")?)
    }

    /// What the calibration leaves of `s`: s − Jβ with β the ridge
    /// least-squares fit of Jβ to `s` on the training points, at every
    /// point. `extra` columns (other candidates' imprints, unpenalised) are
    /// fitted along with J.
    pub fn left(&self, s: &DVector<f64>, extra: &[&DVector<f64>]) -> DVector<f64> {
        let p = self.jac.ncols();
        let cols: Vec<DVector<f64>> = self.jac.column_iter().map(|c| c.into_owned()).chain(extra.iter().map(|e| (*e).clone())).collect();
        if cols.is_empty() {
            return s.clone();
        }
        let a = DMatrix::from_columns(&cols);
        let train: Vec<usize> = (0..self.pts.len()).filter(|&i| !self.held_out[i]).collect();
        let q = a.ncols();
        let mut ata = DMatrix::<f64>::zeros(q, q);
        let mut atb = DVector::<f64>::zeros(q);
        for &i in &train {
            let row = a.row(i);
            ata += row.transpose() * row;
            atb += row.transpose() * s[i];
        }
        for (k, w) in self.ridge.iter().enumerate().take(p) {
            ata[(k, k)] += w;
        }
        let beta = ata.svd(true, true).solve(&atb, 1e-12).unwrap_or_else(|_| DVector::zeros(q));
        s - a * beta
    }

    /// RMS of `v` over the held-out points of channel `ch` (`None` when
    /// there are none).
    pub fn heldout_rms(&self, v: &DVector<f64>, ch: Channel) -> Option<f64> {
        let x: Vec<f64> = (0..self.pts.len()).filter(|&i| self.held_out[i] && self.pts[i].0 == ch).map(|i| v[i] * v[i]).collect();
        (!x.is_empty()).then(|| (x.iter().sum::<f64>() / x.len() as f64).sqrt())
    }

    /// Channels present among the points, in order.
    pub fn channels(&self) -> Vec<Channel> {
        let mut out: Vec<Channel> = Vec::new();
        for (ch, _) in &self.pts {
            if !out.contains(ch) {
                out.push(*ch);
            }
        }
        out
    }
}

/// Ridge weight of each parameter: the weight of its prior row in the fit,
/// (σ_d/σ_ln)², 0 without a prior.
fn ridge(specs: &[ParamSpec]) -> Vec<f64> {
    specs.iter().map(|s| s.prior_sigma_ln.map_or(0.0, |sig| (PRIOR_DATA_SIGMA_K / sig).powi(2))).collect()
}

/// The floor of every channel of `run` for the calibrated series `base` on
/// the training points `pts` (noise σ from the log, RMS rise above ambient
/// on the held-out window, RMS training misfit), as the evidence computes
/// them ([`ChannelFloor`]).
pub fn channel_floors(run: &MeasuredRun, base: &SimSeries, pts: &[Point], split: f64) -> Vec<ChannelFloor> {
    let r = residuals_at(run, base, pts).unwrap_or_default();
    let mut out = Vec::new();
    for ch in Channel::TEMPERATURES {
        let idx: Vec<usize> = (0..pts.len().min(r.len())).filter(|&i| pts[i].0 == ch).collect();
        let Some(v) = run.get(ch) else { continue };
        if idx.is_empty() {
            continue;
        }
        let misfit = (idx.iter().map(|&i| r[i] * r[i]).sum::<f64>() / idx.len() as f64).sqrt();
        out.push(ChannelFloor { channel: ch.name().into(), noise_k: channel_noise_k(v), rise_k: rms_rise_k(run, ch, split), misfit_k: misfit });
    }
    out
}

/// One channel's share of a candidate's projected imprint.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub struct ChannelImprint {
    /// Channel name.
    pub channel: String,
    /// Held-out RMS of the imprint, K.
    pub imprint_k: f64,
    /// Held-out RMS of what the calibration leaves of it, K.
    pub left_k: f64,
    /// The channel's floor when this candidate is judged, K.
    pub floor_k: f64,
    /// Expected imprint ratio √(floor² + left²)/floor.
    pub ratio: f64,
}

/// One candidate at one magnitude on one log.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub struct ProjectedRow {
    /// Candidate name.
    pub candidate: String,
    /// Magnitude injected: (parameter, value, unit).
    pub magnitude: Vec<(String, f64, String)>,
    /// Per channel.
    pub channels: Vec<ChannelImprint>,
    /// The effect's channel (the largest held-out imprint) and its expected
    /// ratio.
    pub best: (String, f64),
}

/// Expected imprint ratio of a left imprint against a floor.
pub fn expected_ratio(left_k: f64, floor_k: f64) -> f64 {
    (floor_k * floor_k + left_k * left_k).sqrt() / floor_k.max(1e-9)
}

/// The per-channel row of candidate `c` at `ext` whose imprint `s` leaves
/// `left`, judged against `floors`.
pub fn row(sens: &Sensitivities, floors: &[ChannelFloor], c: Candidate, ext: &[(String, f64, String)], s: &DVector<f64>, left: &DVector<f64>) -> ProjectedRow {
    let touched: Vec<String> = touched_channels(c).iter().map(|x| x.name().to_string()).collect();
    let channels: Vec<ChannelImprint> = sens
        .channels()
        .into_iter()
        .filter_map(|ch| {
            let f = floors.iter().find(|f| f.channel == ch.name())?;
            let floor = floor_for(f, floors, &touched);
            let l = sens.heldout_rms(left, ch)?;
            Some(ChannelImprint { channel: ch.name().into(), imprint_k: sens.heldout_rms(s, ch)?, left_k: l, floor_k: floor, ratio: expected_ratio(l, floor) })
        })
        .collect();
    // The effect's channel, as the imprint ratio is defined: where the
    // imprint is largest.
    let best = channels.iter().max_by(|a, b| a.imprint_k.total_cmp(&b.imprint_k)).map_or((String::new(), 1.0), |c| (c.channel.clone(), c.ratio));
    ProjectedRow { candidate: c.name().into(), magnitude: ext.to_vec(), channels, best }
}

/// Angles between projected imprints, degrees (0: the log cannot tell the
/// two apart; 90: independent), each point weighted by 1/floor of its
/// channel (the floor when the channel itself is judged).
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub struct Confusability {
    /// Candidate names, in row/column order.
    pub candidates: Vec<String>,
    /// Angle matrix, degrees; NaN where a candidate leaves nothing.
    pub angle_deg: Vec<Vec<f64>>,
}

/// [`Confusability`] of the projected imprints `left` (one per candidate).
pub fn confusability(sens: &Sensitivities, floors: &[ChannelFloor], names: &[String], left: &[DVector<f64>]) -> Confusability {
    let w: Vec<f64> = sens
        .pts
        .iter()
        .map(|(ch, _)| floors.iter().find(|f| f.channel == ch.name()).map_or(1.0, |f| 1.0 / floor_for(f, floors, std::slice::from_ref(&f.channel))))
        .collect();
    let v: Vec<DVector<f64>> = left.iter().map(|l| DVector::from_iterator(l.len(), l.iter().zip(&w).map(|(a, b)| a * b))).collect();
    let angle = |a: &DVector<f64>, b: &DVector<f64>| {
        let (na, nb) = (a.norm(), b.norm());
        if na < 1e-12 || nb < 1e-12 {
            return f64::NAN;
        }
        (a.dot(b) / (na * nb)).abs().min(1.0).acos().to_degrees()
    };
    Confusability { candidates: names.to_vec(), angle_deg: v.iter().map(|a| v.iter().map(|b| angle(a, b)).collect()).collect() }
}

/// The detectability of a log against its floor.
#[derive(Debug, Clone, serde::Serialize)]
pub struct FloorDetectability {
    /// Every candidate at each multiple of its typical magnitude
    /// ([`super::detect::MULTIPLES`], within its bounds).
    pub rows: Vec<ProjectedRow>,
    /// Angles between the candidates' projected imprints at the largest
    /// magnitude tried.
    pub confusability: Confusability,
    /// Per channel: the numbers behind the floors.
    pub floors: Vec<ChannelFloor>,
}

/// The detectability of every candidate on `run` around the calibrated
/// `nuisance` of `sim`: the sensitivities on `pts` (training then held-out
/// points), each candidate at [`super::detect::MULTIPLES`] of its typical
/// magnitude (capped at its upper bound), projected and judged against
/// `floors`. Candidates whose run fails are left out.
pub fn floor_detectability(sim: &dyn Simulator, run: &MeasuredRun, nuisance: &[f64], pts: Vec<Point>, split: f64, floors: Vec<ChannelFloor>) -> Result<FloorDetectability, String> {
    let sens = Sensitivities::new(sim, run, nuisance, pts, split)?;
    let jobs: Vec<(Candidate, Vec<f64>)> = Candidate::EXTENSIONS
        .iter()
        .flat_map(|&c| {
            let specs = sim.extension_params(c);
            let mut seen: Vec<Vec<f64>> = Vec::new();
            for m in super::detect::MULTIPLES {
                let e: Vec<f64> = specs.iter().map(|s| (m * s.start).min(s.hi)).collect();
                if !seen.contains(&e) {
                    seen.push(e);
                }
            }
            seen.into_iter().map(move |e| (c, e))
        })
        .collect();
    // (candidate, parameters, imprint, left), in the order of `jobs`.
    type Job = (Candidate, Vec<f64>, DVector<f64>, DVector<f64>);
    let imprints: Vec<Option<Job>> = jobs
        .par_iter()
        .map(|(c, e)| {
            let s = sens.imprint(sim, nuisance, *c, e).ok()?;
            let l = sens.left(&s, &[]);
            Some((*c, e.clone(), s, l))
        })
        .collect();
    let imprints: Vec<Job> = imprints.into_iter().flatten().collect();
    let named = |c: Candidate, e: &[f64]| -> Vec<(String, f64, String)> { sim.extension_params(c).iter().zip(e).map(|(s, v)| (s.name.clone(), *v, s.unit.clone())).collect() };
    let rows: Vec<ProjectedRow> = imprints.iter().map(|(c, e, s, l)| row(&sens, &floors, *c, &named(*c, e), s, l)).collect();
    // The largest magnitude of each candidate for the angles.
    let mut names = Vec::new();
    let mut lefts = Vec::new();
    for c in Candidate::EXTENSIONS {
        if let Some((_, _, _, l)) = imprints.iter().rev().find(|x| x.0 == c) {
            names.push(c.name().to_string());
            lefts.push(l.clone());
        }
    }
    let confusability = confusability(&sens, &floors, &names, &lefts);
    Ok(FloorDetectability { rows, confusability, floors })
}

/// [`floor_detectability`] of `run` around the calibrated point of the tier
/// whose answer stands in `d`, its floors the diagnosis's own channel
/// numbers, its points the evidence's.
pub fn against_floor(model: &dyn Simulator, d: &super::Diagnosis, run: &MeasuredRun, o: &super::DiagnoseOptions) -> Result<FloorDetectability, String> {
    let floor = |c: &super::evidence::ChannelEvidence| ChannelFloor { channel: c.channel.clone(), noise_k: c.noise_k, rise_k: c.rise_k, misfit_k: c.misfit_k };
    let floors: Vec<ChannelFloor> = d.posterior.channels.iter().map(floor).collect();
    let pts = super::analysis::evidence_points(run, d.split_time_s, o.points_per_channel);
    super::detect::with_answer_tier(model, d, |a| floor_detectability(a.sim, run, a.nuisance, pts, a.split, floors))
}
