//! The stiff solver's settings: errors, tolerances, the scaled
//! finite-difference Jacobian–vector products diffsol's BDF is given, and
//! the same set-up for a general ODE ([`integrate`], the solver's tests).

use super::*;

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
pub(super) fn atol_replay() -> Vec<f64> {
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
pub(super) struct JvpBase {
    t: f64,
    x: Vec<f64>,
    valve: bool,
    pub(super) f0: Vec<f64>,
}

impl JvpBase {
    pub(super) fn matches(&self, t: f64, x: &[f64], valve: bool) -> bool {
        !self.x.is_empty()
            && self.t.to_bits() == t.to_bits()
            && self.valve == valve
            && self.x.iter().zip(x).all(|(a, b)| a.to_bits() == b.to_bits())
    }

    pub(super) fn set(&mut self, t: f64, x: &[f64], valve: bool) {
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
pub(super) fn fd_jvp_at(mut f: impl FnMut(&[f64], &mut [f64]), x: &[f64], v: &[f64], scale: &[f64], xp: &mut [f64], f0: &[f64], y: &mut [f64]) {
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
