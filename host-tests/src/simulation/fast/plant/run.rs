//! The fast plant's stepping: [`FastPlant::run`] (its loop: the pending
//! work, a thermal step tried, accepted or rejected, the callbacks inside
//! it, the hydraulic track advanced), the run's start and its pending work
//! before a step, its helpers (the model's thermal rates, the level's
//! φ-functions, the state write-back) and [`FastPlant::advance`]. The
//! step itself is in `attempt`, the callbacks in `callbacks`, the run's
//! state in `state`.

use super::state::RunState;
use super::steps::{Todo, GROW_ERR, LEVELS, LEVEL_MIN};
use super::FastPlant;
use crate::fast::hydraulic::NH;
use crate::fast::options::FastStats;
use crate::fast::phi::Phi;
use crate::fast::thermal::{Thermal, NE, NT};
use crate::model::{Drive, Model, N_STATE, T0};
use crate::plant::{breakpoints, Control, SimError, Snapshot};

impl FastPlant {
    /// Thermal part of the model's right-hand side at (t, yh, z): node
    /// derivatives K/s into `fz`, energy rates W into `q`.
    pub(super) fn rates(model: &Model, stats: &mut FastStats, t: f64, yh: &[f64; NH], z: &[f64; NT], fz: &mut [f64; NT], q: &mut [f64; NE]) {
        let mut y = [0.0; N_STATE];
        y[..NH].copy_from_slice(yh);
        y[T0..T0 + NT].copy_from_slice(z);
        let mut dy = [0.0; N_STATE];
        model.thermal_rhs(t, &y, &mut dy);
        stats.rhs_evals += 1;
        fz.copy_from_slice(&dy[T0..T0 + NT]);
        q.copy_from_slice(&dy[T0 + NT..]);
    }

    /// Advance to `t_end` in segments of `dt_s`, calling `on_step` with the
    /// snapshot at the start and at the end of every segment, exactly as
    /// [`crate::plant::Plant::run`] does.
    pub fn run<F>(&mut self, dt_s: f64, t_end: f64, mut on_step: F) -> Result<(), SimError>
    where
        F: FnMut(&Snapshot) -> Result<Control, SimError>,
    {
        if !(dt_s > 0.0 && dt_s.is_finite()) {
            return Err(SimError::Scenario(format!("step {dt_s} s must be > 0")));
        }
        let mut stops = breakpoints(&self.model.drive, self.t, t_end);
        stops.push(t_end);
        let ctl = on_step(&self.snapshot())?;
        if let Some(v) = ctl.lng_valve {
            self.model.lng_open.set(v);
        }
        let mut run = self.begin(dt_s, t_end, stops, ctl);
        while !run.ctl.stop && self.t < t_end - 1e-9 {
            let seg_end = run.segment_end(self.t);
            self.prepare(&mut run);
            if let Some(limit) = self.step_limit {
                if self.stats.steps - run.steps_at_start > limit {
                    return Err(SimError::StepBudget { steps: limit, t: self.t });
                }
            }
            let Some(a) = self.attempt(&mut run, seg_end)? else { continue };
            if a.err.is_nan() || a.err > 1.0 {
                self.reject(&mut run, &a)?;
                continue;
            }
            let start = self.accept(&mut run, &a);
            self.write_state(&run.yh, &run.kept.0);
            if self.callbacks(&mut run, &start, &a, &mut on_step)? {
                continue;
            }
            self.write_state(&run.yh, &run.kept.0);
            if !run.replay {
                self.hyd.advance(&self.model, self.t, &run.kept.0.z, seg_end);
            }
        }
        (self.hyd.ros.rtol, self.hyd.ros.atol) = (run.rtol0, run.atol0);
        self.stats.hydraulics = self.hyd.ros.stats;
        self.thermal = Some(run.kept);
        Ok(())
    }

    /// The run's state at its start, the first callback answered (`ctl`):
    /// the thermal scheme taken from the plant (or made: the first run
    /// starts with A = 0, explicit steps, ample for the first milliseconds
    /// from rest, and takes the Jacobian once the step has grown 64-fold;
    /// later runs keep theirs), the start level, the start's looser
    /// tolerances set.
    fn begin(&mut self, dt_s: f64, t_end: f64, stops: Vec<f64>, ctl: Control) -> RunState {
        let first_run = self.thermal.is_none();
        let mut kept =
            self.thermal.take().unwrap_or_else(|| Box::new((Thermal::new(self.t, [0.0; NT], [0.0; NE]), (0..LEVELS).map(|_| None).collect())));
        let th = &mut kept.0;
        th.t = self.t;
        th.z = std::array::from_fn(|i| self.y[T0 + i]);
        th.e = std::array::from_fn(|i| self.y[T0 + NT + i]);
        let drift_z = th.z;
        let valve_moved = self.model.lng_open.get() != self.jacobian_valve;
        let (rtol0, atol0) = (self.hyd.ros.rtol, self.hyd.ros.atol);
        let hyd_loose = first_run && self.opts.start_hyd_s > 0.0;
        if hyd_loose {
            self.hyd.ros.rtol = rtol0 * self.opts.start_hyd_factor;
            self.hyd.ros.atol = atol0.map(|a| a * self.opts.start_hyd_factor);
        }
        let mut run = RunState {
            dt_s,
            t_start: self.t,
            t_end,
            stops: stops.into_iter().peekable(),
            ctl,
            replay: matches!(self.model.drive, Drive::Replay(_)),
            debug: std::env::var_os("FAST_DEBUG").is_some(),
            kept,
            yh: std::array::from_fn(|i| self.y[i]),
            level: 0,
            todo: Todo { fresh: true, hydraulics: true, jacobian: !first_run && valve_moved, ..Todo::default() },
            jac_level: 0,
            refresh_armed: first_run,
            stalled: 0,
            grow_err: GROW_ERR,
            just_grew: false,
            h_fine: dt_s * 2f64.powi(LEVEL_MIN),
            origin: self.t,
            ticks: 0,
            scan_from: self.t,
            k: 1,
            t_cb: self.t + dt_s,
            steps_at_start: self.stats.steps,
            loose_until: if first_run { self.t + self.opts.start_s } else { f64::NEG_INFINITY },
            rtol0,
            atol0,
            hyd_loose_until: self.t + self.opts.start_hyd_s,
            hyd_loose,
            drift_cols: Vec::new(),
            last_worst: 0,
            drift_z,
        };
        run.level = run.start_level(self.opts.h_start_s);
        run.jac_level = run.level;
        run
    }

