//! What carries big-pump's drain miss that the structural bisection's ten
//! switches leave (docs/commissioning-foreign.md, "The held-out drain misses:
//! structural bisection", the rows beyond the control): the control (all
//! ten switched) plus the emulator-side switches of the differences the ten
//! do not cover (`ports`, `duct`, `wall`, `outer`, `mount`, `boost`;
//! `mix_audit::like_reference`), with the held-out mix in the training set
//! (can the reference follow it at all?) and held out.

use super::mix_audit::{bisection_run, parse_switches};
use eha_sim::emulator::bench::machines;

/// The decisive rows, measured at this commit on this build: machine,
/// switches, the held-out mix in the training set, another throttle mix
/// ([`OTHER_MIX`]) in it, then (servo under-prediction, mix
/// max |e|, mix under-prediction), K, firmware drain against the
/// thermocouple without the margin (the bisection's set: `set::STRUCTURAL`
/// held). Asserted within 0.25 K, the bisection's own tolerance
/// (`mix_audit::slow_structural_bisection_of_the_drain_misses`): the same
/// build gives the same numbers; another float rounding moves the fit's
/// basin (the rows hold to ≤ 0.05 K under a 1e-6 K nudge of the logs,
/// docs/commissioning-foreign.md "Reproducibility", but up to 0.59 K between
/// optimiser paths of other builds). The conclusion rests on 0.46 K
/// between the control and `duct,wall` with the mix trained (under-
/// prediction 1.192 against 0.728 K), which four runs with both switches
/// (0.81–0.84 K) against six without (1.15–1.32 K) confirmed before the
/// reference's fix, on the held-out row not moving (1.447 K with
/// `duct,wall`, the control's 1.32 K in the bisection), and on another
/// mix in the training set closing it with `duct,wall` only (control
/// 1.277, `duct,wall` 0.676 K). Measured on the fixed reference (b36ffe3;
/// 492 s wall, 314 s user at load 5–6); the rows before it (old → new):
/// big-pump control trained [0.571, 1.271, 1.271] → [0.576, 1.347,
/// 1.192], `duct,wall` trained [0.548, 0.833, 0.833] → [0.546, 0.728,
/// 0.728], held out [0.549, 1.385, 1.385] → [0.547, 1.447, 1.447], the
/// other mix [0.592, 1.369, 1.369] → [0.592, 1.412, 1.277] and
/// [0.555, 0.784, 0.784] → [0.553, 0.676, 0.676]; leaky-heavy control
/// [0.758, 0.682, 0.682] → [0.734, 0.492, 0.492], `duct,wall` [0.796,
/// 0.777, 0.777] → [0.768, 1.241, 0.642] (its max |e| an over-prediction,
/// 0.46 K outside the tolerance: re-asserted as measured).
/// One measured row: machine, switches, the held-out mix trained, another
/// mix (seed) trained, (servo under, mix max |e|, mix under) K.
type Row = (&'static str, &'static str, bool, Option<u64>, [f64; 3]);

#[test]
#[ignore = "slow: seven commissionings, 278 s on 2 shared cores"]
fn slow_the_block_films_carry_part_of_the_control_miss() {
    let rows: [Row; 7] = [
        ("big-pump", "all", true, None, [0.576, 1.347, 1.192]),
        ("big-pump", "all,duct,wall", true, None, [0.546, 0.728, 0.728]),
        ("big-pump", "all,duct,wall", false, None, [0.547, 1.447, 1.447]),
        ("big-pump", "all", false, Some(OTHER_MIX), [0.592, 1.412, 1.277]),
        ("big-pump", "all,duct,wall", false, Some(OTHER_MIX), [0.553, 0.676, 0.676]),
        ("leaky-heavy", "all", true, None, LH_CTRL),
        ("leaky-heavy", "all,duct,wall", true, None, LH_DUCT_WALL),
    ];
    let ms = machines();
    let mut bad = Vec::new();
    for (name, switches, train_mix, other, want) in rows {
        let m = ms.iter().find(|m| m.name == name).expect("machine");
        let got = bisection_run(m, &parse_switches(switches), train_mix, other);
        let got = [got.0, got.1, got.2];
        eprintln!("{name} [{switches}] mix trained {train_mix}, other mix {other:?}: servo under {:.3}, mix max {:.3} under {:.3} K (measured {want:?})", got[0], got[1], got[2]);
        if got.iter().zip(want).any(|(g, w)| (g - w).abs() > 0.25) {
            bad.push(format!("{name} [{switches}] {train_mix} {other:?}: {got:.3?} against {want:?}"));
        }
    }
    assert!(bad.is_empty(), "rows off their measured numbers: {bad:#?}");
}

/// Leaky-heavy, the control with the mix trained (measured, K).
const LH_CTRL: [f64; 3] = [0.734, 0.492, 0.492];
/// Leaky-heavy, the control and `duct,wall` with the mix trained (measured, K).
const LH_DUCT_WALL: [f64; 3] = [0.768, 1.241, 0.642];

/// Seed of the other throttle mix (its own draw of speeds and loads, not
/// the held-out log's 3603) added to the training set.
const OTHER_MIX: u64 = 3610;
