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

use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};
use eha_guard::memory::ThermalRecord;
use eha_guard::product::mem_board::MemBoard;
use eha_guard::product::wire::{command_key, AckResult, Cmd, Command, FromGuard};
use eha_guard::protocol::Request;
use eha_guard::{faults as fbits, Faults, GuardConfig, Output, Sample};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::missions::random_mission;
use crate::pil::sil::AppTarget;
use crate::pil::Target;
use crate::plant::{Control, Plant, Sensors};
use crate::rig::Rig;
use crate::scenario::{PositionRef, Schedule, Scenario};
use inject::{corrupt_sample, Channel, Fault, Gauss, InputFault};

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
/// The board clock's reading at boot, s.
const RTC0: u32 = 1_000_000;
/// Motor pole pairs of the paper rig (the parameter word `pole_pairs`).
const POLE_PAIRS: f64 = 4.0;

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

/// The MCU: the application on its board; a reboot boots it again on the
/// same board.
struct Mcu {
    app: AppTarget<f32>,
}

impl Mcu {
    fn boot(board: Box<MemBoard>) -> Self {
        Mcu { app: AppTarget::boot(&GuardConfig::DEFAULT, board) }
    }

    /// A reset: no-init RAM and flash keep their contents.
    fn reset(self, damage: Damage) -> Self {
        let mut board = self.app.into_board();
        board.warm_reset();
        let [a, b] = board.records;
        let newest = usize::from(eha_guard::memory::seq_newer(b.seq(), a.seq()));
        for (i, r) in board.records.iter_mut().enumerate() {
            let hit = match damage {
                Damage::None => false,
                Damage::Newest => i == newest,
                Damage::Both => true,
            };
            if hit {
                // One word half written.
                r.temps_c[0] = f32::from_bits(r.temps_c[0].to_bits() ^ 0x0040_0000);
            }
        }
        if damage == Damage::Both {
            board.set_flash_faults(true, false);
        }
        Mcu::boot(board)
    }
}

#[derive(Clone, Copy, PartialEq, Eq)]
enum Damage {
    None,
    Newest,
    Both,
}

/// A record whose LNG charge is used up, node temperatures at `ambient_c`.
fn lng_empty_record(cfg: &GuardConfig, ambient_c: f32) -> ThermalRecord {
    let used_cj = (f64::from(cfg.lng.charge_kg()) * f64::from(cfg.lng.j_per_kg()) * 100.0).ceil() as u32;
    ThermalRecord::new([ambient_c; eha_guard::params::N_NODES], ambient_c, used_cj, 0, 0).with_seq(1, false)
}

/// `s` with its value held at `off` (or at its value at `t0`) from `t0` to
/// `t1`, as it was before and after.
fn hold(s: &Schedule, t0: f64, t1: f64, off: Option<f64>) -> Schedule {
    let (v0, v1) = (s.at(t0), s.at(t1));
    let h = off.unwrap_or(v0);
    let mut p: Vec<(f64, f64)> = s.0.iter().copied().filter(|p| p.0 < t0).collect();
    p.extend([(t0, v0), (t0, h), (t1, h), (t1, v1)]);
    p.extend(s.0.iter().copied().filter(|p| p.0 > t1));
    Schedule(p)
}

/// `sc` with the machine stopped from `t0` to `t1` (a power loss of the
/// whole EHA: pump at rest, needle open, the piston held).
fn machine_off(sc: &Scenario, t0: f64, t1: f64) -> Result<Scenario> {
    let mut m = sc.mission().context("a mission")?;
    m.speed_rpm = hold(&m.speed_rpm, t0, t1, Some(0.0));
    m.needle_bar = hold(&m.needle_bar, t0, t1, Some(0.0));
    if let PositionRef::Profile(p) = &m.position {
        m.position = PositionRef::Profile(hold(p, t0, t1, None));
    }
    Ok(Scenario::Mission(m))
}

/// Whether a case runs on a target given from outside (the PIL image in
/// QEMU): those that need no reboot, no preset memory and no flash.
pub fn runs_on_a_target(fault: Fault) -> bool {
    !matches!(
        fault,
        Fault::WarmReset
            | Fault::PowerLoss
            | Fault::PowerLossMachineRunning
            | Fault::TornRecordWrite
            | Fault::LngEmpty
            | Fault::RefillWhileEmpty
            | Fault::FlashWriteFail
            | Fault::FlashReadFail
            | Fault::CorruptStartClear
    )
}

