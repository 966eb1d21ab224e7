//! Is the calibrated baseline good enough to judge? (the
//! `unexplained` answer.) Compares every channel's held-out error of the
//! calibrated baseline with the channel's own noise floor, estimated from
//! the measured samples, and with how far the channel moved; lists the
//! regressors its residual correlates with, the calibrated parameters that
//! sit on a bound, and what to check or measure.

use super::stats::{Metrics, XCorr};
use super::model::ParamSpec;
use crate::measured::{Channel, MeasuredRun};

/// A channel's noise σ as the diagnosis takes it, K: [`noise_sigma`], 0.1 K
/// when too few samples give it, at least 0.02 K.
pub fn channel_noise_k(v: &[Option<f64>]) -> f64 {
    noise_sigma(v).unwrap_or(0.1).max(0.02)
}

/// RMS rise of channel `ch` of `run` above the ambient over its samples at
/// or after `split`, K (NaN without an ambient column).
pub fn rms_rise_k(run: &MeasuredRun, ch: Channel, split: f64) -> f64 {
    let Some(v) = run.get(ch) else { return 0.0 };
    let rises: Vec<f64> = v
        .iter()
        .zip(&run.time_s)
        .filter(|(x, t)| x.is_some() && **t >= split)
        .map(|(x, t)| x.unwrap_or(0.0) - run.value_at(Channel::AmbientC, *t).unwrap_or(f64::NAN))
        .collect();
    (rises.iter().map(|r| r * r).sum::<f64>() / rises.len().max(1) as f64).sqrt()
}

/// Noise standard deviation of a sampled channel, K, from its second
/// differences (a slowly varying signal plus white noise of σ gives
/// differences y\[i+1\] − 2y\[i\] + y\[i−1\] of variance 6σ²), robustly:
/// 1.4826·MAD/√6 over consecutive present samples. `None` with < 10 triples.
pub fn noise_sigma(v: &[Option<f64>]) -> Option<f64> {
    let mut d: Vec<f64> = v.windows(3).filter_map(|w| Some(w[2]? - 2.0 * w[1]? + w[0]?)).collect();
    if d.len() < 10 {
        return None;
    }
    d.sort_by(f64::total_cmp);
    let med = d[d.len() / 2];
    let mut a: Vec<f64> = d.iter().map(|x| (x - med).abs()).collect();
    a.sort_by(f64::total_cmp);
    Some(1.4826 * a[a.len() / 2] / 6f64.sqrt())
}

/// One channel's fit of the calibrated baseline.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct ChannelFit {
    /// Channel name.
    pub channel: String,
    /// Held-out RMSE of the calibrated baseline, K.
    pub heldout_rmse_k: f64,
    /// Mean residual (simulated − measured) over the run, K.
    pub bias_k: f64,
    /// Noise σ estimated from the measured samples, K.
    pub noise_k: f64,
    /// RMS of the measured rise above ambient on the held-out window, K.
    pub rise_k: f64,
    /// Whether the channel misfits (see [`Adequacy::misfits`]).
    pub misfit: bool,
    /// Regressors the residual correlates with most: (name, peak ρ, lag s).
    pub regressors: Vec<(String, f64, f64)>,
}

/// A calibrated parameter on (within 2 % of the log range of) a bound.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct AtBound {
    /// Parameter name.
    pub name: String,
    /// Calibrated value.
    pub value: f64,
    /// `"lower"` or `"upper"`.
    pub bound: &'static str,
}

/// Verdict on the calibrated baseline.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Adequacy {
    /// Every measured temperature channel.
    pub channels: Vec<ChannelFit>,
    /// Calibrated parameters on a bound.
    pub at_bounds: Vec<AtBound>,
    /// Whether some channel misfits ([`MisfitRule`]).
    pub misfits: bool,
    /// What the user should check or measure, most specific first.
    pub advice: Vec<String>,
}

/// What to check for a channel that misfits.
fn channel_advice(ch: &str, bias: f64) -> String {
    let warm = if bias > 0.0 { "reads colder than the model" } else { "reads warmer than the model" };
    let what = match ch {
        "t_motor_c" => "winding resistance hot and cold, the stator-to-housing path and the iron loss (a no-load spin at several speeds)",
        "t_pump_c" => "the pump's mechanical and leakage losses (case-drain flow and t_drain_c), where Point 3 sits on the housing, and metal paths from the pump to the motor flange and the valve block",
        "t_block_c" => "the main block's mass, the pump's mounting on it and where Point 4 sits",
        "t_ballvalve_c" => "the ball/needle-valve block's mass, its bolting to the main block and how the throttling heat splits between the oil and the block",
        "t_oil_c" => "where the oil sensor sits (flowing manifold or dead-end pocket, Figs. 9–10) and its response time; log t_drain_c",
        _ => "the sensor and the node it is assigned to",
    };
    format!("`{ch}` {warm}: check {what}")
}

/// What a strongly correlated regressor points at.
fn regressor_advice(name: &str) -> Option<&'static str> {
    Some(match name {
        "I^2" | "I^2*T_winding" => "residuals follow the current: copper loss or the winding conductance (measure the phase resistance after a hot run)",
        "dp^2/mu(T)" => "residuals follow the leakage heat: pump gaps or viscosity (measure the case-drain flow at two oil temperatures)",
        "omega^2" | "omega^2.5" => "residuals follow the shaft speed: speed-dependent losses (iron, churning, bearings; a no-load run at several speeds separates them)",
        "friction_power" => "residuals follow the piston speed: seal friction (pressure during slow strokes both ways)",
        "T_motor-T_pump" => "residuals follow the motor–pump temperature difference: a conduction path through the flange or coupling",
        "T_oil_lag30-T_oil" => "residuals follow the oil's rate of change: a sensor lag or an oil capacity error",
        _ => return None,
    })
}

