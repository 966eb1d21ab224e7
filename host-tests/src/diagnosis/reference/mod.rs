//! The reference simulation (`eha_sim::sim`) as a [`Simulator`]: replay of
//! the measured inputs, two nuisance sets (the rig's four global
//! multipliers first; the physical calibration set of
//! [`crate::calibration`] when the diagnosis escalates), and one parameter
//! per candidate extension.

use super::model::{Candidate, ParamSpec, SimSeries, Simulator};
use crate::calibration;
use super::analysis::Structure;
use crate::measured::{Channel, MeasuredRun};
use crate::rig::Rig;
pub use crate::simulation::replay::{circuit_of, replay_inputs, ReplayError, REPLAY_RTOL, SERVO_MIN_TRAVEL_MM, THROTTLE_MAX_TRAVEL_MM};
use crate::scenario::Scenario;
use crate::sim::{simulate_budget, SimOptions};

mod sets;

pub use sets::{nuisance_set, nuisance_set_of, structural_set, HELD_OIL};

/// Errors building the replay model from a measured run.
#[derive(Debug, thiserror::Error)]
pub enum ReferenceError {
    /// The log's inputs cannot drive the model (empty column, circuit).
    #[error(transparent)]
    Replay(#[from] ReplayError),
    /// The rig does not validate or the baseline does not run.
    #[error("reference model: {0}")]
    Model(String),
}

/// The reference model driven by one measured run.
///
/// Global nuisance set (the first tier; log-space, within a factor 2 of
/// the rig file):
/// `outer_scale` (free convection + radiation conductances), `inner_scale`
/// (oil-to-metal conductances), `metal_capacity_scale`,
/// `oil_capacity_scale` (see `eha_sim::rig::Nuisance`). A richer set (per
/// component capacities, 6 parameters) was tried and rejected: it absorbs
/// the effects themselves (forced convection, viscosity and churning were
/// then no longer identified). The physical set ([`nuisance_set`], bounds
/// and priors of [`crate::calibration::PARAMS`]) is the second tier, used
/// when the global baseline misfits ([`Simulator::physical_set`]); it
/// absorbs churning, forced convection and motor–pump conduction on the
/// synthetic cases, hence not from the start. With
/// [`ReferenceModel::with_structure`] the physical tier takes the pump's
/// loss level from the motor current and frees the commissioning's
/// structural freedoms instead ([`structural_set`]). The housing probes
/// read towards the air by the rig's `probes` (the calibration's probe
/// model, `calibration::log::read_surface_probe`), so a commissioned rig
/// file is replayed as it was commissioned.
///
/// Candidate parameters (ranges are the physically plausible ones):
/// `alpha_per_k` 1e-4…1e-2 1/K (copper 3.9e-3; a fit at the upper bound
/// means the extension also absorbs a winding-conductance error — a bound
/// of 6e-3 was tried: the winding test with per-node errors then fell from
/// 71 % to 41 % held-out gain on t_motor_c), `sensor_tau_s` 1…1000 s, `coulomb_n` 1…3000 N,
/// `churning_w_per_rad2_5` 1e-7…1e-2 W/(rad/s)^2.5, `conduction_w_per_k`
/// 0.01…50 W/K, `air_speed_mps` 0.2…40 m/s.
pub struct ReferenceModel {
    rig: Rig,
    /// The physical tier's rig: `rig`, with the pump's `eta_m` from the
    /// motor current under [`Self::with_structure`].
    phys_rig: Rig,
    /// Whether the commissioning's structure was asked for and applied
    /// ([`Self::with_structure`]).
    structure: StructureState,
    /// Indices into [`crate::calibration::PARAMS`] of the physical set for
    /// this run ([`nuisance_set`]).
    free: Vec<usize>,
    /// Prior σ on ln θ replacing the calibration set's, by index into
    /// [`crate::calibration::PARAMS`] ([`Self::with_prior_sigma`], an
    /// experiment knob; empty in the product path).
    priors: Vec<(usize, f64)>,
    /// Whether the nuisance set is the physical set (else the four global
    /// multipliers).
    physical: bool,
    scenario: Scenario,
    times: Vec<f64>,
    opts: SimOptions,
}

/// The commissioning's structure on a [`ReferenceModel`]'s physical tier.
#[derive(Debug, Clone, PartialEq)]
enum StructureState {
    /// Not asked (`--structure off`): the rig file's physical tier.
    NotAsked,
    /// Applied: `eta_m` from the current over `rows` loaded rows.
    Applied { eta_m: f64, rows: usize },
    /// Asked and not applied, and why (no loaded current, an implausible
    /// `eta_m`, an unreadable log): the rig file's physical tier.
    Refused(String),
}

/// The electrical balance behind the structure option over `logs` (one
/// machine's): `eta_m` and its loaded rows from their current together
/// ([`calibration::commission::eta_m_balance`], the one implementation),
/// or why not (an unreadable log, no load, an implausible `eta_m`).
pub fn structure_balance(rig: &Rig, logs: &[&MeasuredRun]) -> Result<(f64, usize), String> {
    logs.iter()
        .map(|r| calibration::CalLog::new("log", (*r).clone(), 1))
        .collect::<Result<Vec<_>, _>>()
        .map_err(|e| format!("the log cannot be read for the electrical balance: {e}"))
        .and_then(|cal| calibration::commission::eta_m_balance(rig, &cal).checked())
}

impl ReferenceModel {
    /// Builds the replay model of `run` on `rig`, checking that the baseline
    /// runs.
    pub fn new(rig: Rig, run: &MeasuredRun) -> Result<Self, ReferenceError> {
        rig.validate().map_err(|e| ReferenceError::Model(e.to_string()))?;
        let inputs = replay_inputs(run, run.meta("rig").unwrap_or("measured"))?;
        let span = run.time_s[run.len() - 1] - run.time_s[0];
        // Output every ~1/400 of the run (≥ 0.5 s): the thermal time
        // constants are minutes, linear interpolation between outputs is
        // far below the 0.1 K sensor noise.
        let dt = (span / 400.0).clamp(0.5, 5.0);
        let opts = SimOptions { output_interval_s: dt, control_interval_s: dt };
        let free = nuisance_set(run);
        let m = ReferenceModel { phys_rig: rig.clone(), rig, structure: StructureState::NotAsked, free, priors: Vec::new(), physical: false, scenario: Scenario::Replay(inputs), times: run.time_s.clone(), opts };
        let n: Vec<f64> = m.nuisance().iter().map(|p| p.start).collect();
        m.simulate(&n, Candidate::None, &[]).map_err(ReferenceError::Model)?;
        Ok(m)
    }

