//! The plant: the full model integrated by diffsol's adaptive BDF (a stiff
//! solver with error control), advanced in lockstep segments with a
//! callback at every segment end. The offline simulation, the firmware
//! comparisons and the QEMU processor-in-the-loop runs all drive the model
//! through [`Plant::run`].

use crate::hydraulics::{ix, OpPoint};
use crate::model::{t_ix, Drive, Losses, Model, E_AMB, E_LNG, E_LOSS, N_STATE, T0};
use crate::network::{Node, N_NODES};
use crate::rig::Rig;
use crate::scenario::{Scenario, ValveRule};
use diffsol::{NalgebraLU, NalgebraMat, OdeBuilder, OdeSolverMethod, OdeSolverStopReason};
use std::cell::Cell;

mod signals;
mod solver;

pub use signals::*;
pub use solver::*;

/// The plant: model plus state.
#[derive(Debug)]
pub struct Plant {
    model: Model,
    y: Vec<f64>,
    y0: Vec<f64>,
    t: f64,
    stats: Stats,
    rtol: f64,
    step_limit: Option<u64>,
    replay_tolerances: bool,
}

impl Plant {
    /// A plant for `scenario` on `rig`, at rest at ambient.
    pub fn new(rig: &Rig, scenario: &Scenario) -> Result<Self, SimError> {
        let (model, t) = model_for(rig, scenario)?;
        let y = model.initial_state();
        Ok(Self { y0: y.clone(), y, t, model, stats: Stats::default(), rtol: RTOL, step_limit: None, replay_tolerances: false })
    }

    /// The model.
    pub fn model(&self) -> &Model {
        &self.model
    }

    /// The full state vector (hydraulics, node temperatures, energy integrals).
    pub fn state(&self) -> &[f64] {
        &self.y
    }

    /// Current time, s.
    pub fn time_s(&self) -> f64 {
        self.t
    }

    /// Solver statistics so far.
    pub fn stats(&self) -> Stats {
        self.stats
    }

    /// The mission that drives the plant (`None` for a replay), for callers
    /// that set its inputs between runs: the FMU holds each communication
    /// step's inputs as constant schedules.
    pub fn mission_mut(&mut self) -> Option<&mut crate::scenario::Mission> {
        match &mut self.model.drive {
            Drive::Mission(m) => Some(m),
            Drive::Replay(_) => None,
        }
    }

    /// Set the LNG valve.
    pub fn set_lng_valve(&mut self, open: bool) {
        self.model.lng_open.set(open);
    }

    /// Relative tolerance of the solver's error control (default [`RTOL`]).
    /// The diagnosis fits replays with a looser one (`diagnosis::reference`).
    pub fn set_rtol(&mut self, rtol: f64) {
        self.rtol = rtol;
    }

    /// Fails a [`Plant::run`] with [`SimError::StepBudget`] once the solver has
    /// taken more than `steps` steps in it (`None`: no limit). The diagnosis
    /// uses it so that one pathological candidate run (the stiff solver
    /// crawling at ~10 ms steps) cannot stall a fit.
    pub fn set_step_limit(&mut self, steps: Option<u64>) {
        self.step_limit = steps;
    }

    /// Error control for replays fitted to logged temperatures (default:
    /// off, every state at [`atol`]). On: (1) the energy integrals (heat in,
    /// to ambient, to the LNG) leave the error control; no derivative
    /// depends on them, and their 1 mJ absolute tolerance set the step of a
    /// throttle replay (about ten times the steps its temperatures need);
    /// (2) the two port-oil nodes, which no logged channel reads and which
    /// swing with every flow reversal of a servo log, are held to
    /// [`REPLAY_PORT_ATOL_K`] instead of the relative tolerance. The logged
    /// channels then stay within about 0.01 K of a 1e-8 solution
    /// (`docs/diagnosis-cost.md`), a tenth of the sensor noise.
    pub fn set_replay_tolerances(&mut self, on: bool) {
        self.replay_tolerances = on;
    }

    /// Snapshot of the current state.
    pub fn snapshot(&self) -> Snapshot {
        snapshot(&self.model, self.t, &self.y, &self.y0)
    }

