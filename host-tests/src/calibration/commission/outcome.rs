//! What commissioning gives ([`Commissioning`], the held-out scores
//! [`HoldoutScore`]), whether its block may be flashed and why not
//! ([`Refusal`]), and the operating region of a training log
//! ([`log_region`]).

use crate::calibration::check::{ReducedCheck, REDUCED_BOUND_K};
use crate::calibration::region::Region;
use crate::calibration::eta_m::EtaMBalance;
use crate::calibration::fit::Calibration;
use crate::calibration::log::{CalLog, ChannelError};
use crate::calibration::margin::MarginValidation;
use crate::calibration::paths::{Choice, PathKind, PathOutcome};
use crate::measured::Channel;
use crate::scenario::Circuit;
use crate::simulation::replay::circuit_of;
use eha_guard::model::ReducedParams;

/// Errors of the reference on one held-out log, before and after commissioning.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct HoldoutScore {
    /// Log name.
    pub log: String,
    /// Per channel with the rig as given.
    pub as_given: Vec<ChannelError>,
    /// Per channel with the commissioned rig.
    pub commissioned: Vec<ChannelError>,
}

/// Everything commissioning produces.
#[derive(Debug, Clone)]
pub struct Commissioning {
    /// The calibration (commissioned rig inside).
    pub cal: Calibration,
    /// Held-out scores of the reference.
    pub holdout: Vec<HoldoutScore>,
    /// Firmware parameters reduced from the commissioned rig.
    pub params: ReducedParams,
    /// Reduced model vs the commissioned reference on every log (training
    /// then held-out).
    pub reduced: Vec<ReducedCheck>,
    /// The paper-default firmware parameters (the compiled-in `DEFAULT`) on
    /// the held-out logs, for comparison.
    pub default_on_holdout: Vec<ReducedCheck>,
    /// Whether every reduced check is within [`REDUCED_BOUND_K`].
    pub reduced_ok: bool,
    /// Operating region of each training log ([`log_region`]).
    pub train_regions: Vec<Region>,
    /// The operating cells the training logs cover, and their drain range
    /// ([`crate::calibration::envelope::Envelope`]; reporting only).
    pub envelope: crate::calibration::envelope::Envelope,
    /// Whether some training log has more than one operating point (else the
    /// loss coefficients are not separable and the block is not flashable).
    pub excitation_ok: bool,
    /// `eta_m` from the training logs' current and the rows used
    /// ([`eta_m_from_current`](crate::calibration::eta_m::eta_m_from_current)); `None`: fitted from the temperatures.
    pub eta_m_from_current: Option<(f64, usize)>,
    /// The training logs' electrical balance behind `eta_m_from_current`
    /// ([`EtaMBalance::refusal`] says why it was not used).
    pub eta_m_balance: EtaMBalance,
    /// The drain margin from validation on a split of the training
    /// missions, when every training log carries `t_drain_c`.
    pub margin: Option<MarginValidation>,
    /// The commissioned firmware on the held-out logs with the margin added
    /// (the margin's accuracy and cost; equal to the held-out part of
    /// `reduced` when there is no margin).
    pub holdout_with_margin: Vec<ReducedCheck>,
    /// The reduction path's firmware, validated and held out.
    pub reduction_path: PathOutcome,
    /// The direct path's firmware, or why it did not run.
    pub direct_path: Result<PathOutcome, String>,
    /// The direct identification behind `direct_path`.
    pub direct_fit: Option<crate::calibration::direct::DirectFit>,
    /// Which path the block (`params`, `margin`, `holdout_with_margin`)
    /// comes from, and why.
    pub choice: Choice,
    /// The flashed block's firmware without the margin on the training
    /// logs it was commissioned on (in-sample, against `t_drain_c`).
    pub train_chosen: Vec<ReducedCheck>,
}

