//! The exported `fmi2*` symbols. One shared library serves both FMUs (the
//! plant and the guard): `fmi2Instantiate` picks the model by the GUID the
//! importer read from the FMU's modelDescription.xml. Every call checks its
//! pointers and the instance's phase and catches panics, which become
//! `fmi2Fatal` with a logged message.

use crate::fmi2::{
    self, c_str, Boolean, CallbackFunctions, Component, FmiString, FmuType, Instance, Integer, Model, Phase, Status, StatusKind,
    Value, ValueReference,
};
use crate::{guard::GuardFmu, plant::PlantFmu};
use std::ffi::{c_char, c_void};
use std::panic::{catch_unwind, AssertUnwindSafe};

// The lifecycle calls here; the typed getters and setters in `values`, the
// step, its status queries and the unsupported capabilities in `step`.
mod values;

mod step;

pub use step::*;
pub use values::*;

/// What the exports need of an instance, whatever its model.
pub trait Slave {
    /// The instance's life-cycle phase.
    fn phase(&self) -> Phase;
    /// Sets the phase.
    fn set_phase(&mut self, p: Phase);
    /// Logs to the importer.
    fn log(&self, s: Status, msg: &str);
    /// fmi2SetupExperiment.
    fn setup(&mut self, start_s: f64, tolerance: Option<f64>, stop_s: Option<f64>);
    /// fmi2ExitInitializationMode.
    fn initialize(&mut self) -> Result<(), String>;
    /// fmi2Reset.
    fn reset(&mut self);
    /// Sets one value.
    fn set(&mut self, vr: ValueReference, v: Value) -> Result<(), String>;
    /// Gets one value.
    fn get(&self, vr: ValueReference) -> Result<Value, String>;
    /// fmi2DoStep.
    fn do_step(&mut self, t_s: f64, h_s: f64) -> Result<(), String>;
    /// Communication time reached, s.
    fn time_s(&self) -> f64;
    /// Keeps a string for fmi2GetString.
    fn keep_string(&mut self, s: &str) -> FmiString;
    /// Drops the strings of the previous fmi2GetString.
    fn clear_strings(&mut self);
}

impl<M: Model> Slave for Instance<M> {
    fn phase(&self) -> Phase {
        self.phase
    }
    fn set_phase(&mut self, p: Phase) {
        self.phase = p;
    }
    fn log(&self, s: Status, msg: &str) {
        Instance::log(self, s, msg)
    }
    fn setup(&mut self, start_s: f64, tolerance: Option<f64>, stop_s: Option<f64>) {
        self.model.set_experiment(tolerance, stop_s.map(|t| t - start_s));
        self.start_s = start_s;
        self.time_s = start_s;
    }
    fn initialize(&mut self) -> Result<(), String> {
        self.model.initialize(self.start_s)
    }
    fn reset(&mut self) {
        self.model = M::new();
        self.phase = Phase::Instantiated;
        self.time_s = 0.0;
        self.start_s = 0.0;
    }
    fn set(&mut self, vr: ValueReference, v: Value) -> Result<(), String> {
        let var = M::variables().iter().find(|x| x.vr == vr).ok_or_else(|| format!("no variable with value reference {vr}"))?;
        match (var.causality, self.phase) {
            (fmi2::Causality::Output, _) => Err(format!("{} is an output and cannot be set", var.name)),
            (fmi2::Causality::Parameter, Phase::StepComplete) => {
                Err(format!("{} is a fixed parameter: set it before fmi2ExitInitializationMode", var.name))
            }
            _ => self.model.set(vr, v),
        }
    }
    fn get(&self, vr: ValueReference) -> Result<Value, String> {
        self.model.get(vr)
    }
    fn do_step(&mut self, t_s: f64, h_s: f64) -> Result<(), String> {
        if !(h_s > 0.0 && h_s.is_finite()) {
            return Err(format!("communication step {h_s} s must be > 0"));
        }
        if (t_s - self.time_s).abs() > 1e-9 * (1.0 + t_s.abs()) {
            return Err(format!("doStep from t = {t_s} s, but the FMU is at t = {} s", self.time_s));
        }
        self.model.do_step(t_s, h_s)?;
        self.time_s = t_s + h_s;
        Ok(())
    }
    fn time_s(&self) -> f64 {
        self.time_s
    }
    fn keep_string(&mut self, s: &str) -> FmiString {
        Instance::keep_string(self, s)
    }
    fn clear_strings(&mut self) {
        Instance::clear_strings(self)
    }
}

