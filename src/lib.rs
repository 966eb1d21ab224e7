//! EHA drain-oil thermal protection core (`#![no_std]`).
//!
//! Reduced-order thermal model of an electro-hydrostatic actuator (Liu et al.,
//! losses eqs. 1-11), multi-rate: inputs validated and losses accumulated every
//! 10 ms tick, the model advanced every 100 ms with an exact zero-order hold of
//! the tick means; LNG valve protection (section IV, eqs. 20-25, Table 6), input
//! validation with a conservative fail-safe in the same tick, an event trace and
//! thermal memory across resets.
//!
//! Module map: [`params`] (SI parameters) → [`model`] (discretised model, generic
//! over [`num::Num`]: `f64`, `f32`, fixed point) → [`validate`], [`protection`],
//! [`trace`], [`memory`] → [`guard`] (`Guard::new`, `Guard::tick`) → [`product`]
//! (the board-agnostic product loop; boards in `src/bin/eha-mps2/` and
//! `src/bin/eha-stm32f4/`).
#![no_std]
#![warn(missing_docs)]
#![cfg_attr(not(test), deny(clippy::unwrap_used, clippy::expect_used, clippy::panic, clippy::indexing_slicing))]

// The hang and panic injection commands are for the QEMU test image only: a
// flashed board must never obey them.
#[cfg(all(feature = "board-stm32f4", feature = "fault-inject"))]
compile_error!("`fault-inject` is for the QEMU test images only: never in the flashed STM32F411 image (`board-stm32f4`)");

pub mod crosscheck;
pub mod faults;
pub mod guard;
pub mod interface;
pub mod linalg;
pub mod memory;
pub mod model;
pub mod num;
pub mod params;
pub mod params_block;
pub mod product;
pub mod protection;
pub mod protocol;
pub mod speedcheck;
#[cfg(target_os = "none")]
pub mod stack;
pub mod trace;
pub mod validate;
#[cfg(all(target_os = "none", not(feature = "board-stm32f4")))]
mod vectors;

pub use faults::{ChannelSet, Faults};
pub use guard::{ClearResult, Guard, GuardConfig, GuardOf, Real};
pub use interface::{Output, Reports, Sample};
pub use memory::{Restore, ThermalRecord};

/// This firmware library's version (the crate's, `MAJOR.MINOR.PATCH`).
pub const VERSION: &str = env!("CARGO_PKG_VERSION");

#[cfg(test)]
mod build_checks {
    extern crate std;

    /// The host test profile (`cargo test --profile fast`, Cargo.toml
    /// `[profile.fast.package.eha-guard]`) builds this crate with overflow
    /// checks and debug assertions, so an arithmetic overflow anywhere in the
    /// firmware core fails the host tests instead of wrapping silently. This
    /// test fails if a profile change drops them.
    #[test]
    // The constant is the point: it is what the build profile made it.
    #[allow(clippy::assertions_on_constants)]
    fn firmware_core_is_tested_with_overflow_checks_and_debug_assertions() {
        assert!(cfg!(debug_assertions), "debug assertions are off in this test build of eha-guard");
        let r = std::panic::catch_unwind(|| core::hint::black_box(u8::MAX) + core::hint::black_box(1u8));
        assert!(r.is_err(), "u8::MAX + 1 did not panic: overflow checks are off in this test build of eha-guard");
    }
}
