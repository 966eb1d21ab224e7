//! One thermal step of [`FastPlant::run`](super::FastPlant::run): where it
//! ends (the level grid, the segment's end, a branch switch of the heat
//! balances on the hydraulic track), its trial and error, and what an
//! accepted or a rejected step does to the run's state.

use super::state::RunState;
use super::steps::{hyd_error, GROW_ERR_MIN, LEVEL_MIN, SWITCH_DROP};
use super::FastPlant;
use crate::fast::dense::norm1;
use crate::fast::hydraulic::{left_of, NH};
use crate::fast::phi::{Phi, VECTOR_NORM_MAX};
use crate::fast::thermal::{Trial, NE, NT};
use crate::plant::SimError;

/// A thermal step tried from the plant's current time: what the accept or
/// reject decision and the callbacks need of it.
#[derive(Debug)]
pub(super) struct Attempt {
    /// The step's end, s.
    pub(super) t1: f64,
    /// The step, s.
    pub(super) h: f64,
    /// Off the level grid (a partial step to the segment's end, or one
    /// ended by a branch switch): a rejection restarts from the level of h/2.
    pub(super) odd: bool,
    /// The step ends its segment (a schedule breakpoint or the run's end).
    pub(super) seg_done: bool,
    /// A branch switch ends the step: f is to be taken at this time.
    pub(super) switch: Option<f64>,
    /// Hydraulic states at `t1`.
    pub(super) yh1: [f64; NH],
    /// The corrected temperatures and energies, and their error.
    pub(super) trial: Trial,
    /// The error in tolerances (> 1 or NaN: rejected).
    pub(super) err: f64,
    /// The hydraulic step at the trial, s (infinite on a replay).
    pub(super) hyd_h: f64,
}

/// The state at an accepted step's start, kept for the Hermite
/// interpolants of the callbacks inside the step.
#[derive(Debug)]
pub(super) struct StepStart {
    /// Time, s.
    pub(super) t: f64,
    /// Node temperatures.
    pub(super) z: [f64; NT],
    /// Their derivatives.
    pub(super) fz: [f64; NT],
    /// Energy integrals.
    pub(super) e: [f64; NE],
    /// Their rates.
    pub(super) q: [f64; NE],
    /// Hydraulic states.
    pub(super) yh: [f64; NH],
}

impl FastPlant {
    /// Tries the next thermal step: to the level's step end, the segment's
    /// end or the first branch switch, whichever is first. `Ok(None)`: a
    /// switch at the step's start, pending in `run.todo` (f on its far
    /// side first).
    pub(super) fn attempt(&mut self, run: &mut RunState, seg_end: f64) -> Result<Option<Attempt>, SimError> {
        let t_level = run.level_end();
        // The level's step ends at the segment's end (a ladder step), or
        // beyond it (an odd step to the end).
        let ends = (t_level - seg_end).abs() <= 1e-9 * seg_end.abs().max(1.0);
        let partial = !ends && t_level > seg_end;
        let mut t1 = if partial || ends { seg_end } else { t_level };
        let mut odd = partial;
        let (odd_phi, odd_phi2);
        let mut h = t1 - self.t;
        let (th, ladder) = &mut *run.kept;
        // While A = 0 (the first run's explicit start) the step is a
        // polynomial in closed form (`Thermal::linear`): no level's
        // matrices (4 of them, 5.4 kB, built and boxed per level).
        let mut phi = if !odd && !th.is_zero() {
            Some(self.phi(ladder, th, run.level, run.dt_s))
        } else if norm1(&th.a) * h > VECTOR_NORM_MAX {
            self.stats.phi_builds += 1;
            odd_phi = Phi::new(&th.a, h);
            Some(&odd_phi)
        } else {
            None
        };
        let mut pred = th.predict(phi, h);
        let mut switch = None;
        if let Some((lo, hi)) = self.find_switch(run.replay, &mut run.scan_from, th.z, t1, pred.zp, seg_end)? {
            if lo <= self.t + 1e-9 * self.t.abs().max(1.0) {
                // At the step's start: f on its far side, then on.
                run.todo.switch = Some(hi);
                return Ok(None);
            }
            t1 = lo;
            h = t1 - self.t;
            switch = Some(hi);
            odd = true;
            phi = None;
            if norm1(&th.a) * h > VECTOR_NORM_MAX {
                self.stats.phi_builds += 1;
                odd_phi2 = Phi::new(&th.a, h);
                phi = Some(&odd_phi2);
            }
            pred = th.predict(phi, h);
        }
        let seg_done = (partial || ends) && switch.is_none();
        let yh1 = if run.replay { run.yh } else { self.hyd.at(&self.model, t1) };
        // At a breakpoint the segment's schedules end with their left limits.
        let t_eval = if seg_done { left_of(t1) } else { t1 };
        let (mut fp, mut qp) = ([0.0; NT], [0.0; NE]);
        Self::rates(&self.model, &mut self.stats, t_eval, &yh1, &pred.zp, &mut fp, &mut qp);
        let trial = th.correct(phi, h, &pred, &fp, &qp);
        let tol = if self.t < run.loose_until { self.opts.tol_k * self.opts.start_tol_factor } else { self.opts.tol_k };
        let err = trial.err_k / tol;
        let hyd_h = if run.replay { f64::INFINITY } else { self.hyd.ros.h };
        if run.debug {
            eprintln!("t {:.4} h {h:.3e} lvl {} err {err:.3e} node {} hyd_h {hyd_h:.3e} odd {odd}", self.t, run.level, trial.worst);
        }
        Ok(Some(Attempt { t1, h, odd, seg_done, switch, yh1, trial, err, hyd_h }))
    }

