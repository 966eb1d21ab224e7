//! `diagnosis.json`: the machine-readable verdict's types (exactly its
//! documented keys) and their construction from a [`Diagnosis`].

use crate::diagnosis::analysis::Diagnosis;

/// One ranking row of `diagnosis.json`.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize, PartialEq)]
pub struct RankingJson {
    /// Candidate name.
    pub cause: String,
    /// BIC on the training fit points (lower is better).
    pub bic: f64,
    /// Pooled held-out RMSE over the temperature channels, K.
    pub heldout_rmse_k: f64,
}

/// One structure's probability in `diagnosis.json`.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize, PartialEq)]
pub struct ProbabilityJson {
    /// `none`, `unexplained` or a candidate name.
    pub cause: String,
    /// Posterior probability.
    pub probability: f64,
    /// ln Bayes factor against `none`.
    pub log_bayes_factor: f64,
    /// Prior probability (0: the log cannot identify the candidate).
    pub prior: f64,
    /// Held-out predictive log density on the channels the structure
    /// touches against `none`'s, nats (part of the Bayes factor); `None`
    /// in records written before it was kept.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub heldout_touched: Option<f64>,
    /// The same on the channels it does not touch.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub heldout_untouched: Option<f64>,
    /// Whether the log can tell the structure apart (its identifiability
    /// rule); `None` in records written before it was kept.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub identifiable: Option<bool>,
}

impl ProbabilityJson {
    /// The posterior of `d` as `diagnosis.json` writes it.
    pub fn of(d: &Diagnosis) -> Vec<ProbabilityJson> {
        d.posterior.causes.iter().map(ProbabilityJson::from).collect()
    }
}

impl From<&crate::diagnosis::evidence::CauseProbability> for ProbabilityJson {
    fn from(c: &crate::diagnosis::evidence::CauseProbability) -> Self {
        ProbabilityJson {
            cause: c.cause.clone(),
            probability: c.probability,
            log_bayes_factor: c.log_bayes_factor,
            prior: c.prior,
            heldout_touched: Some(c.heldout_touched),
            heldout_untouched: Some(c.heldout_untouched),
            identifiable: Some(c.identifiable),
        }
    }
}

/// `diagnosis.json`: exactly its documented top-level keys. RMSEs are pooled
/// over every measured temperature channel, K; "before" is the calibrated
/// baseline, "after" the model with `cause` switched on (equal to "before"
/// when `cause` is `none`).
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize, PartialEq)]
pub struct DiagnosisJson {
    /// Named cause: a candidate name, `none` (the calibrated model explains
    /// the data to the noise level) or `unexplained` (it does not, and no
    /// candidate does).
    pub cause: String,
    /// Fitted parameters of the cause, name → value (units in report.md).
    pub parameters: std::collections::BTreeMap<String, f64>,
    /// Training-window RMSE before, K.
    pub rmse_before_k: f64,
    /// Training-window RMSE after, K.
    pub rmse_after_k: f64,
    /// Held-out RMSE before, K.
    pub heldout_rmse_before_k: f64,
    /// Held-out RMSE after, K.
    pub heldout_rmse_after_k: f64,
    /// Every candidate and `none`, best BIC first.
    pub ranking: Vec<RankingJson>,
    /// Posterior probability of `none`, `unexplained` and every candidate,
    /// most probable first (a cause is named at ≥ 0.9; otherwise the first
    /// two are the answer's top two).
    pub probabilities: Vec<ProbabilityJson>,
    /// Per channel: the calibrated baseline's misfit on the training
    /// window, the structure floor estimated from the other channels, their
    /// ratio, the noise (K) and the Ljung–Box p before and after whitening.
    pub channels: Vec<crate::diagnosis::evidence::ChannelEvidence>,
    /// Present only when `cause` is `unexplained`: what misfits and what
    /// to check.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub unexplained: Option<UnexplainedJson>,
    /// Present only when several logs of one machine were diagnosed
    /// together: each log's errors before and after, on its own training
    /// and held-out windows (the top-level RMSEs pool every log).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub logs: Vec<LogJson>,
}

