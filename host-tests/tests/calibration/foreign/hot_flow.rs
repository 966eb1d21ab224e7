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
    for (m, (margin, path, want, open_s)) in machines().into_iter().zip(measured) {
        let s = commissioning_set_hot(&m, 3600).expect("bench");
        let train: Vec<CalLog> = s.train.iter().map(cal).collect();
        let hold: Vec<CalLog> = s.holdout.iter().map(cal).collect();
        let t0 = std::time::Instant::now();
        let c = commission(&m.rig_file(), &train, &hold, &CalOptions::default()).expect("commissioning");
        report(&m, &c, t0.elapsed().as_secs_f64());
        let h = headline(&m, &c, &s.holdout);
        near(&format!("{} margin", m.name), h.margin_k, margin);
        assert_eq!(c.choice.chosen, path, "{}: {}", m.name, c.choice.why);
        assert!(c.flashable(), "{}: {:?}", m.name, c.refusal().map(|r| r.to_string()));
        for (got, want) in h.measured.iter().zip(want) {
            near(&format!("{} held-out max |e| with margin", m.name), got.0, want.0);
            near(&format!("{} held-out under-prediction with margin", m.name), got.1, want.1);
        }
        let (a, b) = (&c.holdout_without_margin()[1], &c.holdout_with_margin[1]);
        assert!((a.valve_open_s - open_s[0]).abs() <= 20.0 && (b.valve_open_s - open_s[1]).abs() <= 20.0, "{}: valve open {:.0} -> {:.0} s", m.name, a.valve_open_s, b.valve_open_s);
    }
}
