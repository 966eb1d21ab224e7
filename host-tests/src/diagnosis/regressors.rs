//! Physical regressors for the residual cross-correlation: each is the
//! signature of one loss or heat path the baseline may get wrong, built from
//! the measured inputs and the calibrated baseline's internal temperatures.

use super::model::SimSeries;
use crate::measured::{Channel, MeasuredRun};

/// Pump displacement, m³/rad (19 cm³/rev, paper Table 3).
const D_RAD: f64 = 19e-6 / (2.0 * std::f64::consts::PI);
/// Ram area, m² (1526.81 mm², paper Table 3).
const A_RAM: f64 = 1526.81e-6;

/// Kinematic viscosity of ISO VG 46 oil, cSt, by the ASTM D341 (Walther)
/// relation log10 log10(ν+0.7) = A − B log10(T\[K\]) through 46 cSt at 40 °C
/// and 6.8 cSt at 100 °C (ISO VG 46). Used only as the μ(T) of the
/// Δp²/μ(T) leakage regressor (paper eqs. 5–7: leakage loss ∝ Δp²/μ).
pub fn vg46_viscosity_cst(t_c: f64) -> f64 {
    let w = |nu: f64| (nu + 0.7f64).log10().log10();
    let (t1, t2) = ((40.0 + 273.15f64).log10(), (100.0 + 273.15f64).log10());
    let b = (w(46.0) - w(6.8)) / (t2 - t1);
    let a = w(46.0) + b * t1;
    let tk = (t_c.clamp(-40.0, 200.0) + 273.15).log10();
    10f64.powf(10f64.powf(a - b * tk)) - 0.7
}

/// First-order lag of `x` sampled at `t` (s) with time constant `tau` (s),
/// exact for piecewise-constant input between samples.
pub fn first_order_lag(t: &[f64], x: &[f64], tau: f64) -> Vec<f64> {
    let mut y = Vec::with_capacity(x.len());
    for i in 0..x.len() {
        let prev = if i == 0 { x[0] } else { y[i - 1] };
        let a = if i == 0 { 0.0 } else { (-(t[i] - t[i - 1]) / tau).exp() };
        y.push(a * prev + (1.0 - a) * x[i]);
    }
    y
}

/// The regressors, by name, one value per measured row:
/// `I^2` (A²), `I^2*T_winding` (A²·°C), `dp^2/mu(T)` (bar²/cSt),
/// `omega^2` ((rad/s)²), `omega^2.5`, `friction_power` (W per N of Coulomb
/// force: |piston speed|, m/s), `T_motor-T_pump` (K), `T_oil_lag30-T_oil`
/// (K: 30 s first-order lag of the simulated oil minus itself, the dead-end
/// sensor signature of Figs. 9–10). Inputs between samples are interpolated;
/// model-derived ones use the calibrated baseline `base`.
pub fn regressors(run: &MeasuredRun, base: &SimSeries) -> Vec<(String, Vec<f64>)> {
    let t = &run.time_s;
    let at = |ch: Channel| -> Vec<f64> { t.iter().map(|&x| run.value_at(ch, x).unwrap_or(0.0)).collect() };
    let cur = at(Channel::CurrentA);
    let speed: Vec<f64> = at(Channel::SpeedRpm).iter().map(|n| n * std::f64::consts::PI / 30.0).collect();
    let dp: Vec<f64> = at(Channel::PABar).iter().zip(at(Channel::PBBar)).map(|(a, b)| a - b).collect();
    let sim_or = |name: &str, ch: Channel| -> Vec<f64> {
        base.internals.get(name).cloned().or_else(|| base.channels.get(&ch).cloned()).unwrap_or_else(|| at(ch))
    };
    let t_wind = sim_or("t_winding_c", Channel::TMotorC);
    let t_oil = sim_or("t_drain_c", Channel::TOilC);
    let t_oil_sensor = base.channels.get(&Channel::TOilC).cloned().unwrap_or_else(|| t_oil.clone());
    let vel: Vec<f64> = if run.get(Channel::PositionMm).is_some() {
        let x = at(Channel::PositionMm);
        (0..t.len())
            .map(|i| {
                let (a, b) = (i.saturating_sub(1), (i + 1).min(t.len() - 1));
                if b > a { ((x[b] - x[a]) / (t[b] - t[a]) * 1e-3).abs() } else { 0.0 }
            })
            .collect()
    } else {
        speed.iter().map(|w| (w * D_RAD / A_RAM).abs()).collect()
    };
    let mp: Vec<f64> = {
        let m = sim_or("t_motor_c", Channel::TMotorC);
        let p = sim_or("t_pump_c", Channel::TPumpC);
        m.iter().zip(&p).map(|(a, b)| a - b).collect()
    };
    let lag = first_order_lag(t, &t_oil_sensor, 30.0);
    vec![
        ("I^2".into(), cur.iter().map(|i| i * i).collect()),
        ("I^2*T_winding".into(), cur.iter().zip(&t_wind).map(|(i, tw)| i * i * tw).collect()),
        ("dp^2/mu(T)".into(), dp.iter().zip(&t_oil).map(|(d, to)| d * d / vg46_viscosity_cst(*to)).collect()),
        ("omega^2".into(), speed.iter().map(|w| w * w).collect()),
        ("omega^2.5".into(), speed.iter().map(|w| w.abs().powf(2.5)).collect()),
        ("friction_power".into(), vel),
        ("T_motor-T_pump".into(), mp),
        ("T_oil_lag30-T_oil".into(), lag.iter().zip(&t_oil_sensor).map(|(l, o)| l - o).collect()),
    ]
}
