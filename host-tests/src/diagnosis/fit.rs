//! Least-squares calibration with the `levenberg-marquardt` crate: the
//! nuisance set plus a candidate's own parameters, fitted in log space on
//! the training points of a measured run.
//!
//! Bounds: each parameter's log value θ ∈ [ln lo, ln hi] is mapped from an
//! unbounded internal variable z by θ = ln lo + (ln hi − ln lo)(1 + sin z)/2
//! (the MINUIT transform). Clamping θ instead gives a zero Jacobian column
//! once an iterate overshoots a bound, and the parameter then stays pinned
//! there for the rest of the fit (observed: air speed at 40 m/s, conduction
//! at 50 W/K where the truth was 5.6 m/s and 6.8 W/K).

use super::model::{Candidate, ParamSpec, SimSeries, Simulator};
use crate::measured::{Channel, MeasuredRun};
use levenberg_marquardt::{LeastSquaresProblem, LevenbergMarquardt};
use nalgebra::{storage::Owned, DMatrix, DVector, Dyn};
use rayon::prelude::*;

/// Data σ, K, against which the prior rows of [`ParamSpec::prior_sigma_ln`]
/// are weighed (the calibration's default, `CalOptions::sigma_data_k`).
pub const PRIOR_DATA_SIGMA_K: f64 = 0.2;

/// One residual point: channel and row index into the measured run.
pub type Point = (Channel, usize);

/// Budget and tolerances of one fit.
#[derive(Debug, Clone, Copy)]
pub struct FitOptions {
    /// Maximum model runs per fit (Jacobian columns included).
    pub max_sims: usize,
    /// Forward-difference step in log-parameter space.
    pub fd_step: f64,
    /// Relative objective tolerance of the LM iteration.
    pub ftol: f64,
}

impl Default for FitOptions {
    fn default() -> Self {
        FitOptions { max_sims: 80, fd_step: 0.02, ftol: 1e-5 }
    }
}

/// Outcome of one fit.
#[derive(Debug, Clone)]
pub struct FitResult {
    /// Candidate fitted.
    pub candidate: Candidate,
    /// Fitted nuisance values, in [`Simulator::nuisance`] order.
    pub nuisance: Vec<f64>,
    /// Fitted extension values, in [`Simulator::extension_params`] order.
    pub ext: Vec<f64>,
    /// Residual sum of squares over the fit points, K².
    pub rss: f64,
    /// Number of fit points.
    pub n: usize,
    /// Model runs spent.
    pub sims: usize,
    /// Model series at the best parameters (all measured times).
    pub series: SimSeries,
    /// Jacobian of the data residuals (rows: the fit points) with respect
    /// to the logarithms of the parameters (columns: nuisance, then
    /// extension) at the best parameters, K per unit of ln value: the
    /// curvature of the evidence ([`super::evidence`]). `None` when the
    /// model failed there, or while it is still owed (see [`fit_deferred`]).
    pub jac_ln: Option<DMatrix<f64>>,
    /// The internal variables of the best point and the difference step
    /// while its Jacobian is owed ([`fit_deferred`]); `None` once it is in
    /// [`Self::jac_ln`] or failed.
    pub(crate) jac_owed: Option<(DVector<f64>, f64)>,
}

/// Residuals (simulated − measured, K) of `s` at `points`; `None` when the
/// model lacks a channel.
pub fn residuals_at(run: &MeasuredRun, s: &SimSeries, points: &[Point]) -> Option<Vec<f64>> {
    points
        .iter()
        .map(|&(ch, i)| {
            let m = run.get(ch)?[i]?;
            Some(s.channels.get(&ch)?[i] - m)
        })
        .collect()
}

struct Problem<'a> {
    sim: &'a dyn Simulator,
    run: &'a MeasuredRun,
    points: &'a [Point],
    cand: Candidate,
    specs: Vec<ParamSpec>,
    n_nuis: usize,
    x: DVector<f64>,
    r: Option<DVector<f64>>,
    opts: FitOptions,
    sims: std::sync::atomic::AtomicUsize,
    best: Option<(f64, DVector<f64>, SimSeries)>,
    /// The last Jacobian's point and its data rows in ln-parameter space.
    last_jac_ln: std::sync::Mutex<Option<(DVector<f64>, DMatrix<f64>)>>,
}

