//! The admission gate's rejection as an observation (measured, not the
//! product's rule; docs/diagnosis-limits.md, "Which statements at
//! P ≥ 0.99 are wrong").
//!
//! Under the product's rule a candidate that fails the held-out checks
//! gets prior 0, as if the gate never missed an effect. Here it keeps
//! π_c · P(fail | c) and no Bayes factor of its own: the gate already used
//! the held-out window, and a true cause that fails it leaves data that
//! look like "no cause", so its evidence is taken equal to the no-cause
//! block's (`none` and `unexplained` at their priors), Bayes factor 1
//! against that block. P(fail | c) is the share of the candidate's
//! magnitude prior ([`crate::physics::candidates::magnitude_range`],
//! log-uniform) over which this log's expected imprint ratio r̂ (the
//! `--detectability` projection, [`super::projection`]) stays below
//! [`SHOWABLE_RATIO`]; a candidate the identifiability rule rejects fails
//! whatever its size (P(fail | c) = 1). Admitted candidates are left as
//! they are (their P(pass | c) is not applied: the projection ignores the
//! parameters' bounds and can read r̂ ≈ 1 on an effect the diagnosis
//! names, docs/test-plans.md), and so is the gate's false-discovery rate
//! P(pass | no cause).

use super::evidence::{names_a_cause, CANDIDATE_PRIOR};
use super::model::Candidate;
use super::projection::{FloorDetectability, SHOWABLE_RATIO};
use super::report::ProbabilityJson;
use crate::physics::candidates::magnitude_range;

/// One candidate's expected imprint ratio on one log at each magnitude the
/// projection tried ([`super::detect::MULTIPLES`] of its typical
/// magnitude, capped at its bound).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Reach {
    /// Candidate name.
    pub candidate: String,
    /// Magnitudes tried, ascending, in the unit of its parameter
    /// ([`crate::physics::candidates::magnitude_range`]'s).
    pub magnitude: Vec<f64>,
    /// r̂ on the effect's channel at each magnitude (≥ 1).
    pub ratio: Vec<f64>,
}

/// Every candidate's [`Reach`] from a log's projection (its first
/// parameter is the magnitude; every candidate has one).
pub fn reaches(fd: &FloorDetectability) -> Vec<Reach> {
    let mut out: Vec<Reach> = Vec::new();
    for r in &fd.rows {
        let Some((_, m, _)) = r.magnitude.first() else { continue };
        let i = match out.iter().position(|x| x.candidate == r.candidate) {
            Some(i) => i,
            None => {
                out.push(Reach { candidate: r.candidate.clone(), magnitude: Vec::new(), ratio: Vec::new() });
                out.len() - 1
            }
        };
        out[i].magnitude.push(*m);
        out[i].ratio.push(r.best.1);
    }
    for x in &mut out {
        let mut v: Vec<(f64, f64)> = x.magnitude.iter().copied().zip(x.ratio.iter().copied()).collect();
        v.sort_by(|a, b| a.0.total_cmp(&b.0));
        (x.magnitude, x.ratio) = v.into_iter().unzip();
    }
    out
}

