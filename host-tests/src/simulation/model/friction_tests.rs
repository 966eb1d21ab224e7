//! Tests of where the pump's friction heat goes: the viscous term's own
//! case share ([`crate::rig::FrictionPairs::viscous_case_share`]) against
//! the one sliding-pair rule for both terms.

use super::{Drive, Model, ReplayDrive};
use crate::hydraulics::OpPoint;
use crate::rig::Rig;
use crate::scenario::{Circuit, ReplayInputs};

/// A throttle replay model of `rig` (its samples are not read: the tests
/// give the operating point themselves).
fn model(rig: Rig) -> Model {
    let z = vec![0.0; 2];
    let inputs = ReplayInputs {
        name: "friction".into(),
        circuit: Circuit::Throttle,
        time_s: vec![0.0, 1.0],
        speed_rpm: z.clone(),
        current_a: z.clone(),
        p_a_bar: z.clone(),
        p_b_bar: z.clone(),
        ambient_c: z,
        position_mm: None,
        air_speed_mps: None,
        lng_valve: None,
    };
    Model::new(rig, Drive::Replay(ReplayDrive::new(inputs)))
}

/// 640 rpm against 48 bar (big-pump's soak start in
/// docs/commissioning-foreign.md).
fn op(rig: &Rig) -> OpPoint {
    OpPoint {
        omega: 640.0 * std::f64::consts::PI / 30.0,
        p_a: 49.0e5,
        p_b: 1.0e5,
        p_case: rig.hydraulics.accumulator_pa,
        x: 0.0,
        v: 0.0,
        q_path: 1e-4,
        current_a: 20.0,
        circuit: Circuit::Throttle,
        ambient_c: 25.0,
        air_mps: 0.0,
    }
}

/// Without a viscous case share the heat is placed exactly as before it
/// existed (the one rule on viscous + pressure, bit for bit); with one, the
/// case oil gets that share of the viscous term and the rule's of the
/// pressure term, the total is kept (1e-12 relative), and the viscous
/// rest divides between delivered oil and housing in the rule's proportion.
#[test]
fn viscous_case_share_places_the_viscous_term_only() {
    let mut rig = Rig::default();
    rig.pump.friction_pairs.case_share_scale = 0.84;
    let m = model(rig.clone());
    let o = op(&rig);
    let tc = 30.0;
    let fr = m.pump_friction(&o, tc);
    assert!(fr.viscous_w > 1.0 && fr.pressure_w > 1.0, "{fr:?}");
    // before: one rule for both terms
    let (d, c, h) = rig.pump.friction_pairs.shares();
    let films = fr.viscous_w + fr.pressure_w;
    let fh = m.friction_heat(&o, tc);
    assert_eq!((fh.delivered, fh.case, fh.housing, fh.internals), (d * films, c * films, fr.no_load_w + h * films, 0.0));
    // the viscous term's own share
    let mut rv = rig.clone();
    rv.pump.friction_pairs.viscous_case_share = Some(0.6);
    let fv = model(rv.clone()).friction_heat(&o, tc);
    let rel = |a: f64, b: f64| ((a - b) / b).abs();
    assert!(rel(fv.case, c * fr.pressure_w + 0.6 * fr.viscous_w) < 1e-12, "{fv:?}");
    assert!(rel(fv.delivered + fv.case + fv.housing, fh.delivered + fh.case + fh.housing) < 1e-12);
    let (rd, _, rh) = rv.pump.friction_pairs.rule_shares();
    let (vd, _, vh) = rv.pump.friction_pairs.viscous_shares();
    assert!(rel(vd / vh, rd / rh) < 1e-12);
    // set at the pressure term's share, it places the heat as the rule does
    rv.pump.friction_pairs.viscous_case_share = Some(c);
    let fs = model(rv).friction_heat(&o, tc);
    for (a, b) in [(fs.delivered, fh.delivered), (fs.case, fh.case), (fs.housing, fh.housing)] {
        assert!(rel(a, b) < 1e-12, "{a} vs {b}");
    }
}
