//! STM32F411 board (through `stm32f4xx-hal` 0.23): USART1 (controller link,
//! RX by interrupt), TIM2 (10 ms tick interrupt), IWDG, PA5/PA6 outputs, the
//! non-volatile thermal record in flash sectors 6-7, the backup-domain RTC
//! (`rtc.rs`: the off-time of a power loss), DWT cycle stamps.
//!
//! Pins (wiring and the valve the board needs: `docs/firmware.md`, "STM32F411
//! product image"):
//! - PA9 = USART1 TX, PA10 = USART1 RX (AF7), 460800 baud 8N1;
//! - PA5 = valve pin, push-pull, high = energise = close the normally-open
//!   valve;
//! - PA6 = OK pin, push-pull, high = no alarm, no derate.
//!
//! Both outputs are *high = healthy*: at reset the pins are floating inputs
//! (the driver's pull-down holds them low), so an MCU in reset, unpowered or
//! stopped by the watchdog leaves the valve open and the alarm on. The fault
//! handlers drive both pins low with one BSRR write before they reset.
//!
//! The HAL configures every peripheral; the two interrupt handlers and the
//! fault handlers touch registers through the PAC directly (a flag clear, a
//! data register read, one BSRR write), so they own no HAL object.
//!
//! Tick counter, receive queue, no-init records and stack painting:
//! `eha_cortex_m` (shared with the QEMU board).

use core::cell::RefCell;
use core::sync::atomic::{AtomicU32, Ordering::Relaxed};
use cortex_m::interrupt::{self as irq, Mutex};
use cortex_m::peripheral::{DWT, NVIC, SCB};
use cortex_m_rt::exception;
use eha_cortex_m::{noinit, rx, stack, tick};
use eha_guard::memory::nv::{Blocking, NvLoad, NvStore};
use eha_guard::memory::ThermalRecord;
use eha_guard::product::wire::{Pins, ResetCause};
use eha_guard::product::{Board, BootMemory};
use embedded_storage::nor_flash::{ErrorType, NorFlash, ReadNorFlash};
use stm32f4xx_hal::flash::{FlashExt, LockedFlash};
use stm32f4xx_hal::gpio::{Output, PinState, PushPull, PA5, PA6};
use stm32f4xx_hal::pac::{self, interrupt, Interrupt};
use stm32f4xx_hal::prelude::*;
use stm32f4xx_hal::rcc::Config;
use stm32f4xx_hal::serial::{config::Config as SerialConfig, Rx, Tx};
use stm32f4xx_hal::timer::{CounterUs, Event};
use stm32f4xx_hal::watchdog::IndependentWatchdog;

/// External crystal (25 MHz on the WeAct board). A UART at 460800 baud needs
/// it: the internal HSI drifts by several percent over temperature.
const HSE_HZ: u32 = 25_000_000;
/// Core clock: USART1 (APB2, 100 MHz) then divides to 460829 baud (+0.006 %).
const SYSCLK_HZ: u32 = 100_000_000;
/// Core cycles per 10 ms tick (DWT CYCCNT counts core cycles).
const CYCLES_PER_TICK: u32 = SYSCLK_HZ / 100;
/// Controller link rate.
const BAUD: u32 = 460_800;

/// Watchdog window while the tick loop runs, ms (nominal, at the 32 kHz LSI).
/// The LSI of the F411 is 17-47 kHz, so the real window is 170-470 ms: at
/// least 17 ticks, room for overruns, and a hung MCU (pins frozen where they
/// were, possibly valve closed) is reset within half a second.
const WDT_RUN_MS: u32 = 250;
/// Watchdog window during boot (non-volatile record scan) and during each
/// flash sector erase, ms nominal: 5.4 s at the fastest LSI (47 kHz), above
/// the 4 s maximum erase time of a 128 KiB sector at the HAL's x8
/// parallelism, during which the CPU is stalled (single-bank flash).
const WDT_LONG_MS: u32 = 8_000;

/// Byte range of the non-volatile thermal record, offsets from the start of
/// flash: sectors 6-7 (2 x 128 KiB at 0x0804_0000, region `NVREC` of
/// `boards/stm32f411/memory.x`; wear budget in docs/firmware.md).
const NV_RANGE: core::ops::Range<u32> = 0x4_0000..0x8_0000;
/// Erase sector of the NV range, bytes.
const SECTOR: u32 = 128 * 1024;

