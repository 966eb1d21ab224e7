//! The FMI 2.0 co-simulation C interface (fmi2Functions.h, fmi2TypesPlatform.h
//! of the FMI 2.0.4 standard), written by hand: the `fmi-export` crate builds
//! FMI 3.0 only, and FMI 2.0 is what every importing tool takes (AMESim,
//! Dymola, OpenModelica, Simulink). The exported functions check every
//! pointer and the instance's state, and turn every error into a status code
//! and a logger message: nothing unwinds into the importer.

use std::ffi::{c_char, c_int, c_uint, c_void, CStr, CString};

/// `fmi2Component`: the instance handle.
pub type Component = *mut c_void;
/// `fmi2ComponentEnvironment`: the importer's pointer, given back to its callbacks.
pub type ComponentEnvironment = *mut c_void;
/// `fmi2ValueReference`.
pub type ValueReference = c_uint;
/// `fmi2Boolean`: 0 = false, 1 = true.
pub type Boolean = c_int;
/// `fmi2Integer`.
pub type Integer = c_int;
/// `fmi2String`.
pub type FmiString = *const c_char;

/// `fmi2Status`.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Status {
    /// All well.
    Ok = 0,
    /// Things are not quite right; the computation can go on.
    Warning = 1,
    /// The step was not done (co-simulation: the master may retry shorter).
    Discard = 2,
    /// The call failed; the instance may be reset.
    Error = 3,
    /// The instance is unusable.
    Fatal = 4,
    /// Asynchronous step pending (never returned here).
    Pending = 5,
}

/// `fmi2Type`.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FmuType {
    /// Model exchange (not provided by these FMUs).
    ModelExchange = 0,
    /// Co-simulation.
    CoSimulation = 1,
}

/// `fmi2StatusKind`.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StatusKind {
    /// Status of an asynchronous doStep.
    DoStepStatus = 0,
    /// Pending-status string.
    PendingStatus = 1,
    /// Last successful communication time.
    LastSuccessfulTime = 2,
    /// Whether the slave wants to terminate.
    Terminated = 3,
}

/// `fmi2CallbackLogger` (C variadic: the message is passed through `"%s"`).
pub type Logger = Option<unsafe extern "C" fn(ComponentEnvironment, FmiString, Status, FmiString, FmiString, ...)>;

/// `fmi2CallbackFunctions`.
#[repr(C)]
pub struct CallbackFunctions {
    /// Logger.
    pub logger: Logger,
    /// allocateMemory (unused: Rust allocates).
    pub allocate_memory: Option<unsafe extern "C" fn(usize, usize) -> *mut c_void>,
    /// freeMemory (unused).
    pub free_memory: Option<unsafe extern "C" fn(*mut c_void)>,
    /// stepFinished (asynchronous steps; unused).
    pub step_finished: Option<unsafe extern "C" fn(ComponentEnvironment, Status)>,
    /// The importer's environment pointer.
    pub component_environment: ComponentEnvironment,
}

/// Causality of a variable (modelDescription.xml).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Causality {
    /// Set before initialisation, fixed during the run.
    Parameter,
    /// Set by the master at communication points.
    Input,
    /// Read by the master.
    Output,
}

/// Type and start value of a variable.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum VarType {
    /// `Real` with its unit (SI-derived symbol as the XML's unit definition)
    /// and, for inputs and parameters, a start value.
    Real {
        /// Unit name (declared in `UnitDefinitions`).
        unit: &'static str,
        /// Start value (inputs and parameters).
        start: Option<f64>,
    },
    /// `Integer` (outputs: no start).
    Integer {
        /// Start value (inputs and parameters).
        start: Option<i32>,
    },
    /// `Boolean`.
    Boolean {
        /// Start value (inputs and parameters).
        start: Option<bool>,
    },
    /// `String` (parameters only here).
    String {
        /// Start value.
        start: &'static str,
    },
}

/// One scalar variable of a model.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Var {
    /// Value reference (unique per type in a model; here unique overall).
    pub vr: ValueReference,
    /// Name.
    pub name: &'static str,
    /// Causality.
    pub causality: Causality,
    /// Type, unit and start.
    pub ty: VarType,
    /// Description for the importing tool.
    pub description: &'static str,
}

impl Var {
    /// A `Real` input with its start value.
    pub const fn real_input(vr: ValueReference, name: &'static str, unit: &'static str, start: f64, description: &'static str) -> Self {
        Self { vr, name, causality: Causality::Input, ty: VarType::Real { unit, start: Some(start) }, description }
    }

    /// A `Real` output.
    pub const fn real_output(vr: ValueReference, name: &'static str, unit: &'static str, description: &'static str) -> Self {
        Self { vr, name, causality: Causality::Output, ty: VarType::Real { unit, start: None }, description }
    }

    /// A variable of any other kind.
    pub const fn new(vr: ValueReference, name: &'static str, causality: Causality, ty: VarType, description: &'static str) -> Self {
        Self { vr, name, causality, ty, description }
    }
}

/// A value crossing the interface.
#[derive(Debug, Clone, PartialEq)]
pub enum Value {
    /// A `Real`.
    Real(f64),
    /// An `Integer`.
    Integer(i32),
    /// A `Boolean`.
    Boolean(bool),
    /// A `String`.
    String(String),
}

/// A co-simulation model behind the FMI interface.
pub trait Model: Sized {
    /// `modelIdentifier` (also the shared library's file name).
    const IDENTIFIER: &'static str;
    /// `guid`: changes whenever the variables change.
    const GUID: &'static str;
    /// `description` of the model.
    const DESCRIPTION: &'static str;
    /// The model's own fixed step, s: communication steps must be multiples
    /// of it (`canHandleVariableCommunicationStepSize` holds either way).
    const STEP_S: f64;

