//! What one emulator case's diagnosis gives ([`EmuResult`]: the answer,
//! the posterior, the imprint ratio against the effect-free twin), the
//! record that `eha-sim emulator-sweep` writes and its tables render.

use super::evidence::{ChannelEvidence, StructureTerms};
use super::report::ProbabilityJson;
use crate::emulator::EmuCase;

/// Outcome of one emulated log.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub struct EmuResult {
    /// The case.
    pub case: EmuCase,
    /// Hidden magnitude.
    pub magnitude: f64,
    /// The answer (candidate name, `none` or `unexplained`).
    pub answer: String,
    /// Channel the hidden effect changes most and its imprint, K.
    pub affected: Option<(String, f64)>,
    /// Held-out RMSE on the affected channel, calibrated baseline → answer, K.
    pub affected_heldout_k: Option<(f64, f64)>,
    /// Pooled held-out RMSE: nominal baseline, calibrated baseline, answer, K.
    pub pooled_heldout_k: [f64; 3],
    /// Calibrated baseline per channel: (channel, held-out RMSE K, RMSE /
    /// noise σ, RMSE / RMS rise above ambient, misfit).
    pub channels: Vec<(String, f64, f64, f64, bool)>,
    /// Calibrated nuisance parameters on a bound.
    pub at_bounds: Vec<String>,
    /// Best candidate by BIC other than `none`: name, ΔBIC, best-channel
    /// held-out gain, whether it qualified.
    pub best_candidate: Option<(String, f64, f64, bool)>,
    /// The hidden effect's own candidate as fitted in the diagnosis (in the
    /// tier whose answer stands); `None` for the `none` cases. It separates
    /// the misses: the right structure fitted and failing a rule, or the
    /// right structure fitted and explaining no more than the baseline.
    pub hidden_fit: Option<HiddenFit>,
    /// The hidden effect at its true magnitude injected into the calibrated
    /// reference model instead ([`super::detect::detect_one`]): the best
    /// gain a diagnosis could show if the machine had the model's structure.
    /// Below 50 %, this log cannot show the effect whatever the rules; at or
    /// above, and the oracle under it, the emulator's structure decides.
    pub hidden_detect: Option<super::detect::Detectability>,
    /// The imprint ratio against the log's effect-free twin (only when the
    /// sweep ran twins; `None` for the `none` cases).
    #[serde(default)]
    pub twin: Option<TwinCheck>,
    /// The posterior over every structure, most probable first.
    #[serde(default)]
    pub probabilities: Vec<ProbabilityJson>,
    /// Every candidate's fit: (name, ΔBIC, best-channel held-out gain,
    /// whether it qualified), best BIC first.
    #[serde(default)]
    pub ranking: Vec<(String, f64, f64, bool)>,
    /// The evidence's per-channel numbers (misfit, floor, ratio).
    #[serde(default)]
    pub evidence_channels: Vec<ChannelEvidence>,
    /// The calibration set whose answer stands (global or physical tier).
    #[serde(default)]
    pub tier: String,
    /// The posterior under another decision rule ([`MeasuredRule`]),
    /// computed from the stored terms by `emulator-sweep --measure`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub measured: Option<MeasuredRule>,
    /// The evidence's terms per structure (for measuring other decision
    /// rules offline); left out of the committed JSON.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub evidence_terms: Vec<StructureTerms>,
    /// Every candidate's expected imprint ratio at the magnitudes the
    /// `--detectability` projection tried, around the tier whose answer
    /// stands (`emulator-sweep --detectability`; empty otherwise): what the
    /// gate-as-observation re-statement needs ([`super::gate_obs`]).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub reach: Vec<super::gate_obs::Reach>,
    /// Wall time of the diagnosis, s.
    pub seconds: f64,
}

/// The hidden effect's log against its effect-free twin
/// ([`crate::emulator::generate_twin`]: same machine, mission and noise,
/// nothing hidden), both diagnosed blind.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub struct TwinCheck {
    /// Held-out RMSE of the calibrated baseline on the affected channel,
    /// the log, K.
    pub misfit_k: f64,
    /// The same on the twin: the structure floor of this log, K.
    pub twin_misfit_k: f64,
    /// The twin's answer (anything but `none`/`unexplained` is a false
    /// discovery).
    pub twin_answer: String,
    /// The twin's posterior, most probable first.
    #[serde(default)]
    pub twin_probabilities: Vec<ProbabilityJson>,
    /// The twin's per-channel evidence numbers.
    #[serde(default)]
    pub twin_channels: Vec<ChannelEvidence>,
    /// The twin's posterior under the measured rule (see
    /// [`EmuResult::measured`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub twin_measured: Option<MeasuredRule>,
    /// The twin's evidence terms per structure.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub twin_terms: Vec<StructureTerms>,
    /// The twin's calibrated baseline, held out: pooled, then per channel
    /// (the log's structure floor on every channel), K. Empty in sweeps
    /// written before it was kept.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub twin_heldout_k: Vec<(String, f64)>,
    /// The twin's [`EmuResult::reach`].
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub twin_reach: Vec<super::gate_obs::Reach>,
}

impl TwinCheck {
    /// Imprint ratio r = misfit / twin misfit: the effect stands clear of
    /// the floor at r ≥ 2, where a diagnosis must name it.
    pub fn ratio(&self) -> f64 {
        self.misfit_k / self.twin_misfit_k.max(1e-9)
    }
}

/// A log's posterior and answer under a decision rule other than the one
/// the sweep ran with, decided again from its stored evidence terms.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub struct MeasuredRule {
    /// The rule's name (`tempered`, `per-channel`, ...).
    pub rule: String,
    /// The answer under it (see [`super::emu_sweep::redecide`]).
    pub answer: String,
    /// The posterior under it, most probable first.
    pub probabilities: Vec<ProbabilityJson>,
}

/// How the hidden effect's own candidate fared when fitted jointly with the
/// calibration set (the "oracle" structure, known only to the sweep).
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub struct HiddenFit {
    /// BIC decrease against the calibrated baseline.
    pub delta_bic: f64,
    /// Held-out RMSE of the affected channel, calibrated baseline → with
    /// the candidate fitted, K.
    pub affected_heldout_k: Option<(f64, f64)>,
    /// Pooled held-out RMSE, calibrated baseline → with the candidate, K.
    pub pooled_heldout_k: (f64, f64),
    /// Whether it qualified.
    pub qualifies: bool,
    /// Why it cannot be named in this log (empty when it can).
    pub note: String,
}

impl HiddenFit {
    /// Relative held-out RMSE reduction on the affected channel.
    pub fn affected_gain(&self) -> Option<f64> {
        self.affected_heldout_k.map(|(b, a)| 1.0 - a / b)
    }
}

impl EmuResult {
    /// Relative held-out RMSE reduction on the affected channel.
    pub fn affected_gain(&self) -> Option<f64> {
        self.affected_heldout_k.map(|(b, a)| 1.0 - a / b)
    }

    /// Whether the answer is the hidden effect.
    pub fn hit(&self) -> bool {
        self.answer == self.case.hidden.name()
    }
}

