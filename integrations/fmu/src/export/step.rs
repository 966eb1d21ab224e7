//! `fmi2DoStep`, the status queries (synchronous steps: nothing to report
//! but the last step's time) and the capabilities these FMUs do not declare.

use super::*;

/// `fmi2DoStep`.
#[no_mangle]
pub extern "C" fn fmi2DoStep(c: Component, t: f64, h_s: f64, _no_set_prior: Boolean) -> Status {
    with(c, |h| {
        if !allowed(h, "fmi2DoStep", &[Phase::StepComplete]) {
            return Status::Error;
        }
        match h.do_step(t, h_s) {
            Ok(()) => Status::Ok,
            Err(e) => {
                h.log(Status::Error, &format!("fmi2DoStep at t = {t} s: {e}"));
                h.set_phase(Phase::Failed);
                Status::Error
            }
        }
    })
}

/// `fmi2CancelStep`: steps are synchronous, nothing to cancel.
#[no_mangle]
pub extern "C" fn fmi2CancelStep(c: Component) -> Status {
    with(c, |h| {
        h.log(Status::Error, "fmi2CancelStep: steps are synchronous");
        Status::Error
    })
}

/// Status queries that have nothing to report (synchronous steps).
fn no_status(c: Component, call: &str) -> Status {
    with(c, |h| {
        h.log(Status::Discard, &format!("{call}: not available (synchronous steps)"));
        Status::Discard
    })
}

/// `fmi2GetStatus`.
#[no_mangle]
pub extern "C" fn fmi2GetStatus(c: Component, _s: StatusKind, _value: *mut Status) -> Status {
    no_status(c, "fmi2GetStatus")
}

/// `fmi2GetRealStatus`: the last successful communication time.
///
/// # Safety
/// `value` is null or valid for a write.
#[no_mangle]
pub unsafe extern "C" fn fmi2GetRealStatus(c: Component, s: StatusKind, value: *mut f64) -> Status {
    with(c, |h| {
        if s != StatusKind::LastSuccessfulTime || value.is_null() {
            h.log(Status::Discard, "fmi2GetRealStatus: only fmi2LastSuccessfulTime");
            return Status::Discard;
        }
        // SAFETY: non-null, caller contract.
        unsafe { *value = h.time_s() };
        Status::Ok
    })
}

/// `fmi2GetIntegerStatus`.
#[no_mangle]
pub extern "C" fn fmi2GetIntegerStatus(c: Component, _s: StatusKind, _value: *mut Integer) -> Status {
    no_status(c, "fmi2GetIntegerStatus")
}

/// `fmi2GetBooleanStatus`: fmi2Terminated is always false.
///
/// # Safety
/// `value` is null or valid for a write.
#[no_mangle]
pub unsafe extern "C" fn fmi2GetBooleanStatus(c: Component, s: StatusKind, value: *mut Boolean) -> Status {
    with(c, |h| {
        if s != StatusKind::Terminated || value.is_null() {
            h.log(Status::Discard, "fmi2GetBooleanStatus: only fmi2Terminated");
            return Status::Discard;
        }
        // SAFETY: non-null, caller contract.
        unsafe { *value = 0 };
        Status::Ok
    })
}

/// `fmi2GetStringStatus`.
#[no_mangle]
pub extern "C" fn fmi2GetStringStatus(c: Component, _s: StatusKind, _value: *mut FmiString) -> Status {
    no_status(c, "fmi2GetStringStatus")
}

/// Capabilities these FMUs do not declare (modelDescription.xml) but must
/// export: each answers `fmi2Error` with a message.
macro_rules! unsupported {
    ($($name:ident ( $($arg:ident : $ty:ty),* );)*) => {$(
        #[doc = concat!("`", stringify!($name), "`: not supported (not declared in modelDescription.xml).")]
        #[no_mangle]
        pub extern "C" fn $name(c: Component, $($arg: $ty),*) -> Status {
            let _ = ($($arg),*);
            with(c, |h| {
                h.log(Status::Error, concat!(stringify!($name), " is not supported by this FMU"));
                Status::Error
            })
        }
    )*};
}

unsupported! {
    fmi2GetFMUstate(_s: *mut *mut c_void);
    fmi2SetFMUstate(_s: *mut c_void);
    fmi2FreeFMUstate(_s: *mut *mut c_void);
    fmi2SerializedFMUstateSize(_s: *mut c_void, _size: *mut usize);
    fmi2SerializeFMUstate(_s: *mut c_void, _b: *mut c_char, _size: usize);
    fmi2DeSerializeFMUstate(_b: *const c_char, _size: usize, _s: *mut *mut c_void);
    fmi2GetDirectionalDerivative(_u: *const ValueReference, _nu: usize, _k: *const ValueReference, _nk: usize, _dk: *const f64, _du: *mut f64);
    fmi2SetRealInputDerivatives(_vr: *const ValueReference, _n: usize, _o: *const Integer, _v: *const f64);
    fmi2GetRealOutputDerivatives(_vr: *const ValueReference, _n: usize, _o: *const Integer, _v: *mut f64);
}
