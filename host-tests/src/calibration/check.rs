//! The reduced model's checks shared by both commissioning paths: the
//! firmware model (f64) replayed on a log against the commissioned reference
//! and the measured drain, and the operating region of its largest errors
//! (the margin's folds are scored with them in [`super::margin`]).

use super::fit::CalError;
use super::log::CalLog;
use crate::measured::Channel;
use crate::plant::{Control, Plant, Sensors};
use crate::rig::Rig;
use crate::scenario::{Circuit, Scenario};
use crate::simulation::replay::{circuit_of, replay_inputs};
use eha_guard::model::{Model, ModelInputN, ReducedParams};
use eha_guard::params::S_PER_TICK;

/// Largest drain margin the parameter block accepts, K (the firmware's
/// bounds table, `drain_margin_k`).
pub const MARGIN_MAX_K: f64 = 10.0;

/// Bound of the reduced model against the commissioned reference on every
/// log's inputs, drain max |e|, K.
pub const REDUCED_BOUND_K: f64 = 0.2;

/// The reduced model (firmware parameters `p`, f64) on one log's inputs.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct ReducedCheck {
    /// Log name.
    pub log: String,
    /// Drain margin added to the estimate in this check, K (0: none).
    pub margin_k: f64,
    /// Max |reduced − reference| drain, K (reference = the rig it was reduced from).
    pub vs_reference_max_k: f64,
    /// Largest under-prediction of the reference drain (reference − reduced), K.
    pub vs_reference_under_k: f64,
    /// Where the departure from the reference is largest (the ticks within
    /// half of `vs_reference_max_k`).
    pub vs_reference_region: Region,
    /// Max |reduced − measured| drain, K, when the log has `t_drain_c`.
    pub vs_measured_max_k: Option<f64>,
    /// Largest under-prediction of the measured drain (measured − reduced), K.
    pub vs_measured_under_k: Option<f64>,
    /// Largest over-prediction of the measured drain (reduced − measured), K.
    pub vs_measured_over_k: Option<f64>,
    /// RMSE against the measured drain, K.
    pub vs_measured_rmse_k: Option<f64>,
    /// Where the under-prediction of the measured drain is largest (the
    /// ticks within half of `vs_measured_under_k`), when there is one.
    pub vs_measured_region: Option<Region>,
    /// Seconds the guard's valve would be open on this estimate (open
    /// loop: opens above 40 °C, closes after 2 s below 38 °C; the decision
    /// is not fed back into the replay).
    pub valve_open_s: f64,
    /// LNG the guard would book for those seconds (the model's total loss
    /// while open, eq. 23, Table 6 latent and sensible heat), kg.
    pub lng_kg: f64,
    /// The drain error against the measured drain per operating cell
    /// (split by the training envelope in the report; not in the JSON).
    #[serde(skip)]
    pub cells: super::envelope::CellErrors,
}

pub use super::region::Region;
use super::region::TickRow;

#[cfg(test)]
impl ReducedCheck {
    /// A check for unit tests: log `log`; against the measured drain (max
    /// |e|, under-, over-prediction), K, RMSE half the max (`None`: no
    /// drain logged); no margin, nothing else scored, one placeholder region.
    pub(crate) fn for_test(log: &str, measured: Option<(f64, f64, f64)>) -> Self {
        let region = Region { t_s: (0.0, 1.0), speed_rpm: (0.0, 1.0), dp_bar: (0.0, 1.0), drain_c: (20.0, 40.0), servo: false };
        ReducedCheck {
            log: log.into(),
            margin_k: 0.0,
            vs_reference_max_k: 0.0,
            vs_reference_under_k: 0.0,
            vs_reference_region: region.clone(),
            vs_measured_max_k: measured.map(|m| m.0),
            vs_measured_under_k: measured.map(|m| m.1),
            vs_measured_over_k: measured.map(|m| m.2),
            vs_measured_rmse_k: measured.map(|m| m.0 / 2.0),
            vs_measured_region: Some(region),
            valve_open_s: 0.0,
            lng_kg: 0.0,
            cells: Default::default(),
        }
    }
}

/// Ranges of the rows whose `e` is at least half of the largest (all rows
/// when the largest is not positive).
fn region_of(rows: &[TickRow], e: &[f64], servo: bool) -> Region {
    let top = e.iter().copied().fold(0.0, f64::max);
    let mut r = Region::empty(servo);
    for (row, &ek) in rows.iter().zip(e) {
        if top <= 0.0 || ek >= 0.5 * top {
            r.widen(row);
        }
    }
    r
}