    /// Advance to `t_end` in segments of `dt_s`, calling `on_step` with the
    /// snapshot at the start and at the end of every segment; the callback
    /// may command the LNG valve (used during the next segment) or stop.
    /// Schedule breakpoints (steps of speed, pressure, ambient) are hit exactly.
    pub fn run<F>(&mut self, dt_s: f64, t_end: f64, mut on_step: F) -> Result<(), SimError>
    where
        F: FnMut(&Snapshot) -> Result<Control, SimError>,
    {
        if !(dt_s > 0.0 && dt_s.is_finite()) {
            return Err(SimError::Scenario(format!("step {dt_s} s must be > 0")));
        }
        let model = &self.model;
        let evals = Cell::new(0u64);
        let jac_evals = Cell::new(0u64);
        let scale = typical();
        let rhs = |x: &[f64], _p: &[f64], t: f64, y: &mut [f64]| {
            evals.set(evals.get() + 1);
            model.rhs(t, x, y);
        };
        // The solver builds its dense Jacobian one column at a time from
        // J·e_j at the same (t, x): f(t, x) is kept between the columns, and
        // a column of a state no derivative depends on (the energy
        // integrals; in a replay also the imposed hydraulic states) is zero
        // without evaluating f. Both give the same numbers as before.
        let inert = model.inert_states();
        let mut xp = vec![0.0; N_STATE];
        let base = std::cell::RefCell::new((xp.as_mut_slice(), JvpBase::default()));
        let jac = |x: &[f64], _p: &[f64], t: f64, v: &[f64], y: &mut [f64]| {
            if v.iter().zip(&inert).all(|(vi, &skip)| skip || *vi == 0.0) {
                y.iter_mut().for_each(|yi| *yi = 0.0);
                return;
            }
            let mut guard = base.borrow_mut();
            let (xp, b) = &mut *guard;
            let valve = model.lng_open.get();
            if !b.matches(t, x, valve) {
                b.set(t, x, valve);
                model.rhs(t, x, &mut b.f0);
                evals.set(evals.get() + 1);
                jac_evals.set(jac_evals.get() + 1);
            }
            evals.set(evals.get() + 1);
            jac_evals.set(jac_evals.get() + 1);
            fd_jvp_at(|x, y| model.rhs(t, x, y), x, v, &scale, xp, &b.f0, y);
        };
        let y_init = self.y.clone();
        let t_start = self.t;
        let mut problem = OdeBuilder::<NalgebraMat<f64>>::new()
            .t0(t_start)
            .rtol(self.rtol)
            .atol(if self.replay_tolerances { atol_replay() } else { atol() })
            .h0(1e-4)
            .rhs_implicit(rhs, jac)
            .init(move |_p, _t, y| y.copy_from_slice(&y_init), N_STATE)
            .build()
            .map_err(|e| SimError::Solver { t: t_start, message: e.to_string() })?;
        // diffsol 0.18 counts Newton convergence failures over the whole run
        // (its statistics are never reset), not per step as its doc says; a
        // long run with many valve events would hit the default 50. A real
        // failure still ends in the minimum-step error.
        problem.ode_options.max_nonlinear_solver_failures = MAX_NEWTON_FAILURES;
        let mut solver = problem.bdf::<NalgebraLU<f64>>().map_err(|e| SimError::Solver { t: t_start, message: e.to_string() })?;
        let err = |t: f64| move |e: diffsol::DiffsolError| SimError::Solver { t, message: e.to_string() };
        let mut stops = breakpoints(&model.drive, t_start, t_end);
        stops.push(t_end);
        let mut stops = stops.into_iter();
        let mut stop = stops.next().unwrap_or(t_end);
        solver.set_stop_time(stop).map_err(err(t_start))?;
        let mut snap = snapshot(model, t_start, &self.y, &self.y0);
        let mut ctl = on_step(&snap)?;
        if let Some(v) = ctl.lng_valve {
            model.lng_open.set(v);
        }
        let mut k: u64 = 1;
        let mut t_cb = t_start + dt_s;
        let mut y_buf = vec![0.0; N_STATE];
        'outer: while !ctl.stop && snap.t < t_end - 1e-9 {
            let here = solver.state().t;
            if let Some(limit) = self.step_limit {
                if solver.get_statistics().number_of_steps as u64 > limit {
                    return Err(SimError::StepBudget { steps: limit, t: here });
                }
            }
            let reason = solver.step().map_err(err(here))?;
            let t_now = solver.state().t;
            // Callbacks at the segment ends inside this step, by interpolation.
            while !ctl.stop && t_cb <= t_now + 1e-9 && t_cb <= t_end + 1e-9 {
                let tc = t_cb.min(t_now);
                if (tc - t_now).abs() <= 1e-9 {
                    y_buf.copy_from_slice(solver.state().y.batch_as_slice(0));
                } else {
                    let yi = solver.interpolate(tc).map_err(err(tc))?;
                    y_buf.copy_from_slice(yi.batch_as_slice(0));
                }
                snap = snapshot(model, tc, &y_buf, &self.y0);
                ctl = on_step(&snap)?;
                k += 1;
                t_cb = t_start + k as f64 * dt_s;
                let change = ctl.lng_valve.filter(|&v| v != model.lng_open.get());
                if change.is_some() || ctl.stop {
                    // Pin the solver at the callback time before acting.
                    if tc < t_now - 1e-9 {
                        solver.state_mut_back(tc).map_err(err(tc))?;
                    }
                    if let Some(v) = change {
                        model.lng_open.set(v);
                    }
                    if ctl.stop {
                        break 'outer;
                    }
                    continue 'outer;
                }
            }
            if matches!(reason, OdeSolverStopReason::TstopReached) {
                match stops.next() {
                    Some(s) => {
                        stop = s;
                        solver.set_stop_time(stop).map_err(err(t_now))?;
                    }
                    None => break,
                }
            }
        }
        let _ = stop;
        let st = solver.get_statistics();
        self.stats.steps += st.number_of_steps as u64;
        self.stats.newton_iterations += st.number_of_nonlinear_solver_iterations as u64;
        self.stats.factorizations += st.number_of_linear_solver_setups as u64;
        self.stats.jacobian_evals += jac_evals.get();
        let st = solver.state();
        self.t = st.t;
        self.y.copy_from_slice(st.y.batch_as_slice(0));
        self.stats.rhs_evals += evals.get();
        Ok(())
    }

    /// Advance by `dt_s` with the valve held. Convenient for lockstep use;
    /// each call restarts the BDF history, so [`Plant::run`] with a callback is
    /// much cheaper for long lockstep runs.
    pub fn advance(&mut self, dt_s: f64) -> Result<(), SimError> {
        let t_end = self.t + dt_s;
        self.run(dt_s, t_end, |_| Ok(Control::default()))
    }

    /// What the actuator controller measures now.
    pub fn sensors(&self) -> Sensors {
        Sensors::from(&self.snapshot())
    }

    /// The scenario's own valve rule (thermostat or logged command), detached
    /// from the plant so that a run's callback can evaluate it.
    pub fn valve_rule(&self) -> RuleEval {
        RuleEval::for_model(&self.model)
    }
}

