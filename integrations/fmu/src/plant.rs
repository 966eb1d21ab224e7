//! The plant FMU: the reference model (the paper's lumped thermal-hydraulic
//! EHA, `eha_sim::plant::Plant`, BDF with error control) driven by its
//! inputs held constant over each communication step. Outputs are every
//! channel of `eha-sim simulate` (the measured-data columns, every node
//! temperature, the losses, the energy integrals), so the FMU and the native
//! run read alike. A rig file (`eha-sim rig` format) replaces the paper rig.

use crate::fmi2::{Causality, Model, Value, ValueReference, Var, VarType};
use eha_sim::plant::Plant;
use eha_sim::rig::Rig;
use eha_sim::scenario::{Circuit, Mission, PositionRef, Scenario, Schedule, ValveRule};
use eha_sim::sim::channels;
use eha_sim::plant::Control;
use std::sync::{mpsc, OnceLock};
use std::thread;

/// Value references of the inputs and parameters; outputs follow from
/// [`FIRST_OUTPUT`] in the order of `eha_sim::sim::channels`.
mod vr {
    pub const SPEED: u32 = 0;
    pub const NEEDLE: u32 = 1;
    pub const POSITION: u32 = 2;
    pub const AMBIENT: u32 = 3;
    pub const AIR: u32 = 4;
    pub const LNG: u32 = 5;
    pub const RIG: u32 = 10;
    pub const CIRCUIT: u32 = 11;
    pub const RTOL: u32 = 12;
}

/// Value reference of the first output.
pub const FIRST_OUTPUT: u32 = 100;

/// The unit of a channel, from its name's suffix (the project's naming rule:
/// units in names).
pub fn unit_of(name: &str) -> Option<&'static str> {
    const SUFFIXES: [(&str, &str); 12] = [
        ("_mm_s", "mm/s"),
        ("_l_min", "l/min"),
        ("_c", "degC"),
        ("_rpm", "rpm"),
        ("_a", "A"),
        ("_bar", "bar"),
        ("_mm", "mm"),
        ("_mps", "m/s"),
        ("_w", "W"),
        ("_j", "J"),
        ("_kg", "kg"),
        ("lng_valve", "1"),
    ];
    SUFFIXES.iter().find(|(s, _)| name.ends_with(s)).map(|&(_, u)| u)
}

/// The descriptions of the measured-format channels (docs/measured-data-format.md).
fn describe(name: &str) -> &'static str {
    match name {
        "speed_rpm" => "Motor = pump shaft speed",
        "current_a" => "Motor phase current (RMS)",
        "p_a_bar" => "Pump port A pressure (gauge)",
        "p_b_bar" => "Pump port B pressure (gauge)",
        "ambient_c" => "Ambient air temperature",
        "position_mm" => "Piston position",
        "t_motor_c" => "Point 1: motor body surface temperature",
        "t_pump_c" => "Point 3: pump body surface temperature",
        "t_block_c" => "Point 4: main valve block surface temperature",
        "t_ballvalve_c" => "Point 5: ball/needle valve block surface temperature",
        "t_oil_c" => "Oil temperature at the manifold sensor",
        "t_drain_c" => "Pump drain-port (case) oil temperature: what the firmware estimates",
        "lng_valve" => "LNG valve state (1 = open)",
        "air_speed_mps" => "Ram-air speed over the housings (input plus the rig's unlogged forced convection)",
        n if n.starts_with("t_") => "Node temperature of the lumped model",
        n if n.starts_with("p_") => "Power loss (eqs. 1-11)",
        n if n.starts_with("e_") => "Integrated energy",
        _ => "Model channel",
    }
}

