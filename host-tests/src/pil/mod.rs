//! Processor-in-the-loop (PIL): the real firmware binary in QEMU, in
//! closed loop and lockstep with the reference plant on the host.
//!
//! Per tick: the plant's sensor values become one request frame
//! ([`eha_guard::protocol`]), the firmware answers with one reply frame, the
//! reply's valve command drives the plant's LNG valve, the plant advances one
//! tick. The same loop runs against [`sil::SilTarget`] (the same core code on
//! the host), which is the bit-for-bit oracle for the firmware's replies.

pub mod budget;
pub mod defmt_log;
pub mod drill;
pub mod firmware;
pub mod plot;
pub mod product;
pub mod qemu;
pub mod reference;
pub mod cli;
pub mod report;
pub mod sil;

use std::time::{Duration, Instant};

use eha_guard::protocol::{Reply, ReplyKind, Request};

pub use firmware::{build_bin, build_firmware, Build};
pub use qemu::{PilError, QemuOptions, QemuSession};

/// What the firmware can measure, plus the plant's true drain temperature.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PlantSensors {
    /// Motor current, A rms.
    pub current_a: f64,
    /// Port A pressure, bar gauge.
    pub p_a_bar: f64,
    /// Port B pressure, bar gauge.
    pub p_b_bar: f64,
    /// Motor speed, rpm.
    pub speed_rpm: f64,
    /// Piston position, mm.
    pub position_mm: f64,
    /// Ambient air temperature, °C.
    pub ambient_c: f64,
    /// True drain-port oil temperature (not sent to the firmware).
    pub t_drain_c: f64,
    /// Manifold oil sensor (`t_oil_c` of the measured format), if the plant has it.
    pub t_oil_c: Option<f64>,
    /// LNG valve position read back (the valve the plant ran during the last tick),
    /// if the plant reports it; sent in the request's flags byte.
    pub valve_fb: Option<bool>,
}

impl PlantSensors {
    /// The request frame for this sample.
    pub fn request(&self, seq: u16) -> Request {
        Request {
            seq,
            current_a: self.current_a as f32,
            p_a_bar: self.p_a_bar as f32,
            p_b_bar: self.p_b_bar as f32,
            speed_rpm: self.speed_rpm as f32,
            position_mm: self.position_mm as f32,
            ambient_c: self.ambient_c as f32,
            valve_fb: self.valve_fb,
        }
    }
}

/// What the loop tells the plant after one tick.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StepControl {
    /// Keep going with this LNG valve command during the next tick.
    Valve(bool),
    /// Stop now (the run ended or failed).
    Stop,
}

/// A plant that can run in lockstep with the firmware. The plant owns the
/// time loop (a stiff solver keeps its state across its own steps): it calls
/// `on_step(t_s, sensors)` at `t0, t0 + dt, …` up to `t_end` and applies the
/// returned valve command during the following tick.
pub trait PlantModel {
    /// Runs from the plant's start to `t_end_s`, calling `on_step` every
    /// `dt_s` s of plant time; stops early when it returns [`StepControl::Stop`].
    fn run(
        &mut self,
        dt_s: f64,
        t_end_s: f64,
        on_step: &mut dyn FnMut(f64, &PlantSensors) -> StepControl,
    ) -> anyhow::Result<()>;
}

/// The thing that answers request frames: the firmware in QEMU or the SIL core.
pub trait Target {
    /// Send one encoded frame, return the reply to it.
    fn exchange(&mut self, wire: &[u8], tick: u64) -> Result<Reply, PilError>;
}

impl Target for QemuSession {
    fn exchange(&mut self, wire: &[u8], tick: u64) -> Result<Reply, PilError> {
        self.send(wire)?;
        self.recv(tick)
    }
}

/// One lockstep tick.
#[derive(Clone, Copy, Debug)]
pub struct TickRecord {
    /// Plant time at which the sample was taken, s.
    pub t_s: f64,
    /// What the plant measured then (and its true drain temperature).
    pub sensors: PlantSensors,
    /// The frame sent to the firmware.
    pub request: Request,
    /// The firmware's reply to it.
    pub reply: Reply,
}

