//! Least-squares calibration with the `levenberg-marquardt` crate: the
//! nuisance set plus a candidate's own parameters, fitted in log space on
//! the training points of a measured run.

use super::model::{Candidate, ParamSpec, SimSeries, Simulator};
use crate::measured::{Channel, MeasuredRun};
use levenberg_marquardt::{LeastSquaresProblem, LevenbergMarquardt};
use nalgebra::{storage::Owned, DMatrix, DVector, Dyn};
use rayon::prelude::*;

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
}

impl Problem<'_> {
    fn values(&self, x: &DVector<f64>) -> Vec<f64> {
        x.iter().zip(&self.specs).map(|(t, s)| t.clamp(s.lo.ln(), s.hi.ln()).exp()).collect()
    }

    fn eval(&self, x: &DVector<f64>) -> Option<(DVector<f64>, SimSeries)> {
        let used = self.sims.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        if used >= self.opts.max_sims {
            return None;
        }
        let v = self.values(x);
        let s = self.sim.simulate(&v[..self.n_nuis], self.cand, &v[self.n_nuis..]).ok()?;
        let r = residuals_at(self.run, &s, self.points)?;
        r.iter().all(|x| x.is_finite()).then(|| (DVector::from_vec(r), s))
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
        let r0 = self.r.as_ref()?;
        let h = self.opts.fd_step;
        let cols: Vec<Option<DVector<f64>>> = (0..self.x.len())
            .into_par_iter()
            .map(|j| {
                let mut xp = self.x.clone();
                // Step inward at the upper bound so the difference is not zero.
                let up = self.specs[j].hi.ln();
                let step = if xp[j] + h > up { -h } else { h };
                xp[j] += step;
                let (rp, _) = self.eval(&xp)?;
                Some((rp - r0) / step)
            })
            .collect();
        let cols: Option<Vec<DVector<f64>>> = cols.into_iter().collect();
        Some(DMatrix::from_columns(&cols?))
    }
}

/// Fits the nuisance set (starting at `nuis0`) and candidate `cand`'s
/// parameters (starting at their specs) to the measured values at `points`.
/// Returns `None` when the model fails at the starting point.
pub fn fit(
    sim: &dyn Simulator,
    run: &MeasuredRun,
    points: &[Point],
    cand: Candidate,
    nuis0: &[f64],
    opts: FitOptions,
) -> Option<FitResult> {
    let nuis_specs = sim.nuisance();
    let ext_specs = sim.extension_params(cand);
    let n_nuis = nuis_specs.len();
    let mut specs = nuis_specs;
    specs.extend(ext_specs.iter().cloned());
    let x0: Vec<f64> = nuis0.iter().copied().chain(ext_specs.iter().map(|s| s.start)).map(f64::ln).collect();
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
    };
    p.set_params(&DVector::from_vec(x0));
    p.r.as_ref()?;
    let (p, _report) = LevenbergMarquardt::new()
        .with_ftol(opts.ftol)
        .with_xtol(1e-4)
        .with_patience(opts.max_sims.max(1))
        .minimize(p);
    let (rss, x, series) = p.best.clone()?;
    let v = p.values(&x);
    Some(FitResult {
        candidate: cand,
        nuisance: v[..n_nuis].to_vec(),
        ext: v[n_nuis..].to_vec(),
        rss,
        n: points.len(),
        sims: p.sims.load(std::sync::atomic::Ordering::Relaxed).min(opts.max_sims),
        series,
    })
}
