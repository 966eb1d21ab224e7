//! One measured log prepared for calibration: the replay scenario of its
//! inputs, the channels it can be scored on (the five temperatures plus
//! `t_drain_c` when logged) and the thinned fit points.

use crate::simulation::replay::{replay_inputs, REPLAY_RTOL};
use crate::measured::{Channel, MeasuredRun};
use crate::rig::Rig;
use crate::scenario::Scenario;
use crate::sim::{simulate_rtol, SimOptions};
use std::collections::BTreeMap;
pub use super::thinning::Thinning;
use super::thinning::thin_rows;

/// Simulated channels at a log's sample times, °C.
pub type Series = BTreeMap<Channel, Vec<f64>>;

/// A log ready to be replayed by the reference model.
#[derive(Debug, Clone)]
pub struct CalLog {
    /// Name (file name) used in reports.
    pub name: String,
    /// The measured data.
    pub run: MeasuredRun,
    /// Channels with at least one sample: the temperatures and `t_drain_c`.
    pub channels: Vec<Channel>,
    /// Fit points: (channel, row), thinned per channel by `thinning`.
    pub points: Vec<(Channel, usize)>,
    /// The rule `points` were thinned by ([`Thinning::Uniform`] unless
    /// [`CalLog::with_thinning`] set it); [`CalLog::fitted_from`] keeps it.
    pub thinning: Thinning,
    scenario: Scenario,
    opts: SimOptions,
    /// Relative tolerance of the replay solver ([`REPLAY_RTOL`] unless
    /// [`CalLog::with_rtol`] set it).
    pub rtol: f64,
    /// Time from which the fits take their points, s (−∞: the whole log;
    /// [`CalLog::fitted_from`]). The replay always runs from the log's start.
    pub fit_from_s: f64,
}

/// The channels a log can be scored on: [`Channel::TEMPERATURES`] and
/// `t_drain_c`, those with at least one sample.
pub fn scored_channels(run: &MeasuredRun) -> Vec<Channel> {
    Channel::TEMPERATURES
        .into_iter()
        .chain([Channel::TDrainC])
        .filter(|&c| run.get(c).is_some_and(|v| v.iter().any(Option::is_some)))
        .collect()
}

/// Whether `run` logs input `ch` above zero at some sample (a ram-air
/// column of zeros carries no forced convection to calibrate).
pub fn input_above_zero(run: &MeasuredRun, ch: Channel) -> bool {
    run.get(ch).is_some_and(|v| v.iter().flatten().any(|&x| x > 0.0))
}

impl CalLog {
    /// Prepares `run` (named `name`) with at most `points_per_channel` fit
    /// points per channel. Errors when an input column is empty.
    pub fn new(name: &str, run: MeasuredRun, points_per_channel: usize) -> Result<Self, String> {
        Self::new_thinned(name, run, points_per_channel, Thinning::Uniform)
    }

    /// As [`CalLog::new`], the fit points thinned by `rule`.
    pub fn new_thinned(name: &str, run: MeasuredRun, points_per_channel: usize, rule: Thinning) -> Result<Self, String> {
        let inputs = replay_inputs(&run, name).map_err(|e| format!("{name}: {e}"))?;
        let span = run.time_s[run.len() - 1] - run.time_s[0];
        // Output every ~1/400 of the run (as the diagnosis replay does).
        let dt = (span / 400.0).clamp(0.5, 5.0);
        let opts = SimOptions { output_interval_s: dt, control_interval_s: dt };
        let channels = scored_channels(&run);
        let points = thinned_points(&run, &channels, points_per_channel, f64::NEG_INFINITY, rule);
        Ok(CalLog { name: name.into(), run, channels, points, thinning: rule, scenario: Scenario::Replay(inputs), opts, rtol: REPLAY_RTOL, fit_from_s: f64::NEG_INFINITY })
    }

    /// The same log with its fit points (at most `points_per_channel` per
    /// channel, from its `fit_from_s` on) thinned by `rule`.
    pub fn with_thinning(&self, rule: Thinning, points_per_channel: usize) -> Self {
        let points = thinned_points(&self.run, &self.channels, points_per_channel, self.fit_from_s, rule);
        CalLog { points, thinning: rule, ..self.clone() }
    }

    /// The same log with its fit points (at most `points_per_channel` per
    /// channel, thinned by its own rule) taken from `t0_s` on only;
    /// the replay still runs from the log's start, so the state at `t0_s`
    /// is the model's own. The margin's head fold fits these
    /// (`calibration::commission`): its fits see no measured temperature
    /// before `t0_s`.
    pub fn fitted_from(&self, t0_s: f64, points_per_channel: usize) -> Self {
        let points = thinned_points(&self.run, &self.channels, points_per_channel, t0_s, self.thinning);
        CalLog { points, fit_from_s: t0_s, ..self.clone() }
    }

    /// The same log replayed at solver tolerance `rtol`.
    pub fn with_rtol(&self, rtol: f64) -> Self {
        CalLog { rtol, ..self.clone() }
    }

    /// The reference model on `rig` driven by this log's inputs: every
    /// scored channel at every sample time.
    pub fn simulate(&self, rig: &Rig) -> Result<Series, String> {
        let out = simulate_rtol(rig, &self.scenario, &self.opts, self.rtol).map_err(|e| e.to_string())?;
        let mut s = Series::new();
        for &ch in &self.channels {
            let v = out.sample(ch.name(), &self.run.time_s);
            let mut v = v.ok_or_else(|| format!("model has no channel {}", ch.name()))?;
            if surface_probe_fraction(rig, ch) != 0.0 {
                let amb = self.ambient_at_rows().ok_or_else(|| format!("{}: no ambient to read the surface probes against", self.name))?;
                read_surface_probe(rig, ch, &mut v, &amb);
            }
            s.insert(ch, v);
        }
        Ok(s)
    }