/// The variables: inputs, parameters, then one output per channel.
fn vars() -> &'static [Var] {
    static VARS: OnceLock<Vec<Var>> = OnceLock::new();
    VARS.get_or_init(|| {
        let real_in = Var::real_input;
        let mut v = vec![
            real_in(vr::SPEED, "cmd_speed_rpm", "rpm", 500.0, "Motor speed command (throttle circuit)"),
            real_in(vr::NEEDLE, "cmd_needle_bar", "bar", 0.0, "Needle-valve setting: its pressure drop at the 500 rpm reference flow (throttle circuit)"),
            real_in(vr::POSITION, "cmd_position_mm", "mm", 0.0, "Piston position reference (servo circuit)"),
            real_in(vr::AMBIENT, "in_ambient_c", "degC", 16.0, "Ambient air temperature (also the initial temperature of every node)"),
            real_in(vr::AIR, "in_air_speed_mps", "m/s", 0.0, "Ram-air speed over the housings"),
            Var::new(vr::LNG, "cmd_lng_valve", Causality::Input, VarType::Boolean { start: Some(false) }, "LNG cooling valve command (true = open)"),
            Var::new(vr::RIG, "rig_file", Causality::Parameter, VarType::String { start: "" }, "Rig file (TOML, eha-sim rig format); empty = the paper rig (Liu et al., Tables 2-3)"),
            Var::new(vr::CIRCUIT, "circuit", Causality::Parameter, VarType::Integer { start: Some(0) }, "Hydraulic circuit: 0 = throttle (paper Case 1), 1 = servo (Case 2)"),
            Var::new(
                vr::RTOL,
                "rtol",
                Causality::Parameter,
                VarType::Real { unit: "1", start: Some(eha_sim::plant::RTOL) },
                "Relative tolerance of the BDF error control (fmi2SetupExperiment's tolerance overrides it when defined)",
            ),
        ];
        let probe = Plant::new(&Rig::default(), &Scenario::Mission(mission(Circuit::Throttle, &Inputs::default())))
            .map(|p| p.snapshot())
            .ok();
        if let Some(s) = probe {
            for (i, (name, _)) in channels(&s).into_iter().enumerate() {
                v.push(Var::real_output(FIRST_OUTPUT + i as u32, name, unit_of(name).unwrap_or("1"), describe(name)));
            }
        }
        v
    })
}

/// The output values at a snapshot: every channel of `eha-sim simulate`, with
/// the controller's sample channels (current, pressures, speed, position,
/// ambient) computed as the processor-in-the-loop runs compute them
/// (`pil::reference::sensors`), so that the guard FMU fed from this FMU sees
/// the SIL run's samples bit for bit.
fn outputs(snap: &eha_sim::plant::Snapshot) -> Vec<f64> {
    let s = eha_sim::pil::reference::sensors(snap);
    channels(snap)
        .into_iter()
        .map(|(name, x)| match name {
            "current_a" => s.current_a,
            "p_a_bar" => s.p_a_bar,
            "p_b_bar" => s.p_b_bar,
            "speed_rpm" => s.speed_rpm,
            "position_mm" => s.position_mm,
            "ambient_c" => s.ambient_c,
            _ => x,
        })
        .collect()
}

/// The inputs as set by the master.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Inputs {
    speed_rpm: f64,
    needle_bar: f64,
    position_mm: f64,
    ambient_c: f64,
    air_mps: f64,
    lng: bool,
}

impl Default for Inputs {
    fn default() -> Self {
        Self { speed_rpm: 500.0, needle_bar: 0.0, position_mm: 0.0, ambient_c: 16.0, air_mps: 0.0, lng: false }
    }
}

/// A mission holding `u` constant.
fn mission(circuit: Circuit, u: &Inputs) -> Mission {
    Mission {
        name: "fmu".into(),
        circuit,
        duration_s: f64::INFINITY,
        ambient_c: Schedule::constant(u.ambient_c),
        speed_rpm: Schedule::constant(u.speed_rpm),
        needle_bar: Schedule::constant(u.needle_bar),
        position: PositionRef::Profile(Schedule::constant(u.position_mm * 1e-3)),
        air_speed_mps: Schedule::constant(u.air_mps),
        valve: ValveRule::External,
    }
}

/// What the FMU thread asks of the plant's worker.
struct Command {
    u: Inputs,
    h_s: f64,
}

/// The worker's answer at a communication point: every channel, or the error.
type Reply = Result<Vec<f64>, String>;

/// The plant runs in [`Plant::run`] on a worker thread whose callback is the
/// communication point: it sends the channels and waits for the next step.
/// Between steps the BDF keeps its history, exactly as in `eha-sim simulate`
/// and the processor-in-the-loop runs (a valve change goes through the
/// callback's control, as there); a new input value or step size ends the
/// run at the communication point and starts the next with the inputs held.
struct Worker {
    tx: mpsc::Sender<Command>,
    rx: mpsc::Receiver<Reply>,
    handle: Option<thread::JoinHandle<()>>,
}

/// Plant time at which a worker's run ends without a stop time, s (never
/// reached in practice).
const T_NEVER_S: f64 = 1e12;