impl Problem<'_> {
    fn values(&self, x: &DVector<f64>) -> Vec<f64> {
        x.iter().zip(&self.specs).map(|(z, s)| from_internal(*z, s)).collect()
    }

    fn eval(&self, x: &DVector<f64>) -> Option<(DVector<f64>, SimSeries)> {
        let used = self.sims.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        if used >= self.opts.max_sims {
            return None;
        }
        let v = self.values(x);
        let s = self.sim.simulate(&v[..self.n_nuis], self.cand, &v[self.n_nuis..]).ok()?;
        Some((self.residual_vector(x, &s)?, s))
    }

    /// The fit's residuals at internal point `x` whose model series is
    /// `s`: the data rows, then the prior rows; `None` unless all finite.
    fn residual_vector(&self, x: &DVector<f64>, s: &SimSeries) -> Option<DVector<f64>> {
        let v = self.values(x);
        let mut r = residuals_at(self.run, s, self.points)?;
        for (v, sp) in v.iter().zip(&self.specs) {
            if let Some(sig) = sp.prior_sigma_ln {
                r.push(PRIOR_DATA_SIGMA_K * (v / sp.start).ln() / sig);
            }
        }
        r.iter().all(|x| x.is_finite()).then(|| DVector::from_vec(r))
    }
}

impl LeastSquaresProblem<f64, Dyn, Dyn> for Problem<'_> {
    type ResidualStorage = Owned<f64, Dyn>;
    type JacobianStorage = Owned<f64, Dyn, Dyn>;
    type ParameterStorage = Owned<f64, Dyn>;

    fn set_params(&mut self, x: &DVector<f64>) {
        self.x = x.clone();
        match self.eval(x) {
            Some((r, s)) => {
                let rss = r.norm_squared();
                if self.best.as_ref().is_none_or(|b| rss < b.0) {
                    self.best = Some((rss, x.clone(), s));
                }
                self.r = Some(r);
            }
            None => self.r = None,
        }
    }

    fn params(&self) -> DVector<f64> {
        self.x.clone()
    }

    fn residuals(&self) -> Option<DVector<f64>> {
        self.r.clone()
    }

    fn jacobian(&self) -> Option<DMatrix<f64>> {
        let (jz, jln) = self.jacobians()?;
        if let Ok(mut l) = self.last_jac_ln.lock() {
            *l = Some((self.x.clone(), jln));
        }
        Some(jz)
    }
}

impl Problem<'_> {
    /// Forward-difference Jacobians at `self.x`: with respect to the
    /// internal variables (all rows, for the iteration) and to the ln
    /// values (data rows only, for the evidence), from the same model runs.
    fn jacobians(&self) -> Option<(DMatrix<f64>, DMatrix<f64>)> {
        let r0 = self.r.as_ref()?;
        // A Jacobian after which the budget has no run left for the step
        // it is for ends the fit unrun: the fit ends there anyway (a
        // Jacobian the budget cannot finish fails, a step it cannot run
        // fails), and a Jacobian at the best point is computed again only
        // for a fit that is kept ([`settle_jacobian`], the same matrix).
        let used = self.sims.load(std::sync::atomic::Ordering::Relaxed);
        if self.opts.max_sims.saturating_sub(used) < self.x.len() + 1 {
            return None;
        }
        let h = self.opts.fd_step;
        let n_data = self.points.len();
        let cols: Vec<Option<(DVector<f64>, DVector<f64>)>> = (0..self.x.len())
            .into_par_iter()
            .map(|j| {
                let mut xp = self.x.clone();
                // A step of about `h` in log space, towards the interior so
                // the difference is not zero at a bound.
                let s = &self.specs[j];
                let half = 0.5 * (s.hi / s.lo).ln();
                let (sn, cs) = self.x[j].sin_cos();
                let inward = if sn > 0.0 { -cs.signum() } else { cs.signum() };
                let step = inward * (h / half).min(0.5);
                xp[j] += step;
                let (rp, _) = self.eval(&xp)?;
                let d_ln = from_internal(xp[j], s).ln() - from_internal(self.x[j], s).ln();
                let dr = rp - r0;
                let ln_col = DVector::from_iterator(n_data, dr.iter().take(n_data).map(|v| v / d_ln));
                Some((dr / step, ln_col))
            })
            .collect();
        let cols: Option<Vec<(DVector<f64>, DVector<f64>)>> = cols.into_iter().collect();
        let (jz, jln): (Vec<_>, Vec<_>) = cols?.into_iter().unzip();
        Some((DMatrix::from_columns(&jz), DMatrix::from_columns(&jln)))
    }
}

/// Internal (unbounded) variable of value `v` within `s`'s bounds.
fn to_internal(v: f64, s: &ParamSpec) -> f64 {
    let u = ((v.ln() - s.lo.ln()) / (s.hi / s.lo).ln()).clamp(0.0, 1.0);
    (2.0 * u - 1.0).asin()
}

/// Value of internal variable `z` within `s`'s bounds.
fn from_internal(z: f64, s: &ParamSpec) -> f64 {
    (s.lo.ln() + (s.hi / s.lo).ln() * 0.5 * (1.0 + z.sin())).exp()
}

