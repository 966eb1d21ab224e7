//! The open-loop "drill" input sequence used by the PIL equivalence and
//! golden-output tests: 600 s at the firmware's 10 ms tick (60,000 frames).
//!
//! - 0–100 s: hard throttling (140 bar, 60 A, 500 rpm): the predicted drain
//!   temperature crosses 40 °C and the LNG valve opens (about 22 s with the
//!   identified parameters);
//! - from 100 s: 10 bar, 5 A: the prediction falls and the valve closes
//!   before the first fault at 450 s;
//! - step 10,000: 3 lost frames (sequence gap, missed steps, below `stale_steps`);
//! - step 45,000: 10 lost frames (STALE fault latches, fail-safe valve open);
//! - step 50,000: a NaN current (non-finite fault); step 55,000: 5000 bar (range fault).
//! The piston moves ±20 mm slowly throughout; ambient 16 °C.

use eha_guard::protocol::Request;

/// Number of frames.
pub const STEPS: u32 = 60_000;

/// The frames, in order (sequence numbers include the gaps).
pub fn inputs() -> Vec<Request> {
    let mut v = Vec::with_capacity(STEPS as usize);
    let mut seq: u16 = 0;
    for k in 0..STEPS {
        let t = k as f32 * 0.01;
        let hot = t < 100.0;
        let dp = if hot { 140.0 } else { 10.0 };
        let mut r = Request {
            seq,
            current_a: if hot { 60.0 } else { 5.0 },
            p_a_bar: 2.0 + dp,
            p_b_bar: 2.0,
            speed_rpm: 500.0,
            position_mm: 20.0 * (0.05 * t).sin(),
            ambient_c: 16.0,
            valve_fb: None,
        };
        if k == 50_000 {
            r.current_a = f32::NAN;
        }
        if k == 55_000 {
            r.p_a_bar = 5000.0;
        }
        v.push(r);
        seq = seq.wrapping_add(match k {
            10_000 => 4,
            45_000 => 11,
            _ => 1,
        });
    }
    v
}
