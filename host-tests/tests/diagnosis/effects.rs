//! Hidden-effect tests of the diagnosis (issue 5). Each case: the reference
//! simulation with one extension switched on at a random realistic
//! magnitude (`eha_sim::diagnosis::synth::magnitude_range`), nuisance
//! multipliers perturbed ±10–20 % (and, in the `Structure` cases, every node
//! mass and the winding conductance changed individually by ×0.8…1.25,
//! which the baseline's global multipliers cannot represent), σ = 0.1 K
//! sensor noise, 12-bit quantisation, dropped rows and cells; then the
//! diagnosis runs blind on the default rig. The test names say which effect
//! is hidden; the diagnosis only sees the measured run.
//!
//! Assertions and why:
//! - the named cause equals the hidden one — every candidate in at least
//!   two scenarios, chosen to excite it (issue 5); `none` for runs without a
//!   hidden effect, with the nuisance physics as in the rig file or
//!   different from it (no false discovery);
//! - the held-out RMSE of the channel the effect changes most (measured on
//!   the generator: with vs without the effect over the last 30 %) falls by
//!   at least 50 % once the named extension is switched on (issue 5).
//!
//! Seeds are fixed (one per case, chosen before the method changes and not
//! re-drawn); how the method does over other draws is the sweep
//! (`eha-sim diagnose-sweep`, and the `#[ignore]`d test at the end), whose
//! hit rates are in docs/diagnosis.md. Run in release mode: each case is
//! ~600–1000 model runs of 20–40 ms (throttle) or 0.2–0.5 s (servo).

use eha_sim::diagnosis::sweep::{run_case, CaseResult};
use eha_sim::diagnosis::synth::{Mismatch, SynthCase, SynthScenario};
use eha_sim::diagnosis::{Candidate, DiagnoseOptions};
use rayon::prelude::*;

fn case(hidden: &str, scenario: SynthScenario, mismatch: Mismatch, seed: u64) -> SynthCase {
    let hidden = Candidate::from_name(hidden).expect("candidate name");
    SynthCase { hidden, scenario, mismatch, seed, duration_s: 1200.0, sample_s: 2.0 }
}

