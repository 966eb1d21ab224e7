//! The multirate plant: the same model as [`crate::plant::Plant`], the
//! same run/callback contract, a different integrator.
//!
//! * Hydraulic states: RODAS4 with its own error control, the node
//!   temperatures held at the start of each thermal step (they enter only
//!   through the leakage conductance and the oil viscosity).
//! * Node temperatures: exponential Adams steps of order 2 on
//!   z' = A·z + g(t, z), with A the Jacobian of the model's own heat
//!   balances (forward differences of `Model::rhs`, refreshed at restarts
//!   and when a step fails) and g = f − A·z, everything the linear part
//!   misses: the operating point's variation within the step, temperature
//!   dependent conductances, losses and capacities, a stale A. Predictor:
//!   g extrapolated linearly from the last step; one model evaluation at the
//!   predicted end; corrector: g interpolated linearly,
//!   z₁ = z₀ + Φ₁·f₀ + Φ₂·(g₁ − g₀) (exact for a linear network with forcing
//!   linear in time). Error estimate: (corrector − predictor)/6 (Milne), held
//!   below `tol_k` on every node.
//! * Steps are the callback interval times powers of two; a longer step
//!   costs four matrix products, a shorter one is cached; steps also stay
//!   below `alias_ratio` hydraulic steps, so that a forcing periodic within
//!   a step is never sampled at its period.
//! * Energy integrals: trapezoidal rule on the model's heat rates.
//! * Between steps, callbacks see cubic Hermite interpolants (the
//!   temperatures' and the hydraulic steps'); a valve change or a schedule
//!   breakpoint restarts the scheme there.

use super::dense::{mul_vec, mul_vec_add, Mat};
use super::hydraulic::{hermite, left_of, HydTrack, NH};
use super::phi::Phi;
use super::rosenbrock::{RosError, RosStats, Rosenbrock};
use crate::model::{Drive, Model, N_STATE, T0};
use crate::network::N_NODES;
use crate::plant::{breakpoints, model_for, snapshot, typical, Control, RuleEval, SimError, Snapshot, Stats};
use crate::rig::Rig;
use crate::scenario::Scenario;

/// Node temperatures.
const NT: usize = N_NODES;
/// Energy integrals after the temperatures.
const NE: usize = N_STATE - T0 - N_NODES;
const _: () = assert!(T0 == NH, "the temperatures follow the hydraulic states");

/// Finest step level: the callback interval / 2^24.
const LEVEL_MIN: i32 = -24;
/// Coarsest level: the callback interval · 2^8.
const LEVEL_MAX: i32 = 8;
const LEVELS: usize = (LEVEL_MAX - LEVEL_MIN + 1) as usize;
/// Accepted steps without growth (for want of accuracy) after which the
/// thermal Jacobian is refreshed.
const STALL_STEPS: u32 = 16;
/// Growth of the step (in levels, factors of two) after which the thermal
/// Jacobian is refreshed.
const REFRESH_LEVELS: i32 = 6;

/// Accuracy and step settings of the multirate scheme.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FastOptions {
    /// Local error bound of one thermal step on every node, K.
    pub tol_k: f64,
    /// Relative tolerance of the hydraulic integration.
    pub hyd_rtol: f64,
    /// Longest thermal step, in hydraulic steps (anti-aliasing).
    pub alias_ratio: f64,
    /// Longest thermal step, s.
    pub h_max_s: f64,
    /// First thermal step after a start or a schedule breakpoint, s.
    pub h_start_s: f64,
}

impl Default for FastOptions {
    fn default() -> Self {
        Self { tol_k: 1e-4, hyd_rtol: 1e-6, alias_ratio: 8.0, h_max_s: 60.0, h_start_s: 1e-3 }
    }
}

