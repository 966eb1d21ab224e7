//! What a data logger does to a signal, shared by every log generator (the
//! hidden-effect generator, the synthetic other EHA, the rig emulator):
//! Gaussian sensor noise and the 12-bit quantisation of a temperature
//! channel.

use rand::Rng;

/// Standard normal draw (Box–Muller).
pub fn gauss(rng: &mut impl Rng) -> f64 {
    let (u1, u2): (f64, f64) = (rng.random::<f64>().max(1e-300), rng.random());
    (-2.0 * u1.ln()).sqrt() * (2.0 * std::f64::consts::PI * u2).cos()
}

/// 12-bit quantisation of a temperature over the sensor span 0…200 °C
/// (LSB 0.049 K).
pub fn quantise(t_c: f64) -> f64 {
    let lsb = 200.0 / 4095.0;
    ((t_c / lsb).round() * lsb).clamp(0.0, 200.0)
}