    /// The same model calibrating the physical-set parameters `free`
    /// (indices into [`crate::calibration::PARAMS`]) instead of this log's
    /// own [`nuisance_set`]: one machine's logs share one set
    /// ([`nuisance_set_of`]).
    pub fn with_nuisance_set(mut self, free: Vec<usize>) -> Self {
        self.free = free;
        self
    }

    /// The physical tier with the commissioning's structure when `variant`
    /// (a [`Structure`], or a bool: `true` is [`Structure::Full`]) is not
    /// [`Structure::Off`] and
    /// `run` (this model's log) carries motor current under load: the
    /// pump's loss coefficient `eta_m` from the electrical balance
    /// ([`calibration::commission::eta_m_from_current`], the one
    /// implementation), `pump_friction` held there, and the structural
    /// freedoms of `variant` freed ([`structural_set`]).
    /// Without current under load, with an implausible `eta_m` from it
    /// ([`Self::structure_refusal`] says which), or with [`Structure::Off`],
    /// the model is unchanged. The global tier is never changed.
    pub fn with_structure(self, run: &MeasuredRun, variant: impl Into<Structure>) -> Self {
        let variant = variant.into();
        if variant == Structure::Off {
            return self;
        }
        let taken = structure_balance(&self.rig, &[run]);
        self.with_structure_taken(run, variant, &taken)
    }

    /// [`Self::with_structure`] with the electrical balance already taken
    /// (`taken`, [`structure_balance`]: `eta_m` and its loaded rows, or why
    /// not) and the structural freedoms by the channels of `rows`: one of
    /// several logs of a machine diagnosed together, every log's model
    /// with the same balance and set, so that they share one parameter
    /// vector ([`super::multi::joint_reference`]).
    pub fn with_structure_taken(mut self, rows: &MeasuredRun, variant: Structure, taken: &Result<(f64, usize), String>) -> Self {
        if variant == Structure::Off {
            return self;
        }
        match taken {
            &Ok((eta_m, n)) => {
                self.phys_rig.pump.eta_m = eta_m;
                self.structure = StructureState::Applied { eta_m, rows: n };
                self.free = structural_set(rows, &self.free, variant);
            }
            Err(why) => self.structure = StructureState::Refused(why.clone()),
        }
        self
    }

