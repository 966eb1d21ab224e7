//! The diagnosis's progress bar (indicatif, on stderr; hidden when stderr
//! is not a terminal): a [`Simulator`] wrapper that counts every model run
//! of every phase — both tiers (the escalation to the physical set runs
//! through the same bar), restarts, refits, the detectability pass — and
//! keeps the bar's length at the runs done plus an estimate of the runs
//! ahead, so that indicatif's time left (its run rate × runs ahead) is an
//! estimate, not a bound.
//!
//! The estimate, renewed at every phase ([`Phase`]): a fit costs its whole
//! budget until a fit of the tier has been measured, then what the tier's
//! baseline fit cost (scaled by (p + 2)/(p + 1) for a candidate's extra
//! parameter, at least [`CANDIDATE_SHARE`] of the budget), then what the
//! candidate fits cost on average. The phases ahead: the candidates (two
//! starts each), the two restarts and the refits ([`REFIT_SHARE`] of a
//! candidate fit each; the physical tier always restarts, the global tier
//! when a candidate qualifies, which both 30-minute bench logs did); and,
//! while the global baseline fails the strict rule (the diagnosis says
//! so), [`ESCALATION_WEIGHT`] of the physical tier. The residual analysis
//! and the evidence are not counted (0.5 s of a 30-minute log's
//! diagnosis on a quiet machine, bench `diagnose_30min`).

use super::model::{Candidate, ParamSpec, Phase, SimSeries, Simulator};
use std::sync::{Arc, Mutex};
use std::time::Instant;

/// The ETA shown when the bar first reached a fraction of its length.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Crossing {
    /// Fraction of the bar (0.25, 0.5, 0.75).
    pub fraction: f64,
    /// Time since the start, s.
    pub at_s: f64,
    /// Time left the bar showed then, s.
    pub eta_s: f64,
    /// Model runs done then, and the bar's length (runs done + estimated).
    pub runs: (u64, u64),
}

/// Least share of its budget a candidate fit is expected to take before
/// one is measured: the 30-minute servo log's baseline fit converged in 19
/// runs, its candidate fits took 54 of 86 on average (the throttle log's
/// 81 of 86).
pub const CANDIDATE_SHARE: f64 = 0.6;

/// Share of a candidate fit a refit from the better baseline takes
/// (measured: 64 / 81 throttle, 28 / 54 servo).
pub const REFIT_SHARE: f64 = 0.7;

/// Weight of the physical tier in the estimate while the global tier's
/// candidates run and its baseline fails the strict rule: the tier follows
/// only when no cause is named, which the candidates decide. One half: the
/// time left is then wrong by at most half that tier either way (a whole
/// tier counted made the 30-minute throttle log, whose lag is named in the
/// global tier, show 50 s left at a quarter with 13 s to go).
pub const ESCALATION_WEIGHT: f64 = 0.5;

struct Est {
    max_sims: usize,
    params: usize,
    phase_start: u64,
    cand_fits: usize,
    base_fit: Option<f64>,
    cand_fit: Option<f64>,
    crossings: Vec<Crossing>,
}

impl Est {
    /// Prior runs of one fit of `p` parameters: its whole budget
    /// (`diagnosis::fit`: `max_sims`, at least 6 Jacobians, plus one
    /// Jacobian at the best point). Measured on the 30-minute throttle log
    /// (bench `diagnose_30min`): the baseline fit took 85 of its 85, the
    /// candidate fits 81 on average.
    fn prior(&self, p: usize) -> f64 {
        let p1 = (p + 1) as f64;
        self.max_sims.max(6 * (p + 1)) as f64 + p1
    }
    fn base(&self) -> f64 {
        self.base_fit.unwrap_or_else(|| self.prior(self.params))
    }
    /// Runs of one candidate fit: measured, else the baseline fit's scaled
    /// by (p + 2)/(p + 1) but at least [`CANDIDATE_SHARE`] of the budget,
    /// else the budget.
    fn cand(&self) -> f64 {
        let prior = self.prior(self.params + 1);
        self.cand_fit.unwrap_or_else(|| {
            self.base_fit.map_or(prior, |b| (b * (self.params + 2) as f64 / (self.params + 1) as f64).clamp(CANDIDATE_SHARE * prior, prior))
        })
    }
    /// Runs of a whole tier with `p` nuisance parameters, by the prior
    /// (restarts and refits included).
    fn tier(&self, p: usize) -> f64 {
        let (b, c) = (self.prior(p), self.prior(p + 1));
        let n = (2 * Candidate::EXTENSIONS.len()) as f64;
        1.0 + b + n * c + 2.0 * b + Candidate::EXTENSIONS.len() as f64 * REFIT_SHARE * c
    }
}

struct Shared {
    bar: indicatif::ProgressBar,
    est: Mutex<Est>,
    start: Instant,
}

enum Inner<'a> {
    Borrowed(&'a dyn Simulator),
    Owned(Box<dyn Simulator + 'a>),
}

/// A model whose runs advance the progress bar (see the module doc).
pub struct Progress<'a> {
    inner: Inner<'a>,
    shared: Arc<Shared>,
    physical: bool,
}

