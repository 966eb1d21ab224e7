//! The STM32F411's real-time clock (RM0383 §17, LSE 32.768 kHz crystal, the
//! backup domain kept by VBAT): seconds since 2000-01-01 for the cooling over
//! a power loss's off-time (`Board::rtc_s`).
//!
//! Never blocks and never resets a running clock: [`Rtc::seconds`] starts the
//! LSE on its first call and returns `None` until the crystal runs (start-up
//! takes up to ~2 s; the guard only needs the clock at non-volatile saves and
//! at boot), then sets up the calendar once (prescalers at their reset values
//! 127/255 give 1 Hz from 32.768 kHz; the calendar starts at 2000-01-01) and
//! reads it from then on. A backup domain that already runs the calendar from
//! the LSE (the usual case after a power loss with VBAT) is only read. A
//! failed step (no crystal, INIT not acknowledged, registers out of sync)
//! gives `None`: no off-time, no cooling — the conservative restore.
//! Built in CI; not run on hardware here.

use stm32f4xx_hal::pac;

const APB1ENR_PWREN: u32 = 1 << 28;
const PWR_CR_DBP: u32 = 1 << 8;
const BDCR_LSEON: u32 = 1 << 0;
const BDCR_LSERDY: u32 = 1 << 1;
const BDCR_RTCSEL: u32 = 0b11 << 8;
const BDCR_RTCSEL_LSE: u32 = 0b01 << 8;
const BDCR_RTCEN: u32 = 1 << 15;
const BDCR_BDRST: u32 = 1 << 16;
const ISR_INITS: u32 = 1 << 4;
const ISR_RSF: u32 = 1 << 5;
const ISR_INITF: u32 = 1 << 6;
const ISR_INIT: u32 = 1 << 7;
/// Polls of a flag that the RTC sets within two RTCCLK periods (61 µs):
/// far more than enough at 100 MHz, and still bounded.
const POLLS: u32 = 100_000;

/// The clock's state in this power cycle.
pub struct Rtc {
    running: bool,
}

impl Rtc {
    /// Not started yet (the first [`Rtc::seconds`] starts it).
    pub const fn new() -> Self {
        Rtc { running: false }
    }

    /// Seconds since 2000-01-01 00:00, or `None` while the clock is not
    /// (yet) running or its registers do not read consistently.
    pub fn seconds(&mut self) -> Option<u32> {
        // SAFETY: RCC, PWR and RTC are used here only through their
        // backup-domain and calendar registers, which no HAL object of this
        // board owns (the HAL's RCC handle only touches the clock tree and
        // the bus enables; APB1ENR is read-modify-written with interrupts
        // masked).
        let (rcc, pwr, rtc) = unsafe { (&*pac::RCC::ptr(), &*pac::PWR::ptr(), &*pac::RTC::ptr()) };
        if !self.running {
            self.running = start(rcc, pwr, rtc);
            if !self.running {
                return None;
            }
        }
        // The shadow registers are valid once RSF is set (cleared by every
        // reset and by the read below).
        if !poll(|| rtc.isr().read().bits() & ISR_RSF != 0) {
            return None;
        }
        let tr = rtc.tr().read().bits();
        let dr = rtc.dr().read().bits();
        // SAFETY: clearing RSF (rc_w0) with the other ISR bits written as read.
        rtc.isr().modify(|r, w| unsafe { w.bits(r.bits() & !ISR_RSF) });
        eha_guard::product::clock::calendar_s(tr, dr)
    }
}

/// The last-alive word (`eha_guard::memory::alive_word`) kept in RTC backup register 0 (VBAT domain: it
/// survives a power loss; reads 0, i.e. `None`, after a backup-domain reset
/// or on a board without VBAT).
pub fn alive_load() -> Option<u32> {
    // SAFETY: BKP0R is read only here and written only by `alive_store`.
    let rtc = unsafe { &*pac::RTC::ptr() };
    let v = rtc.bkpr(0).read().bits();
    (v != 0).then_some(v)
}

/// Stores the last-alive word (called only once [`Rtc::seconds`] has run
/// the clock, which also enabled backup-domain writes, PWR_CR.DBP).
pub fn alive_store(s: u32) {
    // SAFETY: BKP0R belongs to this function (see `alive_load`); a plain
    // 32-bit data register.
    let rtc = unsafe { &*pac::RTC::ptr() };
    rtc.bkpr(0).write(|w| unsafe { w.bits(s) });
}

fn poll(mut done: impl FnMut() -> bool) -> bool {
    (0..POLLS).any(|_| done())
}

/// One non-blocking step towards a running calendar; `true` once it runs.
fn start(rcc: &pac::rcc::RegisterBlock, pwr: &pac::pwr::RegisterBlock, rtc: &pac::rtc::RegisterBlock) -> bool {
    // SAFETY (every `bits` below): documented bits of RM0383 set or cleared,
    // the rest written as read.
    cortex_m::interrupt::free(|_| rcc.apb1enr().modify(|r, w| unsafe { w.bits(r.bits() | APB1ENR_PWREN) }));
    pwr.cr().modify(|r, w| unsafe { w.bits(r.bits() | PWR_CR_DBP) });
    let bdcr = rcc.bdcr().read().bits();
    let lse_selected = bdcr & BDCR_RTCSEL == BDCR_RTCSEL_LSE;
    if lse_selected && bdcr & (BDCR_RTCEN | BDCR_LSERDY) == BDCR_RTCEN | BDCR_LSERDY && rtc.isr().read().bits() & ISR_INITS != 0 {
        return true; // kept by VBAT across the power loss: read only
    }
    if bdcr & BDCR_RTCSEL != 0 && !lse_selected {
        // Another clock source was selected (RTCSEL is write-once): reset the
        // backup domain, which holds no calendar we could trust anyway.
        rcc.bdcr().modify(|r, w| unsafe { w.bits(r.bits() | BDCR_BDRST) });
        rcc.bdcr().modify(|r, w| unsafe { w.bits(r.bits() & !BDCR_BDRST) });
    }
    if rcc.bdcr().read().bits() & BDCR_LSEON == 0 {
        rcc.bdcr().modify(|r, w| unsafe { w.bits(r.bits() | BDCR_LSEON) });
        return false; // the crystal takes up to ~2 s: try again at the next call
    }
    if rcc.bdcr().read().bits() & BDCR_LSERDY == 0 {
        return false;
    }
    rcc.bdcr().modify(|r, w| unsafe { w.bits((r.bits() & !BDCR_RTCSEL) | BDCR_RTCSEL_LSE | BDCR_RTCEN) });
    if rtc.isr().read().bits() & ISR_INITS != 0 {
        return true;
    }
    // Calendar never set: start it at 2000-01-01 00:00 (TR 0, DR 0x2101:
    // Monday, January 1st; prescalers at their reset values, 24-hour format).
    rtc.wpr().write(|w| unsafe { w.bits(0xCA) });
    rtc.wpr().write(|w| unsafe { w.bits(0x53) });
    rtc.isr().modify(|r, w| unsafe { w.bits(r.bits() | ISR_INIT) });
    let ok = poll(|| rtc.isr().read().bits() & ISR_INITF != 0);
    if ok {
        rtc.tr().write(|w| unsafe { w.bits(0) });
        rtc.dr().write(|w| unsafe { w.bits(0x0000_2101) });
    }
    rtc.isr().modify(|r, w| unsafe { w.bits(r.bits() & !ISR_INIT) });
    rtc.wpr().write(|w| unsafe { w.bits(0xFF) });
    ok
}