    /// **Experiment knob** (not used by the product path): the same model
    /// with the physical tier's prior on calibration parameter `name`
    /// replaced by a log-normal of σ `sigma_ln` on ln θ around the rig file
    /// (`None` drops the replacement, back to the calibration set's).
    /// `examples/imprint_misses.rs` (`sigma=NAME:S`) measured with it that
    /// priors of a physical width do not keep `cap_loop_oil` and
    /// `probe_oil` off their bounds on the emulator's 1704 under the
    /// structure option (docs/diagnosis-limits.md, "Why holds and not narrower
    /// priors").
    /// An unknown name changes nothing.
    pub fn with_prior_sigma(mut self, name: &str, sigma_ln: impl Into<Option<f64>>) -> Self {
        let Some(k) = calibration::set::index(name) else { return self };
        self.priors.retain(|(j, _)| *j != k);
        if let Some(s) = sigma_ln.into() {
            self.priors.push((k, s));
        }
        self
    }

    /// `eta_m` from the current and its loaded rows when the physical tier
    /// takes it so ([`Self::with_structure`]); `None` otherwise.
    pub fn eta_m_from_current(&self) -> Option<(f64, usize)> {
        match self.structure {
            StructureState::Applied { eta_m, rows } => Some((eta_m, rows)),
            _ => None,
        }
    }

    /// Why [`Self::with_structure`] left the model unchanged although a
    /// structure was asked for (no loaded current, or an `eta_m` from it
    /// outside [`calibration::commission::ETA_M_PLAUSIBLE`]); `None` when it
    /// was applied or not asked.
    pub fn structure_refusal(&self) -> Option<&str> {
        match &self.structure {
            StructureState::Refused(why) => Some(why),
            _ => None,
        }
    }

    /// Solver-step budget of one replay of this log ([`REPLAY_STEPS_PER_S`]).
    fn step_budget(&self) -> u64 {
        let span = match (self.times.first(), self.times.last()) {
            (Some(a), Some(b)) => (b - a).max(0.0),
            _ => 0.0,
        };
        (REPLAY_STEPS_PER_S * span).max(10_000.0) as u64
    }

    /// The physical tier's rig with its calibration parameters at `nuis`
    /// (in the order of [`Self::physical_free`], the rest at the rig file),
    /// `eta_m` from the current where [`Self::with_structure`] took it;
    /// whichever tier this model calibrates.
    pub fn physical_rig(&self, nuis: &[f64]) -> Rig {
        let mut theta = calibration::set::nominal();
        for (&k, &v) in self.free.iter().zip(nuis) {
            theta[k] = v;
        }
        calibration::apply(&self.phys_rig, &theta)
    }

    /// Indices into [`crate::calibration::PARAMS`] of the physical tier's
    /// calibration parameters on this log (what [`Self::with_nuisance_set`]
    /// takes).
    pub fn physical_free(&self) -> &[usize] {
        &self.free
    }

