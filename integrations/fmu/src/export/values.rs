//! `fmi2Get*` and `fmi2Set*`: the values by reference, type-checked, in
//! the phases FMI 2.0 allows.

use super::*;

/// Shared body of the typed getters.
///
/// # Safety
/// `vr` has `n` elements or is null; `write` writes the i-th value.
unsafe fn get_values(c: Component, call: &str, vr: *const ValueReference, n: usize, mut write: impl FnMut(&mut dyn Slave, usize, Value) -> Result<(), String>) -> Status {
    with(c, |h| {
        if !allowed(h, call, GETTABLE) {
            return Status::Error;
        }
        // SAFETY: caller contract.
        let Some(vrs) = (unsafe { slice(vr, n) }) else {
            h.log(Status::Error, &format!("{call}: null value-reference array"));
            return Status::Error;
        };
        for (i, &r) in vrs.iter().enumerate() {
            if let Err(e) = h.get(r).and_then(|v| write(h, i, v)) {
                h.log(Status::Error, &format!("{call}: {e}"));
                return Status::Error;
            }
        }
        Status::Ok
    })
}

/// Shared body of the typed setters.
///
/// # Safety
/// `vr` has `n` elements or is null; `read` reads the i-th value.
unsafe fn set_values(c: Component, call: &str, vr: *const ValueReference, n: usize, read: impl Fn(usize) -> Option<Value>) -> Status {
    with(c, |h| {
        if !allowed(h, call, SETTABLE) {
            return Status::Error;
        }
        // SAFETY: caller contract.
        let Some(vrs) = (unsafe { slice(vr, n) }) else {
            h.log(Status::Error, &format!("{call}: null value-reference array"));
            return Status::Error;
        };
        for (i, &r) in vrs.iter().enumerate() {
            let Some(v) = read(i) else {
                h.log(Status::Error, &format!("{call}: null value array"));
                return Status::Error;
            };
            if let Err(e) = h.set(r, v) {
                h.log(Status::Error, &format!("{call}: {e}"));
                return Status::Error;
            }
        }
        Status::Ok
    })
}

fn type_err(want: &str, got: &Value) -> String {
    format!("the variable is not a {want} (it is {got:?})")
}

/// Shared body of the numeric getters: `pick` takes the value of the
/// wanted type out of a [`Value`].
///
/// # Safety
/// FMI contract: arrays of `n` elements.
unsafe fn get_typed<T>(c: Component, call: &str, want: &str, vr: *const ValueReference, n: usize, value: *mut T, pick: impl Fn(&Value) -> Option<T>) -> Status {
    // SAFETY: caller contract.
    let Some(out) = (unsafe { slice_mut(value, n) }) else { return Status::Error };
    // SAFETY: caller contract.
    unsafe {
        get_values(c, call, vr, n, |_, i, v| {
            out[i] = pick(&v).ok_or_else(|| type_err(want, &v))?;
            Ok(())
        })
    }
}

/// `fmi2GetReal`.
///
/// # Safety
/// FMI contract: arrays of `n` elements.
#[no_mangle]
pub unsafe extern "C" fn fmi2GetReal(c: Component, vr: *const ValueReference, n: usize, value: *mut f64) -> Status {
    // SAFETY: caller contract.
    unsafe { get_typed(c, "fmi2GetReal", "Real", vr, n, value, |v| if let Value::Real(x) = v { Some(*x) } else { None }) }
}

/// `fmi2GetInteger`.
///
/// # Safety
/// FMI contract: arrays of `n` elements.
#[no_mangle]
pub unsafe extern "C" fn fmi2GetInteger(c: Component, vr: *const ValueReference, n: usize, value: *mut Integer) -> Status {
    // SAFETY: caller contract.
    unsafe { get_typed(c, "fmi2GetInteger", "Integer", vr, n, value, |v| if let Value::Integer(x) = v { Some(*x) } else { None }) }
}

/// `fmi2GetBoolean`.
///
/// # Safety
/// FMI contract: arrays of `n` elements.
#[no_mangle]
pub unsafe extern "C" fn fmi2GetBoolean(c: Component, vr: *const ValueReference, n: usize, value: *mut Boolean) -> Status {
    // SAFETY: caller contract.
    unsafe { get_typed(c, "fmi2GetBoolean", "Boolean", vr, n, value, |v| if let Value::Boolean(x) = v { Some(Boolean::from(*x)) } else { None }) }
}

/// `fmi2GetString`: the strings stay valid until the next fmi2GetString.
///
/// # Safety
/// FMI contract: arrays of `n` elements.
#[no_mangle]
pub unsafe extern "C" fn fmi2GetString(c: Component, vr: *const ValueReference, n: usize, value: *mut FmiString) -> Status {
    // SAFETY: caller contract.
    let Some(out) = (unsafe { slice_mut(value, n) }) else { return Status::Error };
    let mut first = true;
    // SAFETY: caller contract.
    unsafe {
        get_values(c, "fmi2GetString", vr, n, |h, i, v| {
            if first {
                h.clear_strings();
                first = false;
            }
            match v {
                Value::String(s) => {
                    out[i] = h.keep_string(&s);
                    Ok(())
                }
                o => Err(type_err("String", &o)),
            }
        })
    }
}

/// `fmi2SetReal`.
///
/// # Safety
/// FMI contract: arrays of `n` elements.
#[no_mangle]
pub unsafe extern "C" fn fmi2SetReal(c: Component, vr: *const ValueReference, n: usize, value: *const f64) -> Status {
    // SAFETY: caller contract.
    let v = unsafe { slice(value, n) };
    // SAFETY: caller contract.
    unsafe { set_values(c, "fmi2SetReal", vr, n, |i| v.and_then(|v| v.get(i)).map(|&x| Value::Real(x))) }
}

/// `fmi2SetInteger`.
///
/// # Safety
/// FMI contract: arrays of `n` elements.
#[no_mangle]
pub unsafe extern "C" fn fmi2SetInteger(c: Component, vr: *const ValueReference, n: usize, value: *const Integer) -> Status {
    // SAFETY: caller contract.
    let v = unsafe { slice(value, n) };
    // SAFETY: caller contract.
    unsafe { set_values(c, "fmi2SetInteger", vr, n, |i| v.and_then(|v| v.get(i)).map(|&x| Value::Integer(x))) }
}

/// `fmi2SetBoolean`.
///
/// # Safety
/// FMI contract: arrays of `n` elements.
#[no_mangle]
pub unsafe extern "C" fn fmi2SetBoolean(c: Component, vr: *const ValueReference, n: usize, value: *const Boolean) -> Status {
    // SAFETY: caller contract.
    let v = unsafe { slice(value, n) };
    // SAFETY: caller contract.
    unsafe { set_values(c, "fmi2SetBoolean", vr, n, |i| v.and_then(|v| v.get(i)).map(|&x| Value::Boolean(x != 0))) }
}

/// `fmi2SetString`.
///
/// # Safety
/// FMI contract: arrays of `n` elements, each a NUL-terminated string.
#[no_mangle]
pub unsafe extern "C" fn fmi2SetString(c: Component, vr: *const ValueReference, n: usize, value: *const FmiString) -> Status {
    // SAFETY: caller contract.
    let v = unsafe { slice(value, n) };
    // SAFETY: caller contract (each element NUL-terminated or null).
    unsafe { set_values(c, "fmi2SetString", vr, n, |i| v.and_then(|v| v.get(i)).and_then(|&p| c_str(p)).map(|s| Value::String(s.to_owned()))) }
}