impl Worker {
    fn start(mut plant: Plant, circuit: Circuit, stop_s: Option<f64>, first: Command) -> Result<Self, String> {
        let (tx, cmd_rx) = mpsc::channel::<Command>();
        let (reply_tx, rx) = mpsc::channel::<Reply>();
        tx.send(first).map_err(|e| e.to_string())?;
        let handle = thread::Builder::new()
            .name("eha-plant-fmu".into())
            .spawn(move || {
                let Ok(mut next) = cmd_rx.recv() else { return };
                loop {
                    let cmd = next;
                    if let Some(m) = plant.mission_mut() {
                        *m = mission(circuit, &cmd.u);
                    }
                    plant.set_lng_valve(cmd.u.lng);
                    let mut pending: Option<Command> = None;
                    // A step was asked for and not yet answered.
                    let mut owed = false;
                    let mut first = true;
                    let t_end = stop_s.unwrap_or(plant.time_s() + T_NEVER_S);
                    let r = plant.run(cmd.h_s, t_end, |snap| {
                        if first {
                            // The run's start: the previous communication point.
                            first = false;
                            owed = true;
                            return Ok(Control { lng_valve: Some(cmd.u.lng), stop: false });
                        }
                        owed = false;
                        if reply_tx.send(Ok(outputs(snap))).is_err() {
                            return Ok(Control { lng_valve: None, stop: true });
                        }
                        match cmd_rx.recv() {
                            Ok(c) if c.h_s == cmd.h_s && Inputs { lng: cmd.u.lng, ..c.u } == cmd.u => {
                                owed = true;
                                Ok(Control { lng_valve: Some(c.u.lng), stop: false })
                            }
                            Ok(c) => {
                                pending = Some(c);
                                Ok(Control { lng_valve: None, stop: true })
                            }
                            Err(_) => Ok(Control { lng_valve: None, stop: true }),
                        }
                    });
                    if let Err(e) = r {
                        let _ = reply_tx.send(Err(e.to_string()));
                        return;
                    }
                    match pending.take() {
                        Some(c) => next = c,
                        None => {
                            // The run reached the stop time of fmi2SetupExperiment:
                            // a step asked for now, or later, is refused.
                            let past = || Err("doStep past the stop time given to fmi2SetupExperiment".into());
                            if owed {
                                let _ = reply_tx.send(past());
                            }
                            while cmd_rx.recv().is_ok() {
                                let _ = reply_tx.send(past());
                            }
                            return;
                        }
                    }
                }
            })
            .map_err(|e| format!("starting the plant's worker thread: {e}"))?;
        Ok(Self { tx, rx, handle: Some(handle) })
    }

    fn step(&mut self, cmd: Option<Command>) -> Reply {
        if let Some(c) = cmd {
            self.tx.send(c).map_err(|_| "the plant's worker has stopped".to_string())?;
        }
        self.rx.recv().map_err(|_| "the plant's worker has stopped".to_string())?
    }
}

impl Drop for Worker {
    fn drop(&mut self) {
        // Closing the command channel ends the worker's run at its next callback.
        let (dead, _) = mpsc::channel();
        self.tx = dead;
        if let Some(h) = self.handle.take() {
            let _ = h.join();
        }
    }
}

/// The plant FMU's state.
pub struct PlantFmu {
    u: Inputs,
    rig_file: String,
    circuit: i32,
    rtol: f64,
    /// The built plant, until the first step hands it to the worker.
    plant: Option<Plant>,
    worker: Option<Worker>,
    /// Run length from fmi2SetupExperiment, s: the solver stops there
    /// exactly, as the native run does at its duration.
    stop_s: Option<f64>,
    /// Channel values at the last communication point.
    out: Vec<f64>,
}

impl PlantFmu {
    fn circuit(&self) -> Circuit {
        if self.circuit == 1 {
            Circuit::Servo
        } else {
            Circuit::Throttle
        }
    }
}

impl Model for PlantFmu {
    const IDENTIFIER: &'static str = "EhaPlant";
    const GUID: &'static str = "{8d3f1a90-2c4b-4e7e-b6a5-eha-plant-ref-1}";
    const DESCRIPTION: &'static str = "EHA reference plant (Liu et al., lumped thermal-hydraulic model: losses eqs. 1-11, heat transfer eqs. 12-19, LNG exchanger eqs. 20-25)";
    const STEP_S: f64 = 0.0;