/// The model of `scenario` on `rig` and its start time (the first logged
/// sample of a replay, else 0 s).
pub(crate) fn model_for(rig: &Rig, scenario: &Scenario) -> Result<(Model, f64), SimError> {
    let drive = match scenario {
        Scenario::Replay(r) => {
            if r.time_s.len() < 2 {
                return Err(SimError::Scenario("replay needs at least two samples".into()));
            }
            Drive::Replay(crate::model::ReplayDrive::new(r.clone()))
        }
        other => Drive::Mission(other.mission().ok_or_else(|| SimError::Scenario("no mission".into()))?),
    };
    // The model keeps the rig's physics, not its `uq` ranges (`Rig::physics_clone`).
    let model = Model::new(rig.physics_clone(), drive);
    let t = match &model.drive {
        Drive::Replay(r) => r.inputs().time_s.first().copied().unwrap_or(0.0),
        Drive::Mission(_) => 0.0,
    };
    Ok((model, t))
}

/// The times in (t0, t1) where the drive's schedules kink or step: the
/// solvers stop there.
pub(crate) fn breakpoints(drive: &Drive, t0: f64, t1: f64) -> Vec<f64> {
    let mut v: Vec<f64> = match drive {
        Drive::Mission(m) => m
            .ambient_c
            .breakpoints()
            .chain(m.speed_rpm.breakpoints())
            .chain(m.needle_bar.breakpoints())
            .chain(m.air_speed_mps.breakpoints())
            .chain(match &m.position {
                crate::scenario::PositionRef::Profile(s) => s.0.iter().map(|p| p.0).collect::<Vec<_>>(),
                crate::scenario::PositionRef::Sine { .. } => vec![],
            })
            .collect(),
        // Replayed inputs are interpolated linearly between the logged
        // samples: continuous, so the solver steps across the samples with
        // its own error control instead of restarting at each one (a servo
        // log at 0.1 s would otherwise force 10 stops per simulated second).
        // The logged valve command is applied at the control callbacks.
        Drive::Replay(_) => Vec::new(),
    };
    v.retain(|&b| b > t0 && b < t1);
    v.sort_by(f64::total_cmp);
    v.dedup();
    v
}
