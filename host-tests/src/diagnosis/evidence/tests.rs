//! Tests of the evidence: the filter against the dense likelihood, the
//! floors, the decision rules.

use nalgebra::DMatrix;
use super::*;
use crate::diagnosis::model::SimSeries;
use rand::{Rng, SeedableRng};

/// Dense Gaussian log-likelihood of `y` with covariance
/// s²·exp(−|Δt|/τ) + σ²·I (Cholesky), the definition the filter must match.
fn dense_log_lik(t: &[f64], y: &[f64], s: f64, sigma: f64, tau: f64) -> f64 {
    let n = t.len();
    let k = DMatrix::from_fn(n, n, |i, j| s * s * (-(t[i] - t[j]).abs() / tau).exp() + if i == j { sigma * sigma } else { 0.0 });
    let c = k.cholesky().unwrap();
    let a = c.solve(&nalgebra::DVector::from_column_slice(y));
    let ln_det = 2.0 * c.l().diagonal().iter().map(|d| d.ln()).sum::<f64>();
    -0.5 * (y.iter().zip(a.iter()).map(|(x, z)| x * z).sum::<f64>() + ln_det + n as f64 * (2.0 * std::f64::consts::PI).ln())
}

/// AR(1) discrepancy of amplitude `s`, time constant `tau` at `t`, plus
/// white noise `sigma` (exact discretisation on irregular times).
fn ar1(rng: &mut impl Rng, t: &[f64], s: f64, tau: f64, sigma: f64) -> Vec<f64> {
    let mut g = || -> f64 { (0..12).map(|_| rng.random::<f64>()).sum::<f64>() - 6.0 };
    let mut x = s * g();
    let mut out = Vec::new();
    for (i, ti) in t.iter().enumerate() {
        if i > 0 {
            let f = (-(ti - t[i - 1]) / tau).exp();
            x = f * x + s * (1.0 - f * f).sqrt() * g();
        }
        out.push(x + sigma * g());
    }
    out
}

/// The Kalman filter is the exact likelihood of the AR(1)-plus-noise
/// model on irregular times (samples missing), to rounding; and the
/// whitening it gives turns a residual that the Ljung–Box test rejects
/// outright (p < 1e-6, as every channel of every log does today) into
/// one it accepts (p > 0.01).
#[test]
fn the_discrepancy_filter_is_the_exact_likelihood_and_whitens() {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
    let t: Vec<f64> = (0..40).filter(|i| i % 7 != 3).map(|i| 6.0 * i as f64).collect();
    let y = ar1(&mut rng, &t, 0.4, 300.0, 0.1);
    let w = Whitener::new(&t, 0.4, 0.1, 300.0);
    let (a, b) = (w.log_lik(&y), dense_log_lik(&t, &y, 0.4, 0.1, 300.0));
    assert!((a - b).abs() < 1e-9 * b.abs().max(1.0), "filter {a} against dense {b}");
    let t: Vec<f64> = (0..600).map(|i| 2.0 * i as f64).collect();
    let y = ar1(&mut rng, &t, 0.4, 300.0, 0.1);
    let lb = |v: &[f64]| crate::diagnosis::stats::ljung_box(&v.iter().map(|x| Some(*x)).collect::<Vec<_>>(), 20).p_value;
    let raw = lb(&y);
    let white = lb(&Whitener::new(&t, 0.4, 0.1, 300.0).whiten(&y));
    assert!(raw < 1e-6 && white > 0.01, "Ljung–Box p raw {raw:.2e}, whitened {white:.3}");
}

/// The held-out predictive log density ln p(y_held | y_train) of the
/// filter equals the closed form of the AR(1)-plus-noise Gaussian: the
/// dense joint log density minus the dense training one (Cholesky), to
/// 1e-9 relative (rounding only). 140 training and 60 held-out samples 6 s
/// apart (the diagnosis's spacing), amplitude 0.4 K, τ =
/// [`DISCREPANCY_TAU_S`], σ 0.1 K; the same with samples missing.
#[test]
fn the_heldout_predictive_density_is_the_conditional_gaussian() {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(11);
    let (s, sigma, tau) = (0.4, 0.1, DISCREPANCY_TAU_S);
    for t in [(0..200).map(|i| 6.0 * i as f64).collect::<Vec<f64>>(), (0..230).filter(|i| i % 9 != 4).map(|i| 6.0 * i as f64).collect()] {
        let y = ar1(&mut rng, &t, s, tau, sigma);
        let w = Whitener::new(&t, s, sigma, tau);
        let got = w.predictive_log_density(&y, 140);
        let closed = dense_log_lik(&t, &y, s, sigma, tau) - dense_log_lik(&t[..140], &y[..140], s, sigma, tau);
        assert!((got - closed).abs() < 1e-9 * closed.abs().max(1.0), "filter {got} against closed form {closed}");
    }
}

