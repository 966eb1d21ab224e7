//! The f32 guard (the Cortex-M4F build's `Guard`) driven by structured
//! operation sequences (see `src/guard.rs`).
#![no_main]
use eha_guard::GuardOf;
use libfuzzer_sys::fuzz_target;
use std::sync::OnceLock;

static COLD: OnceLock<GuardOf<eha_guard::Real>> = OnceLock::new();

fuzz_target!(|data: &[u8]| {
    eha_guard_fuzz::guard::run::<eha_guard::Real>(data, "guard", &COLD);
});