    /// The rig with nuisance values `nuis` and candidate `c` at `ext`.
    pub fn rig_for(&self, nuis: &[f64], c: Candidate, ext: &[f64]) -> Rig {
        let mut r = if self.physical {
            self.physical_rig(nuis)
        } else {
            let mut r = self.rig.clone();
            r.nuisance.outer_scale = nuis[0];
            r.nuisance.inner_scale = nuis[1];
            r.nuisance.metal_capacity_scale = nuis[2];
            r.nuisance.oil_capacity_scale = nuis[3];
            r
        };
        let e = &mut r.ext;
        let x = ext.first().copied();
        match c {
            Candidate::WindingResistanceTemperature => e.winding_resistance_temperature = x,
            Candidate::SensorLag => e.sensor_lag = x,
            Candidate::CoulombFriction => e.coulomb_friction = x,
            Candidate::ChurningLoss => e.churning_loss = x,
            Candidate::MotorPumpConduction => e.motor_pump_conduction = x,
            Candidate::ForcedConvection => e.forced_convection = x,
            Candidate::None => {}
        }
        r
    }
}

/// Solver-step budget of one replay, per second of log: a replay normally
/// takes a few hundred steps for 20 minutes; a candidate run that makes the
/// stiff solver crawl (measured: 58–96 thousand steps in 1.2–1.8 s for a
/// fit of a load-cycle log with the viscosity on its Walther line, stalling
/// its case for 266 s) fails instead, and the fit treats it as a failed
/// evaluation.
pub const REPLAY_STEPS_PER_S: f64 = 20.0;

/// Internal series kept for the regressors.
const INTERNALS: [&str; 5] = ["t_winding_c", "t_drain_c", "t_motor_c", "t_pump_c", "t_loop_oil_c"];

impl Simulator for ReferenceModel {
    fn nuisance(&self) -> Vec<ParamSpec> {
        if !self.physical {
            let n = &self.rig.nuisance;
            let p = |name: &str, v: f64| ParamSpec::new(name, "1", v, v / 2.0, v * 2.0);
            return vec![
                p("outer_scale", n.outer_scale),
                p("inner_scale", n.inner_scale),
                p("metal_capacity_scale", n.metal_capacity_scale),
                p("oil_capacity_scale", n.oil_capacity_scale),
            ];
        }
        self.free
            .iter()
            .map(|&k| {
                let d = &calibration::PARAMS[k];
                let sigma = self.priors.iter().find(|(j, _)| *j == k).map_or(d.prior_sigma_ln, |p| p.1);
                ParamSpec::new(d.name, "1", 1.0, d.lo, d.hi).with_prior(sigma)
            })
            .collect()
    }

    fn physical_set(&self) -> Option<Box<dyn Simulator + '_>> {
        (!self.physical).then(|| {
            Box::new(ReferenceModel {
                rig: self.rig.clone(),
                phys_rig: self.phys_rig.clone(),
                structure: self.structure.clone(),
                free: self.free.clone(),
                priors: self.priors.clone(),
                physical: true,
                scenario: self.scenario.clone(),
                times: self.times.clone(),
                opts: self.opts,
            }) as Box<dyn Simulator>
        })
    }

    fn nuisance_set_name(&self) -> &'static str {
        if self.physical { "physical" } else { "global" }
    }

    fn extension_params(&self, c: Candidate) -> Vec<ParamSpec> {
        match c {
            Candidate::WindingResistanceTemperature => vec![ParamSpec::new("alpha_per_k", "1/K", 2e-3, 1e-4, 1e-2)],
            Candidate::SensorLag => vec![ParamSpec::new("sensor_tau_s", "s", 30.0, 1.0, 1000.0)],
            Candidate::CoulombFriction => vec![ParamSpec::new("coulomb_n", "N", 150.0, 1.0, 3000.0)],
            Candidate::ChurningLoss => vec![ParamSpec::new("churning_w_per_rad2_5", "W/(rad/s)^2.5", 2e-4, 1e-7, 1e-2)],
            Candidate::MotorPumpConduction => vec![ParamSpec::new("conduction_w_per_k", "W/K", 1.0, 0.01, 50.0)],
            Candidate::ForcedConvection => vec![ParamSpec::new("air_speed_mps", "m/s", 3.0, 0.2, 40.0)],
            Candidate::None => vec![],
        }
    }

    fn simulate(&self, nuisance: &[f64], c: Candidate, ext: &[f64]) -> Result<SimSeries, String> {
        let rig = self.rig_for(nuisance, c, ext);
        let out = simulate_budget(&rig, &self.scenario, &self.opts, REPLAY_RTOL, Some(self.step_budget())).map_err(|e| e.to_string())?;
        let mut s = SimSeries::default();
        let sample = |name: &str| out.sample(name, &self.times);
        // The housing probes read towards the air where the rig says so
        // (the structural freedoms, [`Self::with_structure`]).
        let amb = match &self.scenario {
            Scenario::Replay(r) if rig.probes != crate::rig::SurfaceProbes::default() => calibration::log::ambient_at(r, &self.times),
            _ => None,
        };
        for ch in Channel::TEMPERATURES {
            if let Some(mut v) = sample(ch.name()) {
                if let Some(a) = &amb {
                    calibration::log::read_surface_probe(&rig, ch, &mut v, a);
                }
                s.channels.insert(ch, v);
            }
        }
        for name in INTERNALS {
            if let Some(v) = sample(name) {
                s.internals.insert(name.into(), v);
            }
        }
        Ok(s)
    }
}