/// How far any constant drain margin can bring the firmware's error on
/// logs it was fitted to: with e = estimate − thermocouple spanning
/// [e_min, e_max] over every log, a margin m leaves max |e + m| ≥
/// (e_max − e_min)/2, reached at m = −(e_max + e_min)/2. A floor for the
/// held-out logs too: a margin cannot do better on logs the model did not
/// see than on those it was fitted to.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TrainingSpread {
    /// Largest under-prediction over the logs, −e_min, K.
    pub under_k: f64,
    /// Largest over-prediction over the logs, e_max, K.
    pub over_k: f64,
}

impl TrainingSpread {
    /// The spread of `checks` (margin 0) against their measured drain;
    /// `None` unless the error takes both signs over them: the checks keep
    /// under- and over-prediction floored at 0, so a one-signed error's
    /// other end is not known and no floor follows.
    pub fn of(checks: &[ReducedCheck]) -> Option<Self> {
        let max = |f: fn(&ReducedCheck) -> Option<f64>| checks.iter().filter_map(f).fold(None, |a: Option<f64>, x| Some(a.map_or(x, |a| a.max(x))));
        let (under_k, over_k) = (max(|c| c.vs_measured_under_k)?, max(|c| c.vs_measured_over_k)?);
        (under_k > 0.0 && over_k > 0.0).then_some(TrainingSpread { under_k, over_k })
    }

    /// The least max |e| any constant margin leaves on these logs, K.
    pub fn floor_k(&self) -> f64 {
        0.5 * (self.under_k + self.over_k)
    }

    /// The constant margin that reaches [`TrainingSpread::floor_k`], K.
    pub fn centring_margin_k(&self) -> f64 {
        0.5 * (self.under_k - self.over_k)
    }
}

/// Why a block is not flashable: which log, which operating region, which
/// channel, and the bench run that would fix it.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Refusal {
    /// What fails.
    pub reason: String,
    /// The log it fails on.
    pub log: String,
    /// The operating region ([`Region`]'s text).
    pub region: String,
    /// The channel and comparison.
    pub channel: String,
    /// The bench run that would fix it.
    pub bench_run: String,
}

impl std::fmt::Display for Refusal {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}: log `{}`, {}; channel {}; bench run that would fix it: {}", self.reason, self.log, self.region, self.channel, self.bench_run)
    }
}

/// Operating region of a whole log (5th–95th percentile of speed and Δp,
/// range of the drain or oil channel).
pub fn log_region(log: &CalLog) -> Region {
    let r = &log.run;
    let col = |ch: Channel| -> Vec<f64> { r.get(ch).map(|v| v.iter().flatten().copied().collect()).unwrap_or_default() };
    let pct = |mut v: Vec<f64>| -> (f64, f64) {
        if v.is_empty() {
            return (0.0, 0.0);
        }
        v.sort_by(f64::total_cmp);
        let at = |q: f64| v[((v.len() - 1) as f64 * q).round() as usize];
        (at(0.05), at(0.95))
    };
    let speed = pct(col(Channel::SpeedRpm).into_iter().map(f64::abs).collect());
    let (pa, pb) = (col(Channel::PABar), col(Channel::PBBar));
    let dp = pct(pa.iter().zip(&pb).map(|(a, b)| (a - b).abs()).collect());
    let t = if log.has(Channel::TDrainC) { col(Channel::TDrainC) } else { col(Channel::TOilC) };
    let drain = (t.iter().copied().fold(f64::MAX, f64::min), t.iter().copied().fold(f64::MIN, f64::max));
    let servo = matches!(circuit_of(r), Ok(Circuit::Servo));
    Region { t_s: (r.time_s[0], r.time_s[r.len() - 1]), speed_rpm: speed, dp_bar: dp, drain_c: drain, servo }
}

impl Commissioning {
    /// Whether the firmware parameter block may be flashed: the training
    /// logs separate the loss coefficients, and the block is either the
    /// direct identification (judged on the logs themselves) or a reduction
    /// that holds the commissioned reference on every log.
    /// Measured: commissioned from one operating point, the other
    /// EHA's firmware under-predicted a held-out high-pressure mission by
    /// 1.8 K with every reduced check passing.
    pub fn flashable(&self) -> bool {
        self.excitation_ok && (self.reduced_ok || self.choice.chosen == PathKind::Direct)
    }

