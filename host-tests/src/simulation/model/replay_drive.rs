//! A replay's drive: linear interpolation in measured inputs (with a
//! segment hint for the solver's nearby times) and the operating point
//! they impose. Separate from the model because it depends only on the
//! logged inputs and the rig, not on the model's state.

use crate::hydraulics::OpPoint;
use crate::rig::Rig;
use crate::scenario::{Circuit, ReplayInputs};
use std::cell::Cell;
use std::f64::consts::PI;

/// Linear interpolation in measured inputs.
#[derive(Debug, Clone)]
pub struct ReplayDrive {
    inputs: ReplayInputs,
    /// Segment of the last [`ReplayDrive::locate`]: the solver asks for
    /// times close to each other, so the next is usually this one or the
    /// one after (checked, else a binary search).
    hint: Cell<usize>,
}

impl ReplayDrive {
    /// Wrap replay inputs.
    pub fn new(inputs: ReplayInputs) -> Self {
        Self { inputs, hint: Cell::new(0) }
    }

    /// The inputs.
    pub fn inputs(&self) -> &ReplayInputs {
        &self.inputs
    }

    /// Segment index and fraction at time `t`.
    fn locate(&self, t: f64) -> (usize, f64) {
        let ts = &self.inputs.time_s;
        let n = ts.len();
        if n < 2 {
            return (0, 0.0);
        }
        // Segment i holds t when ts[i] <= t < ts[i+1]; the first also takes
        // earlier times and the last later ones (the binary search's clamp).
        let holds = |i: usize| i + 1 < n && (i == 0 || ts[i] <= t) && (i + 2 == n || t < ts[i + 1]);
        let h = self.hint.get();
        let i = if holds(h) {
            h
        } else if holds(h + 1) {
            h + 1
        } else {
            ts.partition_point(|&x| x <= t).clamp(1, n - 1) - 1
        };
        self.hint.set(i);
        let (a, b) = (ts[i], ts[i + 1]);
        (i, ((t - a) / (b - a)).clamp(0.0, 1.0))
    }

    fn lerp(v: &[f64], i: usize, f: f64) -> f64 {
        match (v.get(i), v.get(i + 1)) {
            (Some(a), Some(b)) => a + (b - a) * f,
            (Some(a), None) => *a,
            _ => 0.0,
        }
    }

    /// Piston speed at logged sample `i`, mm/s: the mean of the difference
    /// quotients of the segments on either side (one side at the ends).
    fn node_speed(&self, i: usize) -> f64 {
        let r = &self.inputs;
        let Some(p) = &r.position_mm else { return 0.0 };
        let ts = &r.time_s;
        let q = |j: usize| -> Option<f64> {
            let (a, b) = (ts.get(j)?, ts.get(j + 1)?);
            Some((p.get(j + 1)? - p.get(j)?) / (b - a))
        };
        match (i.checked_sub(1).and_then(q), q(i)) {
            (Some(a), Some(b)) => 0.5 * (a + b),
            (Some(a), None) => a,
            (None, Some(b)) => b,
            (None, None) => 0.0,
        }
    }

    /// Operating point at `t` from the measured inputs.
    pub fn op(&self, rig: &Rig, t: f64) -> OpPoint {
        let (i, f) = self.locate(t);
        let r = &self.inputs;
        let circuit = r.circuit;
        // The piston moves only in the servo circuit (in the throttle circuit
        // the cylinder is isolated; a logged position is its rest position).
        let (x, v) = match (&r.position_mm, circuit) {
            (Some(p), Circuit::Servo) => {
                let x = Self::lerp(p, i, f) * 1e-3;
                // Piston speed: the logged samples' difference quotients
                // averaged onto the samples and interpolated linearly, so
                // that the speed is continuous (a piecewise-constant speed
                // would make the friction and flow heat jump at every logged
                // sample and force the solver to stop there).
                let v = (1.0 - f) * self.node_speed(i) + f * self.node_speed(i + 1);
                (x, v * 1e-3)
            }
            _ => (0.0, 0.0),
        };
        let omega = Self::lerp(&r.speed_rpm, i, f) * 2.0 * PI / 60.0;
        let p_a = Self::lerp(&r.p_a_bar, i, f) * 1e5;
        let p_b = Self::lerp(&r.p_b_bar, i, f) * 1e5;
        let logged_air = r.air_speed_mps.as_ref().map_or(0.0, |a| Self::lerp(a, i, f));
        let mut op = OpPoint {
            omega,
            p_a,
            p_b,
            p_case: rig.hydraulics.accumulator_pa,
            x,
            v,
            q_path: 0.0,
            current_a: Self::lerp(&r.current_a, i, f),
            circuit,
            ambient_c: Self::lerp(&r.ambient_c, i, f),
            air_mps: logged_air + rig.ext.forced_convection.unwrap_or(0.0),
        };
        if circuit == Circuit::Throttle {
            // The pump's delivered flow goes through the throttle path (the
            // leakage here at 40 °C; `Model::op_point` takes it at the case oil).
            let k = rig.pump.gaps.conductance(rig.oil.mu_pa_s(40.0));
            op.q_path = rig.displacement_m3_per_rad() * omega - k * (p_a - op.p_case);
        }
        op
    }

    /// Logged LNG valve command at `t`.
    pub fn lng_open(&self, t: f64) -> bool {
        let (i, _) = self.locate(t);
        self.inputs.lng_valve.as_ref().and_then(|v| v.get(i)).is_some_and(|&x| x > 0.5)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The segment hint of `locate` changes only the search, not the
    /// answer: for times ascending, descending, jumping and outside the log,
    /// the same (segment, fraction) as a fresh binary search.
    #[test]
    fn locate_with_a_hint_equals_the_binary_search() {
        let time_s = vec![0.0, 0.1, 0.2, 0.5, 0.6, 2.0];
        let n = time_s.len();
        let z = vec![0.0; n];
        let inputs = ReplayInputs {
            name: "t".into(),
            circuit: Circuit::Throttle,
            time_s: time_s.clone(),
            speed_rpm: z.clone(),
            current_a: z.clone(),
            p_a_bar: z.clone(),
            p_b_bar: z.clone(),
            ambient_c: z,
            position_mm: None,
            air_speed_mps: None,
            lng_valve: None,
        };
        let d = ReplayDrive::new(inputs);
        let fresh = |t: f64| {
            let i = time_s.partition_point(|&x| x <= t).clamp(1, n - 1) - 1;
            (i, ((t - time_s[i]) / (time_s[i + 1] - time_s[i])).clamp(0.0, 1.0))
        };
        let ts = [-1.0, 0.0, 0.05, 0.1, 0.1, 0.15, 0.2, 0.55, 0.6, 1.9, 2.0, 3.0, 0.3, 0.0, 0.19, 2.5, 0.6, 0.59];
        for t in ts {
            assert_eq!(d.locate(t), fresh(t), "t = {t}");
        }
    }
}