    /// The hydraulic states up to `t1` on their own track (seeing the
    /// temperatures on the line from `z0` now to the predictor `zp`), and
    /// the first branch switch of the heat balances in the step, searched
    /// from `scan_from` on (none on a replay, which has no track).
    fn find_switch(
        &mut self,
        replay: bool,
        scan_from: &mut f64,
        z0: [f64; NT],
        t1: f64,
        zp: [f64; NT],
        seg_end: f64,
    ) -> Result<Option<(f64, f64)>, SimError> {
        if replay {
            return Ok(None);
        }
        self.hyd.set_line(&self.model, self.t, z0, t1, zp);
        self.hyd.cover(&self.model, t1, seg_end).map_err(hyd_error)?;
        let found = self.hyd.first_switch(&self.model, (*scan_from).max(self.t), t1);
        if let Some((_, hi)) = found {
            *scan_from = hi;
        }
        Ok(found)
    }

    /// A rejected step: one level down (from the level of h/2 if off the
    /// grid), the doubling bound halved if a doubling failed, the
    /// hydraulic track back to now. Fails below the finest level.
    pub(super) fn reject(&mut self, run: &mut RunState, a: &Attempt) -> Result<(), SimError> {
        self.stats.rejected += 1;
        if run.just_grew && !a.odd {
            run.grow_err = (run.grow_err * 0.5).max(GROW_ERR_MIN);
        }
        run.just_grew = false;
        self.hyd.reject(self.t);
        // One level down (dropping by the levels the error asks for,
        // local error ∝ h⁴, saved 10 % of Case 2's rejections but
        // took Fig. 15's ball-valve oil from 1.7e-3 to 7.8e-3 K off
        // after a valve switch: the estimate is not to be trusted
        // that far).
        run.level = if a.odd { run.start_level(a.h / 2.0) } else { run.level - 1 };
        if run.level <= LEVEL_MIN {
            return Err(SimError::Solver { t: self.t, message: format!("thermal step underflow (error {:.2e} K)", a.trial.err_k) });
        }
        if a.switch.is_some() {
            run.scan_from = self.t;
        }
        Ok(())
    }

    /// An accepted step: the plant moves to its end, and the next step's
    /// level and pending work follow from how it ended (a branch switch,
    /// a segment's end, or on the ladder). Returns the step's start.
    pub(super) fn accept(&mut self, run: &mut RunState, a: &Attempt) -> StepStart {
        run.last_worst = a.trial.worst;
        let th = &mut run.kept.0;
        let start = StepStart { t: self.t, z: th.z, fz: th.fz, e: th.e, q: th.q, yh: run.yh };
        th.accept(&a.trial);
        run.yh = a.yh1;
        self.t = a.t1;
        th.t = a.t1;
        self.stats.steps += 1;
        if let Some(hi) = a.switch {
            run.todo.switch = Some(hi);
            // A level lower on the far side (see `SWITCH_DROP`).
            run.level -= SWITCH_DROP;
            (run.origin, run.ticks) = (self.t, 0);
        } else if a.seg_done {
            // A schedule breakpoint (or the end): the forcing steps.
            run.todo.fresh = true;
            run.todo.hydraulics = true;
            run.level = run.start_level(self.opts.h_start_s);
            (run.jac_level, run.refresh_armed, run.stalled) = (run.level, true, 0);
            (run.origin, run.ticks) = (self.t, 0);
        } else {
            run.after_ladder_step(&self.opts, a.err, a.h, a.hyd_h);
        }
        start
    }
}