/// A controller that arms and confirms a command (a clear or a refill)
/// every `period` ticks from tick `from`, with the key of the default rig id.
struct Commander {
    arm: Cmd,
    confirm: Cmd,
    next: u64,
    period: u64,
    nonce: Option<u32>,
    token: u16,
    done: u32,
}

impl Commander {
    fn new(arm: Cmd, confirm: Cmd, from: u64, period: u64) -> Self {
        Commander { arm, confirm, next: from, period, nonce: None, token: 0x4000, done: 0 }
    }

    /// This tick's command frame, if any.
    fn frame(&mut self, k: u64) -> Option<Vec<u8>> {
        self.token = self.token.wrapping_add(1);
        if let Some(n) = self.nonce.take() {
            let arg = command_key(&[0; 16], n, self.confirm);
            return Some(Command { token: self.token, cmd: self.confirm, arg }.encode().as_slice().to_vec());
        }
        if k >= self.next {
            self.next = k + self.period;
            return Some(Command { token: self.token, cmd: self.arm, arg: 0 }.encode().as_slice().to_vec());
        }
        None
    }

    /// The acknowledgements of the tick.
    fn read(&mut self, others: &[FromGuard]) {
        for f in others {
            if let FromGuard::Ack(a) = f {
                if a.cmd == self.arm && a.result == AckResult::Done {
                    self.nonce = Some(a.value);
                } else if a.cmd == self.confirm && a.result == AckResult::Done {
                    self.done += 1;
                }
            }
        }
    }
}

/// The guard is protecting: a latched fault with the valve commanded open,
/// or the estimate untrusted (alarm and derate held).
fn protected(o: &Output) -> bool {
    (o.faults.intersects(fbits::LATCHED) && o.valve_open) || o.faults.contains(fbits::UNTRUSTED)
}

/// The bits whose appearance counts as a detection.
const DETECT_MASK: Faults = Faults::from_bits(
    fbits::LATCHED.bits() | fbits::UNTRUSTED.bits() | fbits::NV_FAILED.bits() | fbits::NO_VALVE_FEEDBACK.bits() | fbits::LNG_LOW.bits(),
);

/// The named members of a fault set, `+`-separated (channels as
/// `ch:<name>`).
pub fn bit_names(f: Faults) -> String {
    let dbg = format!("{f:?}");
    let inner = dbg.trim_start_matches("Faults(").trim_end_matches(')');
    let mut out: Vec<String> = inner.split(" | ").filter(|p| !p.starts_with("channels")).map(str::to_string).collect();
    for c in Channel::ALL {
        let ch = eha_guard::ChannelSet::channel(Channel::ALL.iter().position(|x| *x == c).unwrap_or(0));
        if f.channel_set().contains(ch) {
            out.push(format!("ch:{}", c.name()));
        }
    }
    out.join(" + ")
}

fn action(o: &Output) -> String {
    let mut a = Vec::new();
    if o.valve_open {
        a.push("valve open");
    }
    if o.alarm {
        a.push("alarm");
    }
    if o.derate {
        a.push("derate");
    }
    if a.is_empty() {
        "none".into()
    } else {
        a.join(", ")
    }
}

/// Run one case in one scenario from `start` on the host application.
pub fn run_one(case: Case, spec: &ScenarioSpec, start: Start) -> Result<FaultResult> {
    run_case(case, spec, start, None)
}