    /// The work pending before a step: the hydraulics restarted (at a
    /// breakpoint), the thermal Jacobian, f or the drifting columns taken
    /// anew, and the hydraulics' start tolerances ended when due.
    fn prepare(&mut self, run: &mut RunState) {
        let todo = run.todo;
        if todo.hydraulics && !run.replay {
            self.hyd.restart(&self.model, &run.kept.0.z, self.t, run.yh, self.opts.h_start_s);
        }
        if todo.jacobian || todo.fresh || todo.switch.is_some() || todo.drift {
            self.refresh_thermal(run);
        }
        run.todo = Todo::default();
        if run.hyd_loose && self.t >= run.hyd_loose_until {
            run.hyd_loose = false;
            self.hyd.ros.rtol = run.rtol0;
            self.hyd.ros.atol = run.atol0;
        }
    }

    /// The thermal part of [`FastPlant::prepare`]: the Jacobian (which
    /// empties the ladder), or f and the drifting columns, at the current
    /// time or on the far side of a pending branch switch.
    fn refresh_thermal(&mut self, run: &mut RunState) {
        let todo = run.todo;
        let (th, ladder) = &mut *run.kept;
        let (t, yy) = match todo.switch {
            Some(ts) if !run.replay => (ts, self.hyd.at(&self.model, ts)),
            _ => (self.t, run.yh),
        };
        let (model, stats) = (&self.model, &mut self.stats);
        let mut rates = |z: &[f64; NT], fz: &mut [f64; NT], q: &mut [f64; NE]| Self::rates(model, stats, t, &yy, z, fz, q);
        if todo.jacobian {
            self.jacobian_valve = self.model.lng_open.get();
            th.jacobian(&mut rates, !todo.fresh);
            ladder.iter_mut().for_each(|p| *p = None);
            run.jac_level = run.level;
            self.stats.jacobians += 1;
            run.drift_z = th.z;
            return;
        }
        if todo.fresh || todo.switch.is_some() {
            th.fresh(&mut rates, !todo.fresh);
        }
        if todo.drift {
            if !run.drift_cols.contains(&run.last_worst) {
                run.drift_cols.push(run.last_worst);
            }
            th.drift(&mut rates, &run.drift_cols);
            run.drift_z = th.z;
            self.stats.drifts += 1;
            if run.debug {
                eprintln!("drift columns {:?} at {:.3}", run.drift_cols, self.t);
            }
        }
    }

    /// The φ-functions of a step level: cached, by doubling the level below, or anew.
    /// (Boxed: a level is 5.4 kB and a run uses a dozen of the 33.)
    pub(super) fn phi<'a>(&mut self, ladder: &'a mut [Option<Box<Phi<NT>>>], th: &Thermal, level: i32, dt: f64) -> &'a Phi<NT> {
        let i = (level - LEVEL_MIN) as usize;
        if ladder[i].is_none() {
            let h = dt * 2f64.powi(level);
            let (lower, upper) = ladder.split_at_mut(i);
            let slot = &mut upper[0];
            match lower.last().and_then(|b| b.as_deref()) {
                // A = 0 before the first Jacobian: Phi::new is closed-form there.
                Some(below) if !th.is_zero() => *slot = Some(below.doubled_boxed()),
                _ => {
                    self.stats.phi_builds += 1;
                    *slot = Some(Box::new(Phi::new(&th.a, h)));
                }
            }
        }
        ladder[i].as_deref().expect("just built")
    }

    /// The plant's state vector from the hydraulic states and the thermal scheme's.
    pub(super) fn write_state(&mut self, yh: &[f64; NH], th: &Thermal) {
        self.y[..NH].copy_from_slice(yh);
        self.y[T0..T0 + NT].copy_from_slice(&th.z);
        self.y[T0 + NT..].copy_from_slice(&th.e);
    }

    /// Advance by `dt_s` with the valve held.
    pub fn advance(&mut self, dt_s: f64) -> Result<(), SimError> {
        let t_end = self.t + dt_s;
        self.run(dt_s, t_end, |_| Ok(Control::default()))
    }
}
