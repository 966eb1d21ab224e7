//! The fast plant's stepping: [`FastPlant::run`] (thermal steps on the
//! level grid, the hydraulic track beside them, the callbacks on the
//! interpolants between steps), its helpers (the model's thermal rates,
//! the level's φ-functions, the state write-back) and
//! [`FastPlant::advance`].

use super::steps::{
    hyd_error, Todo, DRIFT_MOVE_K, GROW_ERR, GROW_ERR_MIN, LEVELS, LEVEL_MAX, LEVEL_MIN, REFRESH_LEVELS, STALL_STEPS, SWITCH_DROP,
};
use super::FastPlant;
use crate::fast::dense::norm1;
use crate::fast::hydraulic::{hermite, left_of, NH};
use crate::fast::options::FastStats;
use crate::fast::phi::{Phi, VECTOR_NORM_MAX};
use crate::fast::thermal::{Thermal, NE, NT};
use crate::model::{Drive, Model, N_STATE, T0};
use crate::plant::{breakpoints, snapshot_stored, Control, SimError, Snapshot};

impl FastPlant {
    /// Thermal part of the model's right-hand side at (t, yh, z): node
    /// derivatives K/s into `fz`, energy rates W into `q`.
    fn rates(model: &Model, stats: &mut FastStats, t: f64, yh: &[f64; NH], z: &[f64; NT], fz: &mut [f64; NT], q: &mut [f64; NE]) {
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
        let t_start = self.t;
        let mut stops = breakpoints(&self.model.drive, t_start, t_end);
        stops.push(t_end);
        let mut stops = stops.into_iter().peekable();
        let mut ctl = on_step(&self.snapshot())?;
        if let Some(v) = ctl.lng_valve {
            self.model.lng_open.set(v);
        }
        let replay = matches!(self.model.drive, Drive::Replay(_));
        // The first run starts with A = 0 (explicit steps, ample for the
        // first milliseconds from rest) and takes the Jacobian once the step
        // has grown 64-fold; later runs keep theirs.
        let first_run = self.thermal.is_none();
        let mut kept =
            self.thermal.take().unwrap_or_else(|| Box::new((Thermal::new(self.t, [0.0; NT], [0.0; NE]), (0..LEVELS).map(|_| None).collect())));
        let (th, ladder) = &mut *kept;
        th.t = self.t;
        th.z = std::array::from_fn(|i| self.y[T0 + i]);
        th.e = std::array::from_fn(|i| self.y[T0 + NT + i]);
        let mut yh: [f64; NH] = std::array::from_fn(|i| self.y[i]);
        let start_level = |h: f64| ((h / dt_s).log2().floor() as i32).clamp(LEVEL_MIN, LEVEL_MAX);
        let mut level = start_level(self.opts.h_start_s);
        // Pending work before the next step.
        let valve_moved = self.model.lng_open.get() != self.jacobian_valve;
        let mut todo = Todo { fresh: true, hydraulics: true, jacobian: !first_run && valve_moved, ..Todo::default() };
        // The level of the last Jacobian, and whether the step's growth
        // since then still calls for one (once after each start or breakpoint).
        let (mut jac_level, mut refresh_armed) = (level, first_run);
        // Accepted steps since the level last grew.
        let mut stalled = 0u32;
        // The error below which the step doubles, and whether the last
        // accepted step was a doubling (see `GROW_ERR`).
        let mut grow_err = GROW_ERR;
        let mut just_grew = false;
        // Position since the grid's origin in units of the finest level:
        // step ends are origin + ticks·h_fine, free of accumulated round-off.
        let h_fine = dt_s * 2f64.powi(LEVEL_MIN);
        let (mut origin, mut ticks) = (self.t, 0u64);
        // Where the next search for a branch switch starts.
        let mut scan_from = self.t;
        let mut k: u64 = 1;
        let mut t_cb = t_start + dt_s;
        let steps_at_start = self.stats.steps;
        let debug = std::env::var_os("FAST_DEBUG").is_some();
        // The end of the start's looser tolerance (`FastOptions::start_tol_factor`).
        let loose_until = if first_run { self.t + self.opts.start_s } else { f64::NEG_INFINITY };
        // The hydraulics' looser tolerances of the start from rest
        // (`FastOptions::start_hyd_factor`), the settings to return to.
        let (rtol0, atol0) = (self.hyd.ros.rtol, self.hyd.ros.atol);
        let hyd_loose_until = self.t + self.opts.start_hyd_s;
        let mut hyd_loose = first_run && self.opts.start_hyd_s > 0.0;
        if hyd_loose {
            self.hyd.ros.rtol = rtol0 * self.opts.start_hyd_factor;
            self.hyd.ros.atol = atol0.map(|a| a * self.opts.start_hyd_factor);
        }
        // The drifting columns (see `DRIFT_MOVE_K`): the nodes that held
        // the step when a drift refresh was due, and the node that held the
        // last accepted step.
        let mut drift_cols: Vec<usize> = Vec::new();
        let mut last_worst = 0usize;
        // Temperatures at the last Jacobian or drift refresh.
        let mut drift_z = th.z;
        'outer: while !ctl.stop && self.t < t_end - 1e-9 {
            while stops.peek().is_some_and(|&s| s <= self.t + 1e-9) {
                stops.next();
            }
            let seg_end = stops.peek().copied().unwrap_or(t_end);
            if todo.hydraulics && !replay {
                self.hyd.restart(&self.model, &th.z, self.t, yh, self.opts.h_start_s);
            }
            if todo.jacobian || todo.fresh || todo.switch.is_some() || todo.drift {
                let (t, yy) = match todo.switch {
                    Some(ts) if !replay => (ts, self.hyd.at(&self.model, ts)),
                    _ => (self.t, yh),
                };
                let (model, stats) = (&self.model, &mut self.stats);
                let mut rates = |z: &[f64; NT], fz: &mut [f64; NT], q: &mut [f64; NE]| Self::rates(model, stats, t, &yy, z, fz, q);
                if todo.jacobian {
                    self.jacobian_valve = self.model.lng_open.get();
                    th.jacobian(&mut rates, !todo.fresh);
                    ladder.iter_mut().for_each(|p| *p = None);
                    jac_level = level;
                    self.stats.jacobians += 1;
                    drift_z = th.z;
                } else {
                    if todo.fresh || todo.switch.is_some() {
                        th.fresh(&mut rates, !todo.fresh);
                    }
                    if todo.drift {
                        if !drift_cols.contains(&last_worst) {
                            drift_cols.push(last_worst);
                        }
                        th.drift(&mut rates, &drift_cols);
                        drift_z = th.z;
                        self.stats.drifts += 1;
                        if debug {
                            eprintln!("drift columns {drift_cols:?} at {:.3}", self.t);
                        }
                    }
                }
            }
            todo = Todo::default();
            if hyd_loose && self.t >= hyd_loose_until {
                hyd_loose = false;
                self.hyd.ros.rtol = rtol0;
                self.hyd.ros.atol = atol0;
            }
            if let Some(limit) = self.step_limit {
                if self.stats.steps - steps_at_start > limit {
                    return Err(SimError::StepBudget { steps: limit, t: self.t });
                }
            }
            // A level is usable where the position is a multiple of its step.
            while level > LEVEL_MIN && ticks % (1u64 << (level - LEVEL_MIN)) != 0 {
                level -= 1;
            }
            let t_level = origin + (ticks + (1u64 << (level - LEVEL_MIN))) as f64 * h_fine;
            // The level's step ends at the segment's end (a ladder step), or
            // beyond it (an odd step to the end).
            let ends = (t_level - seg_end).abs() <= 1e-9 * seg_end.abs().max(1.0);
            let partial = !ends && t_level > seg_end;
            let mut t1 = if partial || ends { seg_end } else { t_level };
            let mut odd = partial;
            let (odd_phi, odd_phi2);
            let mut h = t1 - self.t;
            // While A = 0 (the first run's explicit start) the step is a
            // polynomial in closed form (`Thermal::linear`): no level's
            // matrices (4 of them, 5.4 kB, built and boxed per level).
            let mut phi = if !odd && !th.is_zero() {
                Some(self.phi(ladder, th, level, dt_s))
            } else if norm1(&th.a) * h > VECTOR_NORM_MAX {
                self.stats.phi_builds += 1;
                odd_phi = Phi::new(&th.a, h);
                Some(&odd_phi)
            } else {
                None
            };
            let mut pred = th.predict(phi, h);
            // The hydraulic states at the step's end, from their own track
            // (seeing the temperatures on the line to the predictor); a
            // branch switch of the heat balances inside ends the step there.
            let mut switch = None;
            if !replay {
                self.hyd.set_line(&self.model, self.t, th.z, t1, pred.zp);
                self.hyd.cover(&self.model, t1, seg_end).map_err(hyd_error)?;
                if let Some((lo, hi)) = self.hyd.first_switch(&self.model, scan_from.max(self.t), t1) {
                    scan_from = hi;
                    if lo <= self.t + 1e-9 * self.t.abs().max(1.0) {
                        // At the step's start: f on its far side, then on.
                        todo.switch = Some(hi);
                        continue;
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
            }
            let seg_done = (partial || ends) && switch.is_none();
            let yh1 = if replay { yh } else { self.hyd.at(&self.model, t1) };
            // At a breakpoint the segment's schedules end with their left limits.
            let t_eval = if seg_done { left_of(t1) } else { t1 };
            let (mut fp, mut qp) = ([0.0; NT], [0.0; NE]);
            Self::rates(&self.model, &mut self.stats, t_eval, &yh1, &pred.zp, &mut fp, &mut qp);
            let trial = th.correct(phi, h, &pred, &fp, &qp);
            let tol = if self.t < loose_until { self.opts.tol_k * self.opts.start_tol_factor } else { self.opts.tol_k };
            let err = trial.err_k / tol;
            let hyd_h = if replay { f64::INFINITY } else { self.hyd.ros.h };
            if debug {
                eprintln!("t {:.4} h {h:.3e} lvl {level} err {err:.3e} node {} hyd_h {hyd_h:.3e} odd {odd}", self.t, trial.worst);
            }
            if err.is_nan() || err > 1.0 {
                self.stats.rejected += 1;
                if just_grew && !odd {
                    grow_err = (grow_err * 0.5).max(GROW_ERR_MIN);
                }
                just_grew = false;
                self.hyd.reject(self.t);
                // One level down (dropping by the levels the error asks for,
                // local error ∝ h⁴, saved 10 % of Case 2's rejections but
                // took Fig. 15's ball-valve oil from 1.7e-3 to 7.8e-3 K off
                // after a valve switch: the estimate is not to be trusted
                // that far).
                level = if odd { start_level(h / 2.0) } else { level - 1 };
                if level <= LEVEL_MIN {
                    return Err(SimError::Solver { t: self.t, message: format!("thermal step underflow (error {:.2e} K)", trial.err_k) });
                }
                if switch.is_some() {
                    scan_from = self.t;
                }
                continue;
            }
            last_worst = trial.worst;
            let (t0, z0, f0, e0, q0, yh0) = (self.t, th.z, th.fz, th.e, th.q, yh);
            th.accept(&trial);
            yh = yh1;
            self.t = t1;
            th.t = t1;
            self.stats.steps += 1;
            if let Some(hi) = switch {
                todo.switch = Some(hi);
                // A level lower on the far side (see `SWITCH_DROP`).
                level -= SWITCH_DROP;
                (origin, ticks) = (self.t, 0);
            } else if seg_done {
                // A schedule breakpoint (or the end): the forcing steps.
                todo.fresh = true;
                todo.hydraulics = true;
                level = start_level(self.opts.h_start_s);
                (jac_level, refresh_armed, stalled) = (level, true, 0);
                (origin, ticks) = (self.t, 0);
            } else {
                ticks += 1u64 << (level - LEVEL_MIN);
                let next = level + 1;
                if just_grew {
                    grow_err = (grow_err * 1.1).min(GROW_ERR);
                }
                just_grew = false;
                let grow = err <= grow_err;
                let room = next <= LEVEL_MAX && 2.0 * h <= self.opts.h_max_s && 2.0 * h <= self.opts.alias_ratio * hyd_h;
                if grow && room && ticks % (1u64 << (next - LEVEL_MIN)) == 0 {
                    level = next;
                    stalled = 0;
                    just_grew = true;
                } else {
                    stalled += 1;
                }
                // After a start or a breakpoint, one Jacobian once the step
                // has grown 64-fold (the transient is over) or stopped
                // growing (the explicit start's stability limit, or the
                // transient's own time scale, holds it).
                if refresh_armed && (level >= jac_level + REFRESH_LEVELS || stalled >= STALL_STEPS) {
                    todo.jacobian = true;
                    refresh_armed = false;
                }
                // A node that has moved `DRIFT_MOVE_K` since the last Jacobian
                // or drift refresh: the drifting columns anew.
                if !refresh_armed && !th.is_zero() {
                    let moved = th.z.iter().zip(&drift_z).fold(0.0f64, |a, (x, y)| a.max((x - y).abs()));
                    if moved >= DRIFT_MOVE_K {
                        todo.drift = true;
                    }
                }
            }
            self.write_state(&yh, th);
            // Callbacks inside the step, on the interpolants.
            while !ctl.stop && t_cb <= t1 + 1e-9 && t_cb <= t_end + 1e-9 {
                let at_end = (t_cb - t1).abs() <= 1e-9;
                let tc = if at_end { t_cb } else { t_cb.min(t1) };
                if at_end {
                    self.write_state(&yh, th);
                } else {
                    let (a0, b0, a1, b1) = hermite((tc - t0) / h);
                    for i in 0..NT {
                        self.y[T0 + i] = a0 * z0[i] + b0 * h * f0[i] + a1 * th.z[i] + b1 * h * th.fz[i];
                    }
                    for i in 0..NE {
                        self.y[T0 + NT + i] = a0 * e0[i] + b0 * h * q0[i] + a1 * th.e[i] + b1 * h * th.q[i];
                    }
                    let yhc = if replay { yh0 } else { self.hyd.at(&self.model, tc) };
                    self.y[..NH].copy_from_slice(&yhc);
                }
                let snap = snapshot_stored(&self.model, tc, &self.y, self.model.stored_energy_from(&self.e0, &self.y));
                ctl = on_step(&snap)?;
                k += 1;
                t_cb = t_start + k as f64 * dt_s;
                let change = ctl.lng_valve.filter(|&v| v != self.model.lng_open.get());
                if change.is_some() || ctl.stop {
                    if !at_end {
                        // Continue from the callback time (the hydraulic
                        // track stays: the valve acts on the oil only).
                        self.t = tc;
                        yh.copy_from_slice(&self.y[..NH]);
                        th.z.copy_from_slice(&self.y[T0..T0 + NT]);
                        th.e.copy_from_slice(&self.y[T0 + NT..]);
                        th.t = tc;
                        (origin, ticks) = (tc, 0);
                        scan_from = tc;
                        todo = Todo { fresh: true, ..Todo::default() };
                    }
                    if let Some(v) = change {
                        self.model.lng_open.set(v);
                        todo.jacobian = true;
                        todo.fresh = true;
                    }
                    if ctl.stop {
                        break 'outer;
                    }
                    continue 'outer;
                }
            }
            self.write_state(&yh, th);
            if !replay {
                self.hyd.advance(&self.model, self.t, &th.z, seg_end);
            }
        }
        (self.hyd.ros.rtol, self.hyd.ros.atol) = (rtol0, atol0);
        self.stats.hydraulics = self.hyd.ros.stats;
        self.thermal = Some(kept);
        Ok(())
    }

    /// The φ-functions of a step level: cached, by doubling the level below, or anew.
    /// (Boxed: a level is 5.4 kB and a run uses a dozen of the 33.)
    fn phi<'a>(&mut self, ladder: &'a mut [Option<Box<Phi<NT>>>], th: &Thermal, level: i32, dt: f64) -> &'a Phi<NT> {
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

    fn write_state(&mut self, yh: &[f64; NH], th: &Thermal) {
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