/// Run one case in one scenario from `start`; with `target` (the PIL image
/// in QEMU, in lockstep) instead of the host application. It must give the
/// same result as on the host, bit for bit ([`runs_on_a_target`] says which
/// faults can).
pub fn run_case(case: Case, spec: &ScenarioSpec, start: Start, mut target: Option<&mut dyn Target>) -> Result<FaultResult> {
    let fault = case.fault;
    if target.is_some() && !runs_on_a_target(fault) {
        bail!("{}: reboots, preset memories and flash faults run on the host application only", fault.name());
    }
    let t_start = start.at_s;
    let k_start = (t_start / TICK_S).round() as u64;
    // Power losses: when, and whether the machine stops meanwhile.
    let power_off: Option<(f64, bool)> = match fault {
        Fault::PowerLoss | Fault::FlashReadFail => Some((t_start, true)),
        Fault::FlashWriteFail => Some((t_start + WRITE_FAIL_TO_POWER_LOSS_S, true)),
        Fault::PowerLossMachineRunning => Some((t_start, false)),
        _ => None,
    };
    let k_off = power_off.map(|(t, _)| (t / TICK_S).round() as u64);
    let scenario = match power_off {
        Some((t, true)) => machine_off(&spec.scenario, t, t + POWER_OFF_S)?,
        _ => spec.scenario.clone(),
    };
    let duration = spec.duration_s();
    let mut target_error: Option<anyhow::Error> = None;
    let rig = Rig::default();
    let mut plant = Plant::new(&rig, &scenario).context("plant")?;
    let cfg = GuardConfig::DEFAULT;
    let first = Sensors::from(&plant.snapshot()).sample();
    let mut board = Box::new(MemBoard::new().with_nv());
    board.rtc = Some(RTC0);
    board.rtc_backup = Some(0);
    let budget_empty = spec.tank_empty || matches!(fault, Fault::LngEmpty | Fault::RefillWhileEmpty);
    if budget_empty {
        board.records[0] = lng_empty_record(&cfg, first.ambient_c);
    }
    let mut mcu = Some(Mcu::boot(board));
    let mut off_board: Option<Box<MemBoard>> = None;
    let mut rng = Gauss::new(0x5EED ^ fault.name().len() as u64);
    let mut cmd = match fault {
        Fault::ClearSpam => Some(Commander::new(Cmd::ClearArm, Cmd::ClearConfirm, k_start, 100)),
        Fault::CorruptStartClear => Some(Commander::new(Cmd::ClearArm, Cmd::ClearConfirm, k_start + 200, 1000)),
        Fault::RefillWhileEmpty => Some(Commander::new(Cmd::RefillArm, Cmd::RefillConfirm, k_start, 1000)),
        _ => None,
    };
    let input = match fault {
        Fault::Input(c, f) => Some((c, f)),
        Fault::ClearSpam => Some((Channel::PressureA, InputFault::StuckZero)),
        _ => None,
    };
    let mut seq: u16 = 0;
    let mut out: Option<Output> = None;
    let mut frozen: Option<f32> = None;
    let mut held: Option<Vec<u8>> = None; // out-of-order: a frame held back
    let mut k: u64 = 0;
    let mut before = Faults::NONE;
    let mut observable_at: Option<f64> = None;
    let mut detect: Option<(f64, Faults, Output)> = None;
    // per tick after the start, while not protected: (t, under K, closed drain °C)
    let mut exposed: Vec<(f64, f64, f64)> = Vec::new();
    let mut powered_off_until: Option<f64> = None;
    let mut stuck_closed = false;
    let mut valve_position = false;
    let mut first_open: Option<f64> = None;
    let mut first_alarm: Option<f64> = None;
    let (mut peak, mut peak_s) = (f64::NEG_INFINITY, 0.0);
    plant
        .run(TICK_S, duration, |snap| {
            let s = Sensors::from(snap);
            let t = s.t;
            let active = k >= k_start;
            if k == k_start {
                before = out.map_or(Faults::NONE, |o| o.faults & DETECT_MASK);
                match fault {
                    Fault::WarmReset | Fault::TornRecordWrite | Fault::CorruptStartClear => {
                        let damage = match fault {
                            Fault::TornRecordWrite => Damage::Newest,
                            Fault::CorruptStartClear => Damage::Both,
                            _ => Damage::None,
                        };
                        if let Some(m) = mcu.take() {
                            mcu = Some(m.reset(damage));
                        }
                    }
                    Fault::ValveStuckClosed => stuck_closed = true,
                    Fault::FlashWriteFail => {
                        if let Some(m) = mcu.as_mut() {
                            m.app.board.set_flash_faults(false, true);
                        }
                    }
                    _ => {}
                }
                if fault != Fault::ValveStuckClosed {
                    observable_at = Some(t);
                }
            }
            if Some(k) == k_off {
                if let Some(m) = mcu.take() {
                    let mut b = m.app.into_board();
                    b.power_loss();
                    off_board = Some(b);
                }
                powered_off_until = Some(t + POWER_OFF_S);
            }
            if let Some(until) = powered_off_until {
                if t >= until - 1e-9 {
                    // Power back: RAM is lost, the flash and the clock remain.
                    if let Some(mut b) = off_board.take() {
                        if fault == Fault::FlashReadFail {
                            b.set_flash_faults(true, false);
                        }
                        mcu = Some(Mcu::boot(b));
                    }
                    powered_off_until = None;
                    seq = 0;
                }
            }
            // The board's clock (runs through a power loss).
            let rtc = Some(RTC0 + t as u32);
            if let Some(m) = mcu.as_mut() {
                m.app.board.rtc = rtc;
            }
            if let Some(b) = off_board.as_mut() {
                b.rtc = rtc;
            }
            // The physical tank: empty from the start, or from the fault on.
            let tank_empty = budget_empty || (active && fault == Fault::LngEmptyPhysical);
            // The controller's frame for this tick.
            let truth: Sample = s.sample();
            let mut sample = truth;
            if let (true, Some((c, f))) = (active, input) {
                let fz = *frozen.get_or_insert_with(|| c.get(&sample));
                corrupt_sample(&mut sample, c, f, t - t_start, fz, &mut rng);
            }
            let send = match fault {
                Fault::LateStart => t >= 5.0 - 1e-9,
                Fault::DropoutBursts => !(active && ((t - t_start) % 10.0) < 0.5 - 1e-9),
                _ => true,
            };
            let fb = !(active && fault == Fault::NoValveFeedback);
            let reports = eha_guard::Reports {
                // The valve's position switch: where the valve really is.
                valve_fb: fb.then_some(valve_position),
                elec_hz: (case.inputs != Inputs::NoElec).then(|| (f64::from(truth.speed_rpm) * POLE_PAIRS / 60.0) as f32),
                lng_supply_bar: (case.inputs == Inputs::Supply).then_some(if tank_empty { 0.0 } else { 5.0 }),
            };
            let req = Request { seq, sample, reports };
            seq = seq.wrapping_add(1);
            if let Some(m) = mcu.as_mut() {
                let mut wire: Vec<u8> = Vec::new();
                if send {
                    let mut frame: Vec<u8> = req.encode().as_slice().to_vec();
                    if active && fault == Fault::CorruptedFrames && k.is_multiple_of(50) && frame.len() > 4 {
                        frame[3] ^= 0x10;
                    }
                    if active && fault == Fault::OutOfOrderFrames && k.is_multiple_of(40) {
                        held = Some(frame);
                    } else {
                        wire.extend_from_slice(&frame);
                        if let Some(h) = held.take() {
                            wire.extend_from_slice(&h);
                        }
                    }
                }
                if let Some(c) = cmd.as_mut().filter(|_| active) {
                    if let Some(f) = c.frame(k) {
                        wire.extend_from_slice(&f);
                    }
                }
                let res = match target.as_deref_mut() {
                    Some(t) => t.tick(&wire, k),
                    None => m.app.tick(&wire, k),
                };
                match res {
                    Ok(r) => {
                        if let Some(c) = cmd.as_mut() {
                            c.read(&r.others);
                        }
                        out = Some(r.reply.out);
                    }
                    Err(e) => {
                        target_error = Some(e.into());
                        return Ok(Control { lng_valve: None, stop: true });
                    }
                }
            } else {
                out = None;
            }
            // Physical valve: open while the MCU is off (normally-open valve).
            let commanded = match (&mcu, out) {
                (None, _) => true,
                (Some(_), Some(o)) => o.valve_open,
                (Some(_), None) => true,
            };
            let physical = commanded && !stuck_closed;
            valve_position = physical;
            let cooling = physical && !tank_empty;
            if stuck_closed && commanded && observable_at.is_none() {
                observable_at = Some(t);
            }
            if let (Some(_), Some(o)) = (&mcu, out) {
                if o.valve_open && first_open.is_none() && t > 1.0 {
                    first_open = Some(t);
                }
                if o.alarm && first_alarm.is_none() && t > 1.0 {
                    first_alarm = Some(t);
                }
            }
            if active {
                if s.t_drain_c > peak {
                    (peak, peak_s) = (s.t_drain_c, t);
                }
                if let (Some(_), Some(o)) = (&mcu, out) {
                    let new = o.faults & DETECT_MASK & !before;
                    if !new.is_empty() && detect.is_none() {
                        if let Some(t0) = observable_at {
                            detect = Some(((t - t0).max(0.0), new, o));
                        }
                    }
                    if !protected(&o) {
                        let under = if o.drain_c < 1.0e5 { s.t_drain_c - f64::from(o.drain_c) } else { f64::NEG_INFINITY };
                        let closed = if physical { f64::NEG_INFINITY } else { s.t_drain_c };
                        exposed.push((t, under, closed));
                    }
                }
            }
            k += 1;
            Ok(Control { lng_valve: Some(cooling), stop: false })
        })
        .context("closed-loop run")?;
    if let Some(e) = target_error {
        return Err(e.context(format!("{} on the target", fault.name())));
    }
    // A protected detection within DETECT_S exempts the time before it.
    let grace = match (observable_at, detect) {
        (Some(t0), Some((d, _, o))) if d <= DETECT_S && protected(&o) => Some((t0, t0 + d)),
        _ => None,
    };
    let counted = exposed.iter().filter(|(t, _, _)| grace.is_none_or(|(a, b)| *t < a - 1e-9 || *t > b + 1e-9));
    let (mut max_under, mut max_closed) = (f64::NEG_INFINITY, f64::NEG_INFINITY);
    for (_, u, c) in counted {
        max_under = max_under.max(*u);
        max_closed = max_closed.max(*c);
    }
    let max_under_k = if max_under.is_finite() { max_under } else { 0.0 };
    let max_true_drain_closed_c = max_closed.is_finite().then_some(max_closed);
    let pass = max_under_k <= MAX_UNDER_K && max_true_drain_closed_c.is_none_or(|c| c <= MAX_CLOSED_C);
    Ok(FaultResult {
        fault: case.name(),
        scenario: spec.name.into(),
        start: start.kind.name().into(),
        start_s: t_start,
        detected: detect.is_some(),
        detect_s: detect.map(|d| d.0),
        detect_bits: detect.map(|d| bit_names(d.1)),
        action: detect.map(|d| action(&d.2)),
        max_under_k,
        max_true_drain_closed_c,
        peak_true_drain_c: peak,
        peak_s,
        first_open_s: first_open,
        first_alarm_s: first_alarm,
        commands_done: cmd.map_or(0, |c| c.done),
        pass,
        limit: None,
    })
}

