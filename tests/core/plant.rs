//! Signals of a consistent machine for the tests: the motor current the reference
//! plant draws at given port pressures and speed.

use eha_guard::params::DEFAULT;

std::thread_local! {
    /// The case-oil temperature the plant's viscous friction follows, degC
    /// ([`follow`]).
    static CASE_OIL_C: std::cell::Cell<f64> = const { std::cell::Cell::new(20.0) };
}

/// The plant's case oil follows the guard's estimate of it (call after each tick):
/// the pump's viscous friction goes with the oil's viscosity, as in the reference.
pub fn follow<N: eha_guard::num::Num>(g: &eha_guard::GuardOf<N>) {
    if let Some(m) = g.model() {
        CASE_OIL_C.with(|c| c.set(m.drain_c().to_f64()));
    }
}

/// The plant's case oil, degC.
pub fn case_oil_c() -> f64 {
    CASE_OIL_C.with(|c| c.get())
}

/// Coldest case oil at which the plant's laws hold, degC: the oil's 1000 cSt (the
/// cold-start limit of axial-piston pumps; `eha_sim::fluid::Oil::coldest_valid_c`).
/// Colder, the viscous friction the firmware holds at its −20 degC table value and
/// the current a real drive would give part ways.
pub const COLDEST_VALID_C: f64 = -6.0;

/// Sets the plant's case oil, degC (the start of a run: the air).
pub fn set_case_oil(t_c: f32) {
    CASE_OIL_C.with(|c| c.set(f64::from(t_c)));
}

/// Motor current, A rms, of the reference plant (`eha_sim::hydraulics::shaft_torque`
/// with the extended eq. 8 and no other friction): `|D dp + sign(w) P_f / max(|w|,
/// 1 rad/s)| / Kt` with the friction power `P_f = T0 |w| + C_v mu(T) D w^2 + eta_m D
/// |dp| |w|` (the viscous term at the case oil of [`follow`]) and the reference's
/// smooth sign `w / sqrt(w^2 + 1e-4)`. With it, the guard's two estimates of the
/// shaft's loss (pressures, current) agree: no SENSOR_DISAGREE.
pub fn motor_current(p_a_bar: f32, p_b_bar: f32, speed_rpm: f32) -> f32 {
    let p = DEFAULT;
    let d = p.displacement_m3_per_rad;
    let dp = (p_a_bar - p_b_bar) as f64 * 1e5;
    let w = speed_rpm as f64 * std::f64::consts::PI / 30.0;
    let sign = w / (w * w + 1e-4).sqrt();
    let visc = p.viscous_w_s2_per_rad2 * p.visc_ratio_at(CASE_OIL_C.with(|c| c.get()));
    let friction_w = p.no_load_torque_nm * w.abs() + visc * w * w + p.eta_m * d * dp.abs() * w.abs();
    let tau = d * dp + sign * friction_w / w.abs().max(1.0);
    (tau.abs() / p.torque_constant_nm_per_a) as f32
}
