//! A driven mission of the rig: its hydraulic circuit and the schedules of
//! its inputs (speed, needle valve, servo position, ambient, ram air, the
//! LNG valve rule). The physics reads a mission's inputs at a time; the
//! simulation's scenarios (`crate::scenario`) build missions.

use serde::{Deserialize, Serialize};
use std::cell::Cell;

/// Hydraulic configuration of the rig (paper, Section III.A).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Circuit {
    /// Case 1: needle valves 4.2/4.3 closed, ball valve open, the pump flow
    /// throttled by needle valve 4.1; the cylinder is isolated.
    #[default]
    Throttle,
    /// Case 2: ball valve closed, the pump drives the cylinder against the
    /// spring under closed-loop position control.
    Servo,
}

/// A piecewise-linear schedule of (time s, value) points; constant outside.
/// Two points at the same time make a step.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Schedule(pub Vec<(f64, f64)>);

impl Schedule {
    /// A constant schedule.
    pub fn constant(v: f64) -> Self {
        Schedule(vec![(0.0, v)])
    }

    /// Value at time `t` (linear between points, held outside).
    pub fn at(&self, t: f64) -> f64 {
        let pts = &self.0;
        // A constant schedule (one point): its value at every t, what the
        // tests below give for it (~3 700 calls a fast Case 1 run).
        if let [(_, v)] = pts.as_slice() {
            return *v;
        }
        let Some(first) = pts.first() else { return 0.0 };
        if t <= first.0 {
            return first.1;
        }
        // At or past the last point (every t of a constant schedule): what
        // the search below gives there, without it.
        if let Some(last) = pts.last() {
            if t >= last.0 {
                return last.1;
            }
        }
        // Last point with time <= t.
        let idx = pts.partition_point(|p| p.0 <= t);
        match (pts.get(idx.wrapping_sub(1)), pts.get(idx)) {
            (Some(a), Some(b)) if b.0 > a.0 => a.1 + (b.1 - a.1) * (t - a.0) / (b.0 - a.0),
            (Some(a), _) => a.1,
            _ => first.1,
        }
    }

    /// Times at which the schedule has a kink or a step (solver stops there).
    pub fn breakpoints(&self) -> impl Iterator<Item = f64> + '_ {
        self.0.iter().map(|p| p.0)
    }
}

/// Position reference of the servo circuit, m.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum PositionRef {
    /// x = offset + amplitude·sin(2π·f·t) (Case 2: 20 mm, 0.2 Hz).
    Sine {
        /// Amplitude, m.
        amplitude_m: f64,
        /// Frequency, Hz.
        freq_hz: f64,
        /// Offset, m.
        offset_m: f64,
    },
    /// A piecewise-linear position schedule, m.
    Profile(Schedule),
}

impl PositionRef {
    /// Reference position (m) and velocity (m/s) at `t`.
    pub fn at(&self, t: f64) -> (f64, f64) {
        match self {
            PositionRef::Sine { amplitude_m, freq_hz, offset_m } => {
                // The last answer is kept per thread, keyed by the bits of
                // the sine and of t (the answer is the value computed): the
                // hydraulic integration asks at the same t for a Jacobian's
                // columns and for a step's last stage and end point.
                thread_local! {
                    static LAST: Cell<([u64; 4], (f64, f64))> = const { Cell::new(([u64::MAX; 4], (f64::NAN, f64::NAN))) };
                }
                let key = [amplitude_m.to_bits(), freq_hz.to_bits(), offset_m.to_bits(), t.to_bits()];
                LAST.with(|c| {
                    let (k, v) = c.get();
                    if k == key {
                        return v;
                    }
                    let w = 2.0 * std::f64::consts::PI * freq_hz;
                    let v = (offset_m + amplitude_m * (w * t).sin(), amplitude_m * w * (w * t).cos());
                    c.set((key, v));
                    v
                })
            }
            PositionRef::Profile(s) => {
                let h = 1e-3;
                (s.at(t), (s.at(t + h) - s.at(t - h)) / (2.0 * h))
            }
        }
    }
}

/// How the LNG valve is commanded.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum ValveRule {
    /// No LNG exchanger in the circuit (valve always closed).
    None,
    /// The paper's thermostat on the circulating-oil temperature (Fig. 15).
    LoopOil,
    /// A thermostat on the true drain-port temperature (what the firmware
    /// estimates; used to judge the firmware's switching times).
    Drain,
    /// Commanded from outside (the firmware in the loop).
    External,
}

/// A driven mission of the reference model.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Mission {
    /// Name used in outputs.
    pub name: String,
    /// Hydraulic configuration.
    pub circuit: Circuit,
    /// Duration, s.
    pub duration_s: f64,
    /// Ambient temperature, °C.
    pub ambient_c: Schedule,
    /// Motor speed command, rpm (throttle circuit).
    pub speed_rpm: Schedule,
    /// Needle-valve setting: its pressure drop at the 500 rpm reference flow, bar
    /// (throttle circuit; 0 = fully open).
    pub needle_bar: Schedule,
    /// Position reference (servo circuit).
    pub position: PositionRef,
    /// Ram-air speed over the housings, m/s.
    pub air_speed_mps: Schedule,
    /// LNG valve rule.
    pub valve: ValveRule,
}