/// The component handle: a thin pointer to a boxed trait object.
type Handle = Box<dyn Slave>;

/// Runs `f` on the instance behind `c`; `Error` for a null handle, `Fatal`
/// (logged) for a panic.
fn with(c: Component, f: impl FnOnce(&mut dyn Slave) -> Status) -> Status {
    if c.is_null() {
        return Status::Error;
    }
    // SAFETY: a non-null component was made by fmi2Instantiate from
    // `Box<Handle>` and is not freed until fmi2FreeInstance (FMI contract).
    let h = unsafe { &mut *(c as *mut Handle) };
    match catch_unwind(AssertUnwindSafe(|| f(h.as_mut()))) {
        Ok(s) => s,
        Err(_) => {
            h.log(Status::Fatal, "internal error (panic) in the FMU");
            h.set_phase(Phase::Failed);
            Status::Fatal
        }
    }
}

/// Checks that a call is allowed in the instance's phase.
fn allowed(h: &mut dyn Slave, call: &str, phases: &[Phase]) -> bool {
    if phases.contains(&h.phase()) {
        true
    } else {
        h.log(Status::Error, &format!("{call} is not allowed in phase {:?}", h.phase()));
        false
    }
}

/// A slice from an importer's array (empty for n = 0, `None` for null with n > 0).
///
/// # Safety
/// `p` points to `n` elements or is null.
unsafe fn slice<'a, T>(p: *const T, n: usize) -> Option<&'a [T]> {
    if n == 0 {
        Some(&[])
    } else if p.is_null() {
        None
    } else {
        // SAFETY: non-null with n elements (caller).
        Some(unsafe { std::slice::from_raw_parts(p, n) })
    }
}

/// As [`slice`], mutable.
///
/// # Safety
/// As [`slice`].
unsafe fn slice_mut<'a, T>(p: *mut T, n: usize) -> Option<&'a mut [T]> {
    if n == 0 {
        Some(&mut [])
    } else if p.is_null() {
        None
    } else {
        // SAFETY: non-null with n elements (caller).
        Some(unsafe { std::slice::from_raw_parts_mut(p, n) })
    }
}

const SETTABLE: &[Phase] = &[Phase::Instantiated, Phase::Initialization, Phase::StepComplete];
const GETTABLE: &[Phase] = &[Phase::Initialization, Phase::StepComplete, Phase::Terminated, Phase::Failed];

/// `fmi2GetTypesPlatform`.
#[no_mangle]
pub extern "C" fn fmi2GetTypesPlatform() -> *const c_char {
    c"default".as_ptr()
}

/// `fmi2GetVersion`.
#[no_mangle]
pub extern "C" fn fmi2GetVersion() -> *const c_char {
    c"2.0".as_ptr()
}

/// `fmi2SetDebugLogging`: accepted, nothing more is logged than errors.
#[no_mangle]
pub extern "C" fn fmi2SetDebugLogging(c: Component, _on: Boolean, _n: usize, _categories: *const FmiString) -> Status {
    with(c, |_| Status::Ok)
}