/// A run of the campaign: a case, a scenario, a start.
#[derive(Debug, Clone)]
pub struct Job {
    /// The case.
    pub case: Case,
    /// The scenario (index into [`scenarios`]).
    pub scenario: usize,
    /// The start.
    pub start: Start,
}

/// Every run of the campaign: each case in each scenario at each of the
/// scenario's start times (a fault that acts from boot at the early one
/// only). The baselines run first (in parallel).
pub fn jobs(cases: &[Case]) -> Result<(Vec<ScenarioSpec>, Vec<Job>)> {
    let sc = scenarios();
    let base = baselines(&sc)?;
    let mut v = Vec::new();
    for c in cases {
        for (i, (spec, b)) in sc.iter().zip(&base).enumerate() {
            for st in starts(spec, b) {
                if c.fault.from_boot() && st.kind != StartKind::Early {
                    continue;
                }
                v.push(Job { case: *c, scenario: i, start: st });
            }
        }
    }
    Ok((sc, v))
}

/// The fault-free runs of `sc` (in parallel).
pub fn baselines(sc: &[ScenarioSpec]) -> Result<Vec<Baseline>> {
    sc.par_iter().map(baseline).collect()
}

/// Runs `jobs` (in parallel) and marks each failing run's listed limit.
pub fn run_jobs(sc: &[ScenarioSpec], jobs: &[Job]) -> Result<Vec<FaultResult>> {
    let mut rows: Vec<FaultResult> = jobs.par_iter().map(|j| run_one(j.case, &sc[j.scenario], j.start)).collect::<Result<_>>()?;
    for r in rows.iter_mut().filter(|r| !r.pass) {
        r.limit = limits::find(r).map(|l| l.reason.to_string());
    }
    Ok(rows)
}

