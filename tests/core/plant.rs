//! Signals of a consistent machine for the tests: the motor current the reference
//! plant draws at given port pressures and speed.

use eha_guard::params::DEFAULT;

/// Motor current, A rms, of the reference plant (`eha_sim::hydraulics::shaft_torque`
/// with the extended eq. 8 and no other friction): `|D dp + sign(w) P_f / max(|w|,
/// 1 rad/s)| / Kt` with the friction power `P_f = T0 |w| + C_v mu D w^2 + eta_m D |dp|
/// |w|` and the reference's smooth sign `w / sqrt(w^2 + 1e-4)`. With it, the guard's
/// two estimates of the shaft's loss (pressures, current) agree: no SENSOR_DISAGREE.
pub fn motor_current(p_a_bar: f32, p_b_bar: f32, speed_rpm: f32) -> f32 {
    let p = DEFAULT;
    let d = p.displacement_m3_per_rad;
    let dp = (p_a_bar - p_b_bar) as f64 * 1e5;
    let w = speed_rpm as f64 * std::f64::consts::PI / 30.0;
    let sign = w / (w * w + 1e-4).sqrt();
    let friction_w = p.no_load_torque_nm * w.abs() + p.viscous_w_s2_per_rad2 * w * w + p.eta_m * d * dp.abs() * w.abs();
    let tau = d * dp + sign * friction_w / w.abs().max(1.0);
    (tau.abs() / p.torque_constant_nm_per_a) as f32
}
