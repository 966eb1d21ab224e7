//! Synthetic input profiles shared by the host tests (wire units, 10 ms ticks).
#![allow(dead_code)]

use eha_guard::Sample;

/// Ticks in 600 s at 10 ms.
pub const STEPS_600S: usize = 60_000;

/// Case-1-like: 500 rpm against a needle valve at `dp_bar`, ~30 A, piston still,
/// ambient 16 degC (paper section III, Case 1).
pub fn case1(dp_bar: f32) -> impl Fn(usize) -> Sample {
    move |_k| Sample {
        current_a: 30.0,
        p_a_bar: dp_bar + 5.0,
        p_b_bar: 5.0,
        speed_rpm: 500.0,
        position_mm: 0.0,
        ambient_c: 16.0,
    }
}

/// Case-2-like servo: x = 20 sin(2 pi 0.2 t) mm against a 245 N/mm spring with
/// 15 N/(mm/s) damping (Table 3), pump flow = A v, dp = F / A, I = D dp / (1 Nm/A) + 5 A,
/// ambient 26.4 degC.
pub fn servo(k: usize) -> Sample {
    let t = k as f64 * 0.01;
    let w = 2.0 * core::f64::consts::PI * 0.2;
    let x_mm = 20.0 * (w * t).sin();
    let v_mm_s = 20.0 * w * (w * t).cos();
    let area = 1.52681e-3;
    let d = 19e-6 / (2.0 * core::f64::consts::PI);
    let f_n = 245.0 * x_mm + 15.0 * v_mm_s;
    let dp_pa = f_n / area;
    let omega = area * v_mm_s * 1e-3 / d;
    let current = (d * dp_pa).abs() / 1.0 + 5.0;
    Sample {
        current_a: current as f32,
        p_a_bar: (20.0 + (dp_pa / 1e5).max(0.0)) as f32,
        p_b_bar: (20.0 + (-dp_pa / 1e5).max(0.0)) as f32,
        speed_rpm: (omega * 60.0 / (2.0 * core::f64::consts::PI)) as f32,
        position_mm: x_mm as f32,
        ambient_c: 26.4,
    }
}