/// GPIOA BSRR value that drives PA5 (valve) and PA6 (OK) low: the reset
/// half (bits 16..32) of the set/reset register, one bit per pin.
const SAFE_BSRR: u32 = (1 << (16 + 5)) | (1 << (16 + 6));

/// The IWDG, shared by `feed_watchdog` and the flash erase (both thread
/// mode; no interrupt handler touches it).
static WDT: Mutex<RefCell<Option<IndependentWatchdog>>> = Mutex::new(RefCell::new(None));
/// The window the erase restores after it has widened it.
static WDT_BASE_MS: AtomicU32 = AtomicU32::new(WDT_LONG_MS);

/// Puts the outputs in their safe state with one register write: valve pin
/// low (valve open), OK pin low (alarm). Harmless before GPIOA is set up
/// (the pins are then inputs, held low by the driver's pull-down).
fn safe_outputs() {
    // SAFETY: BSRR is a write-only set/reset register: this write clears the
    // output bits of PA5 and PA6 atomically and touches no other pin.
    unsafe { (*pac::GPIOA::ptr()).bsrr().write(|w| w.bits(SAFE_BSRR)) };
}

/// Masks interrupts, makes the outputs safe, records `cause` and resets the
/// MCU (SYSRESETREQ).
fn fail(cause: ResetCause) -> ! {
    irq::disable();
    safe_outputs();
    noinit::record_cause(cause);
    SCB::sys_reset()
}

fn iwdg_updating() -> bool {
    // SAFETY: read of IWDG_SR (PVU, RVU), no side effect.
    unsafe { (*pac::IWDG::ptr()).sr().read().bits() & 0b11 != 0 }
}

fn with_wdt(f: impl FnOnce(&mut IndependentWatchdog)) {
    irq::free(|cs| {
        if let Some(w) = WDT.borrow(cs).borrow_mut().as_mut() {
            f(w);
        }
    });
}

/// Sets the watchdog window to `ms` and restarts the countdown with it. The
/// IWDG ignores a prescaler/reload write while the previous one is still
/// crossing into its clock domain (PVU/RVU), and a reload takes the value
/// that has arrived there: wait before the write and before the reload.
/// The waits (a few LSI cycles) run with interrupts enabled.
fn watchdog_window(ms: u32) {
    while iwdg_updating() {}
    with_wdt(|w| w.start(ms.millis()));
    while iwdg_updating() {}
    with_wdt(|w| w.feed());
}

/// The internal flash, unlocked only for the duration of an erase or a
/// write (the HAL's `UnlockedFlash` relocks when dropped).
struct Flash(LockedFlash);

impl ErrorType for Flash {
    type Error = stm32f4xx_hal::flash::Error;
}

impl ReadNorFlash for Flash {
    const READ_SIZE: usize = 1;
    fn read(&mut self, offset: u32, bytes: &mut [u8]) -> Result<(), Self::Error> {
        ReadNorFlash::read(&mut self.0, offset, bytes)
    }
    fn capacity(&self) -> usize {
        ReadNorFlash::capacity(&self.0)
    }
}

impl NorFlash for Flash {
    const WRITE_SIZE: usize = 1;
    const ERASE_SIZE: usize = SECTOR as usize;
    /// One sector at a time, each under the long watchdog window: the CPU
    /// stalls for the whole erase (up to 4 s per 128 KiB sector, single
    /// bank), about once per 2 000 record writes. The run window is restored
    /// (and the countdown restarted) afterwards.
    fn erase(&mut self, from: u32, to: u32) -> Result<(), Self::Error> {
        let mut at = from;
        let mut result = Ok(());
        while at < to && result.is_ok() {
            watchdog_window(WDT_LONG_MS);
            let end = at.saturating_add(SECTOR).min(to);
            result = NorFlash::erase(&mut self.0.unlocked(), at, end);
            at = end;
        }
        watchdog_window(WDT_BASE_MS.load(Relaxed));
        result
    }
    fn write(&mut self, offset: u32, bytes: &[u8]) -> Result<(), Self::Error> {
        NorFlash::write(&mut self.0.unlocked(), offset, bytes)
    }
}


/// The board's peripherals (the tick counter and the receive queue are
/// shared with the interrupt handlers).
pub struct F411 {
    valve: PA5<Output<PushPull>>,
    ok: PA6<Output<PushPull>>,
    tx: Tx<pac::USART1>,
    rx: Rx<pac::USART1>,
    tick: CounterUs<pac::TIM2>,
    nv: Option<NvStore<Blocking<Flash>>>,
    nv_errors: u32,
    boot_stack_b: u32,
    /// The backup-domain calendar (off-time of a power loss).
    rtc: crate::rtc::Rtc,
}

