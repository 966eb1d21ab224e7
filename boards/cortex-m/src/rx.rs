//! The controller link's receive queue: the board's UART interrupt
//! [`push`]es each received byte, the tick loop [`read`]s them
//! (`Board::read_rx`). A byte that finds the queue full is counted as
//! dropped, as is a byte the UART itself lost ([`lost`], an overrun).

use core::cell::RefCell;
use core::sync::atomic::{AtomicU32, Ordering::Relaxed};
use cortex_m::interrupt::{self as irq, Mutex};
use heapless::Deque;

static RX_DROPPED: AtomicU32 = AtomicU32::new(0);
static RX: Mutex<RefCell<Deque<u8, 256>>> = Mutex::new(RefCell::new(Deque::new()));

/// Queues a received byte (interrupt handler); a full queue drops it.
#[inline]
pub fn push(b: u8) {
    irq::free(|cs| {
        if RX.borrow(cs).borrow_mut().push_back(b).is_err() {
            RX_DROPPED.fetch_add(1, Relaxed);
        }
    });
}

/// Counts a byte the UART lost before it could be read (overrun).
#[inline]
pub fn lost() {
    RX_DROPPED.fetch_add(1, Relaxed);
}

/// Moves queued bytes into `buf`, oldest first; returns how many.
#[inline]
pub fn read(buf: &mut [u8]) -> usize {
    irq::free(|cs| {
        let mut q = RX.borrow(cs).borrow_mut();
        let mut n = 0;
        for slot in buf.iter_mut() {
            let Some(b) = q.pop_front() else { break };
            *slot = b;
            n += 1;
        }
        n
    })
}

/// Bytes dropped since boot (queue full or UART overrun).
#[inline]
pub fn dropped() -> u32 {
    RX_DROPPED.load(Relaxed)
}
