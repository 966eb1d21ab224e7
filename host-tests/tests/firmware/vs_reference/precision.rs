//! The sensor cross-check's margin on the acceptance runs, and f32 and
//! fixed point against f64 on two of them.

use super::*;

/// The sensor cross-check on every acceptance run: the largest disagreement of the
/// two loss estimates over its windows (2 s means) against its bound (5 W, from the
/// estimate's error budget: `eha_guard::crosscheck`). No run may trip it (the bound
/// tests above assert no latched fault); here the margin: measured at most 0.073 W on
/// the throttle runs and 2.07 W on random-5 (servo), regression bound 3 W. The servo
/// run's disagreement is the cross-check's own approximation: the current's sign is
/// not measured, so when an aiding load drives the pump at low pressure (friction
/// torque above `D dp`) the shaft power is read with the wrong sign; the pump's
/// no-load torque (extended eq. 8) makes that case common at low speed.
#[test]
fn sensor_cross_check_margin_on_the_acceptance_runs() {
    let cfg = GuardConfig::DEFAULT.crosscheck;
    let steps = cfg.window_ticks.div_ceil(eha_guard::params::TICKS_PER_STEP) as usize;
    let mut worst = 0.0f64;
    for r in runs() {
        let w = r
            .mech_pairs
            .chunks_exact(steps)
            .map(|c| (c.iter().map(|(p, i)| i - p).sum::<f64>() / steps as f64).abs())
            .fold(0.0, f64::max);
        let peak = r.mech_pairs.iter().map(|(p, _)| *p).fold(0.0, f64::max);
        println!("{:>14}: largest window disagreement {w:.4} W (bound {} W, margin {:.0}x); peak mechanical loss {peak:.0} W", r.name, cfg.bound_w, cfg.bound_w as f64 / w.max(1e-9));
        assert!(!r.faults.intersects(faults::SENSOR_DISAGREE), "{}", r.name);
        worst = worst.max(w);
    }
    println!("worst {worst:.4} W");
    assert!(worst <= 3.0, "window disagreement {worst} W on reference signals (regression bound 3 W)");
}

/// f32 within 0.01 K and fixed point within 0.1 K of f64, on two runs: Case 1 at
/// 60 bar (largest losses) and the LNG case (exchanger credit switching).
///
/// Each guard credits the exchanger by its *own* valve command. Once two number
/// types decide a valve switching one tick apart (a 1e-6 K difference at the
/// 40 degC threshold is enough), their estimates differ by that tick's credit,
/// which the loop then carries for a while: that is the valve's timing, not the
/// arithmetic. The precision bounds apply up to the first tick at which the two
/// valve commands differ; after it the difference is printed and held to the
/// regression bound [`REG_FX_SWITCHED_K`] (measured 0.120 K for fixed point: the
/// valve cycles every 20 s at 40 degC in these runs).
#[test]
fn number_types_agree_on_a_reference_run() {
    for name in ["case1-60bar", "lng"] {
        let run = runs().iter().find(|r| r.name == name).expect("run");
        let (d64, v64, _) = guard_drain_valve::<f64>(run);
        let (d32, v32, _) = guard_drain_valve::<f32>(run);
        let (dfx, vfx, _) = guard_drain_valve::<Fx>(run);
        let split = |v: &[bool]| v64.iter().zip(v).position(|(a, b)| a != b).unwrap_or(v64.len());
        let max_diff = |d: &[f64], from: usize, to: usize| d64[from..to].iter().zip(&d[from..to]).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
        let (s32, sfx) = (split(&v32), split(&vfx));
        let e32 = max_diff(&d32, 0, s32);
        let efx = max_diff(&dfx, 0, sfx);
        let efx_after = max_diff(&dfx, sfx, d64.len());
        println!(
            "{name}: |f32 - f64| max {e32:.2e} K (valves agree over {s32} of {} ticks), |fixed - f64| max {efx:.2e} K up to tick {sfx}, {efx_after:.3} K after",
            d64.len()
        );
        // Issue (spec): f32 within 0.01 K of f64.
        assert!(e32 <= 0.01, "{name}: f32 {e32} K");
        // Regression: 2.6x the measured 3.81e-6 K.
        assert!(e32 <= REG_F32_K, "{name}: f32 {e32:.2e} K > regression bound {REG_F32_K:.0e} K");
        // Issue (spec): fixed point within 0.1 K of f64.
        assert!(efx <= 0.1, "{name}: fixed {efx} K");
        assert!(efx_after <= REG_FX_SWITCHED_K, "{name}: fixed after a differing valve decision {efx_after} K");
    }
}

/// Regression bound on the fixed-point estimate's difference from f64 after the
/// two first decide a valve switching differently, K (1.7x the measured 0.120 K).
const REG_FX_SWITCHED_K: f64 = 0.2;
