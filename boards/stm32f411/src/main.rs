//! The flashed product image: STM32F411 (Cortex-M4F, e.g. WeAct "Black Pill"
//! STM32F411CEU6). The same application as the QEMU product image
//! ([`eha_guard::product`], `boards/mps2/`), with this board module
//! (`board.rs`) instead of the QEMU one, and the Cortex-M parts both share
//! (`boards/cortex-m/`).
//!
//! Build (CI keeps it building and checks that it has no semihosting symbol):
//! ```text
//! cargo fw-build-stm32f4
//! ```
//! (memory map: this folder's `memory.x`, linked through `build.rs`).
//!
//! Flash and run with probe-rs (ST-LINK or any CMSIS-DAP probe on SWD):
//! ```text
//! cargo install probe-rs-tools --locked          # once
//! probe-rs run --chip STM32F411CEUx target/thumbv7em-none-eabihf/release/eha-stm32f4
//! ```
//! The defmt log goes over RTT (`defmt-rtt`, non-blocking: a full buffer
//! drops log frames, it never stalls the tick loop); without a probe the
//! board runs on its own. Wiring, what the controller must send, and what the
//! board does on every fault: `docs/firmware.md`, "STM32F411 product image".
#![no_std]
#![no_main]

mod board;
mod rtc;

use board::F411;
use core::mem::MaybeUninit;
use cortex_m_rt::entry;
use defmt_rtt as _;
use eha_guard::product::App;
use eha_guard::GuardConfig;

// The hang and panic injection commands are for the QEMU test images only: a
// flashed board must never obey them.
const _: () = assert!(!eha_guard::FAULT_INJECT, "`fault-inject` is for the QEMU test images only: never in the flashed STM32F411 image");

#[entry]
fn main() -> ! {
    let (mut b, mem) = F411::init();
    // The application state lives in .bss, not on the stack.
    static mut APP: MaybeUninit<App> = MaybeUninit::uninit();
    // SAFETY: `main` runs once; this is the only reference to APP.
    let app = App::boot_into(unsafe { &mut *core::ptr::addr_of_mut!(APP) }, &mut b, &GuardConfig::DEFAULT, &mem);
    b.boot_done();
    defmt::info!("eha-stm32f4 up: reset cause {}, faults {=u32:#010x}", app.reset_cause(), app.guard().faults().bits());
    board::start(&mut b);
    app.run(&mut b)
}
