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

/// Errors of a simulation.
#[derive(Debug, thiserror::Error)]
pub enum SimError {
    /// The ODE solver failed (step size underflow, Newton divergence, ...).
    #[error("solver failed at t = {t:.3} s: {message}")]
    Solver {
        /// Time reached, s.
        t: f64,
        /// diffsol's message.
        message: String,
    },
    /// The scenario is not simulable (empty replay, bad duration, ...).
    #[error("invalid scenario: {0}")]
    Scenario(String),
    /// The step callback asked to stop with an error.
    #[error("{0}")]
    Callback(String),
    /// The solver needed more steps than the run's budget
    /// ([`Plant::set_step_limit`]).
    #[error("step budget of {steps} solver steps exhausted at t = {t:.3} s")]
    StepBudget {
        /// The budget.
        steps: u64,
        /// Time reached, s.
        t: f64,
    },
}

/// Newton convergence failures allowed over one run (see [`Plant::run`]).
pub const MAX_NEWTON_FAILURES: usize = 1_000_000;

/// Relative tolerance of the BDF error control.
pub const RTOL: f64 = 1e-6;

/// Per-state absolute tolerances: 1 Pa, 1e-12 m³/s, 1 µm, 1 µm/s, 1e-5 rad/s,
/// 1e-5 K, 1e-3 J.
pub fn atol() -> Vec<f64> {
    let mut a = vec![1e-5; N_STATE];
    a[ix::PA] = 1.0;
    a[ix::PB] = 1.0;
    a[ix::X] = 1e-6;
    a[ix::V] = 1e-6;
    a[ix::OMEGA] = 1e-5;
    for e in [E_LOSS, E_AMB, E_LNG] {
        a[e] = 1e-3;
    }
    a
}

/// Absolute tolerance of the pump's port-oil temperatures in the replays
/// of [`Plant::set_replay_tolerances`], K.
pub const REPLAY_PORT_ATOL_K: f64 = 0.01;

/// [`atol`] for replays fitted to logged temperatures: the energy integrals
/// out of the error control (an absolute tolerance no error reaches) and the
/// port oil at [`REPLAY_PORT_ATOL_K`]. See [`Plant::set_replay_tolerances`].
fn atol_replay() -> Vec<f64> {
    let mut a = atol();
    for e in [E_LOSS, E_AMB, E_LNG] {
        a[e] = 1e30;
    }
    for n in [Node::Inlet, Node::Outlet] {
        a[t_ix(n)] = REPLAY_PORT_ATOL_K;
    }
    a
}

/// f(t, x) kept between the Jacobian columns the solver asks for at the
/// same point (and LNG valve state).
#[derive(Default)]
struct JvpBase {
    t: f64,
    x: Vec<f64>,
    valve: bool,
    f0: Vec<f64>,
}

impl JvpBase {
    fn matches(&self, t: f64, x: &[f64], valve: bool) -> bool {
        !self.x.is_empty()
            && self.t.to_bits() == t.to_bits()
            && self.valve == valve
            && self.x.iter().zip(x).all(|(a, b)| a.to_bits() == b.to_bits())
    }

    fn set(&mut self, t: f64, x: &[f64], valve: bool) {
        self.t = t;
        self.valve = valve;
        self.x.clear();
        self.x.extend_from_slice(x);
        self.f0.resize(x.len(), 0.0);
    }
}

/// Typical magnitudes of the states, used to scale the finite-difference
/// Jacobian–vector products.
pub(crate) fn typical() -> Vec<f64> {
    let mut s = vec![1.0; N_STATE];
    s[ix::PA] = 1e6;
    s[ix::PB] = 1e6;
    s[ix::X] = 1e-2;
    s[ix::V] = 1e-2;
    s[ix::OMEGA] = 10.0;
    for t in s.iter_mut().skip(T0).take(N_NODES) {
        *t = 50.0;
    }
    for e in [E_LOSS, E_AMB, E_LNG] {
        s[e] = 1e5;
    }
    s
}

/// Forward-difference Jacobian–vector product J·v of `f` at `x`, with the
/// step scaled to the state magnitudes `scale` (so that pressures in Pa and
/// temperatures in °C are perturbed by the same relative amount 1e-7).
/// `xp`, `f0` are scratch buffers of the state's length.
pub fn fd_jvp(mut f: impl FnMut(&[f64], &mut [f64]), x: &[f64], v: &[f64], scale: &[f64], xp: &mut [f64], f0: &mut [f64], y: &mut [f64]) {
    if v.iter().all(|vi| *vi == 0.0) {
        y.iter_mut().for_each(|yi| *yi = 0.0);
        return;
    }
    f(x, f0);
    fd_jvp_at(f, x, v, scale, xp, f0, y);
}

