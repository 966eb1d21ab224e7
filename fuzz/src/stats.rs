//! Run statistics of the guard targets, printed to stderr when the process
//! exits if `EHA_FUZZ_STATS` is set (libFuzzer ends a run with `exit()`, so an
//! `atexit` hook sees the totals of every execution of this process). Run the
//! corpus once (`-runs=0`) to get the share over the corpus, or a timed run to
//! get it over every generated input.

use std::sync::atomic::{AtomicBool, AtomicU64, Ordering::Relaxed};
use std::sync::Once;

/// Executions (inputs run).
pub static EXECS: AtomicU64 = AtomicU64::new(0);
/// Guard ticks (`step` + `tick_missing`) over all executions.
pub static TICKS: AtomicU64 = AtomicU64::new(0);
/// Ticks whose output had no bit of `faults::LATCHED` set.
pub static UNLATCHED: AtomicU64 = AtomicU64::new(0);
/// Ticks that fed a valid, rate-limited sample (the generator's `Ramp` op).
pub static VALID_TICKS: AtomicU64 = AtomicU64::new(0);
/// Ticks whose output had the valve commanded open.
pub static VALVE_OPEN_TICKS: AtomicU64 = AtomicU64::new(0);
/// Successful `clear_faults` calls that cleared at least one latched bit.
pub static CLEARS: AtomicU64 = AtomicU64::new(0);
/// Injected faults (non-finite, range, rate, stale bursts, actuator, raw samples).
pub static FAULT_OPS: AtomicU64 = AtomicU64::new(0);

static ON: AtomicBool = AtomicBool::new(false);
static INIT: Once = Once::new();
static mut LABEL: &str = "";

extern "C" {
    fn atexit(cb: extern "C" fn()) -> i32;
}

extern "C" fn print_at_exit() {
    let n = TICKS.load(Relaxed);
    let u = UNLATCHED.load(Relaxed);
    let share = if n > 0 { 100.0 * u as f64 / n as f64 } else { 0.0 };
    // SAFETY: written once inside `INIT.call_once` before the hook is registered.
    let label = unsafe { LABEL };
    eprintln!(
        "EHA_FUZZ_STATS {label}: execs {} ticks {n} unlatched {u} ({share:.1} %) valid-ramp ticks {} \
         valve-open ticks {} fault ops {} successful clears {}",
        EXECS.load(Relaxed),
        VALID_TICKS.load(Relaxed),
        VALVE_OPEN_TICKS.load(Relaxed),
        FAULT_OPS.load(Relaxed),
        CLEARS.load(Relaxed),
    );
}

/// Registers the exit hook once when `EHA_FUZZ_STATS` is set; returns whether
/// statistics are being collected.
pub fn enabled(label: &'static str) -> bool {
    INIT.call_once(|| {
        if std::env::var_os("EHA_FUZZ_STATS").is_some() {
            // SAFETY: single write before any reader (the hook) exists.
            unsafe { LABEL = label };
            // SAFETY: registering a plain `extern "C"` function with libc.
            if unsafe { atexit(print_at_exit) } == 0 {
                ON.store(true, Relaxed);
            }
        }
    });
    ON.load(Relaxed)
}
