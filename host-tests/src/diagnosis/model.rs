//! The model interface the diagnosis fits: candidate extensions, fitted
//! parameters and the [`Simulator`] trait that the reference model (or any
//! other model) implements.

use crate::measured::Channel;
use std::collections::BTreeMap;

pub use crate::physics::candidates::Candidate;

/// A fitted parameter: strictly positive, fitted in log space between
/// `lo` and `hi`, starting from `start`.
#[derive(Debug, Clone, PartialEq)]
pub struct ParamSpec {
    /// Name as reported (e.g. `h_out_scale`, `sensor_tau_s`).
    pub name: String,
    /// Unit of the value (e.g. `1`, `s`, `W/K`).
    pub unit: String,
    /// Initial guess.
    pub start: f64,
    /// Lower bound (> 0).
    pub lo: f64,
    /// Upper bound.
    pub hi: f64,
    /// Prior towards `start`: standard deviation of ln(value/start). With a
    /// prior the fit adds the row σ_d·ln(value/start)/σ to its residuals
    /// (σ_d = [`super::fit::PRIOR_DATA_SIGMA_K`]); `None` = no prior.
    pub prior_sigma_ln: Option<f64>,
}

impl ParamSpec {
    /// A parameter spec with `start` inside `[lo, hi]`, all > 0.
    pub fn new(name: &str, unit: &str, start: f64, lo: f64, hi: f64) -> Self {
        ParamSpec { name: name.into(), unit: unit.into(), start, lo, hi, prior_sigma_ln: None }
    }

    /// The same spec with a prior of width `sigma_ln` (in ln) towards `start`.
    pub fn with_prior(mut self, sigma_ln: f64) -> Self {
        self.prior_sigma_ln = Some(sigma_ln);
        self
    }
}

/// Simulated series at the measured sample times: the temperature channels
/// (°C) plus named internal series used as regressors (`t_winding_c`, …).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SimSeries {
    /// Simulated measured-format channels, one value per measured time.
    pub channels: BTreeMap<Channel, Vec<f64>>,
    /// Internal series (same length), by the reference model's names.
    pub internals: BTreeMap<String, Vec<f64>>,
}

/// A model the diagnosis can drive with the measured inputs. `nuisance` and
/// `ext` are the values of [`Simulator::nuisance`] and
/// [`Simulator::extension_params`] in order.
pub trait Simulator: Sync {
    /// The nuisance set calibrated on every fit (documented by the model).
    fn nuisance(&self) -> Vec<ParamSpec>;
    /// The parameters of candidate `c` (empty for [`Candidate::None`]).
    fn extension_params(&self, c: Candidate) -> Vec<ParamSpec>;
    /// Runs the model with candidate `c` switched on, returning the series
    /// at the measured times, or a message when the model fails.
    fn simulate(&self, nuisance: &[f64], c: Candidate, ext: &[f64]) -> Result<SimSeries, String>;
    /// The same model with the per-node physical calibration set
    /// (`eha_sim::calibration`) as its nuisance set, to which the diagnosis
    /// escalates when the calibrated baseline misfits; `None` when the model
    /// has none or already uses it.
    fn physical_set(&self) -> Option<Box<dyn Simulator + '_>> {
        None
    }
    /// Name of the nuisance set in reports (`global` or `physical`).
    fn nuisance_set_name(&self) -> &'static str {
        "global"
    }
    /// Told by the diagnosis before each of its phases starts (for a
    /// progress display that counts the model runs ahead); the models
    /// themselves ignore it.
    fn phase(&self, _p: Phase) {}
}

/// A phase of the diagnosis of one tier (nuisance set), announced to the
/// model before it starts ([`Simulator::phase`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Phase {
    /// The nominal run and the baseline calibration: one fit of `params`
    /// nuisance parameters.
    Baseline {
        /// Nuisance parameters.
        params: usize,
    },
    /// `fits` candidate fits (`analysis::STARTS_PER_CANDIDATE` starts per candidate, in parallel), each
    /// of the nuisance set plus the candidate's parameters. `may_escalate`:
    /// the global baseline fails the strict rule, so the physical tier
    /// follows unless a cause is named.
    Candidates {
        /// Fits in the phase.
        fits: usize,
        /// Whether the physical tier is likely to follow.
        may_escalate: bool,
    },
    /// `fits` baseline fits from the best candidates' nuisance values.
    Restarts {
        /// Fits in the phase.
        fits: usize,
    },
    /// `fits` candidate fits again from a better baseline.
    Refits {
        /// Fits in the phase.
        fits: usize,
    },
    /// The Jacobians at the best points of the kept fits, for the evidence
    /// (`diagnosis::fit::settle_jacobian`): `runs` model runs.
    Jacobians {
        /// Model runs in the phase.
        runs: usize,
    },
    /// This tier's answer stands (no escalation follows).
    Done,
}
