//! Scenarios: the paper's test cases (Case 1, Case 2, the LNG case of
//! Fig. 15), missions from a CSV of inputs, and replay of measured inputs.

use serde::{Deserialize, Serialize};
use std::cell::Cell;
use std::path::Path;

/// Hydraulic configuration of the rig (paper, Section III.A).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Circuit {
    /// Case 1: needle valves 4.2/4.3 closed, ball valve open, the pump flow
    /// throttled by needle valve 4.1; the cylinder is isolated.
    #[default]
    Throttle,
    /// Case 2: ball valve closed, the pump drives the cylinder against the
    /// spring under closed-loop position control.
    Servo,
}

/// A piecewise-linear schedule of (time s, value) points; constant outside.
/// Two points at the same time make a step.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Schedule(pub Vec<(f64, f64)>);

impl Schedule {
    /// A constant schedule.
    pub fn constant(v: f64) -> Self {
        Schedule(vec![(0.0, v)])
    }

    /// Value at time `t` (linear between points, held outside).
    pub fn at(&self, t: f64) -> f64 {
        let pts = &self.0;
        let Some(first) = pts.first() else { return 0.0 };
        if t <= first.0 {
            return first.1;
        }
        // Last point with time <= t.
        let idx = pts.partition_point(|p| p.0 <= t);
        match (pts.get(idx.wrapping_sub(1)), pts.get(idx)) {
            (Some(a), Some(b)) if b.0 > a.0 => a.1 + (b.1 - a.1) * (t - a.0) / (b.0 - a.0),
            (Some(a), _) => a.1,
            _ => first.1,
        }
    }

    /// Times at which the schedule has a kink or a step (solver stops there).
    pub fn breakpoints(&self) -> impl Iterator<Item = f64> + '_ {
        self.0.iter().map(|p| p.0)
    }
}

/// Position reference of the servo circuit, m.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum PositionRef {
    /// x = offset + amplitude·sin(2π·f·t) (Case 2: 20 mm, 0.2 Hz).
    Sine {
        /// Amplitude, m.
        amplitude_m: f64,
        /// Frequency, Hz.
        freq_hz: f64,
        /// Offset, m.
        offset_m: f64,
    },
    /// A piecewise-linear position schedule, m.
    Profile(Schedule),
}

impl PositionRef {
    /// Reference position (m) and velocity (m/s) at `t`.
    pub fn at(&self, t: f64) -> (f64, f64) {
        match self {
            PositionRef::Sine { amplitude_m, freq_hz, offset_m } => {
                // The last answer is kept per thread, keyed by the bits of
                // the sine and of t (the answer is the value computed): the
                // hydraulic integration asks at the same t for a Jacobian's
                // columns and for a step's last stage and end point.
                thread_local! {
                    static LAST: Cell<([u64; 4], (f64, f64))> = const { Cell::new(([u64::MAX; 4], (f64::NAN, f64::NAN))) };
                }
                let key = [amplitude_m.to_bits(), freq_hz.to_bits(), offset_m.to_bits(), t.to_bits()];
                LAST.with(|c| {
                    let (k, v) = c.get();
                    if k == key {
                        return v;
                    }
                    let w = 2.0 * std::f64::consts::PI * freq_hz;
                    let v = (offset_m + amplitude_m * (w * t).sin(), amplitude_m * w * (w * t).cos());
                    c.set((key, v));
                    v
                })
            }
            PositionRef::Profile(s) => {
                let h = 1e-3;
                (s.at(t), (s.at(t + h) - s.at(t - h)) / (2.0 * h))
            }
        }
    }
}

/// How the LNG valve is commanded.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum ValveRule {
    /// No LNG exchanger in the circuit (valve always closed).
    None,
    /// The paper's thermostat on the circulating-oil temperature (Fig. 15).
    LoopOil,
    /// A thermostat on the true drain-port temperature (what the firmware
    /// estimates; used to judge the firmware's switching times).
    Drain,
    /// Commanded from outside (the firmware in the loop).
    External,
}

