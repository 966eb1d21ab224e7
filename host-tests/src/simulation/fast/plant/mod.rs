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
//!
//! The plant is split by topic: this file holds the plant, its
//! construction and its accessors; `steps` the step-size control's
//! constants and bookkeeping; `run` the stepping itself
//! ([`FastPlant::run`]: its start and loop), with `state` the run's
//! mutable state, `attempt` one thermal step and `callbacks` the
//! callbacks inside a step.

mod attempt;
mod callbacks;
mod run;
mod state;
mod steps;

use super::hydraulic::{HydTrack, NH};
use super::options::{FastOptions, FastStats};
use super::rosenbrock::{Rosenbrock, Tableau};
use super::thermal::{Thermal, NT};
use crate::hydraulics::ix;
use crate::model::{Model, N_STATE, T0};
use crate::plant::{model_for, snapshot_stored, typical, RuleEval, SimError, Snapshot, Stats};
use crate::rig::Rig;
use crate::scenario::Scenario;
use steps::Ladder;

const _: () = assert!(T0 == NH, "the temperatures follow the hydraulic states");

/// Hydraulic steps a Jacobian is kept (ROS34PW2 is a W-method: order 3
/// with any Jacobian; a rejected step takes a fresh one). Measured on Case 2
/// alone at rtol 1e-4: 85.8 k evaluations for 600 s against 207 k for RODAS4
/// with a Jacobian every step.
const HYD_JACOBIAN_STEPS: u32 = 20;

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
}
