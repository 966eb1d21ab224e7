//! The tick counter: the board's 10 ms timer interrupt calls [`advance`],
//! the tick loop reads [`count`] and sleeps in [`wait`] until it moves.

use core::sync::atomic::{AtomicU32, Ordering::Relaxed};
use cortex_m::interrupt;

static TICKS: AtomicU32 = AtomicU32::new(0);

/// One timer period has elapsed (called from the timer's interrupt handler).
#[inline]
pub fn advance() {
    TICKS.fetch_add(1, Relaxed);
}

/// Adds `n` periods at once: those an interrupts-off stall swallowed (a
/// flash erase), which the timer's pending flag counted as one.
#[inline]
pub fn catch_up(n: u32) {
    TICKS.fetch_add(n, Relaxed);
}

/// Timer periods since boot (wrapping).
#[inline]
pub fn count() -> u32 {
    TICKS.load(Relaxed)
}

/// Sleeps (WFI) until the count differs from `seen`.
#[inline]
pub fn wait(seen: u32) {
    while TICKS.load(Relaxed) == seen {
        // WFI with interrupts masked: a tick that fires between the check
        // and the WFI still wakes it (pending), and runs after `free`.
        interrupt::free(|_| {
            if TICKS.load(Relaxed) == seen {
                cortex_m::asm::wfi();
            }
        });
    }
}
