//! The 10 ms tick and what happens between ticks: a sample, a missing
//! sample, missed and stalled periods, the outputs, the valve pin's read-back.

use eha_guard::product::catch_up;

use super::*;

/// One 10 ms tick with a new sample and the controller's reports (valve
/// position, LNG supply, electrical frequency), in the product loop's
/// order. A sample with a flag out of range is not used: the tick runs as
/// a missing sample and [`EhaStatus::EhaErrArg`] is returned (a NULL
/// `sample`: the same, [`EhaStatus::EhaErrNull`]).
///
/// # Safety
/// `storage` as initialised by `eha_guard_init`; `sample` NULL or valid;
/// `out` NULL or valid for a write.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn eha_guard_tick(storage: *mut c_void, sample: *const EhaSample, out: *mut EhaOutput) -> EhaStatus {
    // SAFETY: NULL or valid (caller).
    let sample = unsafe { sample.as_ref() }.map(EhaSample::to_guard);
    // SAFETY: forwarded (caller).
    unsafe {
        with_guard(storage, out, |s| {
            let (o, st) = match sample {
                Some(Some((smp, rep))) => (s.guard.tick_reported(&smp, &rep), EhaStatus::EhaOk),
                Some(None) => (s.guard.tick_missing(), EhaStatus::EhaErrArg),
                None => (s.guard.tick_missing(), EhaStatus::EhaErrNull),
            };
            put(out, EhaOutput::of(&o));
            st
        })
    }
}

/// One 10 ms tick without a new sample (inputs held; STALE after
/// `stale_ticks` in a row; before the first sample the guard waits, valve
/// open).
///
/// # Safety
/// As [`eha_guard_tick`].
#[unsafe(no_mangle)]
pub unsafe extern "C" fn eha_guard_tick_missing(storage: *mut c_void, out: *mut EhaOutput) -> EhaStatus {
    // SAFETY: forwarded (caller).
    unsafe {
        with_guard(storage, out, |s| {
            put(out, EhaOutput::of(&s.guard.tick_missing()));
            EhaStatus::EhaOk
        })
    }
}

/// Timer periods that passed without a tick of their own, accounted as the
/// product does before this period's tick: the `stalled` of them a
/// non-volatile save stalled the core for are blind ticks (no STALE, no
/// cooling credit, at most 500), the rest missing ticks (at most 100).
/// `out` receives the outputs after them.
///
/// # Safety
/// As [`eha_guard_tick`].
#[unsafe(no_mangle)]
pub unsafe extern "C" fn eha_guard_catch_up(storage: *mut c_void, lost: u32, stalled: u32, out: *mut EhaOutput) -> EhaStatus {
    // SAFETY: forwarded (caller).
    unsafe {
        with_guard(storage, out, |s| {
            catch_up(&mut s.guard, lost, stalled);
            put(out, EhaOutput::of(&s.guard.output()));
            EhaStatus::EhaOk
        })
    }
}

/// The outputs as the last call left them.
///
/// # Safety
/// As [`eha_guard_tick`].
#[unsafe(no_mangle)]
pub unsafe extern "C" fn eha_guard_output(storage: *mut c_void, out: *mut EhaOutput) -> EhaStatus {
    // SAFETY: forwarded (caller).
    unsafe {
        with_guard(storage, out, |s| {
            put(out, EhaOutput::of(&s.guard.output()));
            if out.is_null() {
                EhaStatus::EhaErrNull
            } else {
                EhaStatus::EhaOk
            }
        })
    }
}

/// The valve or OK pin read back differs from what was written: ACTUATOR
/// latches and the valve is commanded open at once (write the pins again
/// from `out`), as the product loop does.
///
/// # Safety
/// As [`eha_guard_tick`].
#[unsafe(no_mangle)]
pub unsafe extern "C" fn eha_guard_report_actuator_fault(storage: *mut c_void, out: *mut EhaOutput) -> EhaStatus {
    // SAFETY: forwarded (caller).
    unsafe {
        with_guard(storage, out, |s| {
            s.guard.report_actuator_fault();
            put(out, EhaOutput::of(&s.guard.output()));
            EhaStatus::EhaOk
        })
    }
}