/// P(fail | c): the share of the log-uniform magnitude range `range`
/// (lo, hi) over which r̂ stays below [`SHOWABLE_RATIO`]. r̂ is
/// interpolated linearly in ln magnitude between the magnitudes tried and
/// held at the end values beyond them. `None` without any magnitude tried.
pub fn p_fail(reach: &Reach, range: (f64, f64)) -> Option<f64> {
    let x: Vec<f64> = reach.magnitude.iter().map(|m| m.ln()).collect();
    let r = &reach.ratio;
    if x.is_empty() || r.len() != x.len() {
        return None;
    }
    let at = |v: f64| -> f64 {
        if v <= x[0] {
            return r[0];
        }
        for k in 1..x.len() {
            if v <= x[k] {
                let t = if x[k] > x[k - 1] { (v - x[k - 1]) / (x[k] - x[k - 1]) } else { 1.0 };
                return r[k - 1] + t * (r[k] - r[k - 1]);
            }
        }
        r[x.len() - 1]
    };
    let (a, b) = (range.0.ln(), range.1.ln());
    if b <= a {
        return Some(if at(a) < SHOWABLE_RATIO { 1.0 } else { 0.0 });
    }
    // r̂ is linear between consecutive break points: sum the part below 2.
    let mut cuts = vec![a];
    cuts.extend(x.iter().copied().filter(|v| *v > a && *v < b));
    cuts.push(b);
    let mut below = 0.0;
    for w in cuts.windows(2) {
        let (ra, rb, len) = (at(w[0]), at(w[1]), w[1] - w[0]);
        below += match (ra < SHOWABLE_RATIO, rb < SHOWABLE_RATIO) {
            (true, true) => len,
            (false, false) => 0.0,
            (true, false) => len * (SHOWABLE_RATIO - ra) / (rb - ra),
            (false, true) => len * (ra - SHOWABLE_RATIO) / (ra - rb),
        };
    }
    Some(below / (b - a))
}

/// P(fail | c) of every candidate on a log from its `reach`, by name;
/// `None` for a candidate whose reach is missing.
pub fn p_fail_of(reach: &[Reach], cause: &str) -> Option<f64> {
    let c = Candidate::from_name(cause)?;
    p_fail(reach.iter().find(|r| r.candidate == cause)?, magnitude_range(c))
}

/// `probs` (a stored posterior) re-stated with the gate's rejection as an
/// observation: each candidate of prior 0 gets prior
/// [`CANDIDATE_PRIOR`] · P(fail | c) (1 where `identifiable` is false,
/// else `p_fail(cause)`) and the no-cause block's evidence, ln B against
/// `none` = ln((1 + e^u)/2) with u `unexplained`'s ln B; everything else as
/// stored. `None` when a rejected, identifiable candidate has no P(fail).
pub fn restate_gate_observed(probs: &[ProbabilityJson], p_fail: &dyn Fn(&str) -> Option<f64>) -> Option<Vec<ProbabilityJson>> {
    let u = probs.iter().find(|p| p.cause == "unexplained").map_or(f64::NEG_INFINITY, |p| p.log_bayes_factor);
    // ln((1 + e^u)/2), stable for any u.
    let block = u.max(0.0) + (-u.abs()).exp().ln_1p() - 2f64.ln();
    let mut out = Vec::with_capacity(probs.len());
    for p in probs {
        let mut q = p.clone();
        if names_a_cause(&p.cause) && p.prior == 0.0 {
            let f = if p.identifiable == Some(false) { 1.0 } else { p_fail(&p.cause)? };
            q.prior = CANDIDATE_PRIOR * f;
            q.log_bayes_factor = block;
        }
        out.push(q);
    }
    let l: Vec<f64> = out.iter().map(|p| p.log_bayes_factor + p.prior.max(1e-300).ln()).collect();
    let m = l.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let s: f64 = l.iter().map(|x| (x - m).exp()).sum();
    for (p, x) in out.iter_mut().zip(&l) {
        p.probability = if p.prior > 0.0 { (x - m).exp() / s } else { 0.0 };
    }
    out.sort_by(|a, b| b.probability.total_cmp(&a.probability));
    Some(out)
}

