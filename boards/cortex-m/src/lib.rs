//! The Cortex-M parts both product boards share (`boards/mps2`,
//! `boards/stm32f411`): what a board module needs beyond its own
//! peripherals to run [`eha_guard::product::App`].
//!
//! - [`tick`]: the tick counter that the board's 10 ms timer interrupt
//!   advances, and the low-power wait for the next tick;
//! - [`rx`]: the controller link's receive queue, filled by the board's
//!   UART interrupt;
//! - [`noinit`]: the thermal and reset-cause records in no-init RAM (what a
//!   warm reset keeps) and the [`eha_guard::product::BootMemory`] they give;
//! - [`stack`]: stack painting (boot and tick-loop high-water marks).
//!
//! Target only (`target_os = "none"`): a host build of this crate is empty.
//! The functions that were each board's own code are `#[inline]`: they
//! compile into the board's image as they did there (the product image's
//! flash budget has no room for a different inlining).
#![no_std]
#![warn(missing_docs)]

#[cfg(target_os = "none")]
pub mod noinit;
#[cfg(target_os = "none")]
pub mod rx;
#[cfg(target_os = "none")]
pub mod stack;
#[cfg(target_os = "none")]
pub mod tick;

/// The [`eha_guard::product::Board`] methods every board answers from this
/// crate alone (receive queue, tick counter, no-init records): expands, inside
/// a board's `impl Board for …` block, to `read_rx`, `rx_dropped`, `ticks`,
/// `wait_tick`, `store_record`, `store_cause`, `stack_high_water_b`,
/// `boot_stack_b` (the board struct's `boot_stack_b: u32` field, which its
/// `boot_done` sets from [`stack::boot_done`]) and `param_block` (the
/// linker's PARAMS region). The board writes the
/// methods that touch its own peripherals (pins, UART transmit, watchdog,
/// non-volatile store, clocks).
#[macro_export]
macro_rules! shared_board_methods {
    () => {
        fn read_rx(&mut self, buf: &mut [u8]) -> usize {
            $crate::rx::read(buf)
        }

        fn rx_dropped(&self) -> u32 {
            $crate::rx::dropped()
        }

        fn ticks(&self) -> u32 {
            $crate::tick::count()
        }

        fn wait_tick(&mut self, seen: u32) {
            $crate::tick::wait(seen);
        }

        fn store_record(&mut self, slot: usize, rec: &::eha_guard::memory::ThermalRecord) {
            $crate::noinit::store_record(slot, rec);
        }

        fn store_cause(&mut self, rec: &::eha_guard::product::reset::CauseRecord) {
            $crate::noinit::store_cause(rec);
        }

        fn stack_high_water_b(&self) -> u32 {
            $crate::stack::high_water()
        }

        fn boot_stack_b(&self) -> u32 {
            self.boot_stack_b
        }

        fn param_block(&self) -> Option<&'static [u8; ::eha_guard::params_block::BLOCK_LEN]> {
            Some(::eha_guard::params_block::flash_region())
        }
    };
}

/// The two fatal handlers every board has, both ending in the board's own
/// `fail` (safe outputs, the reset cause in no-init RAM, a reset): the
/// HardFault exception and the panic handler. `fail` is a function
/// `fn(ResetCause) -> !` of the board module.
#[macro_export]
macro_rules! fatal_handlers {
    ($fail:ident) => {
        #[cortex_m_rt::exception]
        unsafe fn HardFault(_ef: &cortex_m_rt::ExceptionFrame) -> ! {
            $fail(::eha_guard::product::wire::ResetCause::HardFault)
        }

        #[panic_handler]
        fn panic(_info: &core::panic::PanicInfo) -> ! {
            $fail(::eha_guard::product::wire::ResetCause::Panic)
        }
    };
}
