//! The parameter block: blocks whose model cannot protect are refused,
//! with the alarm from the first instant.

use super::*;

/// Boots with the parameter block of `c`; (where the constants came from,
/// the faults at boot, the pins at boot).
fn boot_with_block(c: &crate::model::ModelConsts<f32>) -> (ParamSource, crate::Faults, Pins) {
    let mut b = board();
    b.block = Some(super::tests::flash_block(params_block::encode(c, "test-rig")));
    let app = boot(&mut b);
    (app.params(), app.guard().faults(), b.pins)
}

/// `c` with its `Phi` computed for its own model (as the reduction tool
/// does), so that only the checks of the values can refuse it.
fn rediscretised(mut c: crate::model::ModelConsts<f32>) -> crate::model::ModelConsts<f32> {
    let m = crate::model::Model::<f64>::for_linearisation(&c).expect("values within their bounds");
    let j = m.nominal_jacobian_f32().map(|r| r.map(f64::from));
    c.phi = crate::model::etd_matrix(&j, crate::params::S_PER_STEP).map(|r| r.map(|x| x as f32));
    c
}

/// A block whose every loss coefficient is zero (with its own, consistent
/// `Phi`) passed the format and stability checks although its model never
/// heats: refused now (CONFIG: the bounds table), with the valve open, the
/// alarm and the OK pin low from boot; so is a block whose losses are all
/// within their ranges but 50 times too small to heat at the stated minimum
/// rate (the minimum-heating check).
#[test]
fn a_block_whose_model_cannot_heat_is_refused() {
    let mut zero = crate::model::DEFAULT_CONSTS;
    let mut tiny = zero;
    for (z, t) in [
        (&mut zero.k_lf, &mut tiny.k_lf),
        (&mut zero.k_lf_half, &mut tiny.k_lf_half),
        (&mut zero.k_lp, &mut tiny.k_lp),
        (&mut zero.k_mech, &mut tiny.k_mech),
        (&mut zero.k_cu, &mut tiny.k_cu),
        (&mut zero.fe1, &mut tiny.fe1),
        (&mut zero.fe2, &mut tiny.fe2),
        (&mut zero.fe15, &mut tiny.fe15),
        (&mut zero.k_m0, &mut tiny.k_m0),
        (&mut zero.k_mv, &mut tiny.k_mv),
        (&mut zero.r1, &mut tiny.r1),
        (&mut zero.r2, &mut tiny.r2),
        (&mut zero.k_act, &mut tiny.k_act),
    ] {
        *z = 0.0;
        *t *= 0.02;
    }
    // the zero block's Phi: the default one (its own cannot be built: the
    // model refuses its words); the tiny one's: its own
    for (name, c) in [("zero losses", zero), ("losses x 0.02", rediscretised(tiny))] {
        let (src, f, pins) = boot_with_block(&c);
        assert!(f.contains(faults::CONFIG), "{name} accepted: source {src:?}, faults {f:?}");
        assert!(!pins.valve_pin && !pins.ok_pin, "{name}: valve open and OK low from boot: {pins:?}");
    }
}

/// `k_sh = 0` switched the sensor cross-check off without a word: refused.
#[test]
fn a_block_without_a_torque_constant_is_refused() {
    let c = crate::model::ModelConsts { k_sh: 0.0, ..crate::model::DEFAULT_CONSTS };
    let (src, f, _) = boot_with_block(&c);
    assert!(f.contains(faults::CONFIG), "k_sh = 0 accepted: source {src:?}, faults {f:?}");
}

/// The block's cooling bound at rest is checked against its own model: a
/// bound claiming 100 times the cooling is refused, not trusted.
#[test]
fn a_block_claiming_more_cooling_at_rest_than_its_model_is_refused() {
    let mut c = crate::model::DEFAULT_CONSTS;
    for r in c.rest_rate.iter_mut() {
        *r *= 100.0;
    }
    let (src, f, _) = boot_with_block(&c);
    assert!(f.contains(faults::CONFIG), "rest rate x100 accepted: source {src:?}, faults {f:?}");
}

/// A block that fails its header or CRC: CONFIG with the valve open, the
/// alarm and the OK pin low from the first instant (not after the first
/// sample, up to 10 s later).
#[test]
fn a_refused_block_shows_the_alarm_from_the_first_instant() {
    let mut torn = params_block::encode(&crate::model::DEFAULT_CONSTS, "torn");
    torn[500] ^= 0x10;
    let mut b = board();
    b.block = Some(super::tests::flash_block(torn));
    let app = boot(&mut b);
    let out = app.guard().output();
    assert!(out.faults.contains(faults::CONFIG) && out.valve_open && out.alarm, "{out:?}");
    assert!(!b.pins.valve_pin && !b.pins.ok_pin, "valve pin and OK pin low at boot: {:?}", b.pins);
}
