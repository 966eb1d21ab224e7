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
//! (the board-agnostic product loop; the board images in `boards/mps2/` and
//! `boards/stm32f411/`).
//!
//! # Integrating the guard into a 10 ms task
//!
//! The guard is one value: build it once at boot ([`Guard::new`], or
//! [`GuardOf::new_in`] into a static), then every 10 ms hand it the tick's
//! sample ([`Guard::tick`]; [`GuardOf::tick_missing`] when none arrived) and
//! drive the LNG valve and the status pin from the [`Output`]. Writing the
//! guard's [`ThermalRecord`] to two slots of RAM that a reset does not clear
//! lets a warm reset resume from the estimate ([`memory`]); a power-on reads
//! two empty slots and starts cold. Faults never stop the loop: a bad or
//! missing input latches a fault in [`Output::faults`] and opens the valve
//! in the same tick.
//!
//! ```
//! use eha_guard::memory::slots::{restore_from, AbWriter};
//! use eha_guard::{Guard, GuardConfig, Sample, ThermalRecord};
//!
//! // Boot. On the target, `ram` is a static in RAM that a reset leaves as it
//! // is (cortex-m-rt: `#[link_section = ".uninit.records"]`).
//! let mut ram = [ThermalRecord::EMPTY; 2];
//! let mut guard = Guard::new(&GuardConfig::DEFAULT, restore_from(&ram[0], &ram[1]));
//! let mut records = AbWriter::after_boot(&ram[0], &ram[1]);
//! let mut recorded_epoch = None;
//!
//! // The 10 ms task: 60 s of the pump under load (65 bar across it, 100 rpm).
//! let mut out = guard.output();
//! for tick in 0..6000u32 {
//!     let valve_switch_open = out.valve_open; // the valve's position switch
//!     guard.valve_feedback(valve_switch_open);
//!     out = match read_sensors(tick) {
//!         Some(sample) => guard.tick(&sample),
//!         None => guard.tick_missing(), // no fresh sample: counted, stale after 50 ms
//!     };
//!     // Pins are high = healthy, so a stopped MCU leaves the valve open
//!     // and the alarm on.
//!     set_pins(!out.valve_open, !out.alarm && !out.derate);
//!     // The record, whenever the guard's recorded state has changed.
//!     if recorded_epoch != Some(guard.epoch()) {
//!         recorded_epoch = Some(guard.epoch());
//!         records.write(&guard.snapshot_unsealed(), |slot, rec| ram[slot] = *rec);
//!     }
//! }
//! // One minute from 16 °C warms the drain oil (to 20.2 °C), far from the
//! // 40 °C valve limit.
//! assert_eq!(out.faults.bits(), 0, "consistent sensors latch no fault");
//! assert!(out.drain_c > 16.0 && out.drain_c < 40.0 && !out.valve_open, "{out:?}");
//! // A warm reset now would resume from the newest record.
//! assert!(matches!(restore_from(&ram[0], &ram[1]), eha_guard::Restore::Warm(_)));
//!
//! /// The tick's sensor scan in SI-ish units (A, bar, rpm, mm, °C); `None`
//! /// when the scan did not complete in time. Here: 65 bar across the pump
//! /// at 100 rpm and the motor current these take.
//! fn read_sensors(_tick: u32) -> Option<Sample> {
//!     let (p_a_bar, p_b_bar, speed_rpm) = (70.0, 5.0, 100.0);
//!     Some(Sample { current_a: motor_current_a(p_a_bar - p_b_bar, speed_rpm), p_a_bar, p_b_bar, speed_rpm, position_mm: 0.0, ambient_c: 16.0 })
//! }
//! # /// Motor current of the paper's rig at a pressure difference and speed
//! # /// (the torque balance the guard's cross-check expects; its viscous
//! # /// friction at 40 °C, within the check's 5 W of the cold oil's at this
//! # /// low speed).
//! # fn motor_current_a(dp_bar: f32, rpm: f32) -> f32 {
//! #     let p = &eha_guard::params::DEFAULT;
//! #     let d = p.displacement_m3_per_rad as f32;
//! #     let dp = dp_bar * 1e5;
//! #     let w = rpm * core::f32::consts::PI / 30.0;
//! #     let t_f = p.no_load_torque_nm as f32 + p.viscous_w_s2_per_rad2 as f32 * w + p.eta_m as f32 * d * dp;
//! #     (d * dp + t_f) / p.torque_constant_nm_per_a as f32
//! # }
//! # fn set_pins(_valve_pin: bool, _ok_pin: bool) {}
//! ```
//!
//! The product application ([`product::App`]) is this loop with the
//! controller link, the non-volatile record, commands and the watchdog; the
//! board images in `boards/` run it on QEMU and on an STM32F411.
#![no_std]
#![warn(missing_docs)]
#![cfg_attr(not(test), deny(clippy::unwrap_used, clippy::expect_used, clippy::panic, clippy::indexing_slicing))]

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
pub mod trace;
pub mod validate;

pub use faults::{ChannelSet, Faults};
pub use guard::{ClearResult, Guard, GuardConfig, GuardOf, Real};
pub use interface::{Output, Reports, Sample};
pub use memory::{Restore, ThermalRecord};

/// This firmware library's version (the crate's, `MAJOR.MINOR.PATCH`).
pub const VERSION: &str = env!("CARGO_PKG_VERSION");

/// Whether this build obeys the test-only hang and panic injection commands
/// (feature `fault-inject`, QEMU test images only). A flashed image asserts
/// at compile time that it is `false`.
pub const FAULT_INJECT: bool = cfg!(feature = "fault-inject");

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