/// A driven mission of the reference model.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Mission {
    /// Name used in outputs.
    pub name: String,
    /// Hydraulic configuration.
    pub circuit: Circuit,
    /// Duration, s.
    pub duration_s: f64,
    /// Ambient temperature, °C.
    pub ambient_c: Schedule,
    /// Motor speed command, rpm (throttle circuit).
    pub speed_rpm: Schedule,
    /// Needle-valve setting: its pressure drop at the 500 rpm reference flow, bar
    /// (throttle circuit; 0 = fully open).
    pub needle_bar: Schedule,
    /// Position reference (servo circuit).
    pub position: PositionRef,
    /// Ram-air speed over the housings, m/s.
    pub air_speed_mps: Schedule,
    /// LNG valve rule.
    pub valve: ValveRule,
}

/// Measured inputs for replay: the input columns of a measured-data file,
/// missing cells already bridged by linear interpolation between the
/// neighbouring samples of the same channel (never extrapolated).
#[derive(Debug, Clone, PartialEq)]
pub struct ReplayInputs {
    /// Name used in outputs.
    pub name: String,
    /// Hydraulic circuit of the run: stated in the log (`# circuit:`) or
    /// inferred from the piston's travel (`diagnosis::reference::circuit_of`),
    /// never from which columns the file has.
    pub circuit: Circuit,
    /// Sample times, s (strictly increasing).
    pub time_s: Vec<f64>,
    /// Motor speed, rpm.
    pub speed_rpm: Vec<f64>,
    /// Motor current, A rms.
    pub current_a: Vec<f64>,
    /// Port A pressure, bar gauge.
    pub p_a_bar: Vec<f64>,
    /// Port B pressure, bar gauge.
    pub p_b_bar: Vec<f64>,
    /// Ambient, °C.
    pub ambient_c: Vec<f64>,
    /// Piston position, mm (absent: not logged; the servo circuit needs it).
    pub position_mm: Option<Vec<f64>>,
    /// Logged ram-air speed, m/s (absent: still air).
    pub air_speed_mps: Option<Vec<f64>>,
    /// Logged LNG valve command (absent: closed).
    pub lng_valve: Option<Vec<f64>>,
}

/// A scenario to simulate.
#[derive(Debug, Clone, PartialEq)]
pub enum Scenario {
    /// Case 1: 16 °C ambient, 500 rpm, needle valve at `needle_bar`.
    Case1 {
        /// Needle-valve differential pressure, bar (paper: 0, 20, 40, 60).
        needle_bar: f64,
        /// Duration, s (paper: 600).
        duration_s: f64,
    },
    /// Case 2: 26.4 °C ambient, closed-loop tracking of a 20 mm, 0.2 Hz sine.
    Case2 {
        /// Duration, s.
        duration_s: f64,
    },
    /// Fig. 15: Case 1 at 60 bar with the LNG exchanger and its 40 °C valve.
    Lng {
        /// Duration, s.
        duration_s: f64,
    },
    /// A general mission.
    Mission(Mission),
    /// Replay of measured inputs.
    Replay(ReplayInputs),
}

impl Scenario {
    /// Duration of the scenario, s.
    pub fn duration_s(&self) -> f64 {
        match self {
            Scenario::Case1 { duration_s, .. } | Scenario::Case2 { duration_s } | Scenario::Lng { duration_s } => *duration_s,
            Scenario::Mission(m) => m.duration_s,
            Scenario::Replay(r) => r.time_s.last().copied().unwrap_or(0.0),
        }
    }