/// The hardware's hint from RCC_CSR (read before it is cleared).
fn hw_hint(csr: u32) -> Option<ResetCause> {
    const IWDGRSTF: u32 = 1 << 29;
    const PORRSTF: u32 = 1 << 27;
    const BORRSTF: u32 = 1 << 25;
    if csr & IWDGRSTF != 0 {
        Some(ResetCause::Watchdog)
    } else if csr & (PORRSTF | BORRSTF) != 0 {
        Some(ResetCause::PowerOn)
    } else {
        None
    }
}

impl F411 {
    /// Safe outputs, stack paint, watchdog armed (long boot window), clocks,
    /// peripherals, and what the memories hold.
    pub fn init() -> (F411, BootMemory) {
        let Some(dp) = pac::Peripherals::take() else { fail(ResetCause::Other) };
        let Some(mut cp) = cortex_m::Peripherals::take() else { fail(ResetCause::Other) };
        // 1. Safe outputs first (still on the 16 MHz HSI): valve open, alarm.
        let mut rcc = dp.RCC.constrain();
        let gpioa = dp.GPIOA.split(&mut rcc);
        let valve = gpioa.pa5.into_push_pull_output_in_state(PinState::Low);
        let ok = gpioa.pa6.into_push_pull_output_in_state(PinState::Low);
        stack::paint();
        // 2. Watchdog (LSI, independent of the clock tree below): a boot that
        // hangs, e.g. on a crystal that never starts, is reset.
        // With a probe attached, the IWDG stops while the core is halted, and
        // the bus clocks run during WFI so that RTT can be read (both bits
        // only matter to a debugger).
        let wdt = IndependentWatchdog::new(dp.IWDG);
        wdt.stop_on_debug(&dp.DBGMCU, true);
        dp.DBGMCU.cr().modify(|_, w| w.dbg_sleep().set_bit());
        irq::free(|cs| WDT.borrow(cs).replace(Some(wdt)));
        watchdog_window(WDT_LONG_MS);
        // 3. Why we reset, from the hardware, then clear the flags (RMVF).
        let csr = rcc.csr().read().bits();
        rcc.csr().modify(|_, w| w.rmvf().clear());
        let mut rcc = rcc.freeze(Config::hse(HSE_HZ.Hz()).sysclk(SYSCLK_HZ.Hz()));
        cp.DCB.enable_trace();
        cp.DWT.enable_cycle_counter();
        // 4. Controller link (enabled, RX interrupt off until `start`) and tick timer.
        let serial = dp.USART1.serial((gpioa.pa9, gpioa.pa10), SerialConfig::default().baudrate(BAUD.bps()), &mut rcc);
        let Ok(serial) = serial else { fail(ResetCause::Other) };
        let (tx, rx) = serial.split();
        let tick = dp.TIM2.counter_us(&mut rcc);
        // 5. Memories: no-init RAM records, the non-volatile record, the cause.
        let mut nv = NvStore::new(Blocking(Flash(LockedFlash::new(dp.FLASH))), NV_RANGE).ok();
        // A store that cannot be opened is a damaged record, not an empty
        // one: the machine may be hot (conservative start).
        let nv_rec = nv.as_mut().map_or(NvLoad::Damaged, |n| n.load());
        let alive = crate::rtc::alive_load().and_then(eha_guard::memory::alive_from_word);
        let mem: BootMemory = noinit::boot_memory(nv_rec, alive.map(|a| a.0), alive.is_some_and(|a| a.1), hw_hint(csr));
        defmt::info!(
            "RCC_CSR {=u32:#010x}, sysclk {=u32} Hz, NV store {}, NV record {}",
            csr,
            rcc.clocks.sysclk().raw(),
            nv.is_some(),
            nv_rec != NvLoad::Empty
        );
        // The RTC: started here (the LSE crystal needs up to ~2 s; never waited for).
        let mut rtc = crate::rtc::Rtc::new();
        let _ = rtc.seconds();
        let board = F411 { valve, ok, tx, rx, tick, nv, nv_errors: 0, boot_stack_b: 0, rtc };
        (board, mem)
    }

    /// Called after `App::boot`: the boot stack is measured, then repainted so
    /// that the status reply reports the tick loop's own high-water mark.
    pub fn boot_done(&mut self) {
        self.boot_stack_b = stack::boot_done();
    }
}

