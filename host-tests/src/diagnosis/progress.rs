//! The diagnosis's progress bar (indicatif, on stderr; hidden when stderr
//! is not a terminal): a [`Simulator`] wrapper that counts every model run
//! of every phase — both tiers (the escalation to the physical set runs
//! through the same bar), restarts, refits, the Jacobians of the kept fits,
//! the detectability pass — and keeps the bar's length at the runs done
//! plus an estimate of the runs ahead.
//!
//! The runs ahead, renewed at every phase ([`Phase`]), by phase: a fit costs
//! its whole budget until a fit of the tier has been measured, then what the
//! tier's baseline fit cost (scaled by (p + 2)/(p + 1) for a candidate's
//! extra parameter, at least [`CANDIDATE_SHARE`] of the budget), then what
//! the candidate fits cost on average. The phases ahead: the candidates (two
//! starts each), the two restarts and the refits ([`REFIT_SHARE`] of a
//! candidate fit each; the physical tier always restarts, the global tier
//! when a candidate qualifies, which both synthetic 30-minute bench logs
//! did), the Jacobians of the kept fits; and, while the global baseline
//! fails the strict rule (the diagnosis says so), [`ESCALATION_WEIGHT`] of
//! the physical tier.
//!
//! The time left is the diagnosis's own estimate, not indicatif's (its
//! smoothed recent rate showed 20–40 % short on the 30-minute emulator
//! log): the runs ahead of each phase times that phase's wall time per
//! run, as measured in this tier once the phase has run; the current
//! phase's own mean rate after [`MIN_RATE_RUNS`] runs; phases not yet run
//! at the current phase's rate (else the mean so far). A fixed ratio of
//! cost per run between phases was tried and not kept: measured twice on
//! the emulator log, the physical tier's candidates against its baseline
//! fit ran at 1.35 and at 0.85 times its runs' wall time, the refits
//! against the candidates at 1.3 and 1.0. The residual analysis and the
//! evidence are not counted (0.5 s of a 30-minute log's diagnosis on a
//! quiet machine, bench `diagnose_30min`).

use super::model::{Candidate, ParamSpec, Phase, SimSeries, Simulator};
use std::sync::{Arc, Mutex};
use std::time::Instant;

/// Makes the runs ahead by phase from the estimate, given the runs the
/// closed phase took ([`Progress`]'s phases).
type PlanMaker<'a> = dyn Fn(&mut Est, f64) -> Vec<(Kind, f64)> + 'a;

/// The time left shown when the bar first reached a fraction of its length.
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

/// The kinds of runs whose wall time per run differs: a phase's runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Kind {
    Baseline,
    Candidates,
    Restarts,
    Refits,
    Jacobians,
    Detectability,
}

/// Runs of the current phase after which its own wall time per run is used
/// for its remaining runs.
pub const MIN_RATE_RUNS: f64 = 20.0;

struct Est {
    max_sims: usize,
    params: usize,
    phase_start: u64,
    cand_fits: usize,
    base_fit: Option<f64>,
    cand_fit: Option<f64>,
    crossings: Vec<Crossing>,
    /// The current phase's kind and start.
    kind: Kind,
    phase_t: Instant,
    /// Runs ahead by phase, as estimated at the current phase's start
    /// (the current phase first).
    plan: Vec<(Kind, f64)>,
    /// Wall time and runs of this tier's finished phases, by kind.
    spent: [(f64, f64); 6],
    /// Wall time and runs of every finished phase.
    all: (f64, f64),
}