impl<'a> Progress<'a> {
    /// The bar over `inner`'s runs; `max_sims` is the fits' budget
    /// (`FitOptions::max_sims`); `visible`: drawn on stderr (when a terminal).
    pub fn new(inner: &'a dyn Simulator, max_sims: usize, visible: bool) -> Self {
        let bar = if visible { indicatif::ProgressBar::new(1) } else { indicatif::ProgressBar::hidden() };
        bar.set_style(
            indicatif::ProgressStyle::with_template("{msg:36} [{bar:30}] {pos}/{len} model runs, {elapsed} elapsed, ~{eta} left")
                .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar())
                .progress_chars("=> "),
        );
        if visible {
            bar.enable_steady_tick(std::time::Duration::from_millis(200));
        }
        let est = Est { max_sims, params: 0, phase_start: 0, cand_fits: 0, base_fit: None, cand_fit: None, crossings: Vec::new() };
        Progress { inner: Inner::Borrowed(inner), shared: Arc::new(Shared { bar, est: Mutex::new(est), start: Instant::now() }), physical: false }
    }

    fn inner(&self) -> &dyn Simulator {
        match &self.inner {
            Inner::Borrowed(s) => *s,
            Inner::Owned(s) => &**s,
        }
    }

    /// Announces `runs` more model runs of a pass after the diagnosis (the
    /// detectability), under `msg`.
    pub fn extend(&self, runs: u64, msg: &str) {
        let b = &self.shared.bar;
        b.set_length(b.position() + runs.max(1));
        b.set_message(msg.to_string());
    }

    /// Clears the bar; returns the time left it showed at 25, 50 and 75 %.
    pub fn finish(&self) -> Vec<Crossing> {
        self.shared.bar.finish_and_clear();
        self.shared.est.lock().map(|e| e.crossings.clone()).unwrap_or_default()
    }

    fn set_ahead(&self, ahead: f64, msg: String) {
        let b = &self.shared.bar;
        b.set_length(b.position() + ahead.round().max(1.0) as u64);
        b.set_message(msg);
    }
}

impl Simulator for Progress<'_> {
    fn nuisance(&self) -> Vec<ParamSpec> {
        self.inner().nuisance()
    }

    fn extension_params(&self, c: Candidate) -> Vec<ParamSpec> {
        self.inner().extension_params(c)
    }

    fn physical_set(&self) -> Option<Box<dyn Simulator + '_>> {
        let p = self.inner().physical_set()?;
        Some(Box::new(Progress { inner: Inner::Owned(p), shared: self.shared.clone(), physical: true }))
    }

    fn nuisance_set_name(&self) -> &'static str {
        self.inner().nuisance_set_name()
    }

    fn simulate(&self, nuisance: &[f64], c: Candidate, ext: &[f64]) -> Result<SimSeries, String> {
        let b = &self.shared.bar;
        b.inc(1);
        let (pos, len) = (b.position(), b.length().unwrap_or(1).max(1));
        if let Ok(mut e) = self.shared.est.lock() {
            let f = pos as f64 / len as f64;
            for frac in [0.25, 0.5, 0.75] {
                if f >= frac && !e.crossings.iter().any(|x| x.fraction == frac) {
                    let at_s = self.shared.start.elapsed().as_secs_f64();
                    e.crossings.push(Crossing { fraction: frac, at_s, eta_s: b.eta().as_secs_f64(), runs: (pos, len) });
                }
            }
        }
        self.inner().simulate(nuisance, c, ext)
    }

    fn phase(&self, p: Phase) {
        let pos = self.shared.bar.position();
        let Ok(mut e) = self.shared.est.lock() else { return };
        let tier = if self.physical { "physical" } else { "global" };
        let done = (pos - e.phase_start) as f64;
        let ext = Candidate::EXTENSIONS.len() as f64;
        let (ahead, msg) = match p {
            Phase::Baseline { params } => {
                (e.params, e.base_fit, e.cand_fit) = (params, None, None);
                (e.tier(params), format!("{tier}: baseline ({params} parameters)"))
            }
            Phase::Candidates { fits, may_escalate } => {
                e.base_fit = Some((done - 1.0).max(1.0));
                e.cand_fits = fits;
                let mut ahead = fits as f64 * e.cand() + 2.0 * e.base() + ext * REFIT_SHARE * e.cand();
                if may_escalate {
                    let pp = self.inner().physical_set().map_or(e.params, |s| s.nuisance().len());
                    ahead += ESCALATION_WEIGHT * e.tier(pp);
                }
                (ahead, format!("{tier}: {fits} candidate fits"))
            }
            Phase::Restarts { fits } => {
                if e.cand_fit.is_none() && e.cand_fits > 0 {
                    e.cand_fit = Some(done / e.cand_fits as f64);
                }
                (fits as f64 * e.base() + ext * REFIT_SHARE * e.cand(), format!("{tier}: {fits} baseline restarts"))
            }
            Phase::Refits { fits } => (fits as f64 * REFIT_SHARE * e.cand(), format!("{tier}: {fits} candidate refits")),
            Phase::Done => (0.0, format!("{tier}: deciding")),
        };
        e.phase_start = pos;
        drop(e);
        self.set_ahead(ahead, msg);
    }
}
