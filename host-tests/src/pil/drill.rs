//! The open-loop "drill" input sequence used by the PIL equivalence and
//! golden-output tests: 600 s at the firmware's 10 ms tick (60,000 ticks,
//! 59,987 sample frames).
//!
//! - 0–100 s: hard throttling (140 bar, 500 rpm): the predicted drain
//!   temperature crosses 40 °C and the LNG valve opens (about 22 s);
//! - from 100 s: 10 bar: the prediction falls and the valve closes;
//! - the motor current is the one the reference plant draws at these pressures
//!   and speed ([`motor_current`]: 84.6 A, then 6.0 A), so the sensor
//!   cross-check agrees, until
//! - 300 s: the current sensor reads 30 % low (SENSOR_DISAGREE latches within
//!   1 s, two 0.5 s windows: valve forced open, alarm and derate held, the model
//!   heats with the larger loss);
//! - tick 10,000: 3 lost frames (3 ticks without a sample, below `stale_ticks`);
//! - tick 45,000: 10 lost frames (STALE fault latches, fail-safe valve open);
//! - tick 50,000: a NaN current (non-finite fault); tick 55,000: 5000 bar (range fault).
//!
//! The piston moves ±20 mm slowly throughout; ambient 16 °C. The valve's
//! position switch reports the valve the last tick commanded ([`bytes`]: the
//! harness passes the last tick reply's command; a valve that follows).

use eha_guard::protocol::Request;
use eha_guard::{Reports, Sample};

/// Motor current of the reference plant, A rms: `|D dp + sign(w) T_f| / Kt` with
/// the friction torque of the extended eq. (8),
/// `T_f = T0 + C_v mu(T)/mu(40) D |w| + eta_m D |dp|` at the case oil `case_oil_c`, degC
/// (`eha_sim::hydraulics::shaft_torque`, |w| >= 1 rad/s), with the firmware's
/// own parameters.
pub fn motor_current(p_a_bar: f32, p_b_bar: f32, speed_rpm: f32, case_oil_c: f64) -> f32 {
    let p = eha_guard::params::DEFAULT;
    let d = p.displacement_m3_per_rad;
    let dp = (p_a_bar - p_b_bar) as f64 * 1e5;
    let w = (speed_rpm as f64 * std::f64::consts::PI / 30.0).abs();
    let t_f = p.no_load_torque_nm + p.viscous_w_s2_per_rad2 * p.visc_ratio_at(case_oil_c) * w + p.eta_m * d * dp.abs();
    let tau = d * dp + (speed_rpm as f64).signum() * t_f;
    (tau.abs() / p.torque_constant_nm_per_a) as f32
}

/// Number of ticks.
pub const STEPS: u32 = 60_000;

/// The bytes of tick `k` of the drill (empty: the frame was lost), with the
/// valve's position as the last tick commanded it (`last_open`).
pub fn bytes(r: &Option<Request>, last_open: bool) -> Vec<u8> {
    r.map_or_else(Vec::new, |r| Request { reports: Reports { valve_fb: Some(last_open), ..r.reports }, ..r }.encode().to_vec())
}

/// Per tick, the sample the controller sent (`None`: lost on the way).
pub fn requests() -> Vec<Option<Request>> {
    use eha_guard::num::Num;
    let mut v = Vec::with_capacity(STEPS as usize);
    let mut seq: u16 = 0;
    // the case oil the current's viscous friction follows
    let mut oil = eha_guard::GuardOf::<f64>::new(&eha_guard::GuardConfig::DEFAULT, eha_guard::Restore::Cold);
    for k in 0..STEPS {
        let oil_c = oil.model().map_or(16.0, |m| m.drain_c().to_f64());
        let t = k as f32 * 0.01;
        let hot = t < 100.0;
        let dp = if hot { 140.0 } else { 10.0 };
        let sensor_gain = if t < 300.0 { 1.0 } else { 0.7 };
        let mut sample = Sample {
            current_a: sensor_gain * motor_current(2.0 + dp, 2.0, 500.0, oil_c),
            p_a_bar: 2.0 + dp,
            p_b_bar: 2.0,
            speed_rpm: 500.0,
            position_mm: 20.0 * (0.05 * t).sin(),
            ambient_c: 16.0,
        };
        if k == 50_000 {
            sample.current_a = f32::NAN;
        }
        if k == 55_000 {
            sample.p_a_bar = 5000.0;
        }
        let r = Request { seq, sample, reports: Reports::default() };
        let lost = (10_001..10_004).contains(&k) || (45_001..45_011).contains(&k);
        oil.valve_feedback(oil.output().valve_open);
        if lost {
            oil.tick_missing();
        } else {
            oil.tick(&r.sample);
        }
        v.push((!lost).then_some(r));
        seq = seq.wrapping_add(1);
    }
    v
}
