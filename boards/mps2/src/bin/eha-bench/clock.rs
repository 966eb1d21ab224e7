//! The SysTick clock of the bench: elapsed ticks of the down-counting
//! 24-bit counter (a wrap counted by its interrupt discards the sample) and
//! min / mean / max statistics in instructions (ticks / 25.6 under
//! `-icount shift=10`).

use core::sync::atomic::{AtomicU32, Ordering};
use cortex_m::peripheral::SYST;
use semihosting::eprintln;

/// SysTick wraps since reset (counted by the SysTick handler).
pub static WRAPS: AtomicU32 = AtomicU32::new(0);

/// Min / max / sum of timed samples, SysTick ticks.
pub struct Stats {
    pub min: u32,
    max: u32,
    sum: u64,
    n: u32,
}

impl Stats {
    /// No samples yet.
    pub const fn new() -> Self {
        Stats {
            min: u32::MAX,
            max: 0,
            sum: 0,
            n: 0,
        }
    }
    /// One timed sample, ticks.
    pub fn add(&mut self, ticks: u32) {
        self.min = self.min.min(ticks);
        self.max = self.max.max(ticks);
        self.sum += ticks as u64;
        self.n += 1;
    }
    /// Prints min / mean / max instructions (ticks / 25.6) minus `overhead` ticks.
    pub fn report(&self, name: &str, overhead: u32) {
        let n = self.n.max(1) as u64;
        let i = |t: u64| (t.saturating_sub(overhead as u64) * 10) / 256;
        let mean10 = (self.sum.saturating_sub(overhead as u64 * n) * 100) / (256 * n);
        eprintln!(
            "{}: instructions/tick min {} mean {}.{} max {} (n = {})",
            name,
            i(self.min as u64),
            mean10 / 10,
            mean10 % 10,
            i(self.max as u64),
            self.n
        );
    }
}

#[inline(always)]
/// The SysTick counter now.
pub fn now() -> u32 {
    SYST::get_current()
}

/// Elapsed ticks of the down-counting 24-bit SysTick, `None` if it wrapped.
#[inline(always)]
pub fn elapsed(t0: u32, w0: u32) -> Option<u32> {
    let t1 = now();
    if WRAPS.load(Ordering::Relaxed) != w0 {
        return None;
    }
    Some(t0.wrapping_sub(t1) & 0x00FF_FFFF)
}
