//! Tests of the two replay bookkeeping rules that a servo hold and a charge
//! pressure off the rig file's exposed: the check valves' make-up flow and
//! the ring's direction in a hold.

use super::{Drive, Model, ReplayDrive};
use crate::hydraulics::{self, OpPoint};
use crate::network::N_NODES;
use crate::scenario::ReplayInputs;
use crate::rig::Rig;
use crate::scenario::Circuit;

/// A servo replay drive (its samples are not read: the tests give the
/// operating point themselves).
fn servo_model() -> Model {
    let z = vec![0.0; 2];
    let inputs = ReplayInputs {
        name: "hold".into(),
        circuit: Circuit::Servo,
        time_s: vec![0.0, 1.0],
        speed_rpm: z.clone(),
        current_a: z.clone(),
        p_a_bar: z.clone(),
        p_b_bar: z.clone(),
        ambient_c: z.clone(),
        position_mm: Some(z),
        air_speed_mps: None,
        lng_valve: None,
    };
    Model::new(Rig::default(), Drive::Replay(ReplayDrive::new(inputs)))
}

/// A hold: piston still, the pump turning at `omega` against `p_a`/`p_b`.
fn hold(rig: &Rig, omega: f64, p_a_bar: f64, p_b_bar: f64) -> OpPoint {
    OpPoint {
        omega,
        p_a: p_a_bar * 1e5,
        p_b: p_b_bar * 1e5,
        p_case: rig.hydraulics.accumulator_pa,
        x: 0.0,
        v: 0.0,
        q_path: 0.0,
        current_a: 3.0,
        circuit: Circuit::Servo,
        ambient_c: 25.0,
        air_mps: 0.0,
    }
}

/// Energy input (W) of the model at `op` with every node at 40 °C.
fn energy_in(m: &Model, op: &OpPoint) -> f64 {
    let temps = [40.0; N_NODES];
    let l = m.losses(0.0, op, &temps);
    let mut dt = [0.0; N_NODES];
    m.thermal(op, &l, &temps, &mut dt).0
}

/// A hold against a load on port B (the pump turning backwards to make up
/// B's leakage) is the mirror of one on port A: the same energy input to
/// rounding (1e-9 relative). Taking the ring's direction from the piston
/// (still: "forward") lost the pump's work on B's leakage, 6–23 W on the
/// emulator's servo holds; here K·Δp² at 50 bar.
#[test]
fn a_reverse_servo_hold_books_the_mirror_of_the_forward_one() {
    let m = servo_model();
    let rig = Rig::default();
    let fwd = energy_in(&m, &hold(&rig, 1.5, 50.0, 4.0));
    let rev = energy_in(&m, &hold(&rig, -1.5, 4.0, 50.0));
    assert!(fwd > 0.0);
    assert!((fwd - rev).abs() <= 1e-9 * fwd, "forward hold {fwd:.6} W, reverse {rev:.6} W");
}

/// In a replay the check valves pass no more than the loop loses to the
/// case: with the logged low side 1 bar under the rig file's accumulator
/// (a bench charged at 4 bar) the orifice law alone would pass ~0.1 L/s;
/// limited, the make-up is the leakage to within the soft minimum's width
/// (1e-9 m³/s), and the valve heat is that flow times the 1 bar.
#[test]
fn a_replay_books_only_the_make_up_flow_through_the_check_valves() {
    let rig = Rig::default();
    let op = hold(&rig, 1.5, 50.0, rig.hydraulics.accumulator_pa / 1e5 - 1.0);
    let k = rig.pump.gaps.conductance(rig.oil.mu_pa_s(40.0));
    let mut f = hydraulics::flows(&rig, &op, k);
    let orifice = f.check_a + f.check_b;
    let need = (f.leak_a + f.leak_b).max(0.0); // a port under the case pressure takes case oil
    assert!(orifice > 10.0 * need, "the orifice law {orifice:e} m³/s against the leakage {need:e}");
    hydraulics::limit_check_to_makeup(&mut f);
    assert!((f.check_a + f.check_b - need).abs() <= 1e-9, "make-up {:e} m³/s, leakage {need:e}", f.check_a + f.check_b);
    // Under the need (the low side just under the accumulator) the orifice law stands.
    let op = hold(&rig, 1.5, 50.0, rig.hydraulics.accumulator_pa / 1e5 - 0.001);
    let mut f = hydraulics::flows(&rig, &op, k);
    let orifice = f.check_a + f.check_b;
    hydraulics::limit_check_to_makeup(&mut f);
    assert!(orifice < need && (f.check_a + f.check_b - orifice).abs() <= 1e-9, "orifice {orifice:e}, limited {:e}", f.check_a + f.check_b);
    // And the model's valve heat is the limited flow across the 1 bar.
    let m = servo_model();
    let op = hold(&rig, 1.5, 50.0, rig.hydraulics.accumulator_pa / 1e5 - 1.0);
    let valves = m.losses(0.0, &op, &[40.0; N_NODES]).valves;
    assert!((valves - need * 1e5).abs() <= 1e-3, "valve heat {valves:.4} W, make-up × 1 bar {:.4} W", need * 1e5);
}
