//! The hot-flow training run (`commissioning_set_hot`) on the emulator
//! machines: the procedure's two training logs and speed steps at
//! 850–1200 rpm and 40–50 bar with the oil hot (docs/commissioning.md,
//! "The hot-flow run and the ducts' turbulent level").

use super::*;

/// The procedure's training set with the hot-flow run as a third log
/// (`commissioning_set_hot`: speed steps at 850–1200 rpm and 40–50 bar
/// after a warm-up, drain up to 81 / 71 °C), the calibration's defaults
/// (the ducts' turbulent level held, `fit::DUCT_TURBULENT_HELD`); the
/// same held-out logs. Measured (max |e| / under vs the thermocouple,
/// margin counted; servo, throttle mix; one commissioning per machine,
/// 169 s and 125 s wall at load 4–5, 135 s and 110 s CPU with the bench
/// logs):
/// - big-pump: the reduction refused (0.446 K off the reference on the
///   servo log), direct path, margin 1.116 K: 1.807 / 0.000 and
///   2.676 / 0.372 K (the two-log set: 2.017 / 0.000 and 2.786 / 0.699 K,
///   margin 1.319 K); valve open on the mix 1425 → 1513 s, LNG 2.854 →
///   3.001 kg. With `duct_turbulent` freed (it fitted ×1.80): margin
///   1.020 K, 1.483 / 0.000 and 2.500 / 1.143 K.
/// - leaky-heavy (`duct_turbulent` held by the excitation rule too: the
///   passage flow stays below Re 2000): the reduction refused (0.573 K on
///   the servo log), direct path, margin 0.826 K: 1.109 / 0.380 and
///   2.020 / 1.137 K (two-log set: 1.838 / 0.000 and 2.339 / 0.568 K,
///   margin 1.196 K); valve 1547 → 1555 s, LNG 1.953 → 1.966 kg.
///
/// The acceptance (1.0 / 0.3 K) is met on neither. Not reproducible on
/// this set: a 1e-6 K nudge of the logs moved big-pump's headline 0.51 K
/// (margin 1.556 K, 2.110 / 0.000 and 2.903 / 0.883 K;
/// `EXP_TRAIN=hot` on
/// `slow_commissioning_is_reproducible_beyond_the_last_digit_big_pump`),
/// so big-pump's 0.70 → 0.37 K is within the path spread. The rows above
/// are one build's, deterministic on it.
#[test]
#[ignore = "slow tier: two commissionings with margin validation on three training logs (~2–3 min each)"]
fn slow_commissioning_with_the_hot_flow_run() {
    let measured = [
        (1.116, PathKind::Direct, [(1.807, 0.000), (2.676, 0.372)], [1425.0, 1513.0]),
        (0.826, PathKind::Direct, [(1.109, 0.380), (2.020, 1.137)], [1547.0, 1555.0]),
    ];
    for (m, row) in machines().into_iter().zip(measured) {
        commission_as_measured(&m, &commissioning_set_hot(&m, 3600).expect("bench"), row);
    }
}