    /// The mission of a paper case (None for replay).
    pub fn mission(&self) -> Option<Mission> {
        let throttle = |name: &str, bar: f64, d: f64, valve| Mission {
            name: name.into(),
            circuit: Circuit::Throttle,
            duration_s: d,
            ambient_c: Schedule::constant(16.0),
            speed_rpm: Schedule::constant(500.0),
            needle_bar: Schedule::constant(bar),
            position: PositionRef::Profile(Schedule::constant(0.0)),
            air_speed_mps: Schedule::constant(0.0),
            valve,
        };
        match self {
            Scenario::Case1 { needle_bar, duration_s } => {
                Some(throttle(&format!("case1-{needle_bar}bar"), *needle_bar, *duration_s, ValveRule::None))
            }
            Scenario::Lng { duration_s } => Some(throttle("lng-fig15", 60.0, *duration_s, ValveRule::LoopOil)),
            Scenario::Case2 { duration_s } => Some(Mission {
                name: "case2".into(),
                circuit: Circuit::Servo,
                duration_s: *duration_s,
                ambient_c: Schedule::constant(26.4),
                speed_rpm: Schedule::constant(0.0),
                needle_bar: Schedule::constant(0.0),
                position: PositionRef::Sine { amplitude_m: 0.020, freq_hz: 0.2, offset_m: 0.0 },
                air_speed_mps: Schedule::constant(0.0),
                valve: ValveRule::None,
            }),
            Scenario::Mission(m) => Some(m.clone()),
            Scenario::Replay(_) => None,
        }
    }
}

/// One row of a mission CSV (`time_s,speed_rpm,needle_bar,position_mm,ambient_c,air_speed_mps`).
#[derive(Debug, Deserialize)]
struct MissionRow {
    time_s: f64,
    speed_rpm: Option<f64>,
    needle_bar: Option<f64>,
    position_mm: Option<f64>,
    ambient_c: f64,
    air_speed_mps: Option<f64>,
}

/// Errors of mission files.
#[derive(Debug, thiserror::Error)]
pub enum MissionError {
    /// I/O or CSV syntax error, with the file and position.
    #[error("{path}: {message}")]
    Csv {
        /// File.
        path: String,
        /// Message with line (and field) from the csv crate.
        message: String,
    },
    /// A semantic problem at a line.
    #[error("{path}:{line}: {message}")]
    Invalid {
        /// File.
        path: String,
        /// 1-based line.
        line: u64,
        /// What was expected.
        message: String,
    },
}

/// Read a mission from a CSV of inputs with header
/// `time_s,speed_rpm,needle_bar,position_mm,ambient_c,air_speed_mps`:
/// a throttle mission if `position_mm` is empty throughout, else a servo
/// mission whose position reference is the `position_mm` profile.
pub fn read_mission_csv(path: &Path, valve: ValveRule) -> Result<Mission, MissionError> {
    let p = path.display().to_string();
    let file = std::fs::File::open(path).map_err(|e| MissionError::Csv { path: p.clone(), message: e.to_string() })?;
    let name = path.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
    read_mission(file, &p, name, valve)
}

/// [`read_mission_csv`] on CSV text held in memory: `path` names it in
/// errors, `name` becomes the mission's name.
pub fn read_mission_str(text: &str, path: &str, name: &str, valve: ValveRule) -> Result<Mission, MissionError> {
    read_mission(text.as_bytes(), path, name.to_string(), valve)
}

