//! The firmware's reduced model (`Model<f64>`) replayed on a measured log's
//! own inputs, without the reference plant: the logged current, pressures,
//! speed, piston position, ambient and LNG valve interpolated linearly to the
//! guard's 10 ms tick exactly as the reference's replay does
//! (`crate::model::ReplayDrive`), fed tick by tick as the guard feeds its
//! model (`check_reduced` in [`super::commission`] does the same through the
//! plant). A 30 min log is 180 000 ticks: tens of milliseconds, so that the
//! direct identification ([`super::direct`]) can run the model hundreds of
//! times.

use super::log::{CalLog, ChannelError};
use crate::measured::Channel;
use crate::scenario::Circuit;
use eha_guard::model::{Model, ModelInputN, ReducedParams};
use eha_guard::params::{NODE_BALL_BLOCK, NODE_DRAIN, NODE_LOOP, NODE_MAIN_BLOCK, NODE_PUMP, N_NODES, S_PER_TICK, TICKS_PER_STEP};

/// Logged temperatures the reduced model has a node for, with that node:
/// the drain thermocouple (case oil), the pump housing (Point 3), the
/// manifold oil sensor (loop oil, whose node holds the sensor pocket), the
/// main block (Point 4) and the ball-valve block (Point 5).
pub const NODE_CHANNELS: [(Channel, usize); 5] = [
    (Channel::TDrainC, NODE_DRAIN),
    (Channel::TPumpC, NODE_PUMP),
    (Channel::TOilC, NODE_LOOP),
    (Channel::TBlockC, NODE_MAIN_BLOCK),
    (Channel::TBallvalveC, NODE_BALL_BLOCK),
];

/// The model node of logged channel `ch`, if the reduced model has one.
pub fn node_of(ch: Channel) -> Option<usize> {
    NODE_CHANNELS.iter().find(|(c, _)| *c == ch).map(|(_, n)| *n)
}

/// One log's inputs at every 10 ms tick, ready to drive the model many times.
#[derive(Debug, Clone)]
pub struct TickInputs {
    /// Log name.
    pub name: String,
    /// Time of tick 0 (the log's first row), s.
    pub t0_s: f64,
    /// Inputs of every tick, model units.
    pub ticks: Vec<ModelInputN<f64>>,
    /// Logged LNG valve open (≥ 0.5) at every tick.
    pub lng_open: Vec<bool>,
    /// Ambient at tick 0, °C: the model starts uniform there (cold start,
    /// as in `check_reduced` and the guard without a thermal record).
    pub ambient0_c: f64,
}

/// Segment `i` and fraction of `t` in `ts` as the reference's replay
/// locates it (`ts[i] <= t < ts[i+1]`, the ends clamped).
fn locate(ts: &[f64], t: f64) -> (usize, f64) {
    let n = ts.len();
    if n < 2 {
        return (0, 0.0);
    }
    let i = ts.partition_point(|&x| x <= t).clamp(1, n - 1) - 1;
    (i, ((t - ts[i]) / (ts[i + 1] - ts[i])).clamp(0.0, 1.0))
}

fn lerp(v: &[f64], i: usize, f: f64) -> f64 {
    match (v.get(i), v.get(i + 1)) {
        (Some(a), Some(b)) => a + (b - a) * f,
        (Some(a), None) => *a,
        _ => 0.0,
    }
}