/// Work counters of the multirate scheme.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct FastStats {
    /// Accepted thermal steps.
    pub steps: u64,
    /// Rejected thermal steps.
    pub rejected: u64,
    /// Thermal Jacobians (each N_NODES model evaluations).
    pub jacobians: u64,
    /// φ-function sets computed from scratch (doublings not counted).
    pub phi_builds: u64,
    /// Full model evaluations (steps and Jacobian columns).
    pub rhs_evals: u64,
    /// The hydraulic integrator's counters.
    pub hydraulics: RosStats,
}

/// The multirate plant (see the module documentation).
#[derive(Debug)]
pub struct FastPlant {
    model: Model,
    y: [f64; N_STATE],
    y0: [f64; N_STATE],
    t: f64,
    opts: FastOptions,
    hyd: HydTrack,
    stats: FastStats,
    step_limit: Option<u64>,
}

/// The thermal scheme's state between steps.
struct Thermal {
    z: [f64; NT],
    e: [f64; NE],
    fz: [f64; NT],
    q: [f64; NE],
    /// dg/dt from the last step (None after a restart).
    slope: Option<[f64; NT]>,
    a: Mat<NT>,
    a_e: [[f64; NT]; NE],
    ladder: Vec<Option<Phi<NT>>>,
}

impl FastPlant {
    /// A plant for `scenario` on `rig`, at rest at ambient.
    pub fn new(rig: &Rig, scenario: &Scenario) -> Result<Self, SimError> {
        Self::with_options(rig, scenario, FastOptions::default())
    }