/// [`fd_jvp`] with f(x) given in `f0`.
fn fd_jvp_at(mut f: impl FnMut(&[f64], &mut [f64]), x: &[f64], v: &[f64], scale: &[f64], xp: &mut [f64], f0: &[f64], y: &mut [f64]) {
    let vmax = v.iter().zip(x.iter().zip(scale)).map(|(vi, (xi, s))| vi.abs() / (xi.abs() + s)).fold(0.0, f64::max);
    if vmax == 0.0 {
        y.iter_mut().for_each(|yi| *yi = 0.0);
        return;
    }
    let eps = 1e-7 / vmax;
    for ((p, xi), vi) in xp.iter_mut().zip(x).zip(v) {
        *p = xi + eps * vi;
    }
    f(xp, y);
    for (yi, f0i) in y.iter_mut().zip(f0.iter()) {
        *yi = (*yi - f0i) / eps;
    }
}

/// Integrate a general ODE dy/dt = f(t, y) from `y0` at t = 0 to `t_end`
/// with the same solver set-up as the plant (diffsol BDF, nalgebra LU,
/// finite-difference Jacobian scaled by `scale`). Used to verify the solver
/// on problems with analytic solutions.
pub fn integrate(
    f: impl Fn(f64, &[f64], &mut [f64]),
    y0: &[f64],
    scale: &[f64],
    t_end: f64,
    rtol: f64,
    atol: f64,
) -> Result<Vec<f64>, SimError> {
    let n = y0.len();
    let bufs = std::cell::RefCell::new((vec![0.0; n], vec![0.0; n]));
    let y_init = y0.to_vec();
    let err = |e: diffsol::DiffsolError| SimError::Solver { t: 0.0, message: e.to_string() };
    let problem = OdeBuilder::<NalgebraMat<f64>>::new()
        .rtol(rtol)
        .atol(vec![atol; n])
        .h0(1e-6)
        .rhs_implicit(
            |x: &[f64], _p: &[f64], t: f64, y: &mut [f64]| f(t, x, y),
            |x: &[f64], _p: &[f64], t: f64, v: &[f64], y: &mut [f64]| {
                let mut b = bufs.borrow_mut();
                let (xp, f0) = &mut *b;
                fd_jvp(|x, y| f(t, x, y), x, v, scale, xp, f0, y);
            },
        )
        .init(move |_p, _t, y| y.copy_from_slice(&y_init), n)
        .build()
        .map_err(err)?;
    let mut solver = problem.bdf::<NalgebraLU<f64>>().map_err(err)?;
    solver.set_stop_time(t_end).map_err(err)?;
    while !matches!(solver.step().map_err(err)?, OdeSolverStopReason::TstopReached) {}
    Ok(solver.state().y.batch_as_slice(0).to_vec())
}

/// What the model shows at one instant: the operating point, every node
/// temperature, every loss and the energy integrals.
#[derive(Debug, Clone, PartialEq)]
pub struct Snapshot {
    /// Time, s.
    pub t: f64,
    /// Hydraulic operating point.
    pub op: OpPoint,
    /// Node temperatures, °C, in [`crate::network::NODES`] order.
    pub temps: [f64; N_NODES],
    /// Losses, W.
    pub losses: Losses,
    /// LNG valve open.
    pub lng_open: bool,
    /// Integrated losses, J.
    pub e_loss_j: f64,
    /// Integrated heat to ambient, J.
    pub e_amb_j: f64,
    /// Integrated heat to the LNG, J.
    pub e_lng_j: f64,
    /// Energy stored in the nodes since the start, J.
    pub stored_j: f64,
    /// LNG used since the start, kg (eq. 24).
    pub lng_used_kg: f64,
}

impl Snapshot {
    /// Temperature of a node, °C.
    pub fn temp(&self, n: Node) -> f64 {
        self.temps[n as usize]
    }
}

