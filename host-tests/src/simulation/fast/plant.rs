//! The multirate plant: the same model as [`crate::plant::Plant`], the
//! same run/callback contract, a different integrator.
//!
//! * Hydraulic states ([`super::hydraulic`]): ROS34PW2 at their own pace,
//!   the node temperatures held at the start of each thermal step (they
//!   enter only through the leakage conductance and the oil viscosity).
//! * Node temperatures ([`super::thermal`]): exponential Adams steps of
//!   order 2 on the model's own linearised heat balances, one model
//!   evaluation per step, error below `tol_k` on every node.
//! * Thermal steps are the callback interval times powers of two (a longer
//!   one costs four matrix products, a shorter one is cached) and stay
//!   below `alias_ratio` hydraulic steps, so that a forcing periodic within
//!   a step is never sampled at its period. A step ends early at a
//!   schedule breakpoint (the forcing steps: the hydraulics restart, f is
//!   taken anew) and at a branch switch of the heat balances (a pressure,
//!   flow or speed reversal, located on the hydraulic track: f is taken
//!   anew on its far side).
//! * The Jacobian is taken at the start, at a valve change, and once the
//!   step has grown 64-fold since the last one (after a breakpoint's
//!   transient: a Jacobian of the operating point the drive has left can
//!   be stiffer than the network, and damp modes the network keeps,
//!   unseen by the error estimate).
//! * Between steps, callbacks see cubic Hermite interpolants (the
//!   temperatures' and the hydraulic track's); a valve change there
//!   continues from the callback time.

use super::hydraulic::{hermite, left_of, HydTrack, NH};
use super::phi::{Phi, VECTOR_NORM_MAX};
use super::options::{FastOptions, FastStats};
use super::rosenbrock::{RosError, Rosenbrock, Tableau};
use super::thermal::{Thermal, NE, NT};
use super::dense::norm1;
use crate::hydraulics::ix;
use crate::model::{Drive, Model, N_STATE, T0};
use crate::plant::{breakpoints, model_for, snapshot_stored, typical, Control, RuleEval, SimError, Snapshot, Stats};
use crate::rig::Rig;
use crate::scenario::Scenario;

const _: () = assert!(T0 == NH, "the temperatures follow the hydraulic states");

/// Finest step level: the callback interval / 2^24.
const LEVEL_MIN: i32 = -24;
/// Coarsest level: the callback interval · 2^8.
const LEVEL_MAX: i32 = 8;
const LEVELS: usize = (LEVEL_MAX - LEVEL_MIN + 1) as usize;
/// Hydraulic steps a Jacobian is kept (ROS34PW2 is a W-method: order 3
/// with any Jacobian; a rejected step takes a fresh one). Measured on Case 2
/// alone at rtol 1e-4: 85.8 k evaluations for 600 s against 207 k for RODAS4
/// with a Jacobian every step.
const HYD_JACOBIAN_STEPS: u32 = 20;
/// Growth of the thermal step (levels: factors of two) after which the
/// thermal Jacobian is taken anew.
const REFRESH_LEVELS: i32 = 6;
/// Accepted steps without growth after which that Jacobian is taken anyway.
const STALL_STEPS: u32 = 16;
/// Error (in tolerances) below which a thermal step doubles: (0.9/2)³,
/// the doubled step's error at 0.9 of the bound were it ∝ h³. A doubling
/// that is then rejected halves this bound for the run (down to
/// `GROW_ERR_MIN`), a doubling accepted raises it by 10 % (up to
/// `GROW_ERR`): on Case 2 the step is a servo cycle's, too long at some
/// phases of it, and the doubling failed there every cycle (1 536 rejected
/// steps of 8 681, each also re-integrating its hydraulics; with this and
/// `SWITCH_DROP`, 513 of 7 765, 332 → 265 M instructions, 6.75e-3 → 6.41e-3 K).
const GROW_ERR: f64 = 0.091125;
/// Lowest doubling bound, in tolerances.
const GROW_ERR_MIN: f64 = 0.01;
/// Levels the step drops on the far side of a branch switch of the heat
/// balances: the first step there at the former level failed nine times in
/// ten on Case 2 (errors of 3–18 tolerances: the forcing's slope changes
/// there). Two levels cost accuracy (Case 2's winding 6.4e-3 → 9.8e-3 K).
const SWITCH_DROP: i32 = 1;
/// Largest move of a node temperature, K, since the last thermal Jacobian
/// or drift refresh after which the Jacobian's drifting columns are taken
/// anew (`Thermal::drift`: the columns of the nodes that held the step,
/// one model evaluation each and one at z; the φ-functions stay A's). The
/// case oil's diagonal grows 4.3× from the start's A to 600 s on Case 1
/// (viscosity: its gap film and the leakage), treated explicitly that held
/// the steps by an error growing from step to step. Measured on Case 1
/// (`docs/reference-speed.md` section 8): 119 → 105 thermal steps, 2.62 →
/// 2.51 M instructions at 20 K; 30 K the same, a fixed 100 s or 250 s
/// interval 2.52 / 2.47 M (two refreshes, at 65 s and 250 s, here).
const DRIFT_MOVE_K: f64 = 20.0;

