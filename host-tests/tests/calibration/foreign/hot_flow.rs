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
/// margin counted; servo, throttle mix) on the fixed reference (b36ffe3;
/// 175.2 s and 144.2 s wall per commissioning at load 5–6 on the 2 cores,
/// 4 141 and 3 800 reference runs in the calibration; 219.7 s user for
/// both):
/// - big-pump: the reduction refused (0.206 K off the reference on the
///   servo log; 0.458 K before the fix), direct path, margin 1.132 K:
///   1.651 / 0.000 and 2.763 / 0.391 K (the two-log set: 1.859 / 0.000
///   and 2.782 / 0.541 K, margin 1.319 K); valve open on the mix 1426 →
///   1514 s, LNG 2.865 → 3.012 kg.
/// - leaky-heavy (`duct_turbulent` held by the excitation rule too: the
///   passage flow stays below Re 2000): the reduction refused (0.307 K on
///   the servo log; 0.871 K before), direct path, margin 0.822 K:
///   1.092 / 0.355 and 2.042 / 1.104 K since the firmware throttles
///   nothing in a reverse servo hold (1.360 / 0.354 K on the servo log
///   with the old bookkeeping; two-log set: 1.471 / 0.000 and
///   2.334 / 0.617 K, margin 1.191 K); valve 1548 → 1555 s, LNG 1.956 →
///   1.968 kg. Big-pump's row re-run with the firmware's fix passes
///   within the 0.15 K (its servo row not printed again).
/// - Before the fix: 1.121 K, 1.768 / 0.000, 2.703 / 0.391 K and
///   0.833 K, 1.278 / 0.340, 2.068 / 1.046 K.
///
/// - **With the margin's head folds** (2026-11-28 night, the default;
///   measured by `slow_structure_experiment` with `EXP_MARGIN=1
///   EXP_TRAIN=hot`, the same commissioning; 367.8 / 325.8 s wall, 481 s
///   user for both at load 4–8): big-pump direct (the reduction 0.207 K
///   off), margin 1.132 → **1.765 K** (the soak start 1.33–1.57 K under),
///   **2.271 / 0.000 and 3.396 / 0.000 K**, valve on the mix 1426 →
///   1519 s, LNG 2.865 → 3.027 kg; leaky-heavy: the reduction holds here
///   (0.121 K off; recorded 0.307 K before, not investigated), the
///   held-out rule flashes the direct path (both beyond 0.3 K under, the
///   direct path 0.33 K lower), margin 0.822 → **1.488 K**,
///   **1.758 / 0.000 and 2.707 / 0.439 K** (reduction, margin 1.251 K:
///   1.512 / 0.000, 2.391 / 0.773 K), valve 1548 → 1560 s, LNG 1.956 →
///   1.976 kg. Asserted below.
///
/// The acceptance (1.0 / 0.3 K) is met on neither; leaky-heavy's
/// under-prediction is worse than with the two logs. Reproducible: a
/// 1e-6 K nudge of every logged temperature moves the headline 0.028 K
/// (big-pump) and 0.027 K (leaky-heavy), measured before the fix
/// ([`super::reproducible::slow_hot_set_is_reproducible_beyond_the_last_digit_big_pump`]);
/// before the continuation, LM from the rig file reached either of two
/// basins and the nudge moved big-pump 0.51 K.
#[test]
#[ignore = "slow tier: two commissionings with margin validation on three training logs (~2–3 min each)"]
fn slow_commissioning_with_the_hot_flow_run() {
    let measured = [
        (1.765, PathKind::Direct, [(2.271, 0.000), (3.396, 0.000)], [1426.0, 1519.0]),
        (1.488, PathKind::Direct, [(1.758, 0.000), (2.707, 0.439)], [1548.0, 1560.0]),
    ];
    for (m, row) in machines().into_iter().zip(measured) {
        commission_as_measured(&m, &commissioning_set_hot(&m, 3600).expect("bench"), row);
    }
}
