//! Hardware edge: a board trait in the spirit of hubris's `BspInterface`
//! (sampling, valve output via embedded-hal `OutputPin`, time) and the one
//! function the main loop calls per tick.
//!
//! Boards:
//! * QEMU `mps2-an386` (Cortex-M4F) / `mps2-an385` (Cortex-M3): [`mps2::GpioPin`]
//!   drives the valve on CMSDK GPIO0; samples come from the PIL harness
//!   (`src/protocol.rs`, `src/bin/eha-fw.rs`, branch `pil`).
//! * STM32F411 (e.g. WeAct "Black Pill"), `src/bin/eha-stm32f4.rs`, feature
//!   `board-stm32f4`; flashing with probe-rs, see that file.

use crate::guard::{GuardOf, Output, Sample};
use crate::num::Num;
use embedded_hal::digital::OutputPin;

/// What the protection needs from a board.
pub trait Board {
    /// Valve solenoid driver (high = open).
    type Valve: OutputPin;
    /// The newest sample if one arrived since the last call (`None` = missing).
    fn poll_sample(&mut self) -> Option<Sample>;
    /// The valve output.
    fn valve(&mut self) -> &mut Self::Valve;
    /// Blocks until the next 10 ms tick.
    fn wait_tick(&mut self);
    /// Monotonic time, ms (wrapping).
    fn now_ms(&self) -> u32;
}

/// One tick: sample → [`GuardOf::step`] (or [`GuardOf::step_missing`]) → valve pin.
/// A pin error latches the ACTUATOR fault (the valve state is then unknown).
pub fn service<B: Board, N: Num>(board: &mut B, guard: &mut GuardOf<N>) -> Output {
    let out = match board.poll_sample() {
        Some(s) => guard.step(&s),
        None => guard.step_missing(),
    };
    let r = if out.valve_open {
        board.valve().set_high()
    } else {
        board.valve().set_low()
    };
    if r.is_err() {
        guard.report_actuator_fault();
    }
    out
}

/// QEMU MPS2 (AN385/AN386) pieces.
#[cfg(target_os = "none")]
pub mod mps2 {
    use core::convert::Infallible;
    use embedded_hal::digital::{ErrorType, OutputPin};

    /// CMSDK GPIO0 base address on MPS2 AN385/AN386.
    pub const GPIO0_BASE: usize = 0x4001_0000;
    const DATAOUT: usize = 0x004;
    const OUTENSET: usize = 0x010;

    /// One CMSDK GPIO0 output bit (valve solenoid driver).
    pub struct GpioPin {
        mask: u32,
    }

    impl GpioPin {
        /// Claims bit `bit` (0-15) of GPIO0 as an output.
        pub fn new(bit: u8) -> Self {
            let mask = 1u32 << (bit & 15);
            // SAFETY: MMIO register of the CMSDK GPIO block; single-threaded init.
            unsafe { core::ptr::write_volatile((GPIO0_BASE + OUTENSET) as *mut u32, mask) };
            GpioPin { mask }
        }

        fn modify(&mut self, high: bool) {
            let p = (GPIO0_BASE + DATAOUT) as *mut u32;
            // SAFETY: MMIO read-modify-write of DATAOUT from the main loop only.
            unsafe {
                let v = core::ptr::read_volatile(p);
                core::ptr::write_volatile(p, if high { v | self.mask } else { v & !self.mask });
            }
        }
    }

    impl ErrorType for GpioPin {
        type Error = Infallible;
    }

    impl OutputPin for GpioPin {
        fn set_low(&mut self) -> Result<(), Infallible> {
            self.modify(false);
            Ok(())
        }
        fn set_high(&mut self) -> Result<(), Infallible> {
            self.modify(true);
            Ok(())
        }
    }
}
