//! The guard FMU: the firmware's f32 `Guard` itself (the code that is
//! flashed), one 10 ms tick per 10 ms of communication step. Inputs are the
//! controller's sample; outputs the drain estimate, the valve command, the
//! alarm and the fault word. A parameter block file written by
//! `eha-sim params-block write` or `eha-sim commission` can replace the
//! compiled-in paper-rig constants.

use crate::fmi2::{Causality, Model, Value, ValueReference, Var, VarType};
use eha_guard::model::ModelConsts;
use eha_guard::params_block::{self, BLOCK_LEN};
use eha_guard::{Guard, GuardConfig, Output, Restore, Sample};

/// Value references.
mod vr {
    pub const CURRENT: u32 = 0;
    pub const P_A: u32 = 1;
    pub const P_B: u32 = 2;
    pub const SPEED: u32 = 3;
    pub const POSITION: u32 = 4;
    pub const AMBIENT: u32 = 5;
    pub const VALVE_FB: u32 = 6;
    pub const DRAIN: u32 = 10;
    pub const VALVE: u32 = 11;
    pub const ALARM: u32 = 12;
    pub const DERATE: u32 = 13;
    pub const FAULTS: u32 = 14;
    pub const LNG_KG: u32 = 15;
    pub const LNG_S: u32 = 16;
    pub const PARAMS: u32 = 20;
}

/// Boolean outputs have no start value.
const BOOL_OUT: VarType = VarType::Boolean { start: None };

static VARS: [Var; 15] = [
    Var::real_input(vr::CURRENT, "current_a", "A", 0.0, "Motor phase current (RMS)"),
    Var::real_input(vr::P_A, "p_a_bar", "bar", 0.0, "Pump port A pressure (gauge)"),
    Var::real_input(vr::P_B, "p_b_bar", "bar", 0.0, "Pump port B pressure (gauge)"),
    Var::real_input(vr::SPEED, "speed_rpm", "rpm", 0.0, "Motor = pump shaft speed, signed by direction"),
    Var::real_input(vr::POSITION, "position_mm", "mm", 0.0, "Piston position from the linear encoder"),
    Var::real_input(vr::AMBIENT, "ambient_c", "degC", 20.0, "Ambient air temperature near the actuator"),
    Var::new(vr::VALVE_FB, "valve_feedback", Causality::Input, VarType::Integer { start: Some(-1) }, "LNG valve position switch: -1 = not wired, 0 = shut, 1 = open"),
    Var::real_output(vr::DRAIN, "drain_c", "degC", "Estimated pump drain-port oil temperature with the parameter block's commissioning margin, the value the valve and alarm act on (1e6 when the model is refused: CONFIG fault)"),
    Var::new(vr::VALVE, "valve_open", Causality::Output, BOOL_OUT, "LNG cooling valve command (true = open)"),
    Var::new(vr::ALARM, "alarm", Causality::Output, BOOL_OUT, "Over-temperature alarm (drain above 60 degC, cleared below 58 degC) or untrusted estimate"),
    Var::new(vr::DERATE, "derate", Causality::Output, BOOL_OUT, "Derate request to the actuator controller"),
    Var::new(vr::FAULTS, "faults", Causality::Output, VarType::Integer { start: None }, "Latched fault word (eha_guard::faults, docs/firmware.md)"),
    Var::real_output(vr::LNG_KG, "lng_remaining_kg", "kg", "LNG remaining in the tank model"),
    Var::real_output(vr::LNG_S, "lng_seconds_left", "s", "Seconds of LNG cooling left at the present dissipation"),
    Var::new(vr::PARAMS, "params_file", Causality::Parameter, VarType::String { start: "" }, "Firmware parameter block file (eha-sim params-block / commission); empty = the compiled-in paper rig"),
];

/// The guard FMU's state.
pub struct GuardFmu {
    sample: Sample,
    valve_fb: i32,
    params_file: String,
    /// The parameter block's constants (kept for the guard's lifetime).
    consts: Option<Box<ModelConsts<f32>>>,
    guard: Option<Box<Guard>>,
    out: Output,
}

impl GuardFmu {
    fn real(&mut self, vr: ValueReference) -> Option<&mut f32> {
        let s = &mut self.sample;
        Some(match vr {
            vr::CURRENT => &mut s.current_a,
            vr::P_A => &mut s.p_a_bar,
            vr::P_B => &mut s.p_b_bar,
            vr::SPEED => &mut s.speed_rpm,
            vr::POSITION => &mut s.position_mm,
            vr::AMBIENT => &mut s.ambient_c,
            _ => return None,
        })
    }

