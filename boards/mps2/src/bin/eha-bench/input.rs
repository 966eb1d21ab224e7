//! The bench's deterministic input samples.

use eha_guard::Sample;

/// Ticks of the bench run (60 s of 10 ms ticks).
pub const TICKS: u32 = 6000;

/// Deterministic input: 0-30 s Case 1 (60 bar, 500 rpm, 30 A) with small noise,
/// 30-60 s sinusoidal servo (20 mm, 0.2 Hz) against the Table 3 spring.
/// Motor current of the reference plant at these pressures and speed (the
/// extended eq. 8 with its no-load and viscous friction, as
/// `eha_sim::pil::drill::motor_current`): consistent sensors, so the
/// cross-check agrees.
fn motor_current(p_a: f32, p_b: f32, rpm: f32) -> f32 {
    let p = &eha_guard::params::DEFAULT;
    let d = p.displacement_m3_per_rad as f32;
    let dp = (p_a - p_b) * 1e5;
    let w = libm::fabsf(rpm * core::f32::consts::PI / 30.0);
    let t_f = p.no_load_torque_nm as f32 + p.viscous_w_s2_per_rad2 as f32 * w + p.eta_m as f32 * d * libm::fabsf(dp);
    let s = if rpm < 0.0 { -1.0 } else { 1.0 };
    libm::fabsf(d * dp + s * t_f) / p.torque_constant_nm_per_a as f32
}

/// Sample of tick `k`; `noise` is the generator state.
pub fn sample(k: u32, noise: &mut u32) -> Sample {
    *noise = noise.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
    let n = ((*noise >> 9) as f32 / 8_388_608.0 - 0.5) * 0.2;
    if k < TICKS / 2 {
        Sample {
            current_a: motor_current(65.0 + n, 5.0, 500.0 + n),
            p_a_bar: 65.0 + n,
            p_b_bar: 5.0,
            speed_rpm: 500.0 + n,
            position_mm: n * 0.01,
            ambient_c: 16.0,
        }
    } else {
        let w = 2.0 * core::f32::consts::PI * 0.2;
        let t = k as f32 * 0.01;
        let x = 20.0 * libm::sinf(w * t);
        let v = 20.0 * w * libm::cosf(w * t);
        let dp = (245.0 * x + 15.0 * v) / 1.52681e-3 / 1e5;
        let rpm = 1.52681e-3 * v * 1e-3 / 3.0239e-6 * 60.0 / (2.0 * core::f32::consts::PI);
        let (p_a, p_b) = (20.0 + if dp > 0.0 { dp } else { 0.0 }, 20.0 + if dp < 0.0 { -dp } else { 0.0 });
        Sample {
            current_a: motor_current(p_a, p_b, rpm),
            p_a_bar: p_a,
            p_b_bar: p_b,
            speed_rpm: rpm,
            position_mm: x,
            ambient_c: 16.0,
        }
    }
}
