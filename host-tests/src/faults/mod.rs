//! Fault campaign (`eha-sim faults`): every fault of [`inject`] applied to
//! the product application (the f32 [`eha_guard::product::App`] on the
//! shared in-memory board, the host twin of the flashed image; the faults
//! that need no reboot also on the PIL image in QEMU) in closed loop with
//! the reference plant, in three scenarios (the Fig. 15 LNG case, a random
//! mission, and Case 1 at 60 bar with the LNG tank empty, which reaches the
//! 60 °C alarm), each fault starting at up to three times taken from the
//! scenario's fault-free run: early (30 s, before the valve first opened),
//! after the valve first opened, and hot (after the first alarm, or at the
//! hottest moment of a scenario that never alarms).
//!
//! The controller sends one frame per 10 ms tick with the valve's position
//! switch and the motor drive's electrical frequency (speed faults also
//! run without it: `…+no-elec`; the empty-tank faults also with the LNG
//! supply pressure: `…+supply`); the application takes the newest valid
//! sample of the tick, and a tick without one is a missing sample. Clears
//! and refills are armed and keyed as a controller would send them. A
//! reset or a power loss boots the application again on the same board,
//! from what its memories keep; the board's clock runs on through a power
//! loss (the power-off cooling is on), and a power loss of the whole EHA
//! stops the pump meanwhile. While the MCU is off the valve is open
//! (normally open, the fail-safe design).
//!
//! **Pass rule** per run: from the fault's start, whenever the guard is not
//! in a protected state — a latched fault with the valve commanded open, or
//! the estimate declared untrusted (alarm and derate held) — its drain
//! estimate never under-predicts the true drain by more than
//! [`MAX_UNDER_K`], and the true drain never exceeds [`MAX_CLOSED_C`] while
//! the valve is physically closed; the time between the fault becoming
//! observable and a protected detection within [`DETECT_S`] is exempt.
//! A run that fails is either listed in [`limits::KNOWN_LIMITS`] (a
//! measured design limit, with its reason) or fails the campaign
//! (`eha-sim faults` exits non-zero). The failure-mode table in
//! `docs/failure-modes.md` is generated from `out/faults/faults.json`
//! ([`modes`]).

pub mod inject;
pub mod limits;
pub mod modes;
mod campaign;
mod commander;
mod outcome;
mod run;

pub use campaign::{baselines, campaign, data_json, fast_campaign, fast_subset, jobs, run, run_jobs, table, unlisted_failures, write, FaultsArgs, Job};
pub use outcome::bit_names;
pub use run::{run_case, run_one, runs_on_a_target};

use anyhow::Result;
use serde::{Deserialize, Serialize};

use crate::missions::random_mission;
use crate::scenario::Scenario;
use inject::Fault;

/// Tick of the guard and of the controller's frames, s.
pub const TICK_S: f64 = 0.01;
/// The early start of a fault, s after boot (before the LNG case's first
/// opening at ≈ 78 s).
pub const FAULT_AT_S: f64 = 30.0;
/// Length of the LNG case and the random mission, s.
pub const DURATION_S: f64 = 600.0;
/// Length of the hot scenario (Case 1 at 60 bar, tank empty), s: past the
/// 60 °C alarm.
pub const HOT_DURATION_S: f64 = 900.0;
/// Detection bound of the pass rule, s.
pub const DETECT_S: f64 = 1.0;
/// Under-prediction bound of the pass rule, K.
pub const MAX_UNDER_K: f64 = 1.0;
/// True drain bound while the valve is closed, °C (the 40 °C threshold plus 2 K).
pub const MAX_CLOSED_C: f64 = 42.0;
/// Off-time of the power-loss faults, s.
pub const POWER_OFF_S: f64 = 60.0;
/// Time from a flash that stops writing to the power loss, s.
pub const WRITE_FAIL_TO_POWER_LOSS_S: f64 = 120.0;
/// Seed of the campaign's random mission (`missions::random_mission`).
pub const MISSION_SEED: u64 = 1;

/// A campaign scenario.
#[derive(Debug, Clone)]
pub struct ScenarioSpec {
    /// Name in the results.
    pub name: &'static str,
    /// What the plant runs.
    pub scenario: Scenario,
    /// The LNG tank is empty from the start, and the guard's budget says
    /// so (its record: the charge used up).
    pub tank_empty: bool,
}

impl ScenarioSpec {
    /// Length of a run, s.
    pub fn duration_s(&self) -> f64 {
        self.scenario.duration_s()
    }
}

/// The campaign's scenarios.
pub fn scenarios() -> Vec<ScenarioSpec> {
    vec![
        ScenarioSpec { name: "lng", scenario: Scenario::Lng { duration_s: DURATION_S }, tank_empty: false },
        ScenarioSpec { name: "random-1", scenario: Scenario::Mission(random_mission(MISSION_SEED, DURATION_S)), tank_empty: false },
        ScenarioSpec { name: "hot-60", scenario: Scenario::Case1 { needle_bar: 60.0, duration_s: HOT_DURATION_S }, tank_empty: true },
    ]
}

/// The scenario named `name`.
pub fn scenario(name: &str) -> Option<ScenarioSpec> {
    scenarios().into_iter().find(|s| s.name == name)
}

/// What the controller reports besides the six sensors.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum Inputs {
    /// The valve's position switch and the drive's electrical frequency.
    Full,
    /// The valve's position switch only (no second speed source).
    NoElec,
    /// Both, and the LNG supply pressure.
    Supply,
}