/// The `report.md` section of `diagnose --detectability`: the stated
/// posterior `stated` beside its restatement `restated`
/// ([`restate_gate_observed`]) with each rejected candidate's P(fail | c)
/// from `reach`, and what the restatement measured on the emulator.
pub fn markdown(stated: &[ProbabilityJson], restated: &[ProbabilityJson], reach: &[Reach]) -> String {
    use std::fmt::Write as _;
    let mut s = String::from(
        "\n## Probabilities with the gate's rejection as an observation\n\n\
         The posterior above gives a candidate that failed the held-out checks prior 0, as if the checks never missed \
         an effect. Here it keeps its prior times P(fail | c), the share of its magnitude prior over which this log's \
         expected imprint ratio (the section above) stays below 2, and the no-cause evidence. The answer is the same. \
         How often such statements were right on the emulator, against the posterior above: docs/diagnosis-gate.md \
         (closer to the stated values than the posterior above, not within 10 points in every bin).\n\n\
         | cause | posterior above | gate as an observation | P(fail \\| c) |\n|---|---:|---:|---:|\n",
    );
    for q in restated {
        let st = stated.iter().find(|p| p.cause == q.cause);
        let p = st.map_or(0.0, |p| p.probability);
        // P(fail | c) only where the gate rejected c (an admitted candidate passed it)
        let f = match st {
            Some(x) if names_a_cause(&q.cause) && x.prior > 0.0 => "admitted".into(),
            _ if names_a_cause(&q.cause) => p_fail_of(reach, &q.cause).map_or("–".into(), |f| format!("{f:.2}")),
            _ => "–".into(),
        };
        let _ = writeln!(s, "| `{}` | {p:.3} | {:.3} | {f} |", q.cause, q.probability);
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    fn reach(ratio: [f64; 3]) -> Reach {
        Reach { candidate: "sensor-lag".into(), magnitude: vec![1.0, 4.0, 16.0], ratio: ratio.to_vec() }
    }

    /// The report section: one row per structure, the rejected candidate's
    /// P(fail | c) from its reach, an admitted one marked as such.
    #[test]
    fn markdown_lists_both_posteriors() {
        let p = |c: &str, prob: f64, prior: f64| ProbabilityJson { cause: c.into(), probability: prob, log_bayes_factor: 0.0, prior, heldout_touched: None, heldout_untouched: None, identifiable: None };
        let stated = vec![p("churning-loss", 0.95, CANDIDATE_PRIOR), p("none", 0.05, 0.25), p("sensor-lag", 0.0, 0.0)];
        let lag = Reach { candidate: "sensor-lag".into(), magnitude: vec![30.0, 120.0, 480.0], ratio: vec![1.0, 1.0, 1.0] };
        let restated = restate_gate_observed(&stated, &|c| p_fail_of(std::slice::from_ref(&lag), c)).unwrap();
        let md = markdown(&stated, &restated, &[lag]);
        assert!(md.contains("| `churning-loss` | 0.950 |") && md.contains("| admitted |"), "{md}");
        assert!(md.contains("| `sensor-lag` | 0.000 |") && md.contains("| 1.00 |"), "{md}");
    }

    /// P(fail | c) on known r̂: below 2 everywhere → 1, at or above
    /// everywhere → 0; r̂ 1, 2, 3 at 1, 4, 16 (linear in ln m) crosses 2 at
    /// the middle magnitude, so over 1–16 half the ln range fails; r̂ 1, 3, 3
    /// crosses at m = 2 (halfway from 1 to 4 in ln), so over 1–8 the share
    /// is ln 2 / ln 8 = 1/3; beyond the magnitudes tried r̂ is held at the
    /// end value.
    #[test]
    fn p_fail_is_the_log_uniform_share_below_two() {
        let close = |a: Option<f64>, b: f64| assert!((a.unwrap() - b).abs() < 1e-12, "{a:?} vs {b}");
        close(p_fail(&reach([1.0, 1.5, 1.9]), (1.0, 16.0)), 1.0);
        close(p_fail(&reach([2.0, 5.0, 9.0]), (1.0, 16.0)), 0.0);
        close(p_fail(&reach([1.0, 2.0, 3.0]), (1.0, 16.0)), 0.5);
        close(p_fail(&reach([1.0, 3.0, 3.0]), (1.0, 8.0)), 1.0 / 3.0);
        close(p_fail(&reach([1.0, 3.0, 3.0]), (2.0, 8.0)), 0.0);
        close(p_fail(&reach([3.0, 3.0, 1.0]), (20.0, 40.0)), 1.0);
        close(p_fail(&reach([3.0, 3.0, 1.0]), (0.1, 0.5)), 0.0);
        assert_eq!(p_fail(&Reach { candidate: "sensor-lag".into(), magnitude: vec![], ratio: vec![] }, (1.0, 2.0)), None);
        // By name, over the candidate's own range (60–240 s for the lag).
        let lag = Reach { candidate: "sensor-lag".into(), magnitude: vec![30.0, 120.0, 480.0], ratio: vec![1.0, 2.0, 3.0] };
        close(p_fail_of(&[lag], "sensor-lag"), (120f64 / 60.0).ln() / 4f64.ln());
    }

    fn prob(cause: &str, lbf: f64, prior: f64, identifiable: bool) -> ProbabilityJson {
        ProbabilityJson { cause: cause.into(), probability: 0.0, log_bayes_factor: lbf, prior, heldout_touched: None, heldout_untouched: None, identifiable: Some(identifiable) }
    }

    fn no_cause(p: &[ProbabilityJson]) -> f64 {
        p.iter().filter(|x| !names_a_cause(&x.cause)).map(|x| x.probability).sum()
    }

    /// The restated posterior: with every candidate rejected, "no cause"
    /// is its prior 0.5 when each would have failed at any size, and
    /// 0.5 / (0.5 + 1/12) = 6/7 when all but one (unidentifiable, fails
    /// whatever its size) would have passed at every size — whatever
    /// `unexplained`'s Bayes factor, which only splits `none` from
    /// `unexplained` (odds e^u). An admitted candidate keeps its stored
    /// Bayes factor and stays named. A rejected identifiable candidate
    /// without P(fail) leaves the log un-restated.
    #[test]
    fn the_restated_posterior_holds_the_gate_as_an_observation() {
        let cands = ["winding-resistance-temperature", "sensor-lag", "coulomb-friction", "churning-loss", "motor-pump-conduction", "forced-convection"];
        for u in [-30.0, 0.0, 7.3, 400.0] {
            let mut probs = vec![prob("none", 0.0, 0.25, true), prob("unexplained", u, 0.25, true)];
            probs.extend(cands.iter().map(|c| prob(c, 40.0, 0.0, *c != "coulomb-friction")));
            let all_fail = restate_gate_observed(&probs, &|_| Some(1.0)).unwrap();
            assert!((no_cause(&all_fail) - 0.5).abs() < 1e-12, "u {u}: {all_fail:?}");
            let lag = all_fail.iter().find(|p| p.cause == "sensor-lag").unwrap();
            assert!((lag.probability - 1.0 / 12.0).abs() < 1e-12 && (lag.prior - CANDIDATE_PRIOR).abs() < 1e-15);
            let all_pass = restate_gate_observed(&probs, &|_| Some(0.0)).unwrap();
            assert!((no_cause(&all_pass) - 6.0 / 7.0).abs() < 1e-12, "u {u}: {all_pass:?}");
            let (n, x) = (all_pass.iter().find(|p| p.cause == "none").unwrap(), all_pass.iter().find(|p| p.cause == "unexplained").unwrap());
            assert!(u > 300.0 || ((x.probability / n.probability).ln() - u).abs() < 1e-9);
        }
        let mut probs = vec![prob("none", 0.0, 0.25, true), prob("unexplained", 3.0, 0.25, true), prob("sensor-lag", 30.0, CANDIDATE_PRIOR, true)];
        probs.extend(["churning-loss", "forced-convection"].iter().map(|c| prob(c, 0.0, 0.0, true)));
        let p = restate_gate_observed(&probs, &|_| Some(1.0)).unwrap();
        assert_eq!(p[0].cause, "sensor-lag");
        assert!(p[0].probability > 0.999 && p[0].log_bayes_factor == 30.0, "{p:?}");
        assert!(restate_gate_observed(&probs, &|c| (c != "churning-loss").then_some(1.0)).is_none());
    }
}
