//! Processor-in-the-loop (PIL): the product application in QEMU (the PIL
//! image `eha-fw`: [`eha_guard::product::App`] on a lockstep semihosting
//! board), in closed loop and lockstep with the reference plant on the host.
//!
//! Per tick: the plant's sensor values become one sample frame
//! ([`eha_guard::protocol`]), sent as the bytes the controller's UART
//! delivered in that tick; the application answers with the tick's frames
//! (its tick reply first, [`eha_guard::product::wire`]); the reply's valve
//! command drives the plant's LNG valve, the plant advances one tick. The
//! same loop runs against [`sil::SilTarget`] (the same application on the
//! shared in-memory board, on the host), the bit-for-bit oracle for the
//! firmware's frames.

pub mod budget;
pub mod defmt_log;
pub mod drill;
pub mod firmware;
pub mod plot;
pub mod product;
pub mod error;
pub mod qemu;
pub mod reference;
pub mod cli;
pub mod report;
pub mod sil;

use std::time::{Duration, Instant};

use eha_guard::product::wire::{FromGuard, Status, TickReply};
use eha_guard::protocol::Request;

pub use firmware::{build_bin, build_firmware, Build};
pub use error::PilError;
pub use qemu::{QemuOptions, QemuSession};

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
    /// The motor drive's electrical frequency, Hz (signed), if the controller sends it.
    pub elec_hz: Option<f32>,
    /// LNG supply pressure at the valve, bar gauge, if the controller sends it.
    pub lng_supply_bar: Option<f32>,
}

impl PlantSensors {
    /// The request frame for this sample.
    pub fn request(&self, seq: u16) -> Request {
        let sample = eha_guard::Sample {
            current_a: self.current_a as f32,
            p_a_bar: self.p_a_bar as f32,
            p_b_bar: self.p_b_bar as f32,
            speed_rpm: self.speed_rpm as f32,
            position_mm: self.position_mm as f32,
            ambient_c: self.ambient_c as f32,
        };
        let reports = eha_guard::Reports { valve_fb: self.valve_fb, elec_hz: self.elec_hz, lng_supply_bar: self.lng_supply_bar };
        Request { seq, sample, reports }
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

/// What one tick of the application sent.
#[derive(Clone, Debug, PartialEq)]
pub struct TickOut {
    /// The tick reply.
    pub reply: TickReply,
    /// The other frames of the tick (acknowledgements, status, trace), in order.
    pub others: Vec<FromGuard>,
    /// The tick's cost in core-clock cycles (SysTick; under QEMU `-icount`
    /// 25.6 per instruction); 0 when not measured (the host twin).
    pub cycles: u32,
}

/// The application under test, one tick at a time: the PIL image in QEMU
/// or its host twin.
pub trait Target {
    /// One tick: `rx` is what the controller's UART delivered since the
    /// last tick (a sample frame, commands; empty: a missing sample).
    fn tick(&mut self, rx: &[u8], tick: u64) -> Result<TickOut, PilError>;
}

impl Target for QemuSession {
    fn tick(&mut self, rx: &[u8], tick: u64) -> Result<TickOut, PilError> {
        self.send_chunk(rx)?;
        self.recv_tick(tick)
    }
}

/// Splits a tick's frames into its tick reply and the rest; `None` when
/// there is no tick reply (the caller says what that means).
pub fn tick_out(frames: Vec<FromGuard>, cycles: u32) -> Option<TickOut> {
    let k = frames.iter().position(|f| matches!(f, FromGuard::Tick(_)))?;
    let mut others = frames;
    let FromGuard::Tick(reply) = others.remove(k) else { return None };
    Some(TickOut { reply, others, cycles })
}

/// One lockstep tick.
#[derive(Clone, Copy, Debug)]
pub struct TickRecord {
    /// Plant time at which the sample was taken, s.
    pub t_s: f64,
    /// What the plant measured then (and its true drain temperature).
    pub sensors: PlantSensors,
    /// The sample frame sent to the application.
    pub request: Request,
    /// The tick reply of the tick that used it.
    pub reply: TickReply,
    /// The tick's cost in core-clock cycles (0: not measured).
    pub cycles: u32,
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
        let out = match target.tick(&request.encode(), k) {
            Ok(r) => r,
            Err(e) => {
                failure = Some(e.into());
                return StepControl::Stop;
            }
        };
        let reply = out.reply;
        if !reply.fresh || reply.sample_seq != request.seq {
            let what = format!("expected the tick to use sample {}, it used {} (fresh {})", request.seq, reply.sample_seq, reply.fresh);
            failure = Some(PilError::Protocol { tick: k, what }.into());
            return StepControl::Stop;
        }
        records.push(TickRecord { t_s, sensors: *sensors, request, reply, cycles: out.cycles });
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

/// Replay the exact sample frames of a run through another target (SIL) and
/// return its tick replies.
pub fn replay(records: &[TickRecord], target: &mut dyn Target) -> Result<Vec<TickReply>, PilError> {
    records.iter().enumerate().map(|(k, r)| target.tick(&r.request.encode(), k as u64).map(|o| o.reply)).collect()
}

/// Result of a full PIL session.
#[derive(Debug)]
pub struct PilRun {
    /// Which firmware build ran.
    pub build: Build,
    /// Every lockstep tick.
    pub records: Vec<TickRecord>,
    /// The completion marker (a status reply with the final counters).
    pub done: Status,
    /// The firmware's decoded defmt log.
    pub log: Vec<defmt_log::LogLine>,
    /// Wall-clock time of the session.
    pub wall: Duration,
    /// Whether QEMU counted instructions (`-icount`): the ticks' cycle
    /// counts are then instruction counts × 25.6.
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

/// An open-loop firmware session: fixed inputs in, tick frames out.
#[derive(Debug)]
pub struct OpenLoopRun {
    /// Which firmware build ran.
    pub build: Build,
    /// One tick's frames per input, in order.
    pub ticks: Vec<TickOut>,
    /// The completion marker (a status reply with the final counters).
    pub done: Status,
    /// The firmware's decoded defmt log.
    pub log: Vec<defmt_log::LogLine>,
    /// Wall-clock time of the session.
    pub wall: Duration,
    /// Whether QEMU counted instructions (`-icount`).
    pub icount: bool,
}

/// Runs the drill's samples (per tick: a sample, or `None`: lost) on
/// `target` in lockstep, each reporting the valve the previous tick
/// commanded ([`drill::bytes`]); the tick frames.
pub fn run_drill(target: &mut dyn Target, samples: &[Option<Request>]) -> Result<Vec<TickOut>, PilError> {
    let mut ticks: Vec<TickOut> = Vec::with_capacity(samples.len());
    for (k, r) in samples.iter().enumerate() {
        let open = ticks.last().is_some_and(|t| t.reply.out.valve_open);
        ticks.push(target.tick(&drill::bytes(r, open), k as u64)?);
    }
    Ok(ticks)
}

/// Runs the drill's samples in QEMU ([`run_drill`]), then ends the input
/// and collects the completion marker and the decoded defmt log.
pub fn run_open_loop(qemu: &QemuOptions, samples: &[Option<Request>]) -> anyhow::Result<OpenLoopRun> {
    let start = Instant::now();
    let mut s = QemuSession::spawn(qemu)?;
    let ticks = run_drill(&mut s, samples)?;
    let end = s.finish(samples.len() as u64)?;
    let log = defmt_log::decode(&qemu.elf, &end.defmt)?;
    Ok(OpenLoopRun { build: qemu.build, ticks, done: end.done, log, wall: start.elapsed(), icount: qemu.icount })
}