/// Fits the nuisance set (starting at `nuis0`) and candidate `cand`'s
/// parameters (starting at `ext0`, or their specs' starts) to the measured
/// values at `points`. Returns `None` when the model fails at the starting
/// point.
pub fn fit(
    sim: &dyn Simulator,
    run: &MeasuredRun,
    points: &[Point],
    cand: Candidate,
    nuis0: &[f64],
    ext0: Option<&[f64]>,
    opts: FitOptions,
) -> Option<FitResult> {
    let mut f = fit_deferred(sim, run, points, cand, nuis0, ext0, opts)?;
    settle_jacobian(sim, run, points, &mut f);
    Some(f)
}

/// [`fit`] without the Jacobian at the best point when the iteration did
/// not end there ([`FitResult::jac_ln`] is then owed: p model runs that
/// [`settle_jacobian`] spends). The diagnosis fits several starts and
/// keeps one; the Jacobian is only wanted of the fit it keeps.
pub fn fit_deferred(
    sim: &dyn Simulator,
    run: &MeasuredRun,
    points: &[Point],
    cand: Candidate,
    nuis0: &[f64],
    ext0: Option<&[f64]>,
    opts: FitOptions,
) -> Option<FitResult> {
    let specs = specs_of(sim, cand);
    let n_nuis = sim.nuisance().len();
    let ext_specs = &specs[n_nuis..];
    let starts: Vec<f64> = match ext0 {
        Some(e) => nuis0.iter().chain(e).copied().collect(),
        None => nuis0.iter().copied().chain(ext_specs.iter().map(|s| s.start)).collect(),
    };
    // Keep the start off the bounds themselves, where sin z is stationary.
    let x0: Vec<f64> = starts
        .iter()
        .zip(&specs)
        .map(|(v, s)| to_internal(*v, s).clamp(-1.5, 1.5))
        .collect();
    // A budget of at least ~6 Jacobians: the calibration set has up to 18
    // parameters (80 runs were enough for the former 4 multipliers).
    let opts = FitOptions { max_sims: opts.max_sims.max(6 * (specs.len() + 1)), ..opts };
    let mut p = Problem {
        sim,
        run,
        points,
        cand,
        specs,
        n_nuis,
        x: DVector::from_vec(x0.clone()),
        r: None,
        opts,
        sims: 0.into(),
        best: None,
        last_jac_ln: std::sync::Mutex::new(None),
    };
    p.set_params(&DVector::from_vec(x0));
    p.r.as_ref()?;
    let (p, _report) = LevenbergMarquardt::new()
        .with_ftol(opts.ftol)
        .with_xtol(1e-4)
        .with_patience(opts.max_sims.max(1))
        .minimize(p);
    let (_, x, series) = p.best.clone()?;
    // The ln-space Jacobian at the best point: the iteration's last one when
    // it was taken there, else owed ([`settle_jacobian`]).
    let stored = p.last_jac_ln.lock().ok().and_then(|mut l| l.take()).filter(|(xj, _)| *xj == x).map(|(_, j)| j);
    let sims = p.sims.load(std::sync::atomic::Ordering::Relaxed).min(opts.max_sims);
    let jac_owed = stored.is_none().then(|| (x.clone(), opts.fd_step));
    let v = p.values(&x);
    // The data part only (BIC and RMSEs compare fits on the data).
    let rss = residuals_at(run, &series, points)?.iter().map(|e| e * e).sum();
    Some(FitResult {
        candidate: cand,
        nuisance: v[..n_nuis].to_vec(),
        ext: v[n_nuis..].to_vec(),
        rss,
        n: points.len(),
        sims,
        series,
        jac_ln: stored,
        jac_owed,
    })
}

/// The fitted parameters' specs of candidate `cand`: the nuisance set, then
/// the candidate's.
fn specs_of(sim: &dyn Simulator, cand: Candidate) -> Vec<ParamSpec> {
    let mut specs = sim.nuisance();
    specs.extend(sim.extension_params(cand));
    specs
}

/// Pays a [`fit_deferred`] fit's owed Jacobian at its best point: p model
/// runs (the residual there comes from the stored series, the model being
/// deterministic), added to [`FitResult::sims`]. The same matrix [`fit`]
/// returns; nothing to do when it is not owed.
pub fn settle_jacobian(sim: &dyn Simulator, run: &MeasuredRun, points: &[Point], f: &mut FitResult) {
    let Some((x, fd_step)) = f.jac_owed.take() else { return };
    let specs = specs_of(sim, f.candidate);
    let mut p = Problem {
        sim,
        run,
        points,
        cand: f.candidate,
        n_nuis: f.nuisance.len(),
        r: None,
        specs,
        x,
        opts: FitOptions { max_sims: usize::MAX, fd_step, ftol: 0.0 },
        sims: 0.into(),
        best: None,
        last_jac_ln: std::sync::Mutex::new(None),
    };
    p.r = p.residual_vector(&p.x, &f.series);
    f.jac_ln = p.jacobians().map(|(_, j)| j);
    f.sims += p.sims.load(std::sync::atomic::Ordering::Relaxed);
}