const CHANNELS: [(Channel, f64); 5] =
    [(Channel::TMotorC, 5.0), (Channel::TPumpC, 10.0), (Channel::TBlockC, 8.0), (Channel::TBallvalveC, 8.0), (Channel::TOilC, 10.0)];

/// A toy diagnosis on the training window (0–840 s, 6 s points): every
/// channel's calibrated-baseline residual is a structure floor of 2 % of
/// its rise (AR(1), τ 5 min; the evidence's own τ is [`DISCREPANCY_TAU_S`]) plus σ 0.1 K noise; the oil channel also
/// carries a lag-like imprint of `imprint_k` (1 − e^(−t/200 s)) that the
/// `sensor-lag` fit removes; `block_extra_k` adds a smooth misfit to
/// t_block_c that nothing explains. Returns the posterior.
fn toy(imprint_k: f64, block_extra_k: f64, seed: u64) -> Posterior {
    toy_split(imprint_k, block_extra_k, seed, f64::INFINITY)
}

/// [`toy`] with the points from `split` (s) on held out.
fn toy_split(imprint_k: f64, block_extra_k: f64, seed: u64, split: f64) -> Posterior {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let rows: Vec<f64> = (0..141).map(|i| 6.0 * i as f64).collect();
    let mut run = MeasuredRun::new(rows.clone());
    let (mut base, mut cand) = (SimSeries::default(), SimSeries::default());
    let mut pts = Vec::new();
    let g: Vec<f64> = rows.iter().map(|t| 1.0 - (-t / 200.0).exp()).collect();
    for (ch, rise) in CHANNELS {
        run.set(ch, vec![Some(30.0); rows.len()]);
        let floor = ar1(&mut rng, &rows, 0.02 * rise, 300.0, 0.1);
        let extra: Vec<f64> = match ch {
            Channel::TOilC => g.iter().map(|x| imprint_k * x).collect(),
            Channel::TBlockC => rows.iter().map(|t| block_extra_k * (t / 300.0).sin()).collect(),
            _ => vec![0.0; rows.len()],
        };
        let explained = ch == Channel::TOilC;
        base.channels.insert(ch, floor.iter().zip(&extra).map(|(f, e)| 30.0 + f + e).collect());
        cand.channels.insert(ch, floor.iter().zip(&extra).map(|(f, e)| 30.0 + f + if explained { 0.0 } else { *e }).collect());
        pts.extend((0..rows.len()).map(|i| (ch, i)));
    }
    // Jacobians: one nuisance multiplier moving every channel along a
    // ramp; the candidate's parameter moving the oil along the imprint.
    let n = pts.len();
    let ramp = |i: usize| 0.5 * rows[pts[i].1] / 840.0;
    let j_base = DMatrix::from_fn(n, 1, |i, _| ramp(i));
    let j_cand = DMatrix::from_fn(n, 2, |i, k| if k == 0 { ramp(i) } else if pts[i].0 == Channel::TOilC { 0.5 * g[pts[i].1] } else { 0.0 });
    let fit = |c: Candidate, series: SimSeries, ext: Vec<f64>, j: DMatrix<f64>| FitResult {
        candidate: c,
        nuisance: vec![1.0],
        ext,
        rss: 0.0,
        n,
        sims: 0,
        series,
        jac_ln: Some(j),
        jac_owed: None,
    };
    let nuisance = [ParamSpec::new("scale", "1", 1.0, 0.5, 2.0)];
    let b = fit(Candidate::None, base, vec![], j_base);
    let c = fit(Candidate::SensorLag, cand, vec![100.0], j_cand);
    let chan: Vec<(Channel, f64, f64)> = CHANNELS.iter().map(|(ch, rise)| (*ch, 0.1, *rise)).collect();
    posterior_of(
        &run,
        &pts,
        &pts,
        &b,
        std::slice::from_ref(&c),
        &nuisance,
        &|_| vec![ParamSpec::new("sensor_tau_s", "s", 100.0, 10.0, 1000.0)],
        &chan,
        &|_| true,
        &|_| true,
        split,
        DISCREPANCY_TAU_S,
    )
}

