//! A stored posterior re-stated without refitting: every ln Bayes factor
//! times a power, without the admission gate, or with the held-out
//! likelihood instead of it ([`Variant`]).

use crate::diagnosis::evidence::names_a_cause;
use crate::diagnosis::report::ProbabilityJson;

/// How a log's stored posterior is re-stated.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Variant {
    /// As stored (the product).
    Stored,
    /// Every ln Bayes factor times the smallest channel fraction of
    /// [`fraction_from_ljung_box`](super::fraction_from_ljung_box) (the whitened residual's own correlation).
    LjungBox,
    /// Every ln Bayes factor times [`fraction_from_length_scale`](super::fraction_from_length_scale) at the
    /// fit points' spacing.
    LengthScale,
    /// [`Variant::LjungBox`], and a candidate that failed the held-out
    /// checks keeps a tenth of a candidate's prior (the tempered rule's
    /// `LEAK`, fitted under `off`, not refitted) instead of none.
    LjungBoxLeak,
    /// No admission gate: every candidate keeps a candidate's prior (the
    /// identifiable ones where the record says which; every one in records
    /// that do not), with its stored ln Bayes factor.
    NoGate,
    /// The held-out likelihood instead of the gate
    /// ([`crate::diagnosis::evidence::DecisionRule::HeldOut`]): no gate, identifiable
    /// candidates at a candidate's prior, and each candidate's ln Bayes
    /// factor less its held-out part on the channels it does not touch
    /// ([`restate_heldout`]); only on records that carry the held-out parts.
    HeldOut,
    /// [`Variant::HeldOut`] with every ln Bayes factor times a power η
    /// fitted on the first set of the document (`fit_power`).
    HeldOutTempered,
    /// The gate's rejection as an observation
    /// ([`crate::diagnosis::gate_obs::restate_gate_observed`]): a candidate
    /// that failed keeps a candidate's prior times P(fail | c) from the
    /// log's recorded detectability, with the no-cause block's evidence;
    /// nothing fitted. Only on records that carry the detectability.
    GateObserved,
}

impl Variant {
    /// Every variant of the reliability table, in its order
    /// ([`Variant::GateObserved`] has its own table: it needs the
    /// detectability, which one stored sweep carries).
    pub const ALL: [Variant; 7] =
        [Variant::Stored, Variant::LjungBox, Variant::LengthScale, Variant::LjungBoxLeak, Variant::NoGate, Variant::HeldOut, Variant::HeldOutTempered];

    /// Label in the table.
    pub fn label(self) -> &'static str {
        match self {
            Variant::Stored => "as stated (the product)",
            Variant::LjungBox => "power n_eff/n from the whitened residual (Ljung–Box)",
            Variant::LengthScale => "power dt/2τ (discrepancy length scale)",
            Variant::LjungBoxLeak => "Ljung–Box power + leak 0.1 through the gate",
            Variant::NoGate => "no gate (stored ln BF, every candidate's prior)",
            Variant::HeldOut => "held-out likelihood instead of the gate",
            Variant::HeldOutTempered => "held-out likelihood, tempered (η fitted on 1700s/2700s)",
            Variant::GateObserved => "the gate's rejection as an observation (P(fail \\| c) from the detectability)",
        }
    }
}

/// The posterior re-computed from `probs`' ln Bayes factors times `w`,
/// with a candidate of prior 0 given `leak` of an admitted candidate's.
pub fn powered(probs: &[ProbabilityJson], w: f64, leak: f64) -> Vec<ProbabilityJson> {
    let prior = |p: &ProbabilityJson| if p.prior == 0.0 && names_a_cause(&p.cause) { leak * crate::diagnosis::evidence::CANDIDATE_PRIOR } else { p.prior };
    let l: Vec<f64> = probs.iter().map(|p| w * p.log_bayes_factor + prior(p).max(1e-300).ln()).collect();
    probs.iter().zip(normalised(&l)).map(|(p, probability)| ProbabilityJson { probability, prior: prior(p), ..p.clone() }).collect()
}