/// The whole campaign.
pub fn campaign() -> Result<Vec<FaultResult>> {
    let (sc, jobs) = jobs(&cases())?;
    run_jobs(&sc, &jobs)
}

/// The fast tier's subset: one run per kind of fault and per scenario,
/// the hot starts and the new faults first (about 25 runs).
pub fn fast_subset() -> Vec<(Case, &'static str, StartKind)> {
    use StartKind::{Early, Hot, Open};
    let input = |c, f| Case::new(Fault::Input(c, f));
    vec![
        (Case::new(Fault::None), "lng", Early),
        (Case::new(Fault::None), "random-1", Early),
        (Case::new(Fault::None), "hot-60", Early),
        (input(Channel::Current, InputFault::GainHalf), "lng", Open),
        (input(Channel::PressureA, InputFault::StuckZero), "hot-60", Hot),
        (input(Channel::Speed, InputFault::GainHalf), "lng", Open),
        (Case { fault: Fault::Input(Channel::Speed, InputFault::StuckZero), inputs: Inputs::NoElec }, "hot-60", Open),
        (input(Channel::Ambient, InputFault::Drift), "random-1", Early),
        (Case::new(Fault::DropoutBursts), "hot-60", Hot),
        (Case::new(Fault::WarmReset), "hot-60", Hot),
        (Case::new(Fault::TornRecordWrite), "lng", Open),
        (Case::new(Fault::PowerLoss), "hot-60", Hot),
        (Case::new(Fault::ValveStuckClosed), "lng", Early),
        (Case::new(Fault::NoValveFeedback), "lng", Open),
        (Case::new(Fault::FlashReadFail), "lng", Open),
        (Case::new(Fault::FlashWriteFail), "random-1", Early),
        (Case::new(Fault::ClearSpam), "hot-60", Hot),
        (Case::new(Fault::CorruptStartClear), "lng", Open),
        (Case::new(Fault::RefillWhileEmpty), "lng", Early),
        (Case { fault: Fault::LngEmptyPhysical, inputs: Inputs::Supply }, "lng", Open),
    ]
}

