//! The hot-flow training run (`commissioning_set_hot`) on the emulator
//! machines: the procedure's two training logs and speed steps at
//! 850–1200 rpm and 40–50 bar with the oil hot (docs/commissioning.md,
//! "The hot-flow run and the ducts' turbulent level").

use super::*;

/// The procedure's training set with the hot-flow run as a third log
/// (`commissioning_set_hot`: speed steps at 850–1200 rpm and 40–50 bar
/// after a warm-up, drain up to 81 / 71 °C), the calibration's defaults
/// (the ducts' turbulent level held, `fit::DUCT_TURBULENT_HELD`; the fit
/// continued from the first two logs' fit, `fit::CONTINUATION_LOGS`); the
/// same held-out logs. Measured (max |e| / under vs the thermocouple,
/// margin counted; servo, throttle mix; 2026-11-28, 198 s and 184 s wall
/// per commissioning at load 5–6 on the 2 cores, 130 s and 114 s at load
/// 1–3, 4 887 and 5 166 reference runs in the calibration):
/// - big-pump: the reduction refused (0.458 K off the reference on the
///   servo log), direct path, margin 1.121 K: 1.768 / 0.000 and
///   2.703 / 0.391 K (the two-log set: 2.017 / 0.000 and 2.786 / 0.699 K,
///   margin 1.319 K); valve open on the mix 1425 → 1513 s, LNG 2.858 →
///   3.005 kg.
/// - leaky-heavy (`duct_turbulent` held by the excitation rule too: the
///   passage flow stays below Re 2000): the reduction refused (0.871 K on
///   the servo log), direct path, margin 0.833 K: 1.278 / 0.340 and
///   2.068 / 1.046 K (two-log set: 1.838 / 0.000 and 2.339 / 0.568 K,
///   margin 1.196 K); valve 1548 → 1555 s, LNG 1.950 → 1.963 kg.
///
/// The acceptance (1.0 / 0.3 K) is met on neither; leaky-heavy's
/// under-prediction is worse than with the two logs. Reproducible: a
/// 1e-6 K nudge of every logged temperature moves the headline 0.028 K
/// (big-pump) and 0.027 K (leaky-heavy)
/// ([`super::reproducible::slow_hot_set_is_reproducible_beyond_the_last_digit_big_pump`]);
/// before the continuation, LM from the rig file reached either of two
/// basins and the nudge moved big-pump 0.51 K.
#[test]
#[ignore = "slow tier: two commissionings with margin validation on three training logs (~2–3 min each)"]
fn slow_commissioning_with_the_hot_flow_run() {
    let measured = [
        (1.121, PathKind::Direct, [(1.768, 0.000), (2.703, 0.391)], [1425.0, 1513.0]),
        (0.833, PathKind::Direct, [(1.278, 0.340), (2.068, 1.046)], [1548.0, 1555.0]),
    ];
    for (m, row) in machines().into_iter().zip(measured) {
        commission_as_measured(&m, &commissioning_set_hot(&m, 3600).expect("bench"), row);
    }
}