/// What a parameter on a bound points at.
fn bound_advice(b: &AtBound) -> String {
    let what = match (b.name.as_str(), b.bound) {
        ("outer_scale", "upper") => "more heat leaves to ambient than free convection and radiation carry: air flow over the housings (log air_speed_mps), or metal paths into the bench",
        ("outer_scale", "lower") => "less heat leaves to ambient than expected: enclosure or insulation; check the housing areas",
        ("inner_scale", _) => "the oil-to-metal films are off by more than ×2: check passage geometry and flows, or heat that enters the metal directly (friction at the port plate)",
        ("metal_capacity_scale", _) => "the metal capacities are off by more than ×2: check the masses that take part (mounting plates, bench) and the node each sensor sits on",
        ("oil_capacity_scale", _) => "the oil capacity is off by more than ×2: check the oil volumes (accumulator, hoses)",
        _ => "the rig file's value for it may be wrong",
    };
    format!("`{}` = {:.3} on its {} bound: {what}", b.name, b.value, b.bound)
}

/// When a channel of the calibrated baseline misfits: its held-out RMSE
/// exceeds `noise_factor`·σ (σ estimated from its samples) and either
/// `rise_fraction` of its RMS rise above ambient on the held-out window or
/// `abs_k` kelvin.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MisfitRule {
    /// Multiple of the channel's noise σ.
    pub noise_factor: f64,
    /// Fraction of the channel's RMS rise above ambient.
    pub rise_fraction: f64,
    /// Absolute held-out RMSE, K.
    pub abs_k: f64,
}

impl MisfitRule {
    /// Whether a channel with held-out RMSE `rmse`, noise `noise` and RMS
    /// rise `rise` (all K) misfits.
    pub fn misfits(&self, rmse: f64, noise: f64, rise: f64) -> bool {
        rmse > self.noise_factor * noise && (rmse > self.rise_fraction * rise || rmse > self.abs_k)
    }
}

/// Assesses the calibrated baseline: `m` its metrics, `xcorr` its residual
/// cross-correlations, `specs`/`values` the calibrated nuisance set, `rule`
/// when a channel misfits.
pub fn assess(run: &MeasuredRun, split: f64, m: &Metrics, xcorr: &[XCorr], nuisance: (&[ParamSpec], &[f64]), rule: MisfitRule) -> Adequacy {
    let (specs, values) = nuisance;
    let mut channels = Vec::new();
    for c in &m.channels {
        let Some(ch) = Channel::from_name(&c.channel) else { continue };
        let Some(v) = run.get(ch) else { continue };
        let noise = channel_noise_k(v);
        let rise = rms_rise_k(run, ch, split);
        let mut regs: Vec<(String, f64, f64)> =
            xcorr.iter().filter(|x| x.channel == c.channel).map(|x| (x.regressor.clone(), x.peak_rho, x.peak_lag_s)).collect();
        regs.sort_by(|a, b| b.1.abs().total_cmp(&a.1.abs()));
        regs.truncate(2);
        let misfit = rule.misfits(c.heldout_rmse_k, noise, rise);
        channels.push(ChannelFit { channel: c.channel.clone(), heldout_rmse_k: c.heldout_rmse_k, bias_k: c.bias_k, noise_k: noise, rise_k: rise, misfit, regressors: regs });
    }
    let at_bounds: Vec<AtBound> = specs
        .iter()
        .zip(values)
        .filter_map(|(s, &v)| {
            let u = (v / s.lo).ln() / (s.hi / s.lo).ln();
            let bound = if u <= 0.02 { "lower" } else if u >= 0.98 { "upper" } else { return None };
            Some(AtBound { name: s.name.clone(), value: v, bound })
        })
        .collect();
    let misfits = channels.iter().any(|c| c.misfit);
    let mut advice = Vec::new();
    let mut worst: Vec<&ChannelFit> = channels.iter().filter(|c| c.misfit).collect();
    worst.sort_by(|a, b| (b.heldout_rmse_k / b.noise_k).total_cmp(&(a.heldout_rmse_k / a.noise_k)));
    for c in &worst {
        advice.push(channel_advice(&c.channel, c.bias_k));
        if let Some((r, rho, _)) = c.regressors.first().filter(|r| r.1.abs() >= 0.5) {
            if let Some(a) = regressor_advice(r) {
                advice.push(format!("`{}` (ρ = {rho:+.2} with {r}): {a}", c.channel));
            }
        }
    }
    advice.extend(at_bounds.iter().map(bound_advice));
    if misfits {
        advice.push("then diagnose again with the measured values in the rig file (`--rig`, `--set`)".into());
    }
    Adequacy { channels, at_bounds, misfits, advice }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn noise_sigma_recovers_white_noise_on_a_ramp() {
        // Deterministic pseudo-noise of σ ≈ 0.1 on a slow ramp.
        let mut s: u64 = 7;
        let mut next = || {
            s = s.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            ((s >> 11) as f64 / (1u64 << 53) as f64) - 0.5
        };
        let v: Vec<Option<f64>> = (0..2000).map(|i| Some(20.0 + 0.01 * i as f64 + 0.1 * 12f64.sqrt() * next())).collect();
        let sigma = noise_sigma(&v).expect("enough samples");
        assert!((0.085..0.115).contains(&sigma), "{sigma}");
    }
}