/// Closed-loop run options.
#[derive(Clone, Copy, Debug)]
pub struct LoopOptions {
    /// Firmware tick period, s (the plant advances this much per frame).
    pub tick_s: f64,
    /// Plant time to run, s.
    pub duration_s: f64,
}

impl LoopOptions {
    /// Number of firmware ticks in the run.
    pub fn ticks(&self) -> u64 {
        (self.duration_s / self.tick_s).round() as u64
    }
}

/// A closed-loop run that stopped early: the records up to the failure are kept.
#[derive(Debug)]
pub struct LoopFailure {
    /// The ticks completed before the failure.
    pub records: Vec<TickRecord>,
    /// What failed.
    pub error: anyhow::Error,
}

/// Run plant and target in lockstep for `opts.ticks()` firmware ticks. On
/// failure the records so far are returned with the error.
pub fn run_closed_loop(
    plant: &mut dyn PlantModel,
    target: &mut dyn Target,
    opts: &LoopOptions,
) -> Result<Vec<TickRecord>, LoopFailure> {
    let n = opts.ticks();
    let mut records = Vec::with_capacity(n as usize);
    let mut failure: Option<anyhow::Error> = None;
    let mut on_step = |t_s: f64, sensors: &PlantSensors| -> StepControl {
        let k = records.len() as u64;
        if k >= n {
            return StepControl::Stop;
        }
        let request = sensors.request((k & 0xFFFF) as u16);
        let reply = match target.exchange(&request.encode(), k) {
            Ok(r) => r,
            Err(e) => {
                failure = Some(e.into());
                return StepControl::Stop;
            }
        };
        if reply.kind != ReplyKind::Tick || reply.seq != request.seq {
            let what = format!("expected a tick reply to seq {}, got {:?} for seq {}", request.seq, reply.kind, reply.seq);
            failure = Some(PilError::Protocol { tick: k, what }.into());
            return StepControl::Stop;
        }
        records.push(TickRecord { t_s, sensors: *sensors, request, reply });
        if records.len() as u64 >= n {
            StepControl::Stop
        } else {
            StepControl::Valve(reply.out.valve_open)
        }
    };
    // One extra tick of plant time so the plant offers all n samples.
    let t_end = opts.duration_s + opts.tick_s;
    let res = plant.run(opts.tick_s, t_end, &mut on_step);
    if let Some(error) = failure {
        return Err(LoopFailure { records, error });
    }
    if let Err(e) = res {
        let t = records.last().map_or(0.0, |r| r.t_s);
        return Err(LoopFailure { records, error: e.context(format!("plant failed after t = {t} s")) });
    }
    if (records.len() as u64) < n {
        let error = anyhow::anyhow!("plant stopped after {} of {n} ticks", records.len());
        return Err(LoopFailure { records, error });
    }
    Ok(records)
}

/// Replay the exact request frames of a run through another target (SIL) and
/// return its replies.
pub fn replay(records: &[TickRecord], target: &mut dyn Target) -> Result<Vec<Reply>, PilError> {
    records.iter().enumerate().map(|(k, r)| target.exchange(&r.request.encode(), k as u64)).collect()
}

/// Result of a full PIL session.
#[derive(Debug)]
pub struct PilRun {
    /// Which firmware build ran.
    pub build: Build,
    /// Every lockstep tick.
    pub records: Vec<TickRecord>,
    /// The completion marker (a `Done` reply with the final counters).
    pub done: Reply,
    /// The firmware's decoded defmt log.
    pub log: Vec<defmt_log::LogLine>,
    /// Wall-clock time of the session.
    pub wall: Duration,
    /// Whether QEMU counted instructions (`-icount`): the replies' tick
    /// counts are then instruction counts.
    pub icount: bool,
}

