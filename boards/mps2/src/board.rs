//! QEMU `mps2-an386` board: CMSDK UART0 (controller link), CMSDK timer 0
//! (10 ms tick), CMSDK APB watchdog, FPGAIO LED register as the two output
//! pins (QEMU emulates no GPIO block on this machine; the LED register is a
//! real read/write register that resets to 0, like a GPIO port).
//!
//! Pins: LED bit 0 = valve pin (high = energise = close the normally-open
//! valve), bit 1 = OK pin (high = no alarm). Reset level 0 = valve open,
//! alarm: the safe state.
//!
//! Interrupts (no PAC: the vector table of `vectors.rs` sends every IRQ
//! to `DefaultHandler`, which dispatches by number): UART0 RX = IRQ 0,
//! timer 0 = IRQ 8; the watchdog's warning goes to NMI.
//!
//! Tick counter, receive queue, no-init records and stack painting:
//! `eha_cortex_m` (shared with the STM32F411 board).

use cortex_m::peripheral::{syst::SystClkSource, NVIC, SCB, SYST};
use cortex_m_rt::exception;
use eha_cortex_m::{noinit, rx, stack, tick};
use eha_guard::memory::nv::NvLoad;
use eha_guard::product::wire::{Pins, ResetCause};
use eha_guard::product::{Board, BootMemory};

const SYSCLK_HZ: u32 = 25_000_000;
/// Tick period: 10 ms of the 25 MHz APB clock.
const TICK_RELOAD: u32 = SYSCLK_HZ / 100;
/// Watchdog period: the warning (NMI) after 0.5 s without a feed, the reset
/// after a second period. Long against the 10 ms tick so that a QEMU process
/// descheduled by a loaded host does not look like a hang.
const WDOG_LOAD: u32 = SYSCLK_HZ / 2;

const UART0: usize = 0x4000_4000;
const TIMER0: usize = 0x4000_0000;
const WDOG: usize = 0x4000_8000;
const FPGAIO_LED0: usize = 0x4002_8000;
const IRQ_UART0_RX: u16 = 0;
const IRQ_TIMER0: u16 = 8;

fn wr(addr: usize, v: u32) {
    // SAFETY: MMIO registers of the mps2-an386 memory map (constants above).
    unsafe { core::ptr::write_volatile(addr as *mut u32, v) }
}

fn rd(addr: usize) -> u32 {
    // SAFETY: as in `wr`.
    unsafe { core::ptr::read_volatile(addr as *const u32) }
}

#[derive(Clone, Copy)]
struct Irq(u16);
// SAFETY: the numbers are device interrupt lines of this machine.
unsafe impl cortex_m::interrupt::InterruptNumber for Irq {
    fn number(self) -> u16 {
        self.0
    }
}

/// Puts the outputs in their safe state with one register write: valve
/// pin low (valve open), OK pin low (alarm). Used by the fault handlers.
fn safe_outputs() {
    wr(FPGAIO_LED0, 0);
}

/// Records `cause`, makes the outputs safe and resets the MCU.
fn fail(cause: ResetCause) -> ! {
    safe_outputs();
    noinit::record_cause(cause);
    SCB::sys_reset()
}

/// The board's peripherals (all MMIO; the tick counter and the receive
/// queue are shared with the interrupt handlers).
pub struct Mps2 {
    syst: SYST,
    boot_stack_b: u32,
}


impl Mps2 {
    /// Safe outputs, stack paint, watchdog armed, and what the memories hold.
    pub fn init() -> (Mps2, BootMemory) {
        safe_outputs();
        stack::paint();
        let Some(cp) = cortex_m::Peripherals::take() else { fail(ResetCause::Other) };
        let mut syst = cp.SYST;
        syst.set_clock_source(SystClkSource::Core);
        syst.set_reload(0x00FF_FFFF);
        syst.clear_current();
        syst.enable_counter();
        // Watchdog: unlock, load, interrupt (NMI warning) + reset, lock.
        wr(WDOG + 0xC00, 0x1ACC_E551);
        wr(WDOG, WDOG_LOAD);
        wr(WDOG + 0x008, 0b11);
        wr(WDOG + 0xC00, 0);
        let mem = noinit::boot_memory(NvLoad::Empty, None, false, None);
        (Mps2 { syst, boot_stack_b: 0 }, mem)
    }

    /// Called after `App::boot`: the boot stack is measured, then repainted so
    /// that the status reply reports the tick loop's own high-water mark.
    pub fn boot_done(&mut self) {
        self.boot_stack_b = stack::boot_done();
    }
}

/// Starts UART0 (RX interrupt) and the tick timer.
pub fn start(_b: &mut Mps2) {
    wr(UART0 + 0x010, 16); // BAUDDIV (QEMU needs >= 16; the rate is not modelled)
    wr(UART0 + 0x008, 0b1011); // TX enable, RX enable, RX interrupt enable
    wr(TIMER0 + 0x008, TICK_RELOAD); // RELOAD
    wr(TIMER0 + 0x004, TICK_RELOAD); // VALUE
    wr(TIMER0, 0b1001); // enable, interrupt enable
    // SAFETY: the handlers only touch their peripheral's registers and the
    // tick counter and receive queue (atomics or a critical section).
    unsafe {
        NVIC::unmask(Irq(IRQ_UART0_RX));
        NVIC::unmask(Irq(IRQ_TIMER0));
    }
}

impl Board for Mps2 {
    eha_cortex_m::shared_board_methods!();

    fn write_tx(&mut self, bytes: &[u8]) {
        for &b in bytes {
            while rd(UART0 + 0x004) & 1 != 0 {} // TX full
            wr(UART0, u32::from(b));
        }
    }

    fn set_pins(&mut self, pins: Pins) -> Pins {
        wr(FPGAIO_LED0, u32::from(pins.valve_pin) | (u32::from(pins.ok_pin) << 1));
        let v = rd(FPGAIO_LED0);
        Pins { valve_pin: v & 1 != 0, ok_pin: v & 2 != 0 }
    }

    fn feed_watchdog(&mut self) {
        wr(WDOG + 0xC00, 0x1ACC_E551);
        wr(WDOG + 0x00C, 1); // INTCLR: clears the warning and reloads the count
        wr(WDOG + 0xC00, 0);
    }

    fn cycle_stamp(&self) -> u32 {
        SYST::get_current()
    }

    fn cycles_since(&self, stamp: u32) -> u32 {
        let _ = &self.syst;
        stamp.wrapping_sub(SYST::get_current()) & 0x00FF_FFFF
    }
}

fn uart0_rx() {
    // Acknowledge first, then drain the (one-byte) receive buffer: a byte
    // that arrives after the drain raises the interrupt again. (The other
    // order loses it: its interrupt is cleared with the buffer full, and the
    // UART takes no more bytes while the buffer is full.)
    wr(UART0 + 0x00C, 0b1010); // clear RX and RX-overrun interrupts
    while rd(UART0 + 0x004) & 2 != 0 {
        rx::push(rd(UART0) as u8);
    }
}

fn timer0() {
    wr(TIMER0 + 0x00C, 1);
    tick::advance();
}

#[exception]
unsafe fn DefaultHandler(irqn: i16) {
    match irqn {
        0 => uart0_rx(),
        8 => timer0(),
        _ => fail(ResetCause::Exception),
    }
}

/// The watchdog's warning: the tick loop has not completed for a whole
/// watchdog period.
#[exception]
unsafe fn NonMaskableInt() {
    fail(ResetCause::Watchdog)
}

eha_cortex_m::fatal_handlers!(fail);
