//! The pump's flow bookkeeping in a pressure hold (`src/model/sums.rs`): the
//! shaft turning just fast enough to feed the high-pressure port's leakage, the
//! piston still. Nothing passes a throttle then, in either direction; a forward
//! hold and its mirror (port B high, the shaft reversed) book the same losses.

use eha_guard::model::{Model, ModelInputN, N_LOSSES};
use eha_guard::params::{DEFAULT, TEMP_TABLE_MIN_C, TEMP_TABLE_STEP_K};

/// Oil and air temperature of the holds, degC: a point of the leakage table
/// (its 24th), where the model's leakage conductance is the table's value.
const T_C: f64 = 40.0;
/// Case pressure of the paper rig's block, Pa (`DEFAULT.case_pressure_pa`).
const P_CASE_PA: f64 = 5e5;
/// High port, Pa: 49 bar above the case, the servo log's holds (|Δp| 49 bar).
const P_HIGH_PA: f64 = P_CASE_PA + 49e5;
/// Low port, Pa: 3 bar above the case (its leakage made up by the check valve).
const P_LOW_PA: f64 = P_CASE_PA + 3e5;
/// Index of the loss group "line + throttling" in [`Model::last_losses_kw`].
const THROTTLE: usize = 4;

/// The leakage conductance at [`T_C`], m³/s/Pa.
fn k_leak() -> f64 {
    let i = ((T_C - TEMP_TABLE_MIN_C) / TEMP_TABLE_STEP_K).round() as usize;
    assert!((TEMP_TABLE_MIN_C + i as f64 * TEMP_TABLE_STEP_K - T_C).abs() < 1e-12);
    DEFAULT.k_leak_m3_per_s_pa * DEFAULT.leak_ratio[i]
}

/// One hold tick in model units: port A and B pressures (Pa), shaft speed
/// (rad/s), the piston still, no current.
fn hold(p_a: f64, p_b: f64, omega: f64) -> ModelInputN<f64> {
    ModelInputN { current_ha: 0.0, p_a_hbar: p_a * 1e-7, p_b_hbar: p_b * 1e-7, speed_hrads: omega * 1e-2, dpos_mm: 0.0, ambient_c: T_C }
}

/// The losses of one model step at `u` from every node at [`T_C`], kW.
fn losses(u: &ModelInputN<f64>) -> [f64; N_LOSSES] {
    let mut m = Model::<f64>::new(&DEFAULT).expect("model");
    m.set_uniform(T_C);
    m.step(u, false);
    m.last_losses_kw()
}

/// A reverse servo hold (port B 49 bar above the case, the shaft reversed at
/// the speed that delivers B's leakage): nothing is throttled. The flow
/// balance is exact here (the speed is computed from the model's own leakage
/// conductance at the oil's temperature, the first step reads it there), so
/// only rounding remains: bound 1e-6 W, 10^9 times f64's rounding of the
/// ~8 W terms and 10^7 below what the old bookkeeping booked (port A's
/// leakage subtracted whatever the direction: `Δp (D|ω| + K (p_A − p_case))`,
/// ≈ 8.0 W here, the leakage heat a second time).
#[test]
fn reverse_servo_hold_throttles_nothing() {
    let d = DEFAULT.displacement_m3_per_rad;
    let q_leak_b = k_leak() * (P_HIGH_PA - P_CASE_PA);
    let omega = -q_leak_b / d;
    let l = losses(&hold(P_LOW_PA, P_HIGH_PA, omega));
    let old_w = (P_HIGH_PA - P_LOW_PA) * (q_leak_b + k_leak() * (P_LOW_PA - P_CASE_PA));
    println!("reverse hold at {:.2} rpm: line + throttling {:.3e} W (old bookkeeping ≈ {old_w:.2} W)", omega * 30.0 / std::f64::consts::PI, l[THROTTLE] * 1e3);
    assert!(old_w > 8.0, "the hold must be one the old bookkeeping got wrong: {old_w} W");
    assert!(l[THROTTLE].abs() * 1e3 < 1e-6, "line + throttling {} W", l[THROTTLE] * 1e3);
    // the leakage itself is booked once: K ((p_A - p_case)^2 + (p_B - p_case)^2)
    let leak_w = k_leak() * ((P_LOW_PA - P_CASE_PA).powi(2) + (P_HIGH_PA - P_CASE_PA).powi(2));
    assert!((l[2] * 1e3 - leak_w).abs() < 1e-6 * leak_w, "leakage {} W against {leak_w} W", l[2] * 1e3);
}

/// Mirror symmetry of the pump's bookkeeping: a forward hold (A high, the shaft
/// forward) and its mirror (B high, reversed) book the same losses, at the
/// hold's speed and at three times it (a throttle circuit's path then passes
/// twice the leakage, in either direction). Bound 1e-12 relative: the two
/// differ only in the order of their f64 operations.
#[test]
fn forward_and_reverse_holds_book_the_same_losses() {
    let d = DEFAULT.displacement_m3_per_rad;
    let omega_hold = k_leak() * (P_HIGH_PA - P_CASE_PA) / d;
    for x in [1.0, 3.0] {
        let fwd = losses(&hold(P_HIGH_PA, P_LOW_PA, x * omega_hold));
        let rev = losses(&hold(P_LOW_PA, P_HIGH_PA, -x * omega_hold));
        for (i, (f, r)) in fwd.iter().zip(rev.iter()).enumerate() {
            assert!((f - r).abs() <= 1e-12 * f.abs().max(1e-9), "x {x}, loss group {i}: forward {f} kW, reverse {r} kW");
        }
        if x > 1.0 {
            assert!(fwd[THROTTLE] > 1e-3, "the path's throttling must show: {} kW", fwd[THROTTLE]);
        }
    }
}