impl Inputs {
    fn suffix(self) -> &'static str {
        match self {
            Inputs::Full => "",
            Inputs::NoElec => "+no-elec",
            Inputs::Supply => "+supply",
        }
    }
}

/// A fault with the inputs the controller reports.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Case {
    /// The fault.
    pub fault: Fault,
    /// The inputs reported besides the sensors.
    pub inputs: Inputs,
}

impl Case {
    /// A fault with the full inputs.
    pub fn new(fault: Fault) -> Self {
        Case { fault, inputs: Inputs::Full }
    }

    /// Name in the results, e.g. `speed/gain-x0.5+no-elec`.
    pub fn name(&self) -> String {
        format!("{}{}", self.fault.name(), self.inputs.suffix())
    }
}

/// Every case of the campaign: the baseline, every fault with the full
/// inputs, the speed faults without the electrical frequency, and the
/// empty-tank faults with the supply pressure.
pub fn cases() -> Vec<Case> {
    let mut v = vec![Case::new(Fault::None)];
    v.extend(Fault::all().into_iter().map(Case::new));
    v.extend(Fault::all().into_iter().filter(Fault::is_speed).map(|f| Case { fault: f, inputs: Inputs::NoElec }));
    v.extend(Fault::all().into_iter().filter(Fault::is_supply).map(|f| Case { fault: f, inputs: Inputs::Supply }));
    v
}

/// When a fault starts.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum StartKind {
    /// [`FAULT_AT_S`], before the valve first opened.
    Early,
    /// 10 s after the valve first opened in the fault-free run.
    Open,
    /// 5 s after the fault-free run's first alarm, or at its hottest true
    /// drain if it never alarms.
    Hot,
}

impl StartKind {
    /// Name in the results.
    pub fn name(self) -> &'static str {
        match self {
            StartKind::Early => "early",
            StartKind::Open => "open",
            StartKind::Hot => "hot",
        }
    }
}

/// A fault's start.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Start {
    /// Which.
    pub kind: StartKind,
    /// When, s after boot.
    pub at_s: f64,
}

/// What the fault-free run of a scenario shows (the start times).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Baseline {
    /// First valve opening, s.
    pub first_open_s: Option<f64>,
    /// First alarm, s.
    pub first_alarm_s: Option<f64>,
    /// Hottest true drain, °C, and when, s.
    pub peak_c: f64,
    /// When the true drain was hottest, s.
    pub peak_s: f64,
}

/// The fault-free run of `spec`.
pub fn baseline(spec: &ScenarioSpec) -> Result<Baseline> {
    let start = Start { kind: StartKind::Early, at_s: FAULT_AT_S };
    let r = run_case(Case::new(Fault::None), spec, start, None)?;
    Ok(Baseline { first_open_s: r.first_open_s, first_alarm_s: r.first_alarm_s, peak_c: r.peak_true_drain_c, peak_s: r.peak_s })
}

/// The start times of `spec` from its baseline: early, open and hot, the
/// later two only when they exist and leave a minute of run after them.
pub fn starts(spec: &ScenarioSpec, b: &Baseline) -> Vec<Start> {
    let end = spec.duration_s() - 60.0;
    let mut v = vec![Start { kind: StartKind::Early, at_s: FAULT_AT_S }];
    let snap = |t: f64| (t / TICK_S).round() * TICK_S;
    if let Some(t) = b.first_open_s.map(|t| snap(t + 10.0)).filter(|t| *t > FAULT_AT_S && *t < end) {
        v.push(Start { kind: StartKind::Open, at_s: t });
    }
    let hot = b.first_alarm_s.map_or(b.peak_s, |t| t + 5.0);
    let hot = snap(hot);
    if hot > FAULT_AT_S && hot < end && v.iter().all(|s| (s.at_s - hot).abs() > 5.0) {
        v.push(Start { kind: StartKind::Hot, at_s: hot });
    }
    v
}

/// One row of `faults.json`.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct FaultResult {
    /// Case name ([`Case::name`]).
    pub fault: String,
    /// Scenario name.
    pub scenario: String,
    /// When the fault started ([`StartKind::name`]).
    pub start: String,
    /// When the fault started, s after boot.
    pub start_s: f64,
    /// A fault or status bit came up after the fault started.
    pub detected: bool,
    /// Time from the fault becoming observable to that, s.
    pub detect_s: Option<f64>,
    /// The bits that came up (fault-word names).
    pub detect_bits: Option<String>,
    /// What the guard did then: valve open, alarm, derate.
    pub action: Option<String>,
    /// Largest under-prediction of the true drain while not protected, K.
    pub max_under_k: f64,
    /// Hottest true drain while the valve was physically closed and the
    /// guard not protected, °C (None: never).
    pub max_true_drain_closed_c: Option<f64>,
    /// Hottest true drain from the fault's start on, °C.
    pub peak_true_drain_c: f64,
    /// When the true drain was hottest, s.
    pub peak_s: f64,
    /// The first valve opening, s (the baseline's start times).
    pub first_open_s: Option<f64>,
    /// The first alarm, s.
    pub first_alarm_s: Option<f64>,
    /// Clears or refills the guard did (of those the controller confirmed).
    pub commands_done: u32,
    /// The pass rule.
    pub pass: bool,
    /// A failing run's entry in [`limits::KNOWN_LIMITS`]: why the design
    /// cannot meet the rule.
    pub limit: Option<String>,
}
