//! C API of the EHA drain-oil guard (`include/eha_guard.h`, generated from
//! this crate by cbindgen: `integrations/capi/header`).
//!
//! A C firmware links the static library (`libeha_guard_capi.a`, built for
//! its Cortex-M target) and calls the same Rust code the product image runs,
//! through a thin shim that only converts types and checks pointers:
//! - [`guard`]: the guard in caller-owned storage ([`EHA_GUARD_STORAGE_SIZE`](guard::EHA_GUARD_STORAGE_SIZE)
//!   bytes aligned to [`EHA_GUARD_STORAGE_ALIGN`](guard::EHA_GUARD_STORAGE_ALIGN); no allocation), booted from
//!   the parameter block and the thermal records as the product boots
//!   (`eha_guard::product::boot_guard`); the tick with the controller's
//!   reports (`GuardOf::tick_reported`), missed and stalled ticks
//!   (`product::catch_up`), the valve pin's read-back, the record hooks
//!   (`product::RecordKeeper`) and the keyed clear/refill commands
//!   (`product::CommandRules`).
//! - [`wire`]: the product's UART frames (sample requests in, tick replies
//!   out) for a C loop that speaks the product protocol (the QEMU example
//!   `examples/fig15`).
//!
//! Every function returns an [`EhaStatus`]; none panics into C: the Rust core
//! has no panicking path (`clippy::panic`, `unwrap_used`, `expect_used` and
//! `indexing_slicing` are denied in it and here); on the host a panic is
//! caught at the boundary (the storage is then poisoned); on the target the
//! panic handler executes `udf`, a fault the firmware's HardFault handler
//! takes (the valve pin's reset level is the safe state).
#![cfg_attr(target_os = "none", no_std)]
#![warn(missing_docs)]
#![cfg_attr(not(test), deny(clippy::unwrap_used, clippy::expect_used, clippy::panic, clippy::indexing_slicing))]

pub mod fault_bits;
pub mod guard;
pub mod types;
pub mod wire;

pub use fault_bits::*;
pub use types::*;

/// Version of the guard library (`eha_guard`), `MAJOR`.
pub const EHA_GUARD_VERSION_MAJOR: u32 = 0;
/// Version of the guard library, `MINOR`.
pub const EHA_GUARD_VERSION_MINOR: u32 = 1;
/// Version of the guard library, `PATCH`.
pub const EHA_GUARD_VERSION_PATCH: u32 = 0;
/// The three as one number, `MAJOR << 16 | MINOR << 8 | PATCH`: compare
/// with `eha_guard_version()` at start-up (a header from another build).
pub const EHA_GUARD_VERSION: u32 = (EHA_GUARD_VERSION_MAJOR << 16) | (EHA_GUARD_VERSION_MINOR << 8) | EHA_GUARD_VERSION_PATCH;
/// Format version of the parameter block this library reads
/// (`eha_guard::params_block::VERSION`); another version is refused (CONFIG).
pub const EHA_PARAMS_FORMAT_VERSION: u32 = 7;
/// Size of a parameter block, bytes (`eha_guard::params_block::BLOCK_LEN`).
pub const EHA_PARAMS_BLOCK_LEN: usize = 2488;
/// Format version of the thermal record (`eha_guard::memory::VERSION`); a
/// record of another version restores as damaged (conservative start).
pub const EHA_RECORD_FORMAT_VERSION: u32 = 5;
/// Size of a thermal record in its byte form, bytes.
pub const EHA_RECORD_BYTES: usize = 60;
/// Version of the UART protocol of [`wire`] (`eha_guard::protocol::PROTOCOL_VERSION`).
pub const EHA_PROTOCOL_VERSION: u32 = 2;

/// `MAJOR.MINOR.PATCH` of a version string as one number.
// Compile time only (an out-of-range index is a build error).
#[allow(clippy::indexing_slicing)]
const fn version_of(s: &str) -> u32 {
    let b = s.as_bytes();
    let (mut part, mut acc, mut out, mut i) = (0, 0u32, 0u32, 0);
    while i <= b.len() {
        if i == b.len() || b[i] == b'.' {
            out |= acc << (16 - 8 * part);
            part += 1;
            acc = 0;
        } else {
            acc = acc * 10 + (b[i] - b'0') as u32;
        }
        i += 1;
    }
    out
}

// The header's numbers are literals (cbindgen does not evaluate Rust
// expressions); these make the build fail when one drifts from the code.
const _: () = {
    assert!(EHA_GUARD_VERSION == version_of(eha_guard::VERSION));
    assert!(EHA_PARAMS_FORMAT_VERSION == eha_guard::params_block::VERSION as u32);
    assert!(EHA_PARAMS_BLOCK_LEN == eha_guard::params_block::BLOCK_LEN);
    assert!(EHA_RECORD_FORMAT_VERSION == eha_guard::memory::VERSION as u32);
    assert!(EHA_RECORD_BYTES == eha_guard::memory::RECORD_BYTES);
    assert!(EHA_PROTOCOL_VERSION == eha_guard::protocol::PROTOCOL_VERSION as u32);
};

/// The library's version, [`EHA_GUARD_VERSION`] of the header it was built with.
#[unsafe(no_mangle)]
pub extern "C" fn eha_guard_version() -> u32 {
    EHA_GUARD_VERSION
}

/// A Rust panic never unwinds into C. The core has no panicking path
/// (denied lints, audited in CI); should one remain, `udf` raises a fault
/// that the firmware's own HardFault handler takes.
#[cfg(all(target_os = "none", target_arch = "arm"))]
#[panic_handler]
fn panic(_: &core::panic::PanicInfo) -> ! {
    loop {
        // SAFETY: `udf` only raises the UsageFault/HardFault exception.
        unsafe { core::arch::asm!("udf #0") };
    }
}