/// Runs the [`fast_subset`] (the start times from the baselines).
pub fn fast_campaign() -> Result<Vec<FaultResult>> {
    let sc = scenarios();
    let base = baselines(&sc)?;
    let mut v = Vec::new();
    for (c, name, kind) in fast_subset() {
        let i = sc.iter().position(|s| s.name == name).context("scenario")?;
        let st = starts(&sc[i], &base[i]).into_iter().find(|s| s.kind == kind).with_context(|| format!("{name} has no {} start", kind.name()))?;
        v.push(Job { case: c, scenario: i, start: st });
    }
    run_jobs(&sc, &v)
}

/// Markdown table of the results.
pub fn table(rows: &[FaultResult]) -> String {
    let mut s = String::from(
        "| fault | scenario | start | detected after | bits | max under K | max true drain closed °C | pass |\n|---|---|---|---:|---|---:|---:|---|\n",
    );
    for r in rows {
        s.push_str(&format!(
            "| {} | {} | {} ({:.0} s) | {} | {} | {:.3} | {} | {} |\n",
            r.fault,
            r.scenario,
            r.start,
            r.start_s,
            r.detect_s.map_or("–".into(), |d| format!("{d:.2} s")),
            r.detect_bits.clone().unwrap_or_else(|| "–".into()),
            r.max_under_k,
            r.max_true_drain_closed_c.map_or("–".into(), |c| format!("{c:.2}")),
            match (r.pass, &r.limit) {
                (true, _) => "pass",
                (false, Some(_)) => "limit",
                (false, None) => "**FAIL**",
            }
        ));
    }
    s
}

/// What is wrong with a campaign's rows: failing runs that are not a
/// listed limit.
pub fn unlisted_failures(rows: &[FaultResult]) -> Vec<String> {
    rows.iter()
        .filter(|r| !r.pass && r.limit.is_none())
        .map(|r| {
            format!(
                "{} / {} / {} ({:.0} s) fails: detected {:?} after {:?} s, max under {:.3} K, max true drain with the valve closed {:?} °C",
                r.fault, r.scenario, r.start, r.start_s, r.detect_bits, r.detect_s, r.max_under_k, r.max_true_drain_closed_c
            )
        })
        .collect()
}

