//! The channels a candidate touches and each channel's floor, estimated
//! from the others.

use super::*;

/// The channels a candidate's physics acts on directly: where its heat
/// enters (or, for the probe lag, the probe).
pub fn touched_channels(c: Candidate) -> &'static [Channel] {
    use Candidate::*;
    use Channel::*;
    match c {
        WindingResistanceTemperature => &[TMotorC],
        SensorLag | CoulombFriction => &[TOilC],
        ChurningLoss => &[TPumpC],
        MotorPumpConduction | ForcedConvection => &[TMotorC, TPumpC],
        None => &[],
    }
}

/// One channel's numbers for the evidence: noise, rise, the calibrated
/// baseline's misfit on the training points.
#[derive(Debug, Clone, serde::Serialize)]
pub struct ChannelFloor {
    /// Channel name.
    pub channel: String,
    /// Noise σ estimated from its samples, K.
    pub noise_k: f64,
    /// RMS rise above ambient, K.
    pub rise_k: f64,
    /// RMS residual of the calibrated baseline on the training fit points, K.
    pub misfit_k: f64,
}

/// The floor of channel `c` when the channels in `touched` are judged:
/// `c`'s rise times the median over the untouched channels of their
/// misfit per rise — rig-level structure errors (a film, a capacity, a
/// heat path off by some per cent) scale with how far a channel rises — but
/// never less than `c`'s noise; an untouched channel's floor is its own
/// misfit. With every channel touched (or one channel only), the floor is
/// the noise.
pub fn floor_for(c: &ChannelFloor, all: &[ChannelFloor], touched: &[String]) -> f64 {
    floor_rule(c, all, touched, FloorRule::Rise)
}

/// How the floor of a touched channel is scaled from the others.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum FloorRule {
    /// Misfit per rise.
    Rise,
    /// Misfit per noise σ.
    Noise,
    /// The channel's own misfit.
    Own,
    /// The noise only.
    Bare,
}

/// [`floor_for`] with the scaling `rule`.
pub fn floor_rule(c: &ChannelFloor, all: &[ChannelFloor], touched: &[String], rule: FloorRule) -> f64 {
    if !touched.contains(&c.channel) || rule == FloorRule::Own {
        return c.misfit_k.max(c.noise_k);
    }
    if rule == FloorRule::Bare {
        return c.noise_k;
    }
    let scale = |o: &ChannelFloor| if rule == FloorRule::Rise { o.rise_k.max(1e-6) } else { o.noise_k };
    let mut rel: Vec<f64> = all.iter().filter(|o| !touched.contains(&o.channel)).map(|o| o.misfit_k / scale(o)).collect();
    if rel.is_empty() {
        return c.noise_k;
    }
    rel.sort_by(f64::total_cmp);
    let med = if rel.len() % 2 == 1 { rel[rel.len() / 2] } else { 0.5 * (rel[rel.len() / 2 - 1] + rel[rel.len() / 2]) };
    (med * scale(c)).max(c.noise_k)
}