    fn load_block(path: &str) -> Result<Box<ModelConsts<f32>>, String> {
        let bytes = std::fs::read(path).map_err(|e| format!("params_file {path}: {e}"))?;
        let b: &[u8; BLOCK_LEN] = bytes
            .as_slice()
            .try_into()
            .map_err(|_| format!("params_file {path}: {} bytes, a parameter block has {BLOCK_LEN}", bytes.len()))?;
        match params_block::view(b) {
            Ok(Some(c)) => Ok(Box::new(*c)),
            Ok(None) => Err(format!("params_file {path}: erased block (no parameters)")),
            Err(e) => Err(format!("params_file {path}: refused by the firmware's checks: {e:?}")),
        }
    }
}

impl Model for GuardFmu {
    const IDENTIFIER: &'static str = "EhaGuard";
    const GUID: &'static str = "{5b0c3e52-7a1d-4c61-9f1e-eha-guard-fw-1}";
    const DESCRIPTION: &'static str = "EHA drain-oil thermal protection: the firmware's f32 guard (reduced thermal model, LNG valve, alarm, faults), 10 ms ticks";
    const STEP_S: f64 = 0.01;

    fn variables() -> &'static [Var] {
        &VARS
    }

    fn new() -> Self {
        let sample = Sample { ambient_c: 20.0, ..Sample::default() };
        Self { sample, valve_fb: -1, params_file: String::new(), consts: None, guard: None, out: Output::default() }
    }

    fn set(&mut self, vr: ValueReference, v: Value) -> Result<(), String> {
        match (vr, v) {
            (vr::PARAMS, Value::String(s)) => {
                self.params_file = s;
                Ok(())
            }
            (vr::VALVE_FB, Value::Integer(x)) if (-1..=1).contains(&x) => {
                self.valve_fb = x;
                Ok(())
            }
            (vr::VALVE_FB, Value::Integer(x)) => Err(format!("valve_feedback {x}: must be -1, 0 or 1")),
            (r, Value::Real(x)) => {
                // The controller's wire sample is f32: the same cast as the
                // reference's `Sensors::sample`.
                *self.real(r).ok_or_else(|| format!("value reference {r} is not a Real input"))? = x as f32;
                Ok(())
            }
            (r, v) => Err(format!("value reference {r} does not take {v:?}")),
        }
    }

    fn get(&self, vr: ValueReference) -> Result<Value, String> {
        let o = &self.out;
        Ok(match vr {
            vr::DRAIN => Value::Real(o.drain_c as f64),
            vr::VALVE => Value::Boolean(o.valve_open),
            vr::ALARM => Value::Boolean(o.alarm),
            vr::DERATE => Value::Boolean(o.derate),
            // the 32-bit fault word, bit for bit (FMI 2.0 has no unsigned Integer)
            vr::FAULTS => Value::Integer(i32::from_ne_bytes(o.faults.bits().to_ne_bytes())),
            vr::LNG_KG => Value::Real(o.lng_remaining_kg as f64),
            vr::LNG_S => Value::Real(o.lng_seconds_left as f64),
            vr::VALVE_FB => Value::Integer(self.valve_fb),
            vr::PARAMS => Value::String(self.params_file.clone()),
            r => {
                let s = self.sample;
                Value::Real(match r {
                    vr::CURRENT => s.current_a,
                    vr::P_A => s.p_a_bar,
                    vr::P_B => s.p_b_bar,
                    vr::SPEED => s.speed_rpm,
                    vr::POSITION => s.position_mm,
                    vr::AMBIENT => s.ambient_c,
                    _ => return Err(format!("no variable with value reference {r}")),
                } as f64)
            }
        })
    }

    fn initialize(&mut self, _start_time_s: f64) -> Result<(), String> {
        if !self.params_file.is_empty() {
            self.consts = Some(Self::load_block(&self.params_file)?);
        }
        let model: &ModelConsts<f32> = match &self.consts {
            Some(c) => c,
            None => &eha_guard::model::DEFAULT_CONSTS,
        };
        // A cold boot, as the QEMU image and the SIL run start (zeroed RAM:
        // no thermal record).
        let config = GuardConfig { model, ..GuardConfig::DEFAULT };
        let g = Guard::new(&config, Restore::Cold);
        self.out = g.output();
        self.guard = Some(Box::new(g));
        Ok(())
    }

    fn do_step(&mut self, _t_s: f64, h_s: f64) -> Result<(), String> {
        let n = (h_s / Self::STEP_S).round();
        if n < 1.0 || (n * Self::STEP_S - h_s).abs() > 1e-9 {
            return Err(format!("the guard ticks every 10 ms: the communication step {h_s} s must be a multiple of 0.01 s"));
        }
        let g = self.guard.as_mut().ok_or("the guard is not initialised")?;
        for _ in 0..n as u64 {
            // As the product loop: the position switch's report, then the tick.
            if self.valve_fb >= 0 {
                g.valve_feedback(self.valve_fb == 1);
            }
            self.out = g.tick(&self.sample);
        }
        Ok(())
    }
}