    /// The replayed ambient (°C) at every row of the log.
    fn ambient_at_rows(&self) -> Option<Vec<f64>> {
        ambient_at(self.replay_inputs()?, &self.run.time_s)
    }

    /// Residuals (simulated − measured, K) at the fit points.
    pub fn residuals(&self, s: &Series) -> Vec<f64> {
        self.points
            .iter()
            .map(|&(ch, i)| s[&ch][i] - self.run.get(ch).and_then(|v| v[i]).unwrap_or(f64::NAN))
            .collect()
    }

    /// The log's inputs as the reference replays them (every row, empty
    /// cells interpolated; the circuit).
    pub fn replay_inputs(&self) -> Option<&crate::scenario::ReplayInputs> {
        match &self.scenario {
            Scenario::Replay(r) => Some(r),
            _ => None,
        }
    }

    /// Whether the log carries channel `ch`.
    pub fn has(&self, ch: Channel) -> bool {
        self.channels.contains(&ch)
    }
}

/// Fit points of `run`'s `channels`: per channel its rows with a sample at
/// or after `t0_s` (s), thinned by `rule` to at most `points_per_channel`.
fn thinned_points(run: &MeasuredRun, channels: &[Channel], points_per_channel: usize, t0_s: f64, rule: Thinning) -> Vec<(Channel, usize)> {
    let mut points = Vec::new();
    for &ch in channels {
        let rows: Vec<usize> = (0..run.len()).filter(|&i| run.time_s[i] >= t0_s && run.get(ch).is_some_and(|v| v[i].is_some())).collect();
        points.extend(thin_rows(run, ch, &rows, points_per_channel, rule).into_iter().map(|i| (ch, i)));
    }
    points
}

/// `logs` with their fit points re-thinned by `rule` (at most
/// `points_per_channel` per channel); a log already thinned by `rule` is
/// kept as it is. The commissioning's entry ([`super::commission::commission_with`]).
pub fn rethinned(logs: &[CalLog], rule: Thinning, points_per_channel: usize) -> Vec<CalLog> {
    logs.iter().map(|l| if l.thinning == rule { l.clone() } else { l.with_thinning(rule, points_per_channel) }).collect()
}

/// The replayed ambient (°C) of `r` at `times` (s), linearly interpolated;
/// `None` when the replay has no ambient series.
pub fn ambient_at(r: &crate::scenario::ReplayInputs, times: &[f64]) -> Option<Vec<f64>> {
    let (ts, amb) = (&r.time_s, &r.ambient_c);
    if ts.is_empty() || ts.len() != amb.len() {
        return None;
    }
    times.iter().map(|&t| crate::simulation::sim::interpolate(ts, amb, ts.partition_point(|&x| x <= t), t)).collect()
}

/// Surface channel `ch`'s simulated metal temperatures `v` (°C, one per
/// row) as `rig`'s probe reads them: moved the fraction
/// [`surface_probe_fraction`] towards the ambient `amb` (°C, same rows).
/// The one place the probe model acts (the calibration's replay and the
/// diagnosis's).
pub fn read_surface_probe(rig: &Rig, ch: Channel, v: &mut [f64], amb: &[f64]) {
    let f = surface_probe_fraction(rig, ch);
    if f != 0.0 {
        for (x, a) in v.iter_mut().zip(amb) {
            *x -= f * (*x - a);
        }
    }
}

/// The fraction towards ambient at which `rig` reads surface channel `ch`
/// ([`crate::rig::SurfaceProbes`]); 0 for every other channel.
pub fn surface_probe_fraction(rig: &Rig, ch: Channel) -> f64 {
    let p = &rig.probes;
    match ch {
        Channel::TMotorC => p.motor,
        Channel::TPumpC => p.pump,
        Channel::TBlockC => p.main_block,
        Channel::TBallvalveC => p.ball_block,
        _ => 0.0,
    }
}

/// Error of one channel over a whole log, K.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct ChannelError {
    /// Channel name.
    pub channel: String,
    /// RMSE over every sample, K.
    pub rmse_k: f64,
    /// Largest |simulated − measured|, K.
    pub max_abs_k: f64,
    /// Largest under-prediction (measured − simulated, ≥ 0), K.
    pub max_under_k: f64,
}

/// Per-channel errors of series `s` against log `log` (every sample).
pub fn channel_errors(log: &CalLog, s: &Series) -> Vec<ChannelError> {
    log.channels
        .iter()
        .map(|&ch| {
            let m = log.run.get(ch).unwrap_or(&[]);
            let e: Vec<f64> = m.iter().zip(&s[&ch]).filter_map(|(m, p)| m.map(|m| p - m)).collect();
            let n = e.len().max(1) as f64;
            ChannelError {
                channel: ch.name().into(),
                rmse_k: (e.iter().map(|x| x * x).sum::<f64>() / n).sqrt(),
                max_abs_k: e.iter().fold(0.0f64, |a, x| a.max(x.abs())),
                max_under_k: e.iter().fold(0.0f64, |a, x| a.max(-x)),
            }
        })
        .collect()
}
