//! The callbacks of [`FastPlant::run`](super::FastPlant::run) inside an
//! accepted thermal step: the state there on the cubic Hermite
//! interpolants, and a valve change or a stop continuing from the
//! callback's time.

use super::attempt::{Attempt, StepStart};
use super::state::RunState;
use super::steps::Todo;
use super::FastPlant;
use crate::fast::hydraulic::{hermite, NH};
use crate::fast::thermal::{NE, NT};
use crate::model::T0;
use crate::plant::{snapshot_stored, Control, SimError, Snapshot};

impl FastPlant {
    /// Calls `on_step` at every callback time up to the end of the accepted
    /// step `a` (begun at `start`). `Ok(true)`: a callback changed the valve
    /// or stopped the run, the plant stands at that callback's time, and
    /// the run goes on (or ends) from there, past the step's own ending.
    pub(super) fn callbacks<F>(&mut self, run: &mut RunState, start: &StepStart, a: &Attempt, on_step: &mut F) -> Result<bool, SimError>
    where
        F: FnMut(&Snapshot) -> Result<Control, SimError>,
    {
        let t1 = a.t1;
        while !run.ctl.stop && run.t_cb <= t1 + 1e-9 && run.t_cb <= run.t_end + 1e-9 {
            let at_end = (run.t_cb - t1).abs() <= 1e-9;
            let tc = if at_end { run.t_cb } else { run.t_cb.min(t1) };
            if at_end {
                self.write_state(&run.yh, &run.kept.0);
            } else {
                self.interpolate(run, start, a.h, tc);
            }
            let snap = snapshot_stored(&self.model, tc, &self.y, self.model.stored_energy_from(&self.e0, &self.y));
            run.ctl = on_step(&snap)?;
            run.k += 1;
            run.t_cb = run.t_start + run.k as f64 * run.dt_s;
            let change = run.ctl.lng_valve.filter(|&v| v != self.model.lng_open.get());
            if change.is_some() || run.ctl.stop {
                self.resume(run, at_end, tc, change);
                return Ok(true);
            }
        }
        Ok(false)
    }

    /// The plant's state vector at `tc` inside the step of `h` s begun at
    /// `start`: the temperatures and energies on their cubic Hermite
    /// interpolants, the hydraulics from their track (the step's start on
    /// a replay).
    fn interpolate(&mut self, run: &mut RunState, start: &StepStart, h: f64, tc: f64) {
        let th = &run.kept.0;
        let (a0, b0, a1, b1) = hermite((tc - start.t) / h);
        for i in 0..NT {
            self.y[T0 + i] = a0 * start.z[i] + b0 * h * start.fz[i] + a1 * th.z[i] + b1 * h * th.fz[i];
        }
        for i in 0..NE {
            self.y[T0 + NT + i] = a0 * start.e[i] + b0 * h * start.q[i] + a1 * th.e[i] + b1 * h * th.q[i];
        }
        let yhc: [f64; NH] = if run.replay { start.yh } else { self.hyd.at(&self.model, tc) };
        self.y[..NH].copy_from_slice(&yhc);
    }

    /// After a callback at `tc` that changed the valve (`change`) or
    /// stopped the run: inside the step, the run continues from `tc` (the
    /// hydraulic track stays: the valve acts on the oil only) with f taken
    /// anew; a valve change also takes the Jacobian anew.
    fn resume(&mut self, run: &mut RunState, at_end: bool, tc: f64, change: Option<bool>) {
        if !at_end {
            let th = &mut run.kept.0;
            self.t = tc;
            run.yh.copy_from_slice(&self.y[..NH]);
            th.z.copy_from_slice(&self.y[T0..T0 + NT]);
            th.e.copy_from_slice(&self.y[T0 + NT..]);
            th.t = tc;
            (run.origin, run.ticks) = (tc, 0);
            run.scan_from = tc;
            run.todo = Todo { fresh: true, ..Todo::default() };
        }
        if let Some(v) = change {
            self.model.lng_open.set(v);
            run.todo.jacobian = true;
            run.todo.fresh = true;
        }
    }
}
