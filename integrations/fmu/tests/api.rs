//! The FMI 2.0 entry points called as an importer calls them: the life
//! cycle, and every error path answering a status (never a crash): null
//! handles and arrays, an unknown GUID, model exchange, a parameter set after
//! initialisation, a step the guard cannot take, a bad parameter file.

use eha_fmu::export::*;
use eha_fmu::fmi2::{CallbackFunctions, Component, FmuType, Model, Status};
use eha_fmu::{guard::GuardFmu, plant::PlantFmu};
use std::ffi::CString;

fn callbacks() -> CallbackFunctions {
    CallbackFunctions { logger: None, allocate_memory: None, free_memory: None, step_finished: None, component_environment: std::ptr::null_mut() }
}

fn instantiate(guid: &str, ty: FmuType) -> Component {
    let name = CString::new("t").unwrap();
    let guid = CString::new(guid).unwrap();
    let cb = callbacks();
    // SAFETY: valid strings and callbacks for the duration of the call.
    unsafe { fmi2Instantiate(name.as_ptr(), ty, guid.as_ptr(), std::ptr::null(), &cb, 0, 0) }
}

fn vr_of<M: Model>(name: &str) -> u32 {
    M::variables().iter().find(|v| v.name == name).map(|v| v.vr).unwrap_or_else(|| panic!("no variable {name}"))
}

fn init(c: Component) {
    assert_eq!(fmi2SetupExperiment(c, 0, 0.0, 0.0, 0, 0.0), Status::Ok);
    assert_eq!(fmi2EnterInitializationMode(c), Status::Ok);
    assert_eq!(fmi2ExitInitializationMode(c), Status::Ok);
}

#[test]
fn unknown_guid_and_model_exchange_are_refused() {
    assert!(instantiate("{not-ours}", FmuType::CoSimulation).is_null());
    assert!(instantiate(GuardFmu::GUID, FmuType::ModelExchange).is_null());
    let cb = callbacks();
    // SAFETY: null strings are allowed by the entry point (refused).
    let c = unsafe { fmi2Instantiate(std::ptr::null(), FmuType::CoSimulation, std::ptr::null(), std::ptr::null(), &cb, 0, 0) };
    assert!(c.is_null());
}

#[test]
fn null_handles_and_arrays_give_error_not_a_crash() {
    let null: Component = std::ptr::null_mut();
    assert_eq!(fmi2DoStep(null, 0.0, 0.01, 1), Status::Error);
    assert_eq!(fmi2Terminate(null), Status::Error);
    fmi2FreeInstance(null);
    let c = instantiate(GuardFmu::GUID, FmuType::CoSimulation);
    init(c);
    let mut v = [0.0f64; 2];
    // SAFETY: the entry points check the null arrays.
    unsafe {
        assert_eq!(fmi2GetReal(c, std::ptr::null(), 2, v.as_mut_ptr()), Status::Error);
        assert_eq!(fmi2GetReal(c, [0u32, 1].as_ptr(), 2, std::ptr::null_mut()), Status::Error);
        assert_eq!(fmi2SetReal(c, [0u32].as_ptr(), 1, std::ptr::null()), Status::Error);
        // A value reference that does not exist, and a type mismatch.
        assert_eq!(fmi2GetReal(c, [999u32].as_ptr(), 1, v.as_mut_ptr()), Status::Error);
        let mut b = [0i32; 1];
        assert_eq!(fmi2GetBoolean(c, [vr_of::<GuardFmu>("drain_c")].as_ptr(), 1, b.as_mut_ptr()), Status::Error);
        // An output cannot be set.
        assert_eq!(fmi2SetReal(c, [vr_of::<GuardFmu>("drain_c")].as_ptr(), 1, [1.0].as_ptr()), Status::Error);
    }
    fmi2FreeInstance(c);
}