impl TickInputs {
    /// The inputs of `log` at the ticks `t0 + k 10 ms` up to its last row
    /// (the times of `Plant::run` at 10 ms). The piston moves only on the
    /// servo circuit (the reference's replay rule).
    pub fn of(log: &CalLog) -> Result<Self, String> {
        let r = log.replay_inputs().ok_or_else(|| format!("{}: not a replay", log.name))?;
        let ts = &r.time_s;
        let (t0, t_end) = (ts[0], ts[ts.len() - 1]);
        let servo = r.circuit == Circuit::Servo;
        let (mut ticks, mut lng_open) = (Vec::new(), Vec::new());
        let mut prev_x = None;
        let mut k = 0u64;
        loop {
            let t = t0 + k as f64 * S_PER_TICK;
            if t > t_end + 1e-9 {
                break;
            }
            let (i, f) = locate(ts, t);
            let x = match (&r.position_mm, servo) {
                (Some(p), true) => lerp(p, i, f),
                _ => 0.0,
            };
            let dx = x - prev_x.unwrap_or(x);
            prev_x = Some(x);
            ticks.push(ModelInputN::from_wire_f64(
                lerp(&r.current_a, i, f),
                lerp(&r.p_a_bar, i, f),
                lerp(&r.p_b_bar, i, f),
                lerp(&r.speed_rpm, i, f),
                dx,
                lerp(&r.ambient_c, i, f),
            ));
            lng_open.push(log.run.value_at(Channel::LngValve, t).is_some_and(|v| v >= 0.5));
            k += 1;
        }
        let ambient0_c = ticks.first().map_or(20.0, |u| u.ambient_c);
        Ok(TickInputs { name: log.name.clone(), t0_s: t0, ticks, lng_open, ambient0_c })
    }

    /// Tick index of time `t`, s (nearest).
    pub fn tick_of(&self, t: f64) -> usize {
        (((t - self.t0_s) / S_PER_TICK).round().max(0.0) as usize).min(self.ticks.len().saturating_sub(1))
    }

    /// Runs the reduced model `p` over every tick; `on_tick(k, temps)`
    /// sees the node temperatures (°C, node order) at tick `k` before that
    /// tick's inputs are taken (what the guard reports at that tick).
    /// Errors when the model rejects `p`.
    pub fn run(&self, p: &ReducedParams, mut on_tick: impl FnMut(usize, &[f64; N_NODES])) -> Result<(), String> {
        let mut m = Model::<f64>::new(p).map_err(|e| format!("reduced model rejects the parameters: {e:?}"))?;
        m.set_uniform(self.ambient0_c);
        let mut open = false;
        for (k, u) in self.ticks.iter().enumerate() {
            on_tick(k, &m.temperatures_c());
            if m.tick_n(u) {
                m.update(if open { TICKS_PER_STEP } else { 0 });
            }
            open = self.lng_open[k];
        }
        Ok(())
    }

    /// Node temperatures (°C) at the ticks `at` (in any order), one row each.
    pub fn temperatures_at(&self, p: &ReducedParams, at: &[usize]) -> Result<Vec<[f64; N_NODES]>, String> {
        let mut order: Vec<usize> = (0..at.len()).collect();
        order.sort_by_key(|&j| at[j]);
        let mut out = vec![[f64::NAN; N_NODES]; at.len()];
        let mut next = 0;
        self.run(p, |k, t| {
            while next < order.len() && at[order[next]] == k {
                out[order[next]] = *t;
                next += 1;
            }
        })?;
        Ok(out)
    }
}

/// Errors of the reduced model `p` on `log`, per logged channel the model
/// has a node for ([`NODE_CHANNELS`]), over every tick after the first
/// against the measured value interpolated to the tick (the rule of
/// `check_reduced`'s `vs_measured` columns: for `t_drain_c` the same
/// numbers).
pub fn node_errors(p: &ReducedParams, log: &CalLog, inputs: &TickInputs) -> Result<Vec<ChannelError>, String> {
    let chans: Vec<(Channel, usize)> = NODE_CHANNELS.iter().copied().filter(|(c, _)| log.has(*c)).collect();
    let mut acc = vec![(0.0f64, 0.0f64, 0.0f64, 0usize); chans.len()];
    inputs.run(p, |k, t| {
        if k == 0 {
            return;
        }
        let tk = inputs.t0_s + k as f64 * S_PER_TICK;
        for ((ch, node), a) in chans.iter().zip(acc.iter_mut()) {
            if let Some(meas) = log.run.value_at(*ch, tk) {
                let e = t[*node] - meas;
                a.0 += e * e;
                a.1 = a.1.max(e.abs());
                a.2 = a.2.max(-e);
                a.3 += 1;
            }
        }
    })?;
    Ok(chans
        .iter()
        .zip(acc)
        .map(|((ch, _), (ss, max, under, n))| ChannelError {
            channel: ch.name().into(),
            rmse_k: (ss / n.max(1) as f64).sqrt(),
            max_abs_k: max,
            max_under_k: under,
        })
        .collect())
}