    /// [`FastPlant::new`] with explicit accuracy settings.
    pub fn with_options(rig: &Rig, scenario: &Scenario, opts: FastOptions) -> Result<Self, SimError> {
        let (model, t) = model_for(rig, scenario)?;
        let mut y = [0.0; N_STATE];
        y.copy_from_slice(&model.initial_state());
        // Errors relative to the states' typical magnitudes (1 MPa, 1 cm,
        // 1 cm/s, 10 rad/s): near a flow reversal the BDF's absolute
        // tolerances (1 µm/s, 1e-5 rad/s) set the step without changing a loss.
        let sc = typical();
        let scale: [f64; NH] = std::array::from_fn(|i| sc[i]);
        let atol = scale.map(|s| s * opts.hyd_rtol);
        let mut yh = [0.0; NH];
        yh.copy_from_slice(&y[..NH]);
        let hyd = HydTrack::new(Rosenbrock::new(opts.hyd_rtol, atol, scale, opts.h_start_s), t, yh);
        Ok(Self { model, y, y0: y, t, opts, hyd, stats: FastStats::default(), step_limit: None })
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

    /// Work counters so far.
    pub fn fast_stats(&self) -> FastStats {
        self.stats
    }

    /// Counters in the BDF plant's terms: thermal steps and model evaluations.
    pub fn stats(&self) -> Stats {
        Stats { rhs_evals: self.stats.rhs_evals, steps: self.stats.steps }
    }

    /// Set the LNG valve.
    pub fn set_lng_valve(&mut self, open: bool) {
        self.model.lng_open.set(open);
    }

    /// Fails a run with [`SimError::StepBudget`] after `steps` thermal steps.
    pub fn set_step_limit(&mut self, steps: Option<u64>) {
        self.step_limit = steps;
    }

    /// Snapshot of the current state.
    pub fn snapshot(&self) -> Snapshot {
        snapshot(&self.model, self.t, &self.y, &self.y0)
    }

    /// The scenario's own valve rule.
    pub fn valve_rule(&self) -> RuleEval {
        RuleEval::for_model(&self.model)
    }

    /// Thermal part of the model's right-hand side at (t, yh, z): node
    /// derivatives K/s into `fz`, energy rates W into `q`.
    fn eval(&mut self, t: f64, yh: &[f64; NH], z: &[f64; NT], fz: &mut [f64; NT], q: &mut [f64; NE]) {
        let mut y = [0.0; N_STATE];
        y[..NH].copy_from_slice(yh);
        y[T0..T0 + NT].copy_from_slice(z);
        let mut dy = [0.0; N_STATE];
        self.model.rhs(t, &y, &mut dy);
        self.stats.rhs_evals += 1;
        fz.copy_from_slice(&dy[T0..T0 + NT]);
        q.copy_from_slice(&dy[T0 + NT..]);
    }

    /// Fresh f at the current point and the Jacobian of the heat balances
    /// with respect to the node temperatures (forward differences). With
    /// `keep_history` the slope of g = f − A·z carries over to the new A
    /// (g' changes by (A_old − A_new)·z', z' ≈ f); without, the next step
    /// starts anew (after a valve change or a schedule breakpoint).
    fn restart(&mut self, th: &mut Thermal, yh: &[f64; NH], keep_history: bool) {
        let a_old = th.a;
        let t = self.t;
        let (mut fz, mut q) = ([0.0; NT], [0.0; NE]);
        self.eval(t, yh, &th.z, &mut fz, &mut q);
        let (mut fp, mut qp) = ([0.0; NT], [0.0; NE]);
        for j in 0..NT {
            let mut zp = th.z;
            let d = 1e-5 * (1.0 + th.z[j].abs());
            zp[j] += d;
            self.eval(t, yh, &zp, &mut fp, &mut qp);
            for i in 0..NT {
                th.a[i][j] = (fp[i] - fz[i]) / d;
            }
            for i in 0..NE {
                th.a_e[i][j] = (qp[i] - q[i]) / d;
            }
        }
        th.slope = match (keep_history, th.slope) {
            (true, Some(mut s)) => {
                for i in 0..NT {
                    s[i] += (0..NT).map(|j| (a_old[i][j] - th.a[i][j]) * fz[j]).sum::<f64>();
                }
                Some(s)
            }
            _ => None,
        };
        th.fz = fz;
        th.q = q;
        th.ladder.iter_mut().for_each(|p| *p = None);
        self.stats.jacobians += 1;
    }

    /// φ-functions at `level` from the cache, by doubling the level below, or anew.
    fn phi(&mut self, th: &mut Thermal, level: i32, dt: f64) -> Phi<NT> {
        let i = (level - LEVEL_MIN) as usize;
        if let Some(p) = th.ladder[i] {
            return p;
        }
        let p = match i.checked_sub(1).and_then(|j| th.ladder[j]) {
            Some(below) => below.doubled(),
            None => {
                self.stats.phi_builds += 1;
                Phi::new(&th.a, dt * 2f64.powi(level))
            }
        };
        th.ladder[i] = Some(p);
        p
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
        let mut th = Thermal {
            z: std::array::from_fn(|i| self.y[T0 + i]),
            e: std::array::from_fn(|i| self.y[T0 + NT + i]),
            fz: [0.0; NT],
            q: [0.0; NE],
            slope: None,
            a: [[0.0; NT]; NT],
            a_e: [[0.0; NT]; NE],
            ladder: vec![None; LEVELS],
        };
        let mut yh: [f64; NH] = std::array::from_fn(|i| self.y[i]);
        let start_level = |h: f64| ((h / dt_s).log2().floor() as i32).clamp(LEVEL_MIN, LEVEL_MAX);
        let mut level = start_level(self.opts.h_start_s);
        // Restart of the thermal scheme (Jacobian, history) and, at a
        // schedule breakpoint, of the hydraulic integration.
        let (mut need_restart, mut need_hyd_restart) = (true, true);
        // A Jacobian refresh that keeps the step history, and the level the
        // last Jacobian was taken at.
        let (mut need_jacobian, mut jac_level) = (false, level);
        // Position since the last restart in units of the finest level:
        // step ends are origin + ticks·h_fine, free of accumulated round-off.
        let h_fine = dt_s * 2f64.powi(LEVEL_MIN);
        let (mut origin, mut ticks) = (self.t, 0u64);
        // Accepted steps since the Jacobian, and since the level last grew.
        let (mut age, mut stalled) = (0u32, 0u32);
        let mut k: u64 = 1;
        let mut t_cb = t_start + dt_s;
        let steps_at_start = self.stats.steps;
        let hyd_err = |e: RosError| {
            let (t, what) = match e {
                RosError::StepUnderflow(t) => (t, "hydraulic step underflow"),
                RosError::Singular(t) => (t, "singular hydraulic iteration matrix"),
            };
            SimError::Solver { t, message: what.into() }
        };
        'outer: while !ctl.stop && self.t < t_end - 1e-9 {
            while stops.peek().is_some_and(|&s| s <= self.t + 1e-9) {
                stops.next();
            }
            let seg_end = stops.peek().copied().unwrap_or(t_end);
            if need_hyd_restart && !replay {
                self.hyd.restart(&self.model, &th.z, self.t, yh, self.opts.h_start_s);
                need_hyd_restart = false;
            }
            if need_restart || need_jacobian {
                self.restart(&mut th, &yh, !need_restart);
                (need_restart, need_jacobian) = (false, false);
                (age, stalled, jac_level) = (0, 0, level);
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
            let h_level = dt_s * 2f64.powi(level);
            let partial = self.t + h_level > seg_end - 1e-9 * h_level.max(1.0);
            let (phi, t1) = if partial {
                self.stats.phi_builds += 1;
                (Phi::new(&th.a, seg_end - self.t), seg_end)
            } else {
                (self.phi(&mut th, level, dt_s), origin + (ticks + (1u64 << (level - LEVEL_MIN))) as f64 * h_fine)
            };
            let h = t1 - self.t;
            // The hydraulic states at the step's end, from their own track.
            let yh1 = if replay {
                yh
            } else {
                self.hyd.cover(&self.model, &th.z, t1, seg_end).map_err(hyd_err)?;
                self.hyd.at(t1)
            };
            // Exponential Adams predictor, one model evaluation, corrector.
            let mut g0 = th.fz;
            for (gi, ai) in g0.iter_mut().zip(&th.a) {
                *gi -= ai.iter().zip(&th.z).map(|(p, q)| p * q).sum::<f64>();
            }
            let mut base = th.z;
            mul_vec_add(&phi.p1, &th.fz, &mut base);
            let mut zp = base;
            if let Some(s) = &th.slope {
                let hs = s.map(|x| x * h);
                mul_vec_add(&phi.p2, &hs, &mut zp);
            }
            let (mut fp, mut qp) = ([0.0; NT], [0.0; NE]);
            // At a breakpoint the segment's schedules end with their left limits.
            self.eval(if partial { left_of(t1) } else { t1 }, &yh1, &zp, &mut fp, &mut qp);
            let az = mul_vec(&th.a, &zp);
            let dg: [f64; NT] = std::array::from_fn(|i| fp[i] - az[i] - g0[i]);
            let mut z1 = base;
            mul_vec_add(&phi.p2, &dg, &mut z1);
            let err = z1.iter().zip(&zp).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max) / 6.0 / self.opts.tol_k;
            let hyd_h = if replay { f64::INFINITY } else { self.hyd.ros.h };
            if std::env::var_os("FAST_DEBUG").is_some() {
                let imax = (0..NT).max_by(|&i, &j| (z1[i] - zp[i]).abs().total_cmp(&(z1[j] - zp[j]).abs())).unwrap_or(0);
                eprintln!("t {:.4} h {:.3e} lvl {level} err {err:.3e} node {imax} hyd_h {hyd_h:.3e} partial {partial} slope {}", self.t, h, th.slope.is_some());
            }
            if !(err <= 1.0) {
                self.stats.rejected += 1;
                level = if partial { start_level(h / 2.0) } else { level - 1 };
                if level < LEVEL_MIN {
                    return Err(SimError::Solver { t: self.t, message: format!("thermal step underflow (error {err:.2e} of the bound)") });
                }
                if age >= 4 {
                    // A stale Jacobian shows as a large variation of g: refresh it.
                    need_jacobian = true;
                }
                continue;
            }
            // Accept: f at the corrected point by the linear model.
            let dz: [f64; NT] = std::array::from_fn(|i| z1[i] - zp[i]);
            let adz = mul_vec(&th.a, &dz);
            let f1: [f64; NT] = std::array::from_fn(|i| fp[i] + adz[i]);
            let q1: [f64; NE] = std::array::from_fn(|i| qp[i] + th.a_e[i].iter().zip(&dz).map(|(p, q)| p * q).sum::<f64>());
            let e1: [f64; NE] = std::array::from_fn(|i| th.e[i] + 0.5 * h * (th.q[i] + q1[i]));
            let (t0, z0, f0, e0, q0, yh0) = (self.t, th.z, th.fz, th.e, th.q, yh);
            th.slope = Some(dg.map(|x| x / h));
            (th.z, th.fz, th.e, th.q) = (z1, f1, e1, q1);
            yh = yh1;
            self.t = t1;
            self.stats.steps += 1;
            self.write_state(&yh, &th);
            if partial {
                // A schedule breakpoint (or the end): restart there.
                need_restart = true;
                need_hyd_restart = true;
                level = start_level(self.opts.h_start_s);
                origin = self.t;
                ticks = 0;
            } else {
                ticks += 1u64 << (level - LEVEL_MIN);
                let grow = 0.9 * err.max(1e-12).powf(-1.0 / 3.0) >= 2.0;
                let next = level + 1;
                let room = next <= LEVEL_MAX && 2.0 * h <= self.opts.h_max_s && 2.0 * h <= self.opts.alias_ratio * hyd_h;
                if grow && room && ticks % (1u64 << (next - LEVEL_MIN)) == 0 {
                    level = next;
                    stalled = 0;
                } else if room && !grow {
                    stalled += 1;
                }
                age += 1;
                if stalled >= STALL_STEPS && age >= STALL_STEPS {
                    // The error, not a limit, holds the step: a Jacobian at
                    // the current operating point may free it.
                    need_jacobian = true;
                }
                if level >= jac_level + REFRESH_LEVELS {
                    // Taken at a far shorter step, the Jacobian belongs to an
                    // operating point the drive has left (the start of a
                    // breakpoint's transient): a Jacobian stiffer than the
                    // network would damp modes the network keeps, unseen
                    // by the error estimate.
                    need_jacobian = true;
                }
            }
            // Callbacks inside the step, on the interpolants.
            while !ctl.stop && t_cb <= t1 + 1e-9 && t_cb <= t_end + 1e-9 {
                let at_end = (t_cb - t1).abs() <= 1e-9;
                let tc = if at_end { t_cb } else { t_cb.min(t1) };
                if at_end {
                    self.write_state(&yh, &th);
                } else {
                    let (a0, b0, a1, b1) = hermite((tc - t0) / h);
                    for i in 0..NT {
                        self.y[T0 + i] = a0 * z0[i] + b0 * h * f0[i] + a1 * th.z[i] + b1 * h * th.fz[i];
                    }
                    for i in 0..NE {
                        self.y[T0 + NT + i] = a0 * e0[i] + b0 * h * q0[i] + a1 * th.e[i] + b1 * h * th.q[i];
                    }
                    let yhc = if replay { yh0 } else { self.hyd.at(tc) };
                    self.y[..NH].copy_from_slice(&yhc);
                }
                let snap = snapshot(&self.model, tc, &self.y, &self.y0);
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
                        origin = tc;
                        ticks = 0;
                        need_restart = true;
                    }
                    if let Some(v) = change {
                        self.model.lng_open.set(v);
                        need_restart = true;
                    }
                    if ctl.stop {
                        break 'outer;
                    }
                    continue 'outer;
                }
            }
            self.write_state(&yh, &th);
            if !replay {
                self.hyd.trim(self.t);
            }
        }
        self.stats.hydraulics = self.hyd.ros.stats;
        Ok(())
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