/// One log of a joint diagnosis in `diagnosis.json`.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize, PartialEq)]
pub struct LogJson {
    /// The log's file as given.
    pub file: String,
    /// Rows in the log.
    pub rows: usize,
    /// Start of its held-out window, s (the log's own time).
    pub heldout_from_s: f64,
    /// Training-window RMSE before / after, pooled over its temperature channels, K.
    pub rmse_before_k: f64,
    /// Training-window RMSE after, K.
    pub rmse_after_k: f64,
    /// Held-out RMSE before, K.
    pub heldout_rmse_before_k: f64,
    /// Held-out RMSE after, K.
    pub heldout_rmse_after_k: f64,
    /// Per channel: held-out RMSE before and after, bias before, K.
    pub channels: Vec<LogChannelJson>,
}

/// One channel of one log of a joint diagnosis.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize, PartialEq)]
pub struct LogChannelJson {
    /// Channel name.
    pub channel: String,
    /// Held-out RMSE of the calibrated baseline, K.
    pub heldout_rmse_before_k: f64,
    /// Held-out RMSE with the cause, K.
    pub heldout_rmse_after_k: f64,
    /// Mean residual of the calibrated baseline (simulated − measured), K.
    pub bias_before_k: f64,
}

impl LogJson {
    /// The numbers of one log's part ([`crate::diagnosis::multi::log_parts`]) of a joint diagnosis.
    pub fn of(file: &str, rows: usize, d: &Diagnosis) -> Self {
        LogJson {
            file: file.into(),
            rows,
            heldout_from_s: d.split_time_s,
            rmse_before_k: d.before.train_rmse_k,
            rmse_after_k: d.after.train_rmse_k,
            heldout_rmse_before_k: d.before.heldout_rmse_k,
            heldout_rmse_after_k: d.after.heldout_rmse_k,
            channels: d
                .before
                .channels
                .iter()
                .map(|b| LogChannelJson {
                    channel: b.channel.clone(),
                    heldout_rmse_before_k: b.heldout_rmse_k,
                    heldout_rmse_after_k: d.after.channel(&b.channel).map_or(f64::NAN, |a| a.heldout_rmse_k),
                    bias_before_k: b.bias_k,
                })
                .collect(),
        }
    }
}

/// One misfitting channel in `diagnosis.json`.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize, PartialEq)]
pub struct MisfitJson {
    /// Channel name.
    pub channel: String,
    /// Held-out RMSE of the calibrated baseline, K.
    pub heldout_rmse_k: f64,
    /// Mean residual (simulated − measured), K.
    pub bias_k: f64,
    /// Noise σ estimated from the samples, K.
    pub noise_k: f64,
    /// Regressors the residual correlates with most: name → peak ρ.
    pub correlates_with: std::collections::BTreeMap<String, f64>,
}

/// The evidence behind an `unexplained` answer.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize, PartialEq)]
pub struct UnexplainedJson {
    /// Channels whose held-out error is far above their noise.
    pub misfit_channels: Vec<MisfitJson>,
    /// Calibrated parameters on a bound: name → value.
    pub parameters_at_bounds: std::collections::BTreeMap<String, f64>,
    /// What to check or measure.
    pub check: Vec<String>,
}

impl DiagnosisJson {
    /// The JSON verdict of `d`.
    pub fn from_diagnosis(d: &Diagnosis) -> Self {
        DiagnosisJson {
            cause: d.answer().into(),
            parameters: d.params.iter().map(|(n, v, _)| (n.clone(), *v)).collect(),
            rmse_before_k: d.before.train_rmse_k,
            rmse_after_k: d.after.train_rmse_k,
            heldout_rmse_before_k: d.before.heldout_rmse_k,
            heldout_rmse_after_k: d.after.heldout_rmse_k,
            ranking: d
                .ranking
                .iter()
                .map(|r| RankingJson { cause: r.cause.clone(), bic: r.bic, heldout_rmse_k: r.heldout_rmse_k })
                .collect(),
            probabilities: ProbabilityJson::of(d),
            channels: d.posterior.channels.clone(),
            unexplained: d.unexplained.then(|| UnexplainedJson {
                misfit_channels: d
                    .adequacy
                    .channels
                    .iter()
                    .filter(|c| c.misfit)
                    .map(|c| MisfitJson {
                        channel: c.channel.clone(),
                        heldout_rmse_k: c.heldout_rmse_k,
                        bias_k: c.bias_k,
                        noise_k: c.noise_k,
                        correlates_with: c.regressors.iter().map(|(n, r, _)| (n.clone(), *r)).collect(),
                    })
                    .collect(),
                parameters_at_bounds: d.adequacy.at_bounds.iter().map(|b| (b.name.clone(), b.value)).collect(),
                check: d.adequacy.advice.clone(),
            }),
            logs: Vec::new(),
        }
    }
}