/// The effective sample fraction of an AR(1) residual: 1 for white or
/// alternating residuals, (1 − ρ)/(1 + ρ) otherwise.
#[test]
fn effective_fraction_is_that_of_an_ar1_mean() {
    assert_eq!(effective_fraction(0.0), 1.0);
    assert_eq!(effective_fraction(-0.3), 1.0);
    assert!((effective_fraction(0.5) - 1.0 / 3.0).abs() < 1e-12);
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
    let t: Vec<f64> = (0..4000).map(|i| i as f64).collect();
    let y = ar1(&mut rng, &t, 1.0, 1.0 / 0.5f64.ln().abs(), 0.0);
    assert!((lag1(&y) - 0.5).abs() < 0.05, "lag-1 of an AR(1) with ρ 0.5: {}", lag1(&y));
}

/// The tempered rule judges a candidate on the channels its physics
/// touches: a 3 K misfit on t_block_c that nothing explains (fifteen
/// times its floor) changes the lag's tempered evidence against the
/// no-cause block by < 0.5 nats on five draws (it moves the split
/// between `none` and `unexplained` only).
#[test]
fn the_tempered_rule_keeps_an_untouched_channel_out_of_a_candidate_evidence() {
    let against_no_cause = |p: &[CauseProbability]| {
        let bf = |c: &str| p.iter().find(|x| x.cause == c).unwrap().log_bayes_factor;
        bf("sensor-lag") + 2f64.ln() - log_sum_exp(0.0, bf("unexplained"))
    };
    for seed in 1..=5 {
        let clean = posterior_from_terms(&toy(1.0, 0.0, seed).terms, DecisionRule::Tempered);
        let vetoed = posterior_from_terms(&toy(1.0, 3.0, seed).terms, DecisionRule::Tempered);
        let (a, b) = (against_no_cause(&clean), against_no_cause(&vetoed));
        assert!((a - b).abs() < 0.5, "seed {seed}: {a:.2} clean against {b:.2} with the block misfit");
    }
}

/// Item "a candidate has to beat a discrepancy of floor size": an
/// imprint on the oil channel as large as the floor the other channels
/// show (2 % of its 10 K rise, 0.2 K) gets no name at P ≥ 0.9, on each
/// of five draws of the floor; the same imprint at five times the floor
/// (1 K) is named with P ≥ 0.9 on each.
#[test]
fn a_candidate_must_beat_a_discrepancy_of_floor_size() {
    for seed in 1..=5 {
        let small = toy(0.2, 0.0, seed);
        assert!(small.named().is_none(), "seed {seed}: floor-size imprint named: {:?}", small.causes);
        let clear = toy(1.0, 0.0, seed);
        assert!(clear.of("sensor-lag") >= NAME_PROBABILITY, "seed {seed}: clear imprint: {:?}", clear.causes);
        let oil = clear.channels.iter().find(|c| c.channel == "t_oil_c").unwrap();
        assert!(oil.imprint_ratio >= 2.0, "seed {seed}: oil imprint ratio {:.1}", oil.imprint_ratio);
    }
}

/// The posterior recomputed from the stored terms (the sweep's offline
/// decision) is the diagnosis's own, to the grid's interpolation: ln
/// Bayes factors within 0.1 nats + 0.1 % (measured: 0.16 of 303 nats
/// with the block misfit), probabilities within 0.01, on the toy with
/// and without the block misfit.
#[test]
fn the_posterior_from_stored_terms_is_the_diagnosis_own() {
    for (imprint, block) in [(1.0, 0.0), (0.2, 3.0), (1.0, 3.0), (0.5, 0.0)] {
        let p = toy(imprint, block, 3);
        let q = posterior_from_terms(&p.terms, DECISION_RULE);
        for c in &p.causes {
            let d = q.iter().find(|x| x.cause == c.cause).unwrap();
            assert!((d.log_bayes_factor - c.log_bayes_factor).abs() < 0.1 + 1e-3 * c.log_bayes_factor.abs(), "{imprint}/{block} {}: {} against {}", c.cause, d.log_bayes_factor, c.log_bayes_factor);
            assert!((d.probability - c.probability).abs() < 0.01, "{imprint}/{block} {}: {} against {}", c.cause, d.probability, c.probability);
        }
    }
}

