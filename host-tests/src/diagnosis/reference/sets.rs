//! Which calibration parameters a diagnosis frees on a log: the nuisance
//! set (sensors, inputs and excitation the log carries), and the
//! structural set the pump's loss taken from the current adds to it.

use super::circuit_of;
use crate::calibration::{self, set::Needs};
use crate::diagnosis::analysis::Structure;
use crate::measured::{Channel, MeasuredRun};

/// The calibration parameters (indices into [`calibration::PARAMS`]) the
/// diagnosis calibrates on `run`: those whose sensor is among the
/// diagnosis's channels ([`Channel::TEMPERATURES`], logged), without the
/// loss coefficients that only speed and pressure steps separate when the
/// run has one operating point (the calibration's rule), without the
/// needle split on servo runs (no throttling; the circuit by
/// [`circuit_of`]), without `block_wall`
/// unless the run moves speed and load independently (its
/// [`Needs::SensorWithJointExcitation`]), and without
/// [`calibration::set::DUCT_TURBULENT`] (a commissioning freedom).
pub fn nuisance_set(run: &MeasuredRun) -> Vec<usize> {
    nuisance_set_of(run, &[run])
}

/// The calibration parameters one machine's logs share ([`nuisance_set`]
/// for several logs): sensors, inputs and excitation judged on `run`
/// (every log's rows on one table, e.g. [`crate::diagnosis::multi::combine`]'s), the
/// needle split left out only when every log in `logs` is a servo circuit.
pub fn nuisance_set_of(run: &MeasuredRun, logs: &[&MeasuredRun]) -> Vec<usize> {
    let logged = |ch: Channel| Channel::TEMPERATURES.contains(&ch) && run.get(ch).is_some_and(|v| v.iter().any(Option::is_some));
    let one_point = calibration::ident::one_point(run);
    // The circuit by the log's rule (stated, or the piston's travel), never
    // by whether a position column exists.
    let servo = !logs.is_empty() && logs.iter().all(|l| matches!(circuit_of(l), Ok(crate::scenario::Circuit::Servo)));
    calibration::PARAMS
        .iter()
        .enumerate()
        .filter(|(_, d)| match d.needs {
            Needs::Sensor(ch) => logged(ch),
            Needs::Input(ch) => calibration::log::input_above_zero(run, ch),
            Needs::SensorWithJointExcitation(ch) => logged(ch) && calibration::ident::independent_speed_and_load(run),
            Needs::Nothing => true,
        })
        .filter(|(_, d)| !(one_point && ["leak_gap", "iron_loss", "winding_r", "needle_split"].contains(&d.name)))
        .filter(|(_, d)| !(servo && d.name == "needle_split"))
        // the ducts' turbulent level is a commissioning freedom (freed when
        // the logs run the block flow through the transition hot); the
        // diagnosis's admission and probabilities were measured without it
        .filter(|(_, d)| d.name != calibration::set::DUCT_TURBULENT)
        .map(|(k, _)| k)
        .collect()
}

/// The physical set `free` (indices into [`calibration::PARAMS`]) with the
/// pump's loss level taken from the current ([`super::ReferenceModel::with_structure`]):
/// `pump_friction` left out, the friction heat's case share and speed law
/// ([`calibration::set::FRICTION_CASE`], [`calibration::set::FRICTION_SPEED`])
/// and the surface probes' reading towards ambient of every housing channel
/// `run` logs added, in [`calibration::PARAMS`] order. The calibration
/// frees these only with a drain thermocouple (their `Needs`); the
/// diagnosis's channels have none, so here they rest on the housing
/// sensors and the current alone. [`Structure::NoCase`] leaves out
/// `friction_case` and `probe_surface_pump` (the two a drain thermocouple
/// would separate); [`Structure::NoCaseHeld`] also holds [`HELD_OIL`] at the
/// rig file; [`Structure::Off`] returns `free` unchanged.
pub fn structural_set(run: &MeasuredRun, free: &[usize], variant: Structure) -> Vec<usize> {
    use calibration::set::{index, FRICTION_CASE, FRICTION_SPEED, PROBE_SURFACE};
    if variant == Structure::Off {
        return free.to_vec();
    }
    let logged = |ch: Channel| run.get(ch).is_some_and(|v| v.iter().any(Option::is_some));
    let probes = [Channel::TMotorC, Channel::TPumpC, Channel::TBlockC, Channel::TBallvalveC];
    let friction = index("pump_friction");
    let mut out: Vec<usize> = free.iter().copied().filter(|&k| Some(k) != friction).collect();
    let add = [FRICTION_CASE, FRICTION_SPEED].into_iter().chain(PROBE_SURFACE.iter().zip(probes).filter(|(_, ch)| logged(*ch)).map(|(n, _)| *n));
    let no_case = matches!(variant, Structure::NoCase | Structure::NoCaseHeld);
    let kept = add.filter(|n| !(no_case && (*n == FRICTION_CASE || *n == PROBE_SURFACE[1])));
    out.extend(kept.filter_map(index));
    if variant == Structure::NoCaseHeld {
        let held: Vec<usize> = HELD_OIL.iter().filter_map(|n| index(n)).collect();
        out.retain(|k| !held.contains(k));
    }
    out.sort_unstable();
    out.dedup();
    out
}

/// The calibration parameters [`Structure::NoCaseHeld`] holds at the rig
/// file: the loop oil's capacity and the oil probe's response time. Under
/// the structure option they sit at their upper bounds (×3, ×5) on the
/// emulator's 1704 and carry its dead-end pocket's lag (t_oil_c 0.21 K
/// held out against 0.45 K without the option); priors narrower than the
/// calibration set's did not move them (σ 0.05 on `cap_loop_oil` left it
/// at ×2.9: holding both costs its baseline ≈ 170 K² of training
/// residual, the prior row ≈ 18), so they are held. docs/diagnosis-limits.md,
/// "The structure option and why `no-case-held` is the default".
pub const HELD_OIL: [&str; 2] = ["cap_loop_oil", calibration::set::PROBE_OIL];
