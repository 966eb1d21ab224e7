//! A least-squares problem defined by its residual function, with a
//! forward-difference Jacobian (columns evaluated in parallel), for the
//! `levenberg-marquardt` crate, used by the paper calibration
//! ([`crate::calibrate`]).

use levenberg_marquardt::LeastSquaresProblem;
use nalgebra::{DMatrix, DVector, Dyn, Owned};
use rayon::prelude::*;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};

/// Residual function `r(x)` (None when the model cannot be evaluated there)
/// at parameters `x`, with the forward-difference step `step` in x's units.
pub struct FdProblem<F> {
    residual: F,
    x: DVector<f64>,
    step: f64,
    budget: Option<(Arc<AtomicUsize>, usize)>,
    /// The last residual evaluated and where: the minimiser asks for the
    /// Jacobian at the point whose residual it just took, so the
    /// forward difference reuses it instead of running the model again.
    last: Mutex<Option<(DVector<f64>, DVector<f64>)>>,
}

impl<F> FdProblem<F>
where
    F: Fn(&[f64]) -> Option<DVector<f64>> + Sync,
{
    /// A problem starting at `x0`.
    pub fn new(residual: F, x0: DVector<f64>, step: f64) -> Self {
        Self { residual, x: x0, step, budget: None, last: Mutex::new(None) }
    }

    /// The same problem with an evaluation budget: `used` counts residual
    /// evaluations (a Jacobian counts one per column), shared between
    /// problems; past `max` the problem reports no residuals, which stops
    /// the minimiser. Counted in the minimiser's sequential calls, before a
    /// Jacobian's parallel columns run, so where a fit stops does not
    /// depend on thread timing.
    pub fn with_budget(mut self, used: Arc<AtomicUsize>, max: usize) -> Self {
        self.budget = Some((used, max));
        self
    }

    /// Takes `n` evaluations from the budget; false when it is spent.
    fn take(&self, n: usize) -> bool {
        match &self.budget {
            None => true,
            Some((used, max)) => used.fetch_add(n, Ordering::Relaxed) + n <= *max,
        }
    }

    /// The current parameters.
    pub fn x(&self) -> &DVector<f64> {
        &self.x
    }

    /// The residual at the current parameters, from the cache when the
    /// last evaluation was there (the residual function is deterministic).
    fn residual_here(&self) -> Option<DVector<f64>> {
        let mut last = self.last.lock().unwrap_or_else(|e| e.into_inner());
        if let Some((x, r)) = last.as_ref() {
            if *x == self.x {
                return Some(r.clone());
            }
        }
        let r = (self.residual)(self.x.as_slice())?;
        *last = Some((self.x.clone(), r.clone()));
        Some(r)
    }
}

impl<F> LeastSquaresProblem<f64, Dyn, Dyn> for FdProblem<F>
where
    F: Fn(&[f64]) -> Option<DVector<f64>> + Sync,
{
    type ResidualStorage = Owned<f64, Dyn>;
    type JacobianStorage = Owned<f64, Dyn, Dyn>;
    type ParameterStorage = Owned<f64, Dyn>;

    fn set_params(&mut self, x: &DVector<f64>) {
        self.x.copy_from(x);
    }

    fn params(&self) -> DVector<f64> {
        self.x.clone()
    }

    fn residuals(&self) -> Option<DVector<f64>> {
        if !self.take(1) {
            return None;
        }
        self.residual_here()
    }

    fn jacobian(&self) -> Option<DMatrix<f64>> {
        // The budget counts r0 whether or not it is cached, so that where a
        // fit stops (and so its result) does not depend on the cache.
        if !self.take(self.x.len() + 1) {
            return None;
        }
        let r0 = self.residual_here()?;
        let cols: Option<Vec<DVector<f64>>> = (0..self.x.len())
            .into_par_iter()
            .map(|k| {
                let mut x = self.x.clone();
                x[k] += self.step;
                (self.residual)(x.as_slice()).map(|r| (r - &r0) / self.step)
            })
            .collect();
        Some(DMatrix::from_columns(&cols?))
    }
}
