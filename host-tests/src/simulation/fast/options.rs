//! The multirate plant's settings ([`FastOptions`]) and work counters
//! ([`FastStats`]).

use super::rosenbrock::RosStats;
use crate::scenario::{Scenario, ValveRule};

/// Local error bound of one thermal step under a thermostat valve rule, K
/// ([`FastOptions::for_scenario`]; Fig. 15's switches each within 1 s of
/// the BDF's at this bound).
pub const THERMOSTAT_TOL_K: f64 = 1e-5;

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
    /// Grid of temperatures on which the heat balances interpolate the
    /// outer surfaces' heat flows (linear; cubic on one five times coarser
    /// away from the air), K; the oil's viscosity on one ten times coarser
    /// (cubic), the ducts' laminar Nusselt number on its own grid. 0: exact
    /// (see [`crate::simulation::grids`]).
    pub grid_k: f64,
    /// Factor on `tol_k` for the thermal steps that start within `start_s`
    /// of the plant's first run's start (the machine starting from rest:
    /// on Case 1 the ball-valve oil warms at 8 K/s as the pressure builds
    /// and is flushed on a 0.3 s time scale; what a step leaves on the
    /// fast nodes it holds there decays). Not after schedule breakpoints:
    /// there, on servo missions with a breakpoint every few seconds, the
    /// same factor took the slow tier's deviations up by up to 1.9×
    /// (`docs/reference-speed.md` section 8).
    pub start_tol_factor: f64,
    /// Time after the first run's start with the looser tolerance, s.
    pub start_s: f64,
    /// Factor on the hydraulic tolerances (`hyd_rtol` and the absolute
    /// ones) for the first `start_hyd_s` of the plant's first run: the
    /// pressure building from rest (Case 1: to 60 bar in ~0.1 s, hydraulic
    /// steps of 1–3 ms at the 10 Pa absolute tolerance that servo cycles
    /// need on the low side's check valve, with a rejection and a fresh
    /// Jacobian every few steps there).
    pub start_hyd_factor: f64,
    /// Time after the first run's start with the looser hydraulic
    /// tolerances, s (0: none).
    pub start_hyd_s: f64,
}

impl Default for FastOptions {
    /// The settings measured within 0.01 K of the BDF at rtol 1e-9 on the
    /// paper's cases and the random missions (`docs/reference-speed.md`
    /// section 4): 2e-4 K per thermal step (1e-4 K until 2026-11-28: Case 1
    /// 95 → 83 thermal steps, 1.71 → 1.58 M instructions; its deviation
    /// 4.9e-4 → 6.1e-4 K at 10 s outputs, 4.5e-4 → 1.1e-3 K at 1 s, Case 2
    /// 6.4e-3 → 7.8e-3 K; Case 1's steps are on a plateau, 83–86 from
    /// 1.6e-4 to 2.5e-4 K), hydraulics at 1e-4 of their typical
    /// magnitudes (3e-4 gave 1.25e-2 K on a servo mission's loop oil);
    /// 1.5× the step tolerance for the first second from rest (Case 1 at
    /// 1e-4 K: 105 → 96 thermal steps, 4.8e-4 K unchanged at 10 s outputs)
    /// and hydraulics at 1e-3 (10 Pa → 100 Pa) for the first 0.1 s
    /// (137 → 120 hydraulic steps; deviations unchanged to 2 digits).
    fn default() -> Self {
        Self { tol_k: 2e-4, hyd_rtol: 1e-4, alias_ratio: 8.0, h_max_s: 60.0, h_start_s: 1e-3, grid_k: 0.1, start_tol_factor: 1.5, start_s: 1.0, start_hyd_factor: 10.0, start_hyd_s: 0.1 }
    }
}

impl FastOptions {
    /// The defaults, with the thermal tolerance [`THERMOSTAT_TOL_K`] when
    /// the scenario's LNG valve follows a thermostat (Fig. 15's loop-oil
    /// rule, the drain rule): a switch decided one control interval apart
    /// from the BDF's moves the fast nodes by kelvins, so the temperature at
    /// the threshold must be far closer than its rise per interval (measured
    /// on Fig. 15: at 1e-4 K per step one opening of 60 came 0.1 s early,
    /// 8 K on the port oil; at 1e-5 every switch matches).
    pub fn for_scenario(scenario: &Scenario) -> Self {
        let thermostat = scenario.mission().is_some_and(|m| matches!(m.valve, ValveRule::LoopOil | ValveRule::Drain));
        let d = Self::default();
        if thermostat {
            Self { tol_k: THERMOSTAT_TOL_K, ..d }
        } else {
            d
        }
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
    /// Drift refreshes of the thermal Jacobian's drifting columns
    /// (`DRIFT_MOVE_K`; one model evaluation a column and one more).
    pub drifts: u64,
    /// Full model evaluations (steps and Jacobian columns).
    pub rhs_evals: u64,
    /// The hydraulic integrator's counters.
    pub hydraulics: RosStats,
}