/// Runs the cases in parallel and checks the verdict and the gain.
fn check(cases: &[SynthCase]) {
    let results: Vec<Result<CaseResult, String>> = cases
        .par_iter()
        .map(|c| {
            let r = run_case(*c, &DiagnoseOptions::default());
            if let Ok(r) = &r {
                eprintln!("{} magnitude {:.4}\n{}", r.line(), r.magnitude, r.detail());
            }
            r
        })
        .collect();
    let mut failures = Vec::new();
    for r in results {
        let r = r.expect("case must generate and diagnose");
        if r.named != r.case.hidden {
            failures.push(format!("wrong cause: {}", r.line()));
        } else if r.case.hidden != Candidate::None {
            let g = r.affected_gain().expect("affected channel measured");
            if g < 0.5 {
                failures.push(format!("held-out gain {:.0} % < 50 %: {}", 100.0 * g, r.line()));
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

use Mismatch::{Nuisance, Structure};
use SynthScenario::{
    AirSteps, Case1Pressure, LoadCycles, PressureSpeedSteps, ServoGust, ServoHoldMove, ServoProfile, SpeedSweep,
    ThrottleSteps,
};

/// Dead-end oil sensor: a lag of minutes on t_oil_c, visible in any run.
#[test]
fn hidden_sensor_lag_is_named() {
    check(&[case("sensor-lag", Case1Pressure, Nuisance, 31), case("sensor-lag", ThrottleSteps, Structure, 32)]);
}

/// Copper resistance rising with temperature: extra heat ∝ I²·(T_w − 25 °C)
/// in the winding. Case 1 (constant current, the winding warming) and
/// current steps (throttle pressure steps).
#[test]
fn hidden_winding_resistance_temperature_is_named() {
    check(&[
        case("winding-resistance-temperature", Case1Pressure, Nuisance, 11),
        case("winding-resistance-temperature", ThrottleSteps, Structure, 12),
    ]);
}

/// Viscosity following the oil temperature: leakage heat (∝ Δp²/μ(T)) moves
/// from the throttle to the pump case as the oil warms, and the oil film
/// conductances change. Needs high pressure while the oil warms: load
/// cycles to 70–100 bar, and speed steps at a 70–100 bar drop
/// (`PressureSpeedSteps`). In Case 1 (≤ 60 bar) and in the random throttle
/// steps the nuisance calibration absorbs it (see the ignored test below).
#[test]
fn hidden_viscosity_temperature_is_named() {
    check(&[
        case("viscosity-temperature", LoadCycles, Nuisance, 21),
        case("viscosity-temperature", LoadCycles, Structure, 22),
        case("viscosity-temperature", PressureSpeedSteps, Nuisance, 25),
        case("viscosity-temperature", PressureSpeedSteps, Structure, 26),
    ]);
}

#[test]
#[ignore = "measured miss: in random throttle steps (10–100 bar) the viscosity effect is absorbed by the nuisance set (nuisance case: none, calibrated baseline already 0.158 K on t_oil_c, best channel gain 17 %; structure case: named winding-resistance-temperature with alpha at its 1e-2 bound)"]
fn hidden_viscosity_temperature_in_throttle_steps() {
    check(&[
        case("viscosity-temperature", ThrottleSteps, Nuisance, 23),
        case("viscosity-temperature", ThrottleSteps, Structure, 22),
    ]);
}

/// Coulomb seal friction: heat F·|v| in the actuator body, carried to the
/// oil by the tidal exchange. It needs servo missions in which the piston
/// speed does not follow the load: holding a deflection against the spring
/// alternating with manoeuvres about the centre (`ServoHoldMove`), and
/// gust rejection about trims drawn independently of the gusts
/// (`ServoGust`), both logged at 0.1 s. Measured: 722 N named at 667 N,
/// t_oil_c 0.275 → 0.102 K (63 %); 968 N named at 1533 N, t_oil_c
/// 0.247 → 0.106 K (57 %). 250–380 s per case.
#[test]
fn hidden_coulomb_friction_is_named() {
    check(&[case("coulomb-friction", ServoHoldMove, Nuisance, 45), case("coulomb-friction", ServoGust, Nuisance, 47)]);
}

#[test]
#[ignore = "measured miss: with per-node capacities off the baseline both named none. Hold/move (1198 N): coulomb-friction fitted 1399 N, dBIC 174, t_oil_c 0.326 -> 0.158 K (51 %), but t_motor_c 0.156 -> 0.278 K and t_pump_c 0.250 -> 0.276 K, pooled held-out 4 % < 20 %. Gusts (535 N): 0.46 K imprint, calibrated baseline already at 0.102 K on t_oil_c (coulomb dBIC 159, pooled 10 %). Slow: 300 s per case."]
fn hidden_coulomb_friction_with_structure_mismatch() {
    check(&[case("coulomb-friction", ServoHoldMove, Structure, 46), case("coulomb-friction", ServoGust, Structure, 48)]);
}

#[test]
#[ignore = "measured miss: in ServoProfile (brisk and slow duty segments, logged at 0.5 s) the friction heat grows with the stroke together with the load losses. Nuisance case (554 N): 0.38 K imprint on t_oil_c, calibrated baseline already at 0.150 K, named none. Structure case (942 N): coulomb-friction fitted 565 N, dBIC 92, t_oil_c -61 %, but pooled held-out 16 % < 20 %: none. Slow: 300-600 s per case."]
fn hidden_coulomb_friction_in_servo_profile() {
    check(&[case("coulomb-friction", ServoProfile, Nuisance, 41), case("coulomb-friction", ServoProfile, Structure, 42)]);
}

/// Churning ∝ ω^2.5: needs shaft-speed changes (a constant-speed run cannot
/// tell it from a pump capacity error, so the diagnosis does not name it
/// there).
#[test]
fn hidden_churning_loss_is_named() {
    check(&[case("churning-loss", ThrottleSteps, Nuisance, 51), case("churning-loss", SpeedSweep, Structure, 52)]);
}

/// Flange conduction motor → pump: the pump follows the motor.
#[test]
fn hidden_motor_pump_conduction_is_named() {
    check(&[
        case("motor-pump-conduction", Case1Pressure, Nuisance, 61),
        case("motor-pump-conduction", ThrottleSteps, Structure, 62),
    ]);
}

/// Unlogged draught over the housings: Case 1 in still air, and Case 1
/// with logged ram-air steps (the hidden draught adds to the logged air,
/// so the missing cooling changes with the logged air speed).
#[test]
fn hidden_forced_convection_is_named() {
    check(&[case("forced-convection", Case1Pressure, Nuisance, 71), case("forced-convection", AirSteps, Nuisance, 71)]);
}

#[test]
#[ignore = "measured miss: with per-node capacities off the baseline, a 5.5 m/s draught in the ram-air run is named none (the forced-convection fit gains 14 % on the best channel, motor-pump-conduction 26 %)"]
fn hidden_forced_convection_with_structure_mismatch() {
    check(&[case("forced-convection", AirSteps, Structure, 72)]);
}

/// No hidden effect, nuisance multipliers off the rig file: `none`.
#[test]
fn no_hidden_effect_gives_none_when_only_nuisance_differs() {
    check(&[
        case("none", Case1Pressure, Nuisance, 81),
        case("none", ThrottleSteps, Nuisance, 82),
        case("none", LoadCycles, Nuisance, 85),
        case("none", PressureSpeedSteps, Nuisance, 92),
    ]);
}

/// No hidden effect, per-node capacities and the winding conductance off
/// the baseline (`Structure`): still `none`. These were false discoveries
/// before the pooled held-out gain and the churning identifiability rule.
#[test]
fn no_hidden_effect_gives_none_when_structure_differs() {
    check(&[
        case("none", SpeedSweep, Structure, 84),
        case("none", LoadCycles, Structure, 86),
        case("none", AirSteps, Structure, 88),
    ]);
}

#[test]
#[ignore = "measured false discovery: high-pressure speed steps (70-100 bar, 500-1200 rpm) with per-node capacities off the baseline and nothing hidden are named churning-loss (9e-4 W/(rad/s)^2.5, dBIC 1173, pooled held-out 0.928 -> 0.318 K, t_block_c 1.41 -> 0.38 K): the oil and blocks warm by tens of kelvin, the capacity errors leave ~1 K on the housings, and a speed-dependent pump heat fits them"]
fn no_hidden_effect_in_high_pressure_speed_steps_with_structure_mismatch() {
    check(&[case("none", PressureSpeedSteps, Structure, 93)]);
}

/// The same in the servo missions that name Coulomb friction: no false
/// Coulomb friction or churning (measured: none; best candidate ΔBIC 13.7
/// (hold/move, Coulomb 174 N) and −4.0 (gusts)).
#[test]
fn no_hidden_effect_gives_none_in_servo_when_structure_differs() {
    check(&[case("none", ServoHoldMove, Structure, 89), case("none", ServoGust, Structure, 91)]);
}

/// And in the brisk/slow servo profile. Passes (measured: none, best
/// candidate ΔBIC < 1), ignored only because this replay takes 100–300 s.
#[test]
#[ignore = "slow: servo replay, 100-300 s"]
fn no_hidden_effect_gives_none_in_servo_profile_when_structure_differs() {
    check(&[case("none", ServoProfile, Structure, 83)]);
}

/// The large sweep: every effect × scenario × mismatch × 2 seeds, 1800 s
/// runs (~200 cases, hours on 2 cores with the servo runs). Also available
/// as `eha-sim diagnose-sweep`.
#[test]
#[ignore]
fn large_hidden_effect_sweep() {
    let a = eha_sim::diagnosis::sweep::SweepArgs { seeds: 2, duration: 1800.0, sample: 2.0, no_servo: false };
    let cases = eha_sim::diagnosis::sweep::sweep_cases(&a);
    check(&cases);
}