/// Arguments of `eha-sim faults`.
#[derive(Debug, Clone, clap::Args)]
pub struct FaultsArgs {
    /// Output directory (faults.json, faults.md).
    #[arg(long, default_value = "out/faults")]
    pub out: PathBuf,
    /// Run the fast tier's subset only.
    #[arg(long)]
    pub fast: bool,
    /// Do not run: write the failure-mode table from this `faults.json`.
    #[arg(long)]
    pub from: Option<PathBuf>,
    /// Where the whole campaign's results are committed (after a run of
    /// the whole campaign, or with `--from`), relative to the workspace
    /// root; `docs/failure-modes.md` is then re-rendered from it.
    #[arg(long, default_value = "docs/data/faults.json")]
    pub data: PathBuf,
}

/// `eha-sim faults`: run the campaign, write `faults.json` and `faults.md`
/// (and, for the whole campaign, the failure-mode table); an error when a
/// run fails that is not a listed design limit.
pub fn run(a: &FaultsArgs) -> Result<()> {
    if let Some(json) = &a.from {
        let text = std::fs::read_to_string(json).with_context(|| format!("reading {}", json.display()))?;
        let rows: Vec<FaultResult> = serde_json::from_str(&text).context("parsing faults.json")?;
        return commit_data(a, &rows);
    }
    let t0 = std::time::Instant::now();
    let rows = if a.fast { fast_campaign()? } else { campaign()? };
    write(&a.out, &rows)?;
    print!("{}", table(&rows));
    if !a.fast {
        commit_data(a, &rows)?;
    }
    let passing = rows.iter().filter(|r| r.pass).count();
    let limited = rows.iter().filter(|r| !r.pass && r.limit.is_some()).count();
    println!(
        "{passing} of {} runs pass, {limited} are listed design limits ({:.0} s); wrote {}",
        rows.len(),
        t0.elapsed().as_secs_f64(),
        a.out.join("faults.json").display()
    );
    let bad = unlisted_failures(&rows);
    if !bad.is_empty() {
        bail!("{} runs fail that are not listed design limits:\n{}", bad.len(), bad.join("\n"));
    }
    Ok(())
}

/// The whole campaign's rows to `docs/data/faults.json` (or `a.data`);
/// the command line then re-renders the documents from it (`eha-sim docs`).
fn commit_data(a: &FaultsArgs, rows: &[FaultResult]) -> Result<()> {
    let path = crate::pil::firmware::workspace_root().join(&a.data);
    std::fs::write(&path, data_json(rows)?).with_context(|| format!("writing {}", path.display()))?;
    println!("wrote {} ({} runs)", path.display(), rows.len());
    Ok(())
}

/// `rows` as committed in `docs/data/faults.json`: one run per line, every
/// non-integer number rounded to 1e-4 (the table prints two decimals), so
/// a re-run that changes nothing the table shows changes little in git.
pub fn data_json(rows: &[FaultResult]) -> Result<String> {
    fn round(v: &mut serde_json::Value) {
        match v {
            serde_json::Value::Number(n) => {
                if let Some(x) = n.as_f64().filter(|x| x.fract() != 0.0) {
                    if let Some(r) = serde_json::Number::from_f64((x * 1e4).round() / 1e4) {
                        *n = r;
                    }
                }
            }
            serde_json::Value::Object(m) => m.values_mut().for_each(round),
            serde_json::Value::Array(a) => a.iter_mut().for_each(round),
            _ => {}
        }
    }
    let mut lines = Vec::with_capacity(rows.len());
    for r in rows {
        let mut v = serde_json::to_value(r)?;
        round(&mut v);
        lines.push(serde_json::to_string(&v)?);
    }
    Ok(format!("[\n{}\n]\n", lines.join(",\n")))
}

/// Write `faults.json` and `faults.md` to `dir`.
pub fn write(dir: &Path, rows: &[FaultResult]) -> Result<()> {
    std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    std::fs::write(dir.join("faults.json"), serde_json::to_string_pretty(rows)?).context("writing faults.json")?;
    std::fs::write(dir.join("faults.md"), table(rows)).context("writing faults.md")?;
    Ok(())
}