/// The probabilities of the log-weights `l` (ln prior + ln Bayes factor), normalised.
fn normalised(l: &[f64]) -> Vec<f64> {
    let m = l.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let s: f64 = l.iter().map(|x| (x - m).exp()).sum();
    l.iter().map(|x| (x - m).exp() / s).collect()
}

/// `probs` re-stated with priors `prior` and ln Bayes factors `lbf`, normalised.
fn restated(probs: &[ProbabilityJson], prior: &dyn Fn(&ProbabilityJson) -> f64, lbf: &dyn Fn(&ProbabilityJson) -> f64) -> Vec<ProbabilityJson> {
    let l: Vec<f64> = probs.iter().map(|p| lbf(p) + prior(p).max(1e-300).ln()).collect();
    let mut out: Vec<ProbabilityJson> = probs
        .iter()
        .zip(normalised(&l))
        .map(|(p, probability)| ProbabilityJson { probability, prior: prior(p), log_bayes_factor: lbf(p), ..p.clone() })
        .collect();
    out.sort_by(|a, b| b.probability.total_cmp(&a.probability));
    out
}

/// The stored posterior without the admission gate: every candidate that
/// the record does not mark unidentifiable at a candidate's prior, the
/// stored ln Bayes factors.
pub fn restate_no_gate(probs: &[ProbabilityJson]) -> Vec<ProbabilityJson> {
    let prior = |p: &ProbabilityJson| match names_a_cause(&p.cause) {
        true if p.identifiable != Some(false) => crate::diagnosis::evidence::CANDIDATE_PRIOR,
        true => 0.0,
        false => p.prior,
    };
    restated(probs, &prior, &|p| p.log_bayes_factor)
}

/// The stored posterior re-stated under
/// [`crate::diagnosis::evidence::DecisionRule::HeldOut`]: identifiable candidates at a
/// candidate's prior, each candidate's ln Bayes factor less its held-out
/// part on the channels it does not touch (so its held-out evidence is the
/// predictive density where its physics acts). `None` when the record does
/// not carry the held-out parts (sweeps written before they were kept).
pub fn restate_heldout(probs: &[ProbabilityJson]) -> Option<Vec<ProbabilityJson>> {
    if probs.iter().any(|p| names_a_cause(&p.cause) && (p.heldout_untouched.is_none() || p.identifiable.is_none())) {
        return None;
    }
    let prior = |p: &ProbabilityJson| match names_a_cause(&p.cause) {
        true if p.identifiable == Some(true) => crate::diagnosis::evidence::CANDIDATE_PRIOR,
        true => 0.0,
        false => p.prior,
    };
    Some(restated(probs, &prior, &|p| p.log_bayes_factor - if names_a_cause(&p.cause) { p.heldout_untouched.unwrap_or(0.0) } else { 0.0 }))
}

/// Powers η tried by `fit_power`: 0.05 to 1 in steps of 0.05.
pub fn power_grid() -> Vec<f64> {
    (1..=20).map(|k| 0.05 * k as f64).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A power scales every ln Bayes factor; a prior-0 candidate stays at
    /// P 0 without a leak and gets a share with one.
    #[test]
    fn powered_scales_the_evidence_and_the_gate_holds_without_leak() {
        let p = |c: &str, b: f64, pr: f64| ProbabilityJson { cause: c.into(), probability: 0.0, log_bayes_factor: b, prior: pr, heldout_touched: None, heldout_untouched: None, identifiable: None };
        let probs = [p("none", 0.0, 0.25), p("unexplained", -20.0, 0.25), p("sensor-lag", 20.0, 1.0 / 12.0), p("churning-loss", 30.0, 0.0)];
        let q = powered(&probs, 1.0, 0.0);
        assert!(q[2].probability > 0.999 && q[3].probability < 1e-200, "{q:?}");
        let q = powered(&probs, 0.1, 0.0);
        // ln odds lag : none = 2 + ln(1/3).
        let odds = q[2].probability / q[0].probability;
        assert!((odds.ln() - (2.0 + (1.0f64 / 3.0).ln())).abs() < 1e-9);
        assert!(powered(&probs, 0.1, 0.1)[3].probability > 0.0);
    }
}