/// Starts USART1 reception (RXNE interrupt), the 10 ms tick, and the run
/// watchdog window.
pub fn start(b: &mut F411) {
    b.rx.listen();
    if b.tick.start(10.millis()).is_err() {
        fail(ResetCause::Other);
    }
    b.tick.listen(Event::Update);
    WDT_BASE_MS.store(WDT_RUN_MS, Relaxed);
    watchdog_window(WDT_RUN_MS);
    // SAFETY: the handlers only touch the tick counter and the receive queue
    // (atomics or a critical section) and their own peripheral's flag/data
    // registers.
    unsafe {
        NVIC::unmask(Interrupt::USART1);
        NVIC::unmask(Interrupt::TIM2);
    }
}

impl Board for F411 {
    eha_cortex_m::shared_board_methods!();

    fn write_tx(&mut self, bytes: &[u8]) {
        // Blocking per byte: a 36-byte tick reply takes 0.8 ms at 460800 baud.
        for &b in bytes {
            let _ = stm32f4xx_hal::block!(self.tx.write(b));
        }
    }

    fn set_pins(&mut self, pins: Pins) -> Pins {
        self.valve.set_state(if pins.valve_pin { PinState::High } else { PinState::Low });
        self.ok.set_state(if pins.ok_pin { PinState::High } else { PinState::Low });
        // Read back from the output data register.
        Pins { valve_pin: self.valve.is_set_high(), ok_pin: self.ok.is_set_high() }
    }

    fn feed_watchdog(&mut self) {
        with_wdt(|w| w.feed());
    }

    /// Appends the record to flash. A sector erase stalls the CPU (and the
    /// interrupts) for seconds; the timer's pending flag then counts as one
    /// period only, so the periods the stall swallowed are added here from
    /// the cycle counter (rounded down: never ahead of real time), and the
    /// application sees them as an overrun and missing steps.
    fn nv_save(&mut self, rec: &ThermalRecord) -> Option<bool> {
        let nv = self.nv.as_mut()?;
        let (t0, c0) = (tick::count(), DWT::cycle_count());
        let ok = nv.save(rec).is_ok();
        let elapsed = DWT::cycle_count().wrapping_sub(c0) / CYCLES_PER_TICK;
        let counted = tick::count().wrapping_sub(t0);
        if elapsed > counted {
            tick::catch_up(elapsed - counted);
        }
        if !ok {
            self.nv_errors = self.nv_errors.saturating_add(1);
            if self.nv_errors.is_power_of_two() {
                defmt::warn!("NV save failed ({=u32} so far)", self.nv_errors);
            }
        }
        Some(ok)
    }

    fn cycle_stamp(&self) -> u32 {
        DWT::cycle_count()
    }

    fn cycles_since(&self, stamp: u32) -> u32 {
        DWT::cycle_count().wrapping_sub(stamp)
    }

    fn rtc_s(&mut self) -> Option<u32> {
        self.rtc.seconds()
    }

    fn rtc_alive(&mut self, word: u32) {
        crate::rtc::alive_store(word);
    }
}

/// USART1: RXNE or ORE (RXNEIE enables both). Reading SR then DR clears
/// RXNE, ORE, NE, FE and PE; an overrun means at least one byte was lost.
#[interrupt]
fn USART1() {
    // SAFETY: SR and DR of USART1; only this handler reads DR (TX writes it
    // from thread mode, a different register function).
    let usart = unsafe { &*pac::USART1::ptr() };
    loop {
        let sr = usart.sr().read();
        let (rxne, ore) = (sr.rxne().bit_is_set(), sr.ore().bit_is_set());
        if !rxne && !ore {
            break;
        }
        let b = usart.dr().read().bits() as u8;
        if ore {
            rx::lost();
        }
        if rxne {
            rx::push(b);
        }
    }
}

/// TIM2 update: one 10 ms period.
#[interrupt]
fn TIM2() {
    // SAFETY: TIM2_SR flags are rc_w0: writing 1 leaves a flag, 0 clears it;
    // this clears UIF only.
    unsafe { (*pac::TIM2::ptr()).sr().write(|w| w.bits(0xFFFF & !1)) };
    tick::advance();
}

/// Any other interrupt or exception (NMI included): none is expected.
#[exception]
unsafe fn DefaultHandler(_irqn: i16) {
    fail(ResetCause::Exception)
}

eha_cortex_m::fatal_handlers!(fail);