    fn variables() -> &'static [Var] {
        vars()
    }

    fn set_experiment(&mut self, rtol: Option<f64>, stop_s: Option<f64>) {
        if let Some(r) = rtol.filter(|&r| r > 0.0 && r < 1.0) {
            self.rtol = r;
        }
        self.stop_s = stop_s;
    }

    fn new() -> Self {
        Self { u: Inputs::default(), rig_file: String::new(), circuit: 0, rtol: eha_sim::plant::RTOL, plant: None, worker: None, stop_s: None, out: Vec::new() }
    }

    fn set(&mut self, r: ValueReference, v: Value) -> Result<(), String> {
        let finite = |x: f64, name: &str| if x.is_finite() { Ok(x) } else { Err(format!("{name} = {x} is not finite")) };
        match (r, v) {
            (vr::SPEED, Value::Real(x)) => self.u.speed_rpm = finite(x, "cmd_speed_rpm")?,
            (vr::NEEDLE, Value::Real(x)) => self.u.needle_bar = finite(x, "cmd_needle_bar")?,
            (vr::POSITION, Value::Real(x)) => self.u.position_mm = finite(x, "cmd_position_mm")?,
            (vr::AMBIENT, Value::Real(x)) => self.u.ambient_c = finite(x, "in_ambient_c")?,
            (vr::AIR, Value::Real(x)) => self.u.air_mps = finite(x, "in_air_speed_mps")?,
            (vr::LNG, Value::Boolean(b)) => self.u.lng = b,
            (vr::RIG, Value::String(s)) => self.rig_file = s,
            (vr::CIRCUIT, Value::Integer(c)) if c == 0 || c == 1 => self.circuit = c,
            (vr::CIRCUIT, Value::Integer(c)) => return Err(format!("circuit {c}: 0 = throttle, 1 = servo")),
            (vr::RTOL, Value::Real(x)) if x > 0.0 && x < 1.0 => self.rtol = x,
            (vr::RTOL, Value::Real(x)) => return Err(format!("rtol {x} must lie in (0, 1)")),
            (r, v) => return Err(format!("value reference {r} does not take {v:?}")),
        }
        Ok(())
    }

    fn get(&self, r: ValueReference) -> Result<Value, String> {
        Ok(match r {
            vr::SPEED => Value::Real(self.u.speed_rpm),
            vr::NEEDLE => Value::Real(self.u.needle_bar),
            vr::POSITION => Value::Real(self.u.position_mm),
            vr::AMBIENT => Value::Real(self.u.ambient_c),
            vr::AIR => Value::Real(self.u.air_mps),
            vr::LNG => Value::Boolean(self.u.lng),
            vr::RIG => Value::String(self.rig_file.clone()),
            vr::CIRCUIT => Value::Integer(self.circuit),
            vr::RTOL => Value::Real(self.rtol),
            r => {
                let i = r.checked_sub(FIRST_OUTPUT).ok_or_else(|| format!("no variable with value reference {r}"))?;
                let x = self.out.get(i as usize).ok_or_else(|| format!("no variable with value reference {r}"))?;
                Value::Real(*x)
            }
        })
    }

    fn initialize(&mut self, _start_time_s: f64) -> Result<(), String> {
        let rig = if self.rig_file.is_empty() {
            Rig::default()
        } else {
            Rig::from_toml_file(std::path::Path::new(&self.rig_file)).map_err(|e| format!("rig_file: {e}"))?
        };
        let mut plant = Plant::new(&rig, &Scenario::Mission(mission(self.circuit(), &self.u))).map_err(|e| e.to_string())?;
        plant.set_rtol(self.rtol);
        plant.set_lng_valve(self.u.lng);
        self.out = outputs(&plant.snapshot());
        self.plant = Some(plant);
        Ok(())
    }

    fn do_step(&mut self, _t_s: f64, h_s: f64) -> Result<(), String> {
        let cmd = Command { u: self.u, h_s };
        let reply = match (self.worker.as_mut(), self.plant.take()) {
            (Some(w), _) => w.step(Some(cmd)),
            (None, Some(p)) => {
                let mut w = Worker::start(p, self.circuit(), self.stop_s, cmd)?;
                let r = w.step(None);
                self.worker = Some(w);
                r
            }
            (None, None) => Err("the plant is not initialised".into()),
        };
        self.out = reply?;
        Ok(())
    }
}