/// [`check_reduced_with`] without a margin.
pub fn check_reduced(rig: &Rig, p: &ReducedParams, log: &CalLog) -> Result<ReducedCheck, String> {
    check_reduced_with(rig, p, log, 0.0)
}

/// Runs the reference on `rig` replaying `log`'s inputs at the firmware's
/// 10 ms tick and feeds the same signals to the reduced model `p` exactly as
/// the guard does (tick accumulation, 100 ms model step; the logged LNG
/// valve, if any, is the exchanger command). The drain estimate is the
/// model's plus `margin_k` (the drain margin, K). Errors compare it with
/// the reference's case-oil node and with the measured `t_drain_c`
/// (interpolated to the tick; only where samples exist).
pub fn check_reduced_with(rig: &Rig, p: &ReducedParams, log: &CalLog, margin_k: f64) -> Result<ReducedCheck, String> {
    check_reduced_core(rig, p, log, margin_k, f64::NEG_INFINITY)
}

/// [`check_reduced_with`], the measured drain scored from `score_from_s` on.
pub(crate) fn check_reduced_core(rig: &Rig, p: &ReducedParams, log: &CalLog, margin_k: f64, score_from_s: f64) -> Result<ReducedCheck, String> {
    let mut out = check_reduced_many(rig, log, &[(p, &[margin_k])], score_from_s)?;
    Ok(out.remove(0).remove(0))
}

/// The running scores of one model and margin in [`check_reduced_many`].
#[derive(Debug, Clone, Copy, Default)]
struct Scores {
    /// Largest |estimate − reference drain| and under-prediction of it, K.
    max_ref: f64,
    under_ref: f64,
    /// Against the measured drain: largest |e|, under- and over-prediction,
    /// K, and Σe², K².
    max_meas: f64,
    under: f64,
    over: f64,
    ss: f64,
    /// Ticks with the valve open, and the cooling demand meanwhile, J.
    open_ticks: f64,
    open_j: f64,
}

/// One firmware model in [`check_reduced_many`] and its running scores per margin.
struct Probe {
    model: Model<f64>,
    margins: Vec<f64>,
    valves: Vec<eha_guard::protection::Valve>,
    /// Per margin, the running scores.
    acc: Vec<Scores>,
    /// Per margin, per tick: |est − reference| and the under-prediction of
    /// the measured drain (−∞ where not scored), for the regions.
    e_ref: Vec<Vec<f64>>,
    e_under: Vec<Vec<f64>>,
}

/// [`check_reduced_with`] for several firmware models on one replay of the
/// reference: `models` pairs each parameter set with the margins to score
/// it with (the margin is added to the estimate only, the model's state is
/// the same for every margin, so one model run serves them all). One
/// result per model, one [`ReducedCheck`] per margin, each equal to its own
/// [`check_reduced_with`] run. The reference replay is the expensive part:
/// commissioning scores up to three models with two margins on each
/// held-out log.
pub fn check_reduced_many(rig: &Rig, log: &CalLog, models: &[(&ReducedParams, &[f64])], score_from_s: f64) -> Result<Vec<Vec<ReducedCheck>>, String> {
    check_reduced_window(rig, log, models, (score_from_s, f64::INFINITY))
}

