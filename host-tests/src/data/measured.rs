//! Strict reader and writer of the measured-data format
//! (`docs/measured-data-format.md`): one rig run per file, `# key: value`
//! metadata lines, one CSV header row, one row per sample.
//!
//! Reading never fills, drops or clamps data: an empty cell is a missing
//! sample (`None`); everything the format forbids (missing required column,
//! non-increasing `time_s`, unparsable, non-finite or physically impossible
//! values) is an error that names the file, the line and the column.

use std::collections::BTreeMap;
use std::fmt;
use std::io::{Read, Write};
use std::path::Path;

/// One column of the measured-data table other than `time_s`, with its exact
/// column name, unit and physical range.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Channel {
    /// `speed_rpm`: motor = pump shaft speed, rpm, signed by direction.
    SpeedRpm,
    /// `current_a`: motor phase current, A (RMS).
    CurrentA,
    /// `p_a_bar`: pump port A pressure, bar (gauge).
    PABar,
    /// `p_b_bar`: pump port B pressure, bar (gauge).
    PBBar,
    /// `ambient_c`: ambient air temperature near the actuator, °C.
    AmbientC,
    /// `position_mm`: piston position from the linear encoder, mm.
    PositionMm,
    /// `t_motor_c`: Point 1, centre of the motor body surface, °C.
    TMotorC,
    /// `t_pump_c`: Point 3, centre of the pump body surface, °C.
    TPumpC,
    /// `t_block_c`: Point 4, main valve block surface, °C.
    TBlockC,
    /// `t_ballvalve_c`: Point 5, ball/needle valve block surface, °C.
    TBallvalveC,
    /// `t_oil_c`: oil sensor in the main valve block manifold, °C.
    TOilC,
    /// `lng_valve`: LNG cooling valve command, 0/1 (1 = open).
    LngValve,
    /// `air_speed_mps`: ram-air speed over the housings, m/s.
    AirSpeedMps,
    /// `t_drain_c`: pump drain-port (case) oil temperature, °C — optional
    /// bench thermocouple for commissioning (not in [`Channel::ALL`], which
    /// the fault campaign and the generators iterate; see [`Channel::FORMAT`]).
    TDrainC,
    /// `elec_hz`: the motor drive's electrical (commutation) frequency, Hz,
    /// signed like the speed — the guard's second speed source (optional;
    /// not in [`Channel::ALL`]).
    ElecHz,
    /// `lng_supply_bar`: LNG supply pressure at the valve, bar (gauge) — the
    /// guard's confirmation that the tank has LNG (optional; not in
    /// [`Channel::ALL`]).
    LngSupplyBar,
}

impl Channel {
    /// Every channel the fault campaign and the generators know (the format's
    /// columns without the bench-only `t_drain_c`), in the writer's order.
    pub const ALL: [Channel; 13] = [
        Channel::SpeedRpm,
        Channel::CurrentA,
        Channel::PABar,
        Channel::PBBar,
        Channel::AmbientC,
        Channel::PositionMm,
        Channel::TMotorC,
        Channel::TPumpC,
        Channel::TBlockC,
        Channel::TBallvalveC,
        Channel::TOilC,
        Channel::LngValve,
        Channel::AirSpeedMps,
    ];

    /// Every column of the format other than `time_s`: [`Channel::ALL`] plus
    /// the bench-only `t_drain_c` and the guard's optional inputs `elec_hz`
    /// and `lng_supply_bar`, in the writer's column order.
    pub const FORMAT: [Channel; 16] = {
        let mut f = [Channel::TDrainC; 16];
        let mut i = 0;
        while i < Channel::ALL.len() {
            f[i] = Channel::ALL[i];
            i += 1;
        }
        f[14] = Channel::ElecHz;
        f[15] = Channel::LngSupplyBar;
        f
    };

    /// The measured temperature channels (Points 1, 3, 4, 5 and the manifold
    /// oil sensor), °C.
    pub const TEMPERATURES: [Channel; 5] = [
        Channel::TMotorC,
        Channel::TPumpC,
        Channel::TBlockC,
        Channel::TBallvalveC,
        Channel::TOilC,
    ];

