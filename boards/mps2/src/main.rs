//! The product image on QEMU `mps2-an386` (Cortex-M4F): the same
//! application as the flashed STM32F411 image ([`eha_guard::product`],
//! `boards/stm32f411/`), with this board module (`board.rs`) instead of the
//! STM32 one, and the Cortex-M parts both share (`boards/cortex-m/`).
//!
//! Run by hand (the controller side is a unix socket on the emulated UART0):
//! ```text
//! cargo fw-build-mps2
//! qemu-system-arm -machine mps2-an386 -cpu cortex-m4 -nographic -monitor none \
//!   -semihosting-config enable=on,target=native \
//!   -chardev socket,id=ctl,path=/tmp/eha.sock,server=on,wait=on -serial chardev:ctl \
//!   -kernel target/thumbv7em-none-eabihf/release/eha-mps2
//! ```
//! `eha-sim product` drives it in closed loop with the reference plant.
//! The defmt log goes over semihosting (QEMU's stdout); only this QEMU board
//! uses semihosting.
#![no_std]
#![no_main]

mod board;
mod vectors;

use board::Mps2;
use core::mem::MaybeUninit;
use cortex_m_rt::entry;
use defmt_semihosting as _;
use eha_guard::product::App;
use eha_guard::GuardConfig;

#[entry]
fn main() -> ! {
    let (mut b, mem) = Mps2::init();
    // The application state lives in .bss, not on the stack.
    static mut APP: MaybeUninit<App> = MaybeUninit::uninit();
    // SAFETY: `main` runs once; this is the only reference to APP.
    let app = App::boot_into(unsafe { &mut *core::ptr::addr_of_mut!(APP) }, &mut b, &GuardConfig::DEFAULT, &mem);
    b.boot_done();
    defmt::info!("eha-mps2 up: reset cause {}, faults {=u32:#010x}", app.reset_cause(), app.guard().faults().bits());
    board::start(&mut b);
    app.run(&mut b)
}