/// `fmi2Instantiate`: co-simulation only; the model is chosen by `guid`.
///
/// # Safety
/// The strings are null or NUL-terminated; `functions` is null or valid.
#[no_mangle]
pub unsafe extern "C" fn fmi2Instantiate(
    name: FmiString,
    fmu_type: FmuType,
    guid: FmiString,
    _resources: FmiString,
    functions: *const CallbackFunctions,
    _visible: Boolean,
    _logging_on: Boolean,
) -> Component {
    // SAFETY: caller contract.
    let (name, guid, f) = unsafe { (c_str(name).unwrap_or("instance"), c_str(guid), functions.as_ref()) };
    let Some(f) = f else { return std::ptr::null_mut() };
    let r = catch_unwind(AssertUnwindSafe(|| -> Option<Handle> {
        let h: Handle = match guid {
            Some(g) if g == PlantFmu::GUID => Box::new(Instance::<PlantFmu>::new(name, f)),
            Some(g) if g == GuardFmu::GUID => Box::new(Instance::<GuardFmu>::new(name, f)),
            _ => {
                let tmp = Instance::<GuardFmu>::new(name, f);
                tmp.log(Status::Error, &format!("unknown GUID {guid:?}: this library serves {} and {}", PlantFmu::GUID, GuardFmu::GUID));
                return None;
            }
        };
        if fmu_type != FmuType::CoSimulation {
            h.log(Status::Error, "only co-simulation is provided (fmuType must be fmi2CoSimulation)");
            return None;
        }
        Some(h)
    }));
    match r {
        Ok(Some(h)) => Box::into_raw(Box::new(h)) as Component,
        _ => std::ptr::null_mut(),
    }
}

/// `fmi2FreeInstance`.
#[no_mangle]
pub extern "C" fn fmi2FreeInstance(c: Component) {
    if !c.is_null() {
        // SAFETY: made by fmi2Instantiate, freed once (FMI contract).
        drop(unsafe { Box::from_raw(c as *mut Handle) });
    }
}

/// `fmi2SetupExperiment`: the start time and, when defined, the tolerance and the stop time.
#[no_mangle]
pub extern "C" fn fmi2SetupExperiment(c: Component, tol_defined: Boolean, tol: f64, start: f64, stop_defined: Boolean, stop: f64) -> Status {
    with(c, |h| {
        if !allowed(h, "fmi2SetupExperiment", &[Phase::Instantiated]) {
            return Status::Error;
        }
        if !start.is_finite() {
            h.log(Status::Error, "start time is not finite");
            return Status::Error;
        }
        h.setup(start, (tol_defined != 0).then_some(tol), (stop_defined != 0 && stop.is_finite() && stop > start).then_some(stop));
        Status::Ok
    })
}

/// `fmi2EnterInitializationMode`.
#[no_mangle]
pub extern "C" fn fmi2EnterInitializationMode(c: Component) -> Status {
    with(c, |h| {
        if !allowed(h, "fmi2EnterInitializationMode", &[Phase::Instantiated]) {
            return Status::Error;
        }
        h.set_phase(Phase::Initialization);
        Status::Ok
    })
}

/// `fmi2ExitInitializationMode`: builds the model from the parameters.
#[no_mangle]
pub extern "C" fn fmi2ExitInitializationMode(c: Component) -> Status {
    with(c, |h| {
        if !allowed(h, "fmi2ExitInitializationMode", &[Phase::Initialization]) {
            return Status::Error;
        }
        match h.initialize() {
            Ok(()) => {
                h.set_phase(Phase::StepComplete);
                Status::Ok
            }
            Err(e) => {
                h.log(Status::Error, &e);
                h.set_phase(Phase::Failed);
                Status::Error
            }
        }
    })
}

/// `fmi2Terminate`.
#[no_mangle]
pub extern "C" fn fmi2Terminate(c: Component) -> Status {
    with(c, |h| {
        if !allowed(h, "fmi2Terminate", &[Phase::StepComplete, Phase::Failed]) {
            return Status::Error;
        }
        h.set_phase(Phase::Terminated);
        Status::Ok
    })
}

/// `fmi2Reset`: back to the instantiated state with the start values.
#[no_mangle]
pub extern "C" fn fmi2Reset(c: Component) -> Status {
    with(c, |h| {
        h.reset();
        Status::Ok
    })
}