#[test]
fn guard_steps_in_whole_ticks_and_parameters_are_fixed_after_init() {
    let c = instantiate(GuardFmu::GUID, FmuType::CoSimulation);
    // Calls out of order.
    assert_eq!(fmi2DoStep(c, 0.0, 0.01, 1), Status::Error);
    init(c);
    let p = CString::new("/nonexistent").unwrap();
    // SAFETY: valid arrays.
    unsafe {
        assert_eq!(fmi2SetString(c, [vr_of::<GuardFmu>("params_file")].as_ptr(), 1, [p.as_ptr()].as_ptr()), Status::Error);
    }
    assert_eq!(fmi2DoStep(c, 0.0, 0.025, 1), Status::Error, "2.5 ticks");
    fmi2FreeInstance(c);
    let c = instantiate(GuardFmu::GUID, FmuType::CoSimulation);
    init(c);
    assert_eq!(fmi2DoStep(c, 0.0, 0.03, 1), Status::Ok, "three ticks");
    // From the wrong time.
    assert_eq!(fmi2DoStep(c, 1.0, 0.01, 1), Status::Error);
    fmi2FreeInstance(c);
}

#[test]
fn guard_refuses_a_bad_parameter_block_at_initialisation() {
    let dir = std::env::temp_dir().join(format!("eha-fmu-api-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let bad = dir.join("short.bin");
    std::fs::write(&bad, [0u8; 10]).unwrap();
    let c = instantiate(GuardFmu::GUID, FmuType::CoSimulation);
    assert_eq!(fmi2SetupExperiment(c, 0, 0.0, 0.0, 0, 0.0), Status::Ok);
    assert_eq!(fmi2EnterInitializationMode(c), Status::Ok);
    let p = CString::new(bad.to_str().unwrap()).unwrap();
    // SAFETY: valid arrays.
    unsafe {
        assert_eq!(fmi2SetString(c, [vr_of::<GuardFmu>("params_file")].as_ptr(), 1, [p.as_ptr()].as_ptr()), Status::Ok);
    }
    assert_eq!(fmi2ExitInitializationMode(c), Status::Error);
    fmi2FreeInstance(c);
    let _ = std::fs::remove_dir_all(&dir);
}

/// The plant FMU on 60 s of Case 1 at 60 bar: it heats (the drain rises
/// above its 16 °C start) and its stepping agrees with the native run at the
/// same instant to the solver's history: bit for bit, as the FMU keeps the
/// BDF alive across communication points.
#[test]
fn plant_steps_like_the_native_run() {
    let c = instantiate(PlantFmu::GUID, FmuType::CoSimulation);
    assert_eq!(fmi2SetupExperiment(c, 0, 0.0, 0.0, 1, 60.0), Status::Ok);
    assert_eq!(fmi2EnterInitializationMode(c), Status::Ok);
    // SAFETY: valid arrays.
    unsafe {
        assert_eq!(fmi2SetReal(c, [vr_of::<PlantFmu>("cmd_needle_bar")].as_ptr(), 1, [60.0].as_ptr()), Status::Ok);
    }
    assert_eq!(fmi2ExitInitializationMode(c), Status::Ok);
    for k in 0..60 {
        assert_eq!(fmi2DoStep(c, k as f64, 1.0, 1), Status::Ok, "step {k}");
    }
    assert_eq!(fmi2DoStep(c, 60.0, 1.0, 1), Status::Error, "past the stop time");
    let mut drain = [0.0];
    // SAFETY: valid arrays.
    unsafe { assert_eq!(fmi2GetReal(c, [vr_of::<PlantFmu>("t_drain_c")].as_ptr(), 1, drain.as_mut_ptr()), Status::Ok) };
    fmi2FreeInstance(c);
    let rig = eha_sim::rig::Rig::default();
    let native = eha_sim::sim::simulate(&rig, &eha_sim::scenario::Scenario::Case1 { needle_bar: 60.0, duration_s: 60.0 }, &Default::default()).unwrap();
    let want = native.last("t_drain_c").unwrap();
    assert!(want > 16.1, "the drain heats in 60 s: {want}");
    assert_eq!(drain[0].to_bits(), want.to_bits(), "FMU {} vs native {want}", drain[0]);
}