    /// The exact column name of the format.
    pub fn name(self) -> &'static str {
        match self {
            Channel::SpeedRpm => "speed_rpm",
            Channel::CurrentA => "current_a",
            Channel::PABar => "p_a_bar",
            Channel::PBBar => "p_b_bar",
            Channel::AmbientC => "ambient_c",
            Channel::PositionMm => "position_mm",
            Channel::TMotorC => "t_motor_c",
            Channel::TPumpC => "t_pump_c",
            Channel::TBlockC => "t_block_c",
            Channel::TBallvalveC => "t_ballvalve_c",
            Channel::TOilC => "t_oil_c",
            Channel::LngValve => "lng_valve",
            Channel::AirSpeedMps => "air_speed_mps",
            Channel::TDrainC => "t_drain_c",
            Channel::ElecHz => "elec_hz",
            Channel::LngSupplyBar => "lng_supply_bar",
        }
    }

    /// The channel whose column name is `name` (exact match), if any.
    pub fn from_name(name: &str) -> Option<Channel> {
        Channel::FORMAT.into_iter().find(|c| c.name() == name)
    }

    /// Unit as printed in the format's table.
    pub fn unit(self) -> &'static str {
        match self {
            Channel::SpeedRpm => "rpm",
            Channel::CurrentA => "A",
            Channel::PABar | Channel::PBBar | Channel::LngSupplyBar => "bar",
            Channel::ElecHz => "Hz",
            Channel::PositionMm => "mm",
            Channel::LngValve => "0/1",
            Channel::AirSpeedMps => "m/s",
            _ => "°C",
        }
    }

    /// Whether the format requires the column.
    pub fn required(self) -> bool {
        matches!(
            self,
            Channel::SpeedRpm | Channel::CurrentA | Channel::PABar | Channel::PBBar | Channel::AmbientC
        )
    }

    /// Whether the channel is a temperature, °C.
    pub fn is_temperature(self) -> bool {
        matches!(self.unit(), "°C")
    }

    /// Inclusive physical range `(lo, hi)` a value must lie in. The format
    /// fixes temperatures −60…250 °C, pressures −1…700 bar, speed ±20000 rpm
    /// and current 0…2000 A (and the LNG supply pressure like a pressure,
    /// the electrical frequency ±5000 Hz). It gives none for position; for `lng_valve` the
    /// 0/1 command range and for `air_speed_mps` non-negative speeds below
    /// 1000 m/s (far above any ram-air speed) are enforced here.
    pub fn range(self) -> Option<(f64, f64)> {
        match self {
            Channel::SpeedRpm => Some((-20000.0, 20000.0)),
            Channel::CurrentA => Some((0.0, 2000.0)),
            Channel::PABar | Channel::PBBar | Channel::LngSupplyBar => Some((-1.0, 700.0)),
            Channel::ElecHz => Some((-5000.0, 5000.0)),
            Channel::PositionMm => None,
            Channel::LngValve => Some((0.0, 1.0)),
            Channel::AirSpeedMps => Some((0.0, 1000.0)),
            _ => Some((-60.0, 250.0)),
        }
    }
}

impl fmt::Display for Channel {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// One metadata line before the header: `# key: value`, or free text
/// (`key` empty) when the line has no `key:` form.
#[derive(Debug, Clone, PartialEq)]
pub struct MetaLine {
    /// Key (e.g. `rig`, `case`, `ambient_c`, `note`), empty for free text.
    pub key: String,
    /// Value or the free text.
    pub value: String,
}

/// One measured run: metadata, `time_s` (s) and every channel present in
/// the table as a column of optional samples (`None` = empty cell = missing).
#[derive(Debug, Clone, PartialEq)]
pub struct MeasuredRun {
    /// Metadata lines in file order.
    pub metadata: Vec<MetaLine>,
    /// Sample times, s, strictly increasing.
    pub time_s: Vec<f64>,
    /// Channels present in the file, each as long as `time_s`.
    pub channels: BTreeMap<Channel, Vec<Option<f64>>>,
    /// Reader notes (e.g. ignored unknown columns); not written back.
    pub notes: Vec<String>,
}

mod error;
mod read;
pub use error::MeasuredError;
pub use read::*;

impl MeasuredRun {
    /// An empty run with the given times (s) and no channels.
    pub fn new(time_s: Vec<f64>) -> Self {
        MeasuredRun { metadata: Vec::new(), time_s, channels: BTreeMap::new(), notes: Vec::new() }
    }

    /// Number of rows.
    pub fn len(&self) -> usize {
        self.time_s.len()
    }

    /// Whether the run has no rows.
    pub fn is_empty(&self) -> bool {
        self.time_s.is_empty()
    }

    /// The samples of `ch`, if its column is present.
    pub fn get(&self, ch: Channel) -> Option<&[Option<f64>]> {
        self.channels.get(&ch).map(|v| v.as_slice())
    }

    /// Sets (or replaces) channel `ch`.
    pub fn set(&mut self, ch: Channel, values: Vec<Option<f64>>) {
        self.channels.insert(ch, values);
    }

    /// The value of metadata key `key` (first occurrence).
    pub fn meta(&self, key: &str) -> Option<&str> {
        self.metadata.iter().find(|m| m.key == key).map(|m| m.value.as_str())
    }

    /// Adds a `# key: value` metadata line.
    pub fn push_meta(&mut self, key: &str, value: &str) {
        self.metadata.push(MetaLine { key: key.to_string(), value: value.to_string() });
    }