/// The re-statement of a stored posterior under the held-out likelihood
/// ([`crate::diagnosis::emu_calibration::restate_heldout`], from the
/// numbers diagnosis.json carries) is [`DecisionRule::HeldOut`] decided
/// from the terms, to rounding (1e-9): on the toy with the last 240 s
/// held out. And the lag, which removes the oil imprint, predicts the
/// held-out oil better than `none` (its held-out part on the touched
/// channel > 0) with a 1 K imprint.
#[test]
fn the_heldout_restatement_is_the_heldout_rule() {
    use crate::diagnosis::report::ProbabilityJson;
    for (imprint, block) in [(1.0, 0.0), (0.2, 3.0), (0.0, 0.0)] {
        let p = toy_split(imprint, block, 5, 600.0);
        let stored: Vec<ProbabilityJson> = p.causes.iter().map(ProbabilityJson::from).collect();
        let again = crate::diagnosis::emu_calibration::restate_heldout(&stored).unwrap();
        let rule = posterior_from_terms(&p.terms, DecisionRule::HeldOut);
        for c in &rule {
            let d = again.iter().find(|x| x.cause == c.cause).unwrap();
            assert!((d.log_bayes_factor - c.log_bayes_factor).abs() < 1e-9 * c.log_bayes_factor.abs().max(1.0), "{}: {} against {}", c.cause, d.log_bayes_factor, c.log_bayes_factor);
            assert!((d.probability - c.probability).abs() < 1e-9, "{}: {} against {}", c.cause, d.probability, c.probability);
        }
        if imprint == 1.0 {
            let lag = p.causes.iter().find(|c| c.cause == "sensor-lag").unwrap();
            assert!(lag.heldout_touched > 0.0, "held-out on t_oil_c {}", lag.heldout_touched);
        }
    }
}

/// Per-channel evidence. A channel that misfits far more than the
/// others (t_block_c off by a 3 K sine that nothing explains, fifteen
/// times its floor) beside a clear lag imprint (1 K on t_oil_c), five
/// draws:
/// - the product's pooled rule keeps the lag's Bayes factor decisive
///   (ln BF > 5) but, **measured limit**, `unexplained` takes P ≥ 0.99
///   and the lag is not named: the block vetoes the decision;
/// - the per-channel rule names the lag at P ≥ 0.9 and still names
///   nothing for a floor-size imprint (0.2 K), where the answer leans to
///   `unexplained`, not `none`. It is not the product's rule: on the
///   emulator twin of 1700 it names `sensor-lag` ([`DECISION_RULE`]).
#[test]
fn a_channel_that_misfits_far_more_leaves_the_candidates_bayes_factor() {
    for seed in 1..=5 {
        let (clean, vetoed, faint) = (toy(1.0, 0.0, seed), toy(1.0, 3.0, seed), toy(0.2, 3.0, seed));
        let bf = |p: &Posterior| p.causes.iter().find(|c| c.cause == "sensor-lag").unwrap().log_bayes_factor;
        eprintln!("seed {seed}: ln BF {:.1} clean, {:.1} with the block misfit", bf(&clean), bf(&vetoed));
        assert!(bf(&vetoed) > 5.0, "seed {seed}: ln BF {:.1} against {:.1}", bf(&clean), bf(&vetoed));
        assert!(vetoed.of("unexplained") >= 0.99, "seed {seed}: measured limit changed: {:?}", vetoed.causes);
        let block = vetoed.channels.iter().find(|c| c.channel == "t_block_c").unwrap();
        assert!(block.misfit_k > 1.5, "seed {seed}: block misfit {:.2}", block.misfit_k);
        let of = |p: &[CauseProbability], c: &str| p.iter().find(|x| x.cause == c).map_or(0.0, |x| x.probability);
        let per = posterior_from_terms(&vetoed.terms, DecisionRule::PerChannel);
        assert!(of(&per, "sensor-lag") >= NAME_PROBABILITY, "seed {seed}: per-channel rule, clear lag: {per:?}");
        let per_faint = posterior_from_terms(&faint.terms, DecisionRule::PerChannel);
        assert!(of(&per_faint, "sensor-lag") < NAME_PROBABILITY, "seed {seed}: per-channel rule, floor-size lag named: {per_faint:?}");
        assert!(of(&per_faint, "unexplained") > of(&per_faint, "none"), "seed {seed}: per-channel rule reads the block as `none`: {per_faint:?}");
    }
}