    /// The chosen path's firmware on the held-out logs without the margin.
    pub fn holdout_without_margin(&self) -> &[ReducedCheck] {
        match (&self.choice.chosen, &self.direct_path) {
            (PathKind::Direct, Ok(d)) => &d.holdout,
            _ => &self.reduction_path.holdout,
        }
    }

    /// The margin written into an accepted block, K (0 without validation).
    pub fn margin_k(&self) -> f64 {
        self.margin.as_ref().map_or(0.0, |m| m.margin_k)
    }

    /// Why the block is refused (`None` when [`Self::flashable`]).
    pub fn refusal(&self) -> Option<Refusal> {
        if !self.excitation_ok {
            let n_train = self.reduced.len() - self.holdout.len();
            let first = self.reduced.first();
            return Some(Refusal {
                reason: "no training log has more than one operating point: the pump friction, leakage, iron loss and winding resistance are not separable and the firmware would extrapolate them to other speeds and pressures".into(),
                log: self.reduced[..n_train].iter().map(|r| r.log.clone()).collect::<Vec<_>>().join(", "),
                region: self.train_regions.first().map_or_else(|| first.map(|r| r.vs_reference_region.to_string()).unwrap_or_default(), |r| format!("one operating point: {r}")),
                channel: "every temperature channel (the loss split behind the drain estimate)".into(),
                bench_run: "speed steps at one needle setting (e.g. 400–1200 rpm every 3–4 min at 20 bar) and needle steps at one speed (e.g. 10–50 bar every 3–4 min at 700 rpm), 30 min each, with `t_drain_c` logged".into(),
            });
        }
        if !self.reduced_ok && self.choice.chosen == PathKind::Reduction {
            let r = farthest_from_reference(&self.reduced)?;
            return Some(Refusal {
                reason: format!("the six-state firmware model departs from the commissioned reference by {:.3} K (bound {REDUCED_BOUND_K} K)", r.vs_reference_max_k),
                log: r.log.clone(),
                region: r.vs_reference_region.to_string(),
                channel: "t_drain_c, reduced firmware model vs commissioned reference".into(),
                bench_run: format!(
                    "{} (the margin validation then measures the firmware there; `--accept-with-margin` writes the block with the validated margin)",
                    r.vs_reference_region.bench_run()
                ),
            });
        }
        None
    }
}

/// The reduced model's check farthest from the commissioned reference (the
/// largest drain `vs_reference_max_k`, K; `None` without checks): the log a
/// refusal names.
pub(super) fn farthest_from_reference(reduced: &[ReducedCheck]) -> Option<&ReducedCheck> {
    reduced.iter().max_by(|a, b| a.vs_reference_max_k.total_cmp(&b.vs_reference_max_k))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A training log's check with the measured under- and over-prediction, K.
    fn check(under_k: f64, over_k: f64) -> ReducedCheck {
        ReducedCheck::for_test("train", Some((under_k.max(over_k), under_k, over_k)))
    }

    /// Errors from −1.27 K (one log) to +1.16 K (the other): no margin
    /// leaves less than 1.215 K, reached at +0.055 K (the arithmetic of
    /// big-pump's training logs, docs/commissioning-foreign.md); a
    /// one-signed error gives no floor (its other end was floored at 0).
    #[test]
    fn the_training_spread_floors_any_constant_margin() {
        let t = TrainingSpread::of(&[check(0.85, 0.55), check(1.27, 1.16)]).unwrap();
        assert!((t.floor_k() - 1.215).abs() < 1e-12 && (t.centring_margin_k() - 0.055).abs() < 1e-12, "{t:?}");
        // the margin that reaches it leaves exactly the floor at both ends
        let m = t.centring_margin_k();
        assert!(((1.16 + m) - t.floor_k()).abs() < 1e-12 && ((1.27 - m) - t.floor_k()).abs() < 1e-12);
        assert_eq!(TrainingSpread::of(&[check(0.0, 0.9), check(0.0, 0.4)]), None);
        assert_eq!(TrainingSpread::of(&[]), None);
    }
}