    /// The variables, in value-reference order.
    fn variables() -> &'static [Var];

    /// A model with every variable at its start value.
    fn new() -> Self;

    /// Sets a variable. Outputs cannot be set; parameters only before
    /// [`Model::initialize`].
    fn set(&mut self, vr: ValueReference, v: Value) -> Result<(), String>;

    /// Reads a variable.
    fn get(&self, vr: ValueReference) -> Result<Value, String>;

    /// The relative tolerance and the stop time of fmi2SetupExperiment, when
    /// the master defines them (ignored by models without error control).
    fn set_experiment(&mut self, _rtol: Option<f64>, _stop_s: Option<f64>) {}

    /// Leaves initialisation mode at `start_time_s`: the parameters are read
    /// and the model built.
    fn initialize(&mut self, start_time_s: f64) -> Result<(), String>;

    /// Advances from `t_s` by `h_s` with the inputs as set.
    fn do_step(&mut self, t_s: f64, h_s: f64) -> Result<(), String>;
}

/// Life-cycle state of an instance (FMI 2.0, Fig. 8, co-simulation).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Phase {
    /// After fmi2Instantiate or fmi2Reset.
    Instantiated,
    /// Between fmi2EnterInitializationMode and fmi2ExitInitializationMode.
    Initialization,
    /// Stepping.
    StepComplete,
    /// After fmi2Terminate.
    Terminated,
    /// After an Error or Fatal status.
    Failed,
}

/// One FMU instance: the model, its life-cycle phase and the importer's logger.
pub struct Instance<M> {
    /// The model.
    pub model: M,
    /// Life-cycle phase.
    pub phase: Phase,
    /// Communication time reached, s.
    pub time_s: f64,
    /// Start time from fmi2SetupExperiment, s.
    pub start_s: f64,
    name: CString,
    logger: Logger,
    env: ComponentEnvironment,
    /// Strings handed out by fmi2GetString (valid until the next call).
    strings: Vec<CString>,
}

impl<M: Model> Instance<M> {
    /// A new instance.
    pub fn new(name: &str, f: &CallbackFunctions) -> Self {
        Self {
            model: M::new(),
            phase: Phase::Instantiated,
            time_s: 0.0,
            start_s: 0.0,
            name: CString::new(name.replace('\0', "")).unwrap_or_default(),
            logger: f.logger,
            env: f.component_environment,
            strings: Vec::new(),
        }
    }

    /// Sends `msg` to the importer's logger.
    pub fn log(&self, status: Status, msg: &str) {
        if let Some(log) = self.logger {
            let m = CString::new(msg.replace('\0', "")).unwrap_or_default();
            let cat = c"logStatusError";
            // SAFETY: the logger is the importer's C function; every string is
            // NUL-terminated and outlives the call; "%s" keeps '%' in the
            // message from being read as a format.
            unsafe { log(self.env, self.name.as_ptr(), status, cat.as_ptr(), c"%s".as_ptr(), m.as_ptr()) };
        }
    }

    /// `Error` with a message (the phase becomes [`Phase::Failed`] only for
    /// step failures: a bad set or get leaves the instance usable).
    pub fn fail(&mut self, msg: &str) -> Status {
        self.log(Status::Error, msg);
        Status::Error
    }

    /// Keeps `s` alive until the next get and returns its pointer.
    pub fn keep_string(&mut self, s: &str) -> FmiString {
        self.strings.push(CString::new(s.replace('\0', "")).unwrap_or_default());
        self.strings.last().map_or(std::ptr::null(), |c| c.as_ptr())
    }

    /// Forgets the strings of the previous get.
    pub fn clear_strings(&mut self) {
        self.strings.clear();
    }
}

/// Reads a C string argument (`None` for a null pointer or bad UTF-8).
///
/// # Safety
/// `p` is null or a NUL-terminated string.
pub unsafe fn c_str<'a>(p: FmiString) -> Option<&'a str> {
    if p.is_null() {
        return None;
    }
    // SAFETY: non-null and NUL-terminated (caller).
    unsafe { CStr::from_ptr(p) }.to_str().ok()
}

/// Turns `fmuResourceLocation` (a `file://` URI) into a path.
pub fn resource_path(uri: &str) -> Option<std::path::PathBuf> {
    let rest = uri.strip_prefix("file://").or_else(|| uri.strip_prefix("file:"))?;
    // file:///abs, file://localhost/abs, file:/abs
    let rest = rest.strip_prefix("localhost").unwrap_or(rest);
    let mut out = Vec::new();
    let b = rest.as_bytes();
    let mut i = 0;
    while i < b.len() {
        if b[i] == b'%' && i + 2 < b.len() {
            if let Ok(x) = u8::from_str_radix(&rest[i + 1..i + 3], 16) {
                out.push(x);
                i += 3;
                continue;
            }
        }
        out.push(b[i]);
        i += 1;
    }
    Some(std::path::PathBuf::from(String::from_utf8(out).ok()?))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn resource_uris_become_paths() {
        assert_eq!(resource_path("file:///tmp/a%20b/resources"), Some("/tmp/a b/resources".into()));
        assert_eq!(resource_path("file:/tmp/x"), Some("/tmp/x".into()));
        assert_eq!(resource_path("file://localhost/tmp/x"), Some("/tmp/x".into()));
        assert_eq!(resource_path("http://x"), None);
    }
}