/// The signals the actuator controller has (the firmware's inputs), plus the
/// true drain temperature it tries to estimate.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sensors {
    /// Time, s.
    pub t: f64,
    /// Motor current, A rms.
    pub current_a: f64,
    /// Port A pressure, bar gauge.
    pub p_a_bar: f64,
    /// Port B pressure, bar gauge.
    pub p_b_bar: f64,
    /// Motor speed, rpm.
    pub speed_rpm: f64,
    /// Piston position, mm.
    pub position_mm: f64,
    /// Ambient, °C.
    pub ambient_c: f64,
    /// True drain-port (pump case) oil temperature, °C.
    pub t_drain_c: f64,
    /// True circulating-oil temperature, °C.
    pub t_loop_oil_c: f64,
    /// LNG valve open.
    pub lng_open: bool,
}

impl Sensors {
    /// The firmware's wire sample of these signals (f32, the units of
    /// `eha_guard::Sample`), as a controller would send them every step.
    pub fn sample(&self) -> eha_guard::Sample {
        eha_guard::Sample {
            current_a: self.current_a as f32,
            p_a_bar: self.p_a_bar as f32,
            p_b_bar: self.p_b_bar as f32,
            speed_rpm: self.speed_rpm as f32,
            position_mm: self.position_mm as f32,
            ambient_c: self.ambient_c as f32,
        }
    }
}

impl From<&Snapshot> for Sensors {
    fn from(s: &Snapshot) -> Self {
        Sensors {
            t: s.t,
            current_a: s.op.current_a,
            p_a_bar: s.op.p_a * 1e-5,
            p_b_bar: s.op.p_b * 1e-5,
            speed_rpm: s.op.omega * 60.0 / (2.0 * std::f64::consts::PI),
            position_mm: s.op.x * 1e3,
            ambient_c: s.op.ambient_c,
            t_drain_c: s.temp(Node::Case),
            t_loop_oil_c: s.temp(Node::Loop),
            lng_open: s.lng_open,
        }
    }
}

/// What a step callback returns.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Control {
    /// New LNG valve command (None: unchanged).
    pub lng_valve: Option<bool>,
    /// Stop the run after this step.
    pub stop: bool,
}

/// Solver statistics of a run.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Stats {
    /// Right-hand-side evaluations (including those of Jacobian products).
    pub rhs_evals: u64,
    /// Accepted solver steps.
    pub steps: u64,
    /// Of `rhs_evals`, those spent on Jacobian columns.
    pub jacobian_evals: u64,
    /// Newton iterations (BDF only).
    pub newton_iterations: u64,
    /// Jacobian factorisations (BDF: diffsol's linear-solver setups; fast
    /// path: thermal Jacobians).
    pub factorizations: u64,
}

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
    /// (`docs/diagnosis.md`, speed), a tenth of the sensor noise.
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

/// A scenario's valve rule, evaluated on snapshots.
#[derive(Debug, Clone)]
pub struct RuleEval {
    rule: ValveRule,
    lng: crate::cooling::Lng,
    replay: Option<crate::model::ReplayDrive>,
}

impl RuleEval {
    /// The valve rule of `model`'s drive.
    pub(crate) fn for_model(model: &Model) -> Self {
        RuleEval {
            rule: model.valve_rule(),
            lng: model.rig.lng,
            replay: match &model.drive {
                Drive::Replay(r) => Some(r.clone()),
                Drive::Mission(_) => None,
            },
        }
    }

    /// The valve command at a snapshot (None: leave it to the caller).
    pub fn command(&self, snap: &Snapshot) -> Option<bool> {
        let next = |t: f64| crate::cooling::valve_next(snap.lng_open, t, &self.lng);
        match self.rule {
            ValveRule::None => Some(false),
            ValveRule::LoopOil => Some(next(snap.temp(Node::Loop))),
            ValveRule::Drain => Some(next(snap.temp(Node::Case))),
            ValveRule::External => self.replay.as_ref().map(|r| r.lng_open(snap.t)),
        }
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
    let model = Model::new(rig.clone(), drive);
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

/// Snapshot of state `y` at `t` (with `y0` the initial state for the stored energy).
pub fn snapshot(model: &Model, t: f64, y: &[f64], y0: &[f64]) -> Snapshot {
    let op = model.op_point(t, y);
    let mut temps = [0.0; N_NODES];
    temps.copy_from_slice(&y[T0..T0 + N_NODES]);
    let losses = model.losses(t, &op, &temps);
    Snapshot {
        t,
        op,
        temps,
        losses,
        lng_open: model.lng_open.get(),
        e_loss_j: y[E_LOSS],
        e_amb_j: y[E_AMB],
        e_lng_j: y[E_LNG],
        stored_j: model.stored_energy(y0, y),
        lng_used_kg: y[E_LNG] / model.rig.lng.heat_per_kg(),
    }
}
