//! Replay of a logged run: the inputs a measured log drives the model with
//! (`Scenario::Replay`), the hydraulic circuit it was logged on, and the
//! solver tolerance of replays. Shared by the diagnosis, the commissioning
//! calibration and the command line.

use crate::measured::{Channel, MeasuredRun};
use crate::scenario::{Circuit, ReplayInputs};

/// Why a log's input columns cannot drive the model.
#[derive(Debug, thiserror::Error)]
pub enum ReplayError {
    /// A required input column has no sample at all.
    #[error("input column `{0}` has no sample; the model cannot be driven")]
    EmptyInput(&'static str),
    /// The hydraulic circuit is stated wrongly or cannot be told.
    #[error("{0}")]
    Circuit(String),
}

/// Piston travel (max − min of `position_mm`) at or below which a log is a
/// throttle run (the cylinder isolated; encoder noise and creep), mm.
pub const THROTTLE_MAX_TRAVEL_MM: f64 = 0.5;
/// Piston travel at or above which a log is a servo run, mm.
pub const SERVO_MIN_TRAVEL_MM: f64 = 2.0;

/// The hydraulic circuit of `run`: the `# circuit: throttle|servo` metadata
/// line when there is one (checked against the data), else inferred from the
/// piston: no `position_mm` column, or a travel of at most
/// [`THROTTLE_MAX_TRAVEL_MM`], is the throttle circuit; a travel of at least
/// [`SERVO_MIN_TRAVEL_MM`] the servo circuit; in between the log is
/// ambiguous and refused with the line to add.
pub fn circuit_of(run: &MeasuredRun) -> Result<Circuit, ReplayError> {
    let travel = run.get(Channel::PositionMm).map(|p| {
        let (lo, hi) = p.iter().flatten().fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &x| (lo.min(x), hi.max(x)));
        if hi >= lo {
            hi - lo
        } else {
            0.0
        }
    });
    let stated = run.metadata.iter().enumerate().find(|(_, m)| m.key == "circuit");
    match stated {
        Some((i, m)) => {
            let line = i + 1;
            match (m.value.trim(), travel) {
                ("throttle", Some(t)) if t > THROTTLE_MAX_TRAVEL_MM => Err(ReplayError::Circuit(format!(
                    "line {line}: `# circuit: throttle`, but position_mm travels {t:.2} mm (the throttle circuit isolates the cylinder: at most {THROTTLE_MAX_TRAVEL_MM} mm)"
                ))),
                ("throttle", _) => Ok(Circuit::Throttle),
                ("servo", None) => Err(ReplayError::Circuit(format!(
                    "line {line}: `# circuit: servo`, but the log has no position_mm column (a servo replay is driven by the piston position)"
                ))),
                ("servo", Some(_)) => Ok(Circuit::Servo),
                (other, _) => Err(ReplayError::Circuit(format!("line {line}: `# circuit: {other}`: expected `throttle` or `servo`"))),
            }
        }
        None => match travel {
            None => Ok(Circuit::Throttle),
            Some(t) if t <= THROTTLE_MAX_TRAVEL_MM => Ok(Circuit::Throttle),
            Some(t) if t >= SERVO_MIN_TRAVEL_MM => Ok(Circuit::Servo),
            Some(t) => Err(ReplayError::Circuit(format!(
                "position_mm travels {t:.2} mm: neither a stationary piston (throttle circuit, <= {THROTTLE_MAX_TRAVEL_MM} mm) nor a servo run (>= {SERVO_MIN_TRAVEL_MM} mm); state the circuit with a metadata line `# circuit: throttle` or `# circuit: servo` before the header"
            ))),
        },
    }
}

/// Replay inputs from the input columns of `run`: gaps bridged by linear
/// interpolation between the neighbouring samples, held constant before the
/// first and after the last sample (see [`MeasuredRun::value_at`]).
pub fn replay_inputs(run: &MeasuredRun, name: &str) -> Result<ReplayInputs, ReplayError> {
    let col = |ch: Channel| -> Option<Vec<f64>> {
        run.get(ch)?;
        run.time_s.iter().map(|&t| run.value_at(ch, t)).collect()
    };
    let req = |ch: Channel| col(ch).ok_or(ReplayError::EmptyInput(ch.name()));
    let circuit = circuit_of(run)?;
    Ok(ReplayInputs {
        name: name.into(),
        circuit,
        time_s: run.time_s.clone(),
        speed_rpm: req(Channel::SpeedRpm)?,
        current_a: req(Channel::CurrentA)?,
        p_a_bar: req(Channel::PABar)?,
        p_b_bar: req(Channel::PBBar)?,
        ambient_c: req(Channel::AmbientC)?,
        position_mm: col(Channel::PositionMm),
        air_speed_mps: col(Channel::AirSpeedMps),
        lng_valve: col(Channel::LngValve),
    })
}

/// Relative tolerance of the solver in the diagnosis replays. Measured
/// against 1e-7 on 1200 s synthetic logs: max temperature error 1.4e-2 K on
/// a servo log at 0.1 s (15.6 k steps; 1.6e-3 K and 28 k steps at the
/// simulation's default 1e-6), 1.6e-3 K on a throttle log: an order of
/// magnitude below the 0.1 K sensor noise, at half the run time. The
/// finite-difference Jacobian of the fit perturbs parameters by 2 % in log
/// space, far above this integration error.
pub const REPLAY_RTOL: f64 = 1e-5;
