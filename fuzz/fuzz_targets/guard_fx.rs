//! The fixed-point guard (`GuardOf<Fx>`, the Cortex-M3 build's number type)
//! driven by the same structured operation sequences as `guard`.
#![no_main]
use eha_guard::GuardOf;
use libfuzzer_sys::fuzz_target;
use std::sync::OnceLock;

static COLD: OnceLock<GuardOf<eha_guard::num::Fx>> = OnceLock::new();

fuzz_target!(|data: &[u8]| {
    eha_guard_fuzz::guard::run::<eha_guard::num::Fx>(data, "guard_fx", &COLD);
});