/// The step levels' φ-functions, by level (boxed: a level is 5.4 kB and a
/// run uses a dozen of the 33).
type Ladder = Vec<Option<Box<Phi<NT>>>>;

/// The multirate plant (see the module documentation).
#[derive(Debug)]
pub struct FastPlant {
    model: Model,
    y: [f64; N_STATE],
    /// Each node's stored energy in the initial state, J (the snapshots'
    /// stored energy is relative to it: [`Model::stored_energy_from`]).
    e0: [f64; crate::network::N_NODES],
    t: f64,
    opts: FastOptions,
    hyd: HydTrack,
    /// The thermal scheme and its step levels, kept between runs, and the
    /// valve state its Jacobian belongs to. Boxed: inline, its ~4.7 kB
    /// made the plant a copy glibc does byte by byte (`rep movsb`), twice
    /// in `sim::simulate_fast_with` (~10 k instructions a run).
    thermal: Option<Box<(Thermal, Ladder)>>,
    jacobian_valve: bool,
    stats: FastStats,
    step_limit: Option<u64>,
}

impl FastPlant {
    /// A plant for `scenario` on `rig`, at rest at ambient.
    pub fn new(rig: &Rig, scenario: &Scenario) -> Result<Self, SimError> {
        Self::with_options(rig, scenario, FastOptions::default())
    }

    /// [`FastPlant::new`] with explicit accuracy settings.
    pub fn with_options(rig: &Rig, scenario: &Scenario, opts: FastOptions) -> Result<Self, SimError> {
        let (mut model, t) = model_for(rig, scenario)?;
        model.set_grids(Some(opts.grid_k));
        let mut y = [0.0; N_STATE];
        y.copy_from_slice(&model.initial_state());
        // Errors relative to the states' typical magnitudes (1 MPa, 1 cm,
        // 1 cm/s, 10 rad/s): near a flow reversal the BDF's absolute
        // tolerances (1 µm/s, 1e-5 rad/s) set the step without changing a loss.
        let sc = typical();
        let scale: [f64; NH] = std::array::from_fn(|i| sc[i]);
        let mut atol = scale.map(|s| s * opts.hyd_rtol);
        // Two absolute tolerances nearer the BDF's (measured on 30-minute
        // servo missions with rests, against the BDF at rtol 1e-9): the
        // shaft speed to 1e-5 rad/s (a machine at rest holds ω near 0,
        // where the friction torque's sign sets the motor current: 1.1e-2 K
        // on a port's oil at 1e-3 rad/s, 1.7e-3 K at 1e-5), the line
        // pressures to 10 Pa (the low side sits on its check valve: 100 Pa
        // added 1e-3 K to the inlet port's oil every cycle, 1.55e-2 K in
        // all; 10 Pa, 1.5e-3 K). Together 24 % more hydraulic steps on Case 2.
        atol[ix::OMEGA] = atol[ix::OMEGA].min(1e-5);
        for i in [ix::PA, ix::PB] {
            atol[i] = atol[i].min(10.0);
        }
        let mut yh = [0.0; NH];
        yh.copy_from_slice(&y[..NH]);
        let ros = Rosenbrock::with_method(Tableau::ros34pw2(), HYD_JACOBIAN_STEPS, opts.hyd_rtol, atol, scale, opts.h_start_s);
        let hyd = HydTrack::new(ros, t, yh);
        let e0 = model.node_energies(&y);
        Ok(Self { model, y, e0, t, opts, hyd, thermal: None, jacobian_valve: false, stats: FastStats::default(), step_limit: None })
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
        Stats {
            rhs_evals: self.stats.rhs_evals,
            steps: self.stats.steps,
            jacobian_evals: self.stats.jacobians * NT as u64,
            newton_iterations: 0,
            factorizations: self.stats.jacobians,
        }
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
        snapshot_stored(&self.model, self.t, &self.y, self.model.stored_energy_from(&self.e0, &self.y))
    }

    /// The scenario's own valve rule.
    pub fn valve_rule(&self) -> RuleEval {
        RuleEval::for_model(&self.model)
    }

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

/// Work pending before the next thermal step.
#[derive(Debug, Clone, Copy, Default)]
struct Todo {
    /// Take the thermal Jacobian anew.
    jacobian: bool,
    /// Take f anew and forget the step history (the forcing stepped).
    fresh: bool,
    /// Restart the hydraulic integration (a schedule breakpoint).
    hydraulics: bool,
    /// Take f anew on the far side of a branch switch at this time.
    switch: Option<f64>,
    /// Take the drifting columns of the Jacobian anew (`Thermal::drift`).
    drift: bool,
}

fn hyd_error(e: RosError) -> SimError {
    let (t, what) = match e {
        RosError::StepUnderflow(t) => (t, "hydraulic step underflow"),
        RosError::Singular(t) => (t, "singular hydraulic iteration matrix"),
    };
    SimError::Solver { t, message: what.into() }
}