    /// Value of `ch` at time `t` (s) by linear interpolation between the
    /// nearest present samples; held constant beyond the first/last present
    /// sample. `None` if the column is absent or has no sample at all. This
    /// is how a model is *driven* by logged inputs between samples; it never
    /// alters the stored data.
    pub fn value_at(&self, ch: Channel, t: f64) -> Option<f64> {
        let v = self.get(ch)?;
        let idx = self.time_s.partition_point(|&x| x <= t);
        let before = (0..idx).rev().find_map(|i| v[i].map(|y| (self.time_s[i], y)));
        let after = (idx..v.len()).find_map(|i| v[i].map(|y| (self.time_s[i], y)));
        match (before, after) {
            (Some((t0, y0)), Some((t1, y1))) if t1 > t0 => Some(y0 + (y1 - y0) * (t - t0) / (t1 - t0)),
            (Some((_, y0)), _) => Some(y0),
            (None, Some((_, y1))) => Some(y1),
            (None, None) => None,
        }
    }

    /// Checks the rules of the format on a run built in code (lengths,
    /// required channels, time order, finiteness, ranges); `label` names it.
    pub fn validate(&self, label: &str) -> Result<(), MeasuredError> {
        for ch in Channel::ALL.into_iter().filter(|c| c.required()) {
            if !self.channels.contains_key(&ch) {
                return Err(MeasuredError::MissingColumn { file: label.into(), line: 0, column: ch.name().into() });
            }
        }
        for (ch, v) in &self.channels {
            if v.len() != self.time_s.len() {
                return Err(MeasuredError::LengthMismatch {
                    file: label.into(),
                    column: ch.name().into(),
                    got: v.len(),
                    expected: self.time_s.len(),
                });
            }
        }
        for i in 0..self.time_s.len() {
            let line = i as u64 + 2;
            let t = self.time_s[i];
            if !t.is_finite() {
                return Err(MeasuredError::NonFinite { file: label.into(), line, column: "time_s".into(), value: t.to_string() });
            }
            if i > 0 && t <= self.time_s[i - 1] {
                return Err(MeasuredError::TimeNotIncreasing { file: label.into(), line, previous: self.time_s[i - 1], value: t });
            }
            for (ch, v) in &self.channels {
                if let Some(x) = v[i] {
                    check_value(label, line, *ch, x, &x.to_string())?;
                }
            }
        }
        Ok(())
    }

    /// Writes the run in the measured-data format: metadata, header
    /// (`time_s` then the present channels in [`Channel::FORMAT`] order), rows
    /// with shortest round-trip decimal numbers, empty cells for `None`.
    pub fn write<W: Write>(&self, w: W) -> Result<(), MeasuredError> {
        self.validate("<output>")?;
        let io = |e: std::io::Error| MeasuredError::Io { file: "<output>".into(), error: e };
        let mut w = w;
        for m in &self.metadata {
            if m.key.is_empty() {
                writeln!(w, "# {}", m.value).map_err(io)?;
            } else {
                writeln!(w, "# {}: {}", m.key, m.value).map_err(io)?;
            }
        }
        let mut cw = csv::WriterBuilder::new().terminator(csv::Terminator::Any(b'\n')).from_writer(w);
        let cols: Vec<Channel> = Channel::FORMAT.into_iter().filter(|c| self.channels.contains_key(c)).collect();
        let csv_err = |e: csv::Error| MeasuredError::Csv { file: "<output>".into(), line: 0, message: e.to_string() };
        let mut header = vec!["time_s".to_string()];
        header.extend(cols.iter().map(|c| c.name().to_string()));
        cw.write_record(&header).map_err(csv_err)?;
        for i in 0..self.time_s.len() {
            let mut rec = vec![format!("{}", self.time_s[i])];
            for c in &cols {
                rec.push(self.channels[c][i].map(|x| format!("{x}")).unwrap_or_default());
            }
            cw.write_record(&rec).map_err(csv_err)?;
        }
        cw.flush().map_err(io)?;
        Ok(())
    }

    /// Writes the run to `path` (see [`MeasuredRun::write`]).
    pub fn write_file(&self, path: impl AsRef<Path>) -> Result<(), MeasuredError> {
        let p = path.as_ref();
        let f = std::fs::File::create(p).map_err(|e| MeasuredError::Io { file: p.display().to_string(), error: e })?;
        self.write(std::io::BufWriter::new(f))
    }

    /// Reads and validates a measured file from `path`.
    pub fn read_file(path: impl AsRef<Path>) -> Result<MeasuredRun, MeasuredError> {
        let p = path.as_ref();
        let name = p.display().to_string();
        let mut s = String::new();
        std::fs::File::open(p)
            .and_then(|mut f| f.read_to_string(&mut s))
            .map_err(|e| MeasuredError::Io { file: name.clone(), error: e })?;
        parse_str(&name, &s)
    }

    /// Reads and validates measured data from text; `file` names it in errors.
    pub fn from_str_named(file: &str, text: &str) -> Result<MeasuredRun, MeasuredError> {
        parse_str(file, text)
    }
}