impl Est {
    /// Prior runs of one fit of `p` parameters: its whole budget
    /// (`diagnosis::fit`: `max_sims`, at least 6 Jacobians; its Jacobian at
    /// the best point is counted in the Jacobians phase). Measured on the
    /// 30-minute throttle log (bench `diagnose_30min`): the baseline fit
    /// took 85 of its 85, the candidate fits 81 on average.
    fn prior(&self, p: usize) -> f64 {
        self.max_sims.max(6 * (p + 1)) as f64
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
    /// Runs of the Jacobians at the best points of the kept fits (the
    /// baseline and one per candidate; at most, a fit's last Jacobian is
    /// often at its best point already).
    fn jacobians(&self, p: usize) -> f64 {
        ((p + 1) + Candidate::EXTENSIONS.len() * (p + 2)) as f64
    }
    /// The phases of a whole tier with `p` nuisance parameters, by the
    /// prior (restarts and refits included).
    fn tier(&self, p: usize) -> Vec<(Kind, f64)> {
        let (b, c) = (self.prior(p), self.prior(p + 1));
        let ext = Candidate::EXTENSIONS.len() as f64;
        vec![
            (Kind::Baseline, 1.0 + b),
            (Kind::Candidates, super::analysis::STARTS_PER_CANDIDATE as f64 * ext * c),
            (Kind::Restarts, 2.0 * b),
            (Kind::Refits, ext * REFIT_SHARE * c),
            (Kind::Jacobians, self.jacobians(p)),
        ]
    }
    /// Closes the current phase's measurement (`done` runs by now).
    fn close_phase(&mut self, done: f64, now: Instant) {
        let secs = now.duration_since(self.phase_t).as_secs_f64();
        let k = self.kind as usize;
        self.spent[k].0 += secs;
        self.spent[k].1 += done;
        self.all.0 += secs;
        self.all.1 += done;
        self.phase_t = now;
    }
    /// Wall time left, s, with `done` runs of the current phase done:
    /// `None` before any run has been timed.
    fn left_s(&self, done: f64, now: Instant) -> Option<f64> {
        let el = now.duration_since(self.phase_t).as_secs_f64();
        let (secs, runs) = (self.all.0 + el, self.all.1 + done);
        if runs <= 0.0 || secs <= 0.0 {
            return None;
        }
        // A phase not yet run: the current phase's rate once measured,
        // else the mean so far.
        let current = (done >= MIN_RATE_RUNS).then(|| el / done);
        let fallback = current.unwrap_or(secs / runs);
        let per_run = |k: Kind| {
            let (s, n) = self.spent[k as usize];
            if n >= MIN_RATE_RUNS { s / n } else { fallback }
        };
        let mut left = 0.0;
        for (i, (k, n)) in self.plan.iter().enumerate() {
            left += if i == 0 { (n - done).max(0.0) * current.unwrap_or_else(|| per_run(*k)) } else { n * per_run(*k) };
        }
        Some(left)
    }
}

struct Shared {
    bar: indicatif::ProgressBar,
    est: Arc<Mutex<Est>>,
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
        let now = Instant::now();
        let est = Est {
            max_sims,
            params: 0,
            phase_start: 0,
            cand_fits: 0,
            base_fit: None,
            cand_fit: None,
            crossings: Vec::new(),
            kind: Kind::Baseline,
            phase_t: now,
            plan: Vec::new(),
            spent: [(0.0, 0.0); 6],
            all: (0.0, 0.0),
        };
        let est = Arc::new(Mutex::new(est));
        let bar = if visible { indicatif::ProgressBar::new(1) } else { indicatif::ProgressBar::hidden() };
        // The time left is the estimate's (module doc); the bar draws it
        // without holding anything else (the estimate is never locked
        // while the bar is updated).
        let left = {
            let est = est.clone();
            move |st: &indicatif::ProgressState, w: &mut dyn std::fmt::Write| {
                let left = est.lock().ok().and_then(|e| e.left_s(st.pos().saturating_sub(e.phase_start) as f64, Instant::now()));
                let _ = match left {
                    Some(s) => write!(w, "{:#}", indicatif::HumanDuration(std::time::Duration::from_secs_f64(s))),
                    None => write!(w, "?"),
                };
            }
        };
        bar.set_style(
            indicatif::ProgressStyle::with_template("{msg:36} [{bar:30}] {pos}/{len} model runs, {elapsed} elapsed, ~{left} left")
                .map(|st| st.with_key("left", left))
                .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar())
                .progress_chars("=> "),
        );
        if visible {
            bar.enable_steady_tick(std::time::Duration::from_millis(200));
        }
        Progress { inner: Inner::Borrowed(inner), shared: Arc::new(Shared { bar, est, start: now }), physical: false }
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
        self.start_phase(Kind::Detectability, &|_, _| vec![(Kind::Detectability, runs as f64)], msg.to_string());
    }

    /// Clears the bar; returns the time left it showed at 25, 50 and 75 %.
    pub fn finish(&self) -> Vec<Crossing> {
        self.shared.bar.finish_and_clear();
        self.shared.est.lock().map(|e| e.crossings.clone()).unwrap_or_default()
    }

    /// Closes the current phase and starts one of `kind` with the plan
    /// `make` computes from the estimate (after the close; given the runs
    /// the closed phase took) ahead, the bar's length following.
    fn start_phase(&self, kind: Kind, make: &PlanMaker<'_>, msg: String) {
        let b = &self.shared.bar;
        let pos = b.position();
        let ahead = {
            let Ok(mut e) = self.shared.est.lock() else { return };
            let done = (pos - e.phase_start) as f64;
            e.close_phase(done, Instant::now());
            let plan = make(&mut e, done);
            e.kind = kind;
            e.phase_start = pos;
            let ahead: f64 = plan.iter().map(|x| x.1).sum();
            e.plan = plan;
            ahead
        };
        b.set_length(pos + ahead.round().max(1.0) as u64);
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
                    let now = Instant::now();
                    let at_s = now.duration_since(self.shared.start).as_secs_f64();
                    let eta_s = e.left_s(pos.saturating_sub(e.phase_start) as f64, now).unwrap_or(f64::NAN);
                    e.crossings.push(Crossing { fraction: frac, at_s, eta_s, runs: (pos, len) });
                }
            }
        }
        self.inner().simulate(nuisance, c, ext)
    }

    fn phase(&self, p: Phase) {
        let tier = if self.physical { "physical" } else { "global" };
        let ext = Candidate::EXTENSIONS.len() as f64;
        // The physical tier's size, asked before the estimate is locked.
        let physical_params = match p {
            Phase::Candidates { may_escalate: true, .. } => self.inner().physical_set().map(|s| s.nuisance().len()),
            _ => None,
        };
        let (kind, msg) = match p {
            Phase::Baseline { params } => (Kind::Baseline, format!("{tier}: baseline ({params} parameters)")),
            Phase::Candidates { fits, .. } => (Kind::Candidates, format!("{tier}: {fits} candidate fits")),
            Phase::Restarts { fits } => (Kind::Restarts, format!("{tier}: {fits} baseline restarts")),
            Phase::Refits { fits } => (Kind::Refits, format!("{tier}: {fits} candidate refits")),
            Phase::Jacobians { runs } => (Kind::Jacobians, format!("{tier}: Jacobians ({runs} runs)")),
            Phase::Done => (Kind::Jacobians, format!("{tier}: deciding")),
        };
        let make = |e: &mut Est, done: f64| -> Vec<(Kind, f64)> {
            let jac = e.jacobians(e.params);
            match p {
                Phase::Baseline { params } => {
                    (e.params, e.base_fit, e.cand_fit) = (params, None, None);
                    e.spent = [(0.0, 0.0); 6];
                    e.tier(params)
                }
                Phase::Candidates { fits, may_escalate } => {
                    e.base_fit = Some((done - 1.0).max(1.0));
                    e.cand_fits = fits;
                    let mut plan = vec![
                        (Kind::Candidates, fits as f64 * e.cand()),
                        (Kind::Restarts, 2.0 * e.base()),
                        (Kind::Refits, ext * REFIT_SHARE * e.cand()),
                        (Kind::Jacobians, jac),
                    ];
                    if may_escalate {
                        let pp = physical_params.unwrap_or(e.params);
                        plan.extend(e.tier(pp).into_iter().map(|(k, n)| (k, ESCALATION_WEIGHT * n)));
                    }
                    plan
                }
                Phase::Restarts { fits } => {
                    if e.cand_fit.is_none() && e.cand_fits > 0 {
                        e.cand_fit = Some(done / e.cand_fits as f64);
                    }
                    vec![(Kind::Restarts, fits as f64 * e.base()), (Kind::Refits, ext * REFIT_SHARE * e.cand()), (Kind::Jacobians, jac)]
                }
                Phase::Refits { fits } => vec![(Kind::Refits, fits as f64 * REFIT_SHARE * e.cand()), (Kind::Jacobians, jac)],
                Phase::Jacobians { runs } => vec![(Kind::Jacobians, runs as f64)],
                Phase::Done => Vec::new(),
            }
        };
        self.start_phase(kind, &make, msg);
    }
}