fn read_mission<R: std::io::Read>(src: R, path: &str, name: String, valve: ValveRule) -> Result<Mission, MissionError> {
    let p = path.to_string();
    let mut rdr = csv::ReaderBuilder::new().comment(Some(b'#')).trim(csv::Trim::All).from_reader(src);
    let (mut speed, mut needle, mut pos, mut amb, mut air) = (vec![], vec![], vec![], vec![], vec![]);
    let headers = rdr.headers().map_err(|e| MissionError::Csv { path: p.clone(), message: e.to_string() })?.clone();
    let mut last_t = f64::NEG_INFINITY;
    for rec in rdr.records() {
        let rec = rec.map_err(|e| MissionError::Csv { path: p.clone(), message: e.to_string() })?;
        let line = rec.position().map_or(0, |q| q.line());
        let row: MissionRow =
            rec.deserialize(Some(&headers)).map_err(|e| MissionError::Csv { path: p.clone(), message: e.to_string() })?;
        let bad = |column: &str, v: f64, want: &str| MissionError::Invalid {
            path: p.clone(),
            line,
            message: format!("column `{column}`: {v} is not {want}"),
        };
        // Every value must be a finite number in its physical range: a NaN or
        // an infinity would silently poison the simulation.
        let check = |column: &str, v: f64, lo: f64, hi: f64| {
            if v.is_finite() && (lo..=hi).contains(&v) {
                Ok(v)
            } else {
                Err(bad(column, v, &format!("a finite number in [{lo}, {hi}]")))
            }
        };
        let t = check("time_s", row.time_s, 0.0, 1e7)?;
        if t < last_t {
            return Err(bad("time_s", t, &format!("at or after the previous row's {last_t} s")));
        }
        last_t = t;
        if let Some(v) = row.speed_rpm {
            speed.push((t, check("speed_rpm", v, -1e5, 1e5)?));
        }
        if let Some(v) = row.needle_bar {
            needle.push((t, check("needle_bar", v, 0.0, 1e4)?));
        }
        if let Some(v) = row.position_mm {
            pos.push((t, check("position_mm", v, -1e4, 1e4)? * 1e-3));
        }
        amb.push((t, check("ambient_c", row.ambient_c, -100.0, 200.0)?));
        air.push((t, check("air_speed_mps", row.air_speed_mps.unwrap_or(0.0), 0.0, 1e3)?));
    }
    if amb.is_empty() {
        return Err(MissionError::Invalid { path: p, line: 1, message: "no rows".into() });
    }
    let circuit = if pos.is_empty() { Circuit::Throttle } else { Circuit::Servo };
    Ok(Mission {
        name,
        circuit,
        duration_s: last_t,
        ambient_c: Schedule(amb),
        speed_rpm: Schedule(if speed.is_empty() { vec![(0.0, 0.0)] } else { speed }),
        needle_bar: Schedule(if needle.is_empty() { vec![(0.0, 0.0)] } else { needle }),
        position: PositionRef::Profile(Schedule(if pos.is_empty() { vec![(0.0, 0.0)] } else { pos })),
        air_speed_mps: Schedule(air),
        valve,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn schedule_interpolates_and_steps() {
        let s = Schedule(vec![(0.0, 1.0), (10.0, 3.0), (10.0, 5.0), (20.0, 5.0)]);
        assert_eq!(s.at(-1.0), 1.0);
        assert!((s.at(5.0) - 2.0).abs() < 1e-12);
        assert_eq!(s.at(10.0), 5.0);
        assert_eq!(s.at(30.0), 5.0);
    }

    /// Non-finite or out-of-range values are refused with file, line and
    /// column; before this check `inf` and `NaN` were accepted silently.
    #[test]
    fn mission_rejects_non_finite_values_with_line_and_column() {
        let head = "time_s,speed_rpm,needle_bar,position_mm,ambient_c,air_speed_mps\n";
        for (row, col) in [
            ("1,inf,60,,20,0", "speed_rpm"),
            ("1,500,NaN,,20,0", "needle_bar"),
            ("1,500,60,,-inf,0", "ambient_c"),
            ("nan,500,60,,20,0", "time_s"),
            ("1,500,60,,20,-3", "air_speed_mps"),
        ] {
            let text = format!("{head}0,500,60,,20,0\n{row}\n");
            let e = read_mission_str(&text, "m.csv", "m", ValveRule::None).unwrap_err().to_string();
            assert!(e.starts_with("m.csv:3: column `") && e.contains(col), "{row}: {e}");
        }
        let e = read_mission_str(&format!("{head}5,500,60,,20,0\n4,500,60,,20,0\n"), "m.csv", "m", ValveRule::None)
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("m.csv:3: column `time_s`"), "{e}");
        let ok = read_mission_str(&format!("{head}0,500,60,,20,0\n10,500,60,,20,0\n"), "m.csv", "m", ValveRule::None);
        assert_eq!(ok.map(|m| m.duration_s).ok(), Some(10.0));
    }
}