/// [`check_reduced_many`] with the measured drain scored only in the
/// window `[from, until)`, s (the margin's folds: after the split, or
/// before it).
pub fn check_reduced_window(rig: &Rig, log: &CalLog, models: &[(&ReducedParams, &[f64])], (score_from_s, score_until_s): (f64, f64)) -> Result<Vec<Vec<ReducedCheck>>, String> {
    let inputs = replay_inputs(&log.run, &log.name).map_err(|e| e.to_string())?;
    let t_end = log.run.time_s[log.run.len() - 1];
    let mut plant = Plant::new(rig, &Scenario::Replay(inputs)).map_err(|e| e.to_string())?;
    let mut probes = models
        .iter()
        .map(|(p, margins)| {
            let model = Model::<f64>::new(p).map_err(|e| format!("reduced model rejects the parameters: {e:?}"))?;
            let n = margins.len();
            Ok(Probe {
                model,
                margins: margins.to_vec(),
                valves: vec![eha_guard::protection::Valve::new(); n],
                acc: vec![Scores::default(); n],
                e_ref: vec![Vec::new(); n],
                e_under: vec![Vec::new(); n],
            })
        })
        .collect::<Result<Vec<_>, String>>()?;
    let (mut k, mut prev_x) = (0usize, 0.0);
    let mut rows: Vec<TickRow> = Vec::new();
    let has_drain = log.has(Channel::TDrainC);
    let servo = matches!(circuit_of(&log.run), Ok(Circuit::Servo));
    let cfg = eha_guard::protection::ValveConfig::DEFAULT;
    let (open_c, close_c) = (f64::from(cfg.open_c), f64::from(cfg.close_c));
    let mut open = false;
    plant
        .run(S_PER_TICK, t_end, |snap| {
            let s = Sensors::from(snap);
            if k == 0 {
                probes.iter_mut().for_each(|pr| pr.model.set_uniform(s.ambient_c));
                prev_x = s.position_mm;
            }
            rows.push((s.t, s.speed_rpm.abs(), (s.p_a_bar - s.p_b_bar).abs(), s.t_drain_c));
            let meas = if has_drain && k > 0 && s.t >= score_from_s && s.t < score_until_s { log.run.value_at(Channel::TDrainC, s.t) } else { None };
            let u = ModelInputN::from_wire_f64(s.current_a, s.p_a_bar, s.p_b_bar, s.speed_rpm, s.position_mm - prev_x, s.ambient_c);
            for pr in &mut probes {
                let drain = pr.model.drain_c();
                let total_kw = pr.model.last_total_kw();
                for (j, &margin_k) in pr.margins.iter().enumerate() {
                    let est = drain + margin_k;
                    let a = &mut pr.acc[j];
                    a.max_ref = a.max_ref.max((est - s.t_drain_c).abs());
                    a.under_ref = a.under_ref.max(s.t_drain_c - est);
                    pr.e_ref[j].push((est - s.t_drain_c).abs());
                    let mut eu = f64::NEG_INFINITY;
                    if let Some(m) = meas {
                        let e = est - m;
                        a.max_meas = a.max_meas.max(e.abs());
                        a.under = a.under.max(-e);
                        a.over = a.over.max(e);
                        a.ss += e * e;
                        eu = -e;
                    }
                    pr.e_under[j].push(eu);
                    // The guard's valve on this estimate (open loop), decided
                    // every tick with the dwell in ticks.
                    let v = &mut pr.valves[j];
                    v.update_with(est, false, open_c, close_c, cfg.dwell_ticks);
                    if v.is_open() {
                        a.open_ticks += 1.0;
                        a.open_j += total_kw * 1e3 * S_PER_TICK;
                    }
                }
                if pr.model.tick_n(&u) {
                    pr.model.update(if open { 10 } else { 0 });
                }
            }
            prev_x = s.position_mm;
            open = log.run.value_at(Channel::LngValve, s.t).is_some_and(|v| v >= 0.5);
            k += 1;
            Ok(Control { lng_valve: Some(open), stop: false })
        })
        .map_err(|e| e.to_string())?;
    let j_per_kg = f64::from(eha_guard::protection::LngConfig::DEFAULT.j_per_kg());
    let meas = |x: f64| has_drain.then_some(x);
    Ok(probes
        .into_iter()
        .map(|pr| {
            (0..pr.margins.len())
                .map(|j| {
                    let a = pr.acc[j];
                    let n = pr.e_under[j].iter().filter(|x| x.is_finite()).count();
                    ReducedCheck {
                        log: log.name.clone(),
                        margin_k: pr.margins[j],
                        vs_reference_max_k: a.max_ref,
                        vs_reference_under_k: a.under_ref,
                        vs_reference_region: region_of(&rows, &pr.e_ref[j], servo),
                        vs_measured_max_k: meas(a.max_meas),
                        vs_measured_under_k: meas(a.under),
                        vs_measured_over_k: meas(a.over),
                        vs_measured_rmse_k: meas((a.ss / n.max(1) as f64).sqrt()),
                        vs_measured_region: (has_drain && a.under > 0.0).then(|| region_of(&rows, &pr.e_under[j], servo)),
                        valve_open_s: a.open_ticks * S_PER_TICK,
                        lng_kg: a.open_j / j_per_kg,
                        cells: super::envelope::CellErrors::from_ticks(&rows, &pr.e_under[j], S_PER_TICK, servo),
                    }
                })
                .collect()
        })
        .collect())
}

/// Errors of commissioning.
#[derive(Debug, thiserror::Error)]
pub enum CommissionError {
    /// The calibration failed.
    #[error(transparent)]
    Cal(#[from] CalError),
    /// The commissioned rig cannot be reduced to firmware parameters (why).
    #[error("the commissioned rig cannot be flashed: {0}")]
    Reduce(String),
    /// A model run failed.
    #[error("{0}")]
    Run(String),
}