/// Run one PIL session: spawn QEMU, lockstep loop, completion marker, defmt log.
/// On failure, whatever was recorded (ticks, defmt log) is in the error's
/// `LoopFailure` and was not thrown away.
pub fn run_pil(plant: &mut dyn PlantModel, qemu: &QemuOptions, opts: &LoopOptions) -> Result<PilRun, Box<PilFailure>> {
    let start = Instant::now();
    let mut session = QemuSession::spawn(qemu).map_err(|e| PilFailure::new(Vec::new(), Vec::new(), e.into()))?;
    match run_closed_loop(plant, &mut session, opts) {
        Ok(records) => {
            let ticks = records.len() as u64;
            match session.finish(ticks) {
                Ok(end) => {
                    let log = defmt_log::decode(&qemu.elf, &end.defmt)
                        .map_err(|e| PilFailure::new(records.clone(), Vec::new(), e.context("decoding the defmt log")))?;
                    if end.done.counters.accepted != ticks as u32 {
                        let what = format!("firmware accepted {} frames, host sent {ticks}", end.done.counters.accepted);
                        return Err(PilFailure::new(records, log, PilError::Protocol { tick: ticks, what }.into()));
                    }
                    Ok(PilRun { build: qemu.build, records, done: end.done, log, wall: start.elapsed(), icount: qemu.icount })
                }
                Err(e) => Err(PilFailure::new(records, Vec::new(), e.into())),
            }
        }
        Err(fail) => {
            let raw = session.abort();
            let log = defmt_log::decode(&qemu.elf, &raw).unwrap_or_default();
            Err(PilFailure::new(fail.records, log, fail.error))
        }
    }
}

/// A failed PIL session with everything that was recorded before the failure.
#[derive(Debug)]
pub struct PilFailure {
    /// The ticks completed before the failure.
    pub records: Vec<TickRecord>,
    /// The defmt log decoded up to the failure.
    pub log: Vec<defmt_log::LogLine>,
    /// What failed.
    pub error: anyhow::Error,
}

impl PilFailure {
    fn new(records: Vec<TickRecord>, log: Vec<defmt_log::LogLine>, error: anyhow::Error) -> Box<Self> {
        Box::new(Self { records, log, error })
    }
}

impl std::fmt::Display for PilFailure {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "PIL run failed after {} ticks: {:#}", self.records.len(), self.error)
    }
}

impl std::error::Error for PilFailure {}

/// For tests: QEMU must be there (CI installs it); fail loudly otherwise,
/// never skip silently.
pub fn require_qemu() -> String {
    match qemu::qemu_available() {
        Ok(v) => v,
        Err(e) => panic!("QEMU test cannot run: {e}"),
    }
}

/// For tests: build the firmware once per test process and return the ELF.
pub fn firmware_for_tests(build: Build) -> std::path::PathBuf {
    use std::sync::{Mutex, OnceLock};
    static BUILT: OnceLock<Mutex<std::collections::HashMap<Build, std::path::PathBuf>>> = OnceLock::new();
    let map = BUILT.get_or_init(Default::default);
    let mut map = map.lock().unwrap_or_else(|p| p.into_inner());
    if let Some(p) = map.get(&build) {
        return p.clone();
    }
    let elf = build_firmware(build).unwrap_or_else(|e| panic!("building the {} firmware: {e:#}", build.name()));
    map.insert(build, elf.clone());
    elf
}

/// An open-loop firmware session: fixed frames in, replies out.
#[derive(Debug)]
pub struct OpenLoopRun {
    /// Which firmware build ran.
    pub build: Build,
    /// One reply per request, in order.
    pub replies: Vec<Reply>,
    /// The completion marker (a `Done` reply with the final counters).
    pub done: Reply,
    /// The firmware's decoded defmt log.
    pub log: Vec<defmt_log::LogLine>,
    /// Wall-clock time of the session.
    pub wall: Duration,
    /// Whether QEMU counted instructions (`-icount`).
    pub icount: bool,
}

/// Send `requests` one by one in lockstep, then end the input and collect
/// the completion marker and the decoded defmt log.
pub fn run_open_loop(qemu: &QemuOptions, requests: &[Request]) -> anyhow::Result<OpenLoopRun> {
    let start = Instant::now();
    let mut s = QemuSession::spawn(qemu)?;
    let mut replies = Vec::with_capacity(requests.len());
    for (k, r) in requests.iter().enumerate() {
        replies.push(s.exchange(&r.encode(), k as u64)?);
    }
    let end = s.finish(requests.len() as u64)?;
    let log = defmt_log::decode(&qemu.elf, &end.defmt)?;
    Ok(OpenLoopRun { build: qemu.build, replies, done: end.done, log, wall: start.elapsed(), icount: qemu.icount })
}
